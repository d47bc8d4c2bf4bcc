//! `lightgrid export`: a scene at one frame as a glTF 2.0 binary (`.glb`), so another engine
//! can render exactly what lightgrid renders (and lightgrid can load it back).

use crate::args::{SceneOptions, Size};
use crate::files::{Files, Kind};
use anyhow::{bail, Result};
use clap::Args;
use lightgrid::image_io::write_atomic;
use std::path::PathBuf;

#[derive(Args)]
pub(crate) struct ExportArgs {
    #[command(flatten)]
    pub(crate) scene: SceneOptions,
    /// Animation frame to export (objects where they are then, the camera at that frame).
    #[arg(long, allow_hyphen_values = true, default_value_t = 0)]
    pub(crate) frame: u32,
    /// Frame size WIDTHxHEIGHT whose aspect ratio the exported camera gets (default: the
    /// scene's own size).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::args::parse_size)]
    pub(crate) size: Option<Size>,
    /// File to write (a *.glb file).
    #[arg(long)]
    pub(crate) out: PathBuf,
}

pub(crate) fn export(a: &ExportArgs) -> Result<()> {
    let glb = a
        .out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    if !glb {
        bail!(
            "--out: {}: scenes are written as glTF binaries; name the file *.glb",
            a.out.display()
        );
    }
    let mut files = Files::default();
    files.output("--out", Some(&a.out), Kind::Data)?;
    a.scene.claim(&mut files)?;
    let scene = a.scene.build()?;
    for loss in lightgrid::scene::gltf::export_losses(&scene) {
        eprintln!("warning: {}: {loss}", a.scene.scene);
    }
    let (w, h) = Size::or_scene(a.size, &scene);
    let bytes = lightgrid::scene::gltf::export(&scene, a.frame, (w, h))?;
    write_atomic(&a.out, &bytes)?;
    outln!(
        "{} frame {}: {} objects, {} lights, camera at {}x{} written to {} ({} bytes)",
        scene.name,
        a.frame,
        scene.objects.len(),
        scene.lights.len(),
        w,
        h,
        a.out.display(),
        bytes.len()
    );
    Ok(())
}
