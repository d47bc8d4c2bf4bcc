//! glTF 2.0 scenes in and out (`--scene FILE.gltf|.glb`, `lightgrid export`).
//!
//! Reading (`read.rs`, `import.rs`) treats the file as hostile: every index, offset, length
//! and count is checked before it is used or allocated for, totals are bounded
//! (`MAX_VERTICES`, `MAX_TRIANGLES`, `MAX_FILE_BYTES`), the node graph is walked without
//! recursion and refused if it is not a forest, and any problem is an [`Error::Gltf`] naming
//! the file and the problem. What the renderer cannot show (points and lines, directional
//! lights, orthographic cameras, extensions it does not know) is skipped with a warning,
//! unless the file marks the extension required. Of a material's textures the base colour's
//! and the emissive one's (PNG or JPEG) are loaded; every other part not applied (normal,
//! occlusion and metallic-roughness textures, vertex colours, morph targets, skins,
//! animations, NEAREST filtering) is one warning saying what is drawn instead (`unread.rs`),
//! and a glTF 1.0 file is refused as one.
//!
//! Mapping rules (documented in README "glTF scenes"): metallic-roughness materials by
//! `import::map_material`'s rule, shaded with GGX unless `--brdf` says otherwise;
//! KHR_lights_punctual point and spot lights keep their range and their intensity in candela
//! with the inverse-square falloff (`scene::Lighting::photometric`, with the automatic
//! exposure), and a light without a range gets the distance where it shows half a display
//! level on a white surface at that exposure, capped by the scene's bounds
//! (`scene::derive_ranges`). Files written by [`export`] carry lightgrid's exact material and light
//! intensity in `extras.lightgrid` and the scene's lighting conventions at the root, so they
//! load back unchanged; a catalog scene's papers-unit lights are written in candela matched
//! at `LIGHT_MATCH_FRACTION` of the range.

mod animation;
mod export;
mod import;
mod json;
mod read;
mod unread;

pub use animation::{FPS as ANIMATION_FPS, MAX_FRAMES as MAX_ANIMATION_FRAMES};
pub use export::{export, export_losses};
pub use import::ORBIT_FRAMES;

use crate::error::{Error, Result};
use crate::scene::Scene;
use std::path::Path;

/// Largest file (document, buffer or image) read.
pub(crate) const MAX_FILE_BYTES: u64 = 1 << 30;
/// Largest JSON document read.
pub(crate) const MAX_JSON_BYTES: u64 = 64 << 20;
/// Most vertices read from a file's accessors, and baked into its instances.
pub(crate) const MAX_VERTICES: u32 = 1 << 22;
/// Most triangles read and baked.
pub(crate) const MAX_TRIANGLES: u32 = 1 << 23;
/// Where along its range an exported papers-unit light and its inverse-square candela agree.
pub(crate) const LIGHT_MATCH_FRACTION: f32 = 0.25;
/// Extensions read (a file may require these).
pub(crate) const EXTENSIONS_READ: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_texture_transform",
];

/// Choices for loading a file.
#[derive(Clone, Copy, Debug, Default)]
pub struct LoadOptions {
    /// Index into the file's `cameras` (the first node placing it); `None`: the first
    /// perspective camera the scene places, else one fitted to the bounds.
    pub camera: Option<usize>,
}

/// A loaded scene and what was skipped on the way.
#[derive(Debug)]
pub struct Loaded {
    /// The imported scene.
    pub scene: Scene,
    /// What the import skipped or approximated, one message each, without repeats (at most
    /// 50; a last one then says how many more there were).
    pub warnings: Vec<String>,
}

/// Is `spec` a glTF file name rather than a catalog scene (ends in `.gltf` or `.glb`)?
pub fn is_gltf_path(spec: &str) -> bool {
    let lower = spec.to_ascii_lowercase();
    lower.ends_with(".gltf") || lower.ends_with(".glb")
}

/// The files beside a `.gltf` or `.glb` file that it reads (its buffers and images named by
/// URI, resolved as [`load`] resolves them): what no output may replace while the file is an
/// input. Lenient: a file that cannot be read or parsed lists nothing (loading it fails).
pub fn files_named_by(path: &Path) -> Vec<std::path::PathBuf> {
    read::files_named_by(path)
}

/// Load a `.gltf` or `.glb` file; relative URIs resolve beside it.
pub fn load(path: &Path, opts: &LoadOptions) -> Result<Loaded> {
    let fail = |reason: String| Error::Gltf {
        path: path.display().to_string(),
        reason,
    };
    let bytes = read::read_limited(path).map_err(fail)?;
    let name = path
        .file_stem()
        .map_or("gltf".into(), |s| s.to_string_lossy().into_owned());
    let base = path.parent().map(|p| {
        if p.as_os_str().is_empty() {
            Path::new(".")
        } else {
            p
        }
    });
    load_bytes(&bytes, &name, base, opts).map_err(|e| match e {
        Error::Gltf { reason, .. } => fail(reason),
        other => other,
    })
}

/// Load a document from bytes (`base`: where relative URIs resolve; `None` refuses them).
/// Errors name `name`.
pub fn load_bytes(
    bytes: &[u8],
    name: &str,
    base: Option<&Path>,
    opts: &LoadOptions,
) -> Result<Loaded> {
    let fail = |reason: String| Error::Gltf {
        path: name.to_string(),
        reason,
    };
    let doc = read::Document::parse(bytes, base).map_err(fail)?;
    let (scene, warnings) = import::import(&doc, name, opts).map_err(fail)?;
    Ok(Loaded { scene, warnings })
}
