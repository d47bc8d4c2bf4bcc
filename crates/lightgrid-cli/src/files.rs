//! The files a command reads and writes, checked together before anything is rendered or
//! created: every output writable, images named `*.png`, no two arguments naming the same
//! file, no output naming an input. Files are compared by what they are
//! ([`FileIdentity`]: device and inode), so a hard link, a symlink or another spelling of a
//! path is the file it names; a glTF scene's own buffers and images are inputs too
//! ([`Files::scene`]). Every command's outputs go through here, those placed in an output
//! directory too ([`Files::placed`]).

use anyhow::{bail, Result};
use lightgrid::image_io::{check_png_name, check_writable, file_identity, FileIdentity};
use std::path::{Path, PathBuf};

/// What an output holds.
#[derive(Clone, Copy, PartialEq)]
pub(crate) enum Kind {
    /// An image: written as PNG, so its name must end in `.png`.
    Png,
    /// JSON or text: any name.
    Data,
}

/// Arguments naming files, by flag, with what each names on disk.
#[derive(Default)]
pub(crate) struct Files {
    named: Vec<(String, FileIdentity, bool)>,
}

impl Files {
    fn claim(&mut self, flag: &str, path: &Path, output: bool) -> Result<()> {
        let id = file_identity(path);
        // Reading one file twice is fine; writing one that is also read or written is not.
        let clash = self
            .named
            .iter()
            .find(|(_, p, other_out)| *p == id && (output || *other_out));
        if let Some((other, _, other_out)) = clash {
            let what = if output && *other_out {
                "two outputs cannot be the same file"
            } else {
                "an output cannot replace an input"
            };
            bail!("{flag} and {other} both name {}: {what}", path.display());
        }
        self.named.push((flag.to_string(), id, output));
        Ok(())
    }

    /// An input file (read, never written).
    pub(crate) fn input(&mut self, flag: &str, path: &Path) -> Result<()> {
        self.claim(flag, path, false)
    }

    /// A scene given by `flag` (a catalog name or a glTF file): a file is an input, and so is
    /// every file beside it that the document names as a buffer or an image (resolved as the
    /// loader resolves them), so no output replaces what the scene is made of.
    pub(crate) fn scene(&mut self, flag: &str, spec: &str) -> Result<()> {
        if !lightgrid::scene::gltf::is_gltf_path(spec) {
            return Ok(());
        }
        let path = Path::new(spec);
        self.input(flag, path)?;
        for part in lightgrid::scene::gltf::files_named_by(path) {
            self.input(&format!("{flag} (a file {spec} reads)"), &part)?;
        }
        Ok(())
    }

    /// The files a command places in its output directory `dir` (`--out DIR` of `bench`,
    /// `scaling`, `compare`, `report`), by name: none may be an input, and no two may be one.
    /// Called before any of them is moved into place.
    pub(crate) fn placed(&mut self, flag: &str, dir: &Path, written: &[PathBuf]) -> Result<()> {
        for name in written.iter().filter_map(|p| p.file_name()) {
            self.claim(flag, &dir.join(name), true)?;
        }
        Ok(())
    }

    /// An output file, when given: checked for its kind and writability (nothing is left on
    /// disk) and against every other argument.
    pub(crate) fn output(&mut self, flag: &str, path: Option<&Path>, kind: Kind) -> Result<()> {
        let Some(path) = path else { return Ok(()) };
        if kind == Kind::Png {
            check_png_name(path).map_err(|e| anyhow::anyhow!("{flag}: {e}"))?;
        }
        check_writable(path).map_err(|e| anyhow::anyhow!("{flag}: {e}"))?;
        self.claim(flag, path, true)
    }
}
