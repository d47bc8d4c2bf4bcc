//! Where a scene comes from (a catalog name or a glTF file) and what every command can add
//! to it: `--add-lights N` scattered over its bounds, spot lights, no transparency. Commands
//! open scenes only through [`open`], so a file works wherever a catalog name does.

use super::catalog::{self, make_spots, random_light_color, SceneParams};
use super::gltf::{self, LoadOptions};
use super::{bounds_of, Light, LightAnchor, Rng, Scene, SceneLight};
use crate::consts::MAX_LIGHTS;
use crate::error::{Error, Result};
use glam::Vec3;
use std::path::PathBuf;

/// Lights scattered over a scene's bounds (`--add-lights`), the way the papers fill their
/// scenes: uniform in the bounding box, random hues.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AddLights {
    /// How many point lights to add: at least 1, and with the scene's own at most `MAX_LIGHTS`.
    pub count: u32,
    /// `None`: `default_added_range`.
    pub range: Option<f32>,
}

/// Intensity of an added light (the catalog's lights are 0.35 to 1).
pub(crate) const ADDED_LIGHT_INTENSITY: f32 = 0.5;
/// Lights an added light's default range makes reach a point of the bounds, on average.
pub(crate) const ADDED_LIGHT_COVERAGE: f32 = 8.0;

/// A scene to open: a catalog name or a `.gltf`/`.glb` path, with the options.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneRequest {
    /// A catalog scene's name, or a `.gltf`/`.glb` file's path (its name alone with
    /// `contents`).
    pub spec: String,
    /// The catalog's options; for a file only the seed, `--spot-fraction` and
    /// `--transparency` apply.
    pub params: SceneParams,
    /// `--camera N` (files only).
    pub camera: Option<usize>,
    /// `--add-lights`: point lights to scatter over the scene's bounds.
    pub add_lights: Option<AddLights>,
    /// `--exposure`: replaces the scene's (`Lighting::exposure`; the catalog's is 1, a
    /// file's automatic).
    pub exposure: Option<f32>,
    /// The file's bytes when they came without a path (a web page's file picker): `spec` is
    /// then only its name, and relative URIs are refused.
    pub contents: Option<FileContents>,
}

/// A file's bytes, shared; two are the same when they are the same allocation (comparing a
/// request must not compare megabytes).
#[derive(Clone)]
pub struct FileContents(pub std::sync::Arc<[u8]>);

impl PartialEq for FileContents {
    fn eq(&self, other: &Self) -> bool {
        std::sync::Arc::ptr_eq(&self.0, &other.0)
    }
}

impl std::fmt::Debug for FileContents {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "FileContents({} bytes)", self.0.len())
    }
}

impl SceneRequest {
    /// A catalog scene or file with default options.
    pub fn new(spec: &str) -> SceneRequest {
        SceneRequest {
            spec: spec.to_string(),
            params: SceneParams::default(),
            camera: None,
            add_lights: None,
            exposure: None,
            contents: None,
        }
    }

    /// Is this a glTF file (by its name) rather than a catalog scene?
    pub fn is_file(&self) -> bool {
        gltf::is_gltf_path(&self.spec)
    }
}

/// An opened scene and the warnings loading it gave (skipped parts of a file).
#[derive(Debug)]
pub struct Opened {
    /// The scene, with its added lights and spots, validated.
    pub scene: Scene,
    /// What loading a file skipped or approximated; empty for catalog scenes.
    pub warnings: Vec<String>,
}

/// Check the request's options without building or reading anything heavy.
pub fn check(req: &SceneRequest) -> Result<()> {
    if let Some(add) = req.add_lights {
        check_add_lights(&add)?;
    }
    if let Some(e) = req.exposure {
        check_exposure(e)?;
    }
    if req.is_file() {
        let p = &req.params;
        let refuse = |flag: &'static str, what: &str| {
            Err(Error::invalid(
                flag,
                format!("{what}; it does not apply to glTF files"),
            ))
        };
        if p.lights.is_some() {
            return refuse(
                "--lights",
                "--lights sets the stress scene's light count (use --add-lights N for a file)",
            );
        }
        if p.headlights {
            return refuse(
                "--headlights",
                "--headlights gives the catalog's robots headlights",
            );
        }
        catalog::check_spot_fraction(p.spot_fraction)
    } else {
        if req.camera.is_some() {
            return Err(Error::invalid(
                "--camera",
                "chooses a glTF file's camera; catalog scenes have their own camera path",
            ));
        }
        catalog::check_params(&req.spec, &req.params).map(|_| ())
    }
}

/// The largest `--exposure`: with lights at `LIGHT_LIMITS.max_radiance` a sum over every
/// light stays finite in f32.
pub const MAX_EXPOSURE: f32 = 1e6;

/// A positive finite exposure up to [`MAX_EXPOSURE`].
pub(crate) fn check_exposure(e: f32) -> Result<()> {
    if !(e.is_finite() && e > 0.0 && e <= MAX_EXPOSURE) {
        return Err(Error::invalid(
            "--exposure",
            format!(
                "{} is not a positive number up to {MAX_EXPOSURE:e}",
                super::show(e)
            ),
        ));
    }
    Ok(())
}

fn check_add_lights(add: &AddLights) -> Result<()> {
    if add.count == 0 || add.count > MAX_LIGHTS {
        return Err(Error::invalid(
            "--add-lights",
            format!("{} is out of range 1 to {MAX_LIGHTS}", add.count),
        ));
    }
    if let Some(r) = add.range {
        if !r.is_finite() || r <= 0.0 {
            return Err(Error::invalid(
                "--light-range",
                format!("{r} is not a positive number"),
            ));
        }
        let lim = &super::LIGHT_LIMITS;
        if r < lim.min_range || r > lim.max_range {
            return Err(Error::invalid(
                "--light-range",
                format!(
                    "{r:e} is outside {:e} to {:e} (a light's range squared must stay a normal f32)",
                    lim.min_range, lim.max_range
                ),
            ));
        }
    }
    Ok(())
}

/// Build or load the scene a request names, add its lights and spots, and validate it.
pub fn open(req: &SceneRequest) -> Result<Opened> {
    check(req)?;
    let p = req.params;
    let (mut scene, warnings) = if req.is_file() {
        let opts = LoadOptions { camera: req.camera };
        let loaded = match &req.contents {
            // Named as a path's scene is (its stem); errors name the file.
            Some(bytes) => {
                let stem = std::path::Path::new(&req.spec)
                    .file_stem()
                    .map_or("gltf".into(), |s| s.to_string_lossy().into_owned());
                gltf::load_bytes(&bytes.0, &stem, None, &opts).map_err(|e| match e {
                    Error::Gltf { reason, .. } => Error::Gltf {
                        path: req.spec.clone(),
                        reason,
                    },
                    other => other,
                })?
            }
            None => gltf::load(&PathBuf::from(&req.spec), &opts)?,
        };
        let mut scene = loaded.scene;
        if !p.transparency {
            if !scene.has_transparency() {
                return Err(Error::invalid(
                    "--transparency",
                    format!("{} has no transparent (BLEND) materials", req.spec),
                ));
            }
            let transparent: Vec<bool> = scene.materials.iter().map(|m| m.transparent).collect();
            scene.objects.retain(|o| !transparent[o.material]);
            if scene.objects.is_empty() {
                return Err(Error::invalid(
                    "--transparency",
                    format!(
                        "{} is all transparent: off leaves nothing to render",
                        req.spec
                    ),
                ));
            }
        }
        (scene, loaded.warnings)
    } else {
        // Spots are made after the added lights exist, so they are the scene's lights too; the
        // catalog's own lights get the same cones as without --add-lights (one seeded draw per
        // light, in order).
        let without_spots = SceneParams {
            spot_fraction: 0.0,
            ..p
        };
        (catalog::build(&req.spec, &without_spots)?, Vec::new())
    };
    if let Some(add) = req.add_lights {
        add_lights(&mut scene, &add, p.seed)?;
    }
    make_spots(&mut scene, p.seed, p.spot_fraction);
    if let Some(e) = req.exposure {
        scene.lighting.exposure = e;
    }
    if scene.lights.is_empty() && req.is_file() {
        return Err(Error::Gltf {
            path: req.spec.clone(),
            reason: "the file has no point or spot lights (KHR_lights_punctual); add some with --add-lights N".into(),
        });
    }
    // A file's scene that fails validation (a value from its extras, say) names the file.
    scene.validate().map_err(|e| match req.is_file() {
        true => Error::Gltf {
            path: req.spec.clone(),
            reason: e.to_string(),
        },
        false => e,
    })?;
    Ok(Opened { scene, warnings })
}

/// The axis-aligned bounds of the scene's geometry at frame 0, or `None` without geometry.
pub fn bounds(scene: &Scene) -> Option<(Vec3, Vec3)> {
    let state = scene.frame(0);
    bounds_of(
        scene
            .objects
            .iter()
            .zip(&state.transforms)
            .flat_map(|(o, m)| {
                scene.meshes[o.mesh]
                    .positions
                    .iter()
                    .map(move |p| m.transform_point3(*p))
            }),
    )
}

/// An added light's intensity in the scene's units: [`ADDED_LIGHT_INTENSITY`] in the papers'
/// units; in a photometric scene the candela at which, at a quarter of its range and with the
/// scene's exposure, a white surface facing it shows what the papers' light shows there
/// (radiance 0.5 × (1 − 1/16)² under Blinn-Phong; `E · exposure / π` under GGX).
fn added_intensity(lighting: &super::Lighting, range: f32) -> f32 {
    match lighting.units {
        super::LightUnits::Papers => ADDED_LIGHT_INTENSITY,
        super::LightUnits::Photometric => {
            // At a quarter of the range: (d / range)² = 1/16.
            let d = f64::from(range) * 0.25;
            let papers =
                f64::from(ADDED_LIGHT_INTENSITY) * super::LightUnits::Papers.window(0.0625);
            let window = super::LightUnits::Photometric.window(0.0625);
            (papers * std::f64::consts::PI * d * d / (f64::from(lighting.exposure) * window)) as f32
        }
    }
}

/// The box lights are scattered in: the scene's bounds with every side at least a tenth of
/// the longest (a flat street gets a slab of air above it), then grown by a tenth of each
/// side all round but downwards (so a single object's surfaces have lights outside them).
fn light_box(lo: Vec3, hi: Vec3) -> (Vec3, Vec3) {
    let extent = hi - lo;
    let floor = (extent.max_element() * 0.1).max(1e-3);
    let extent = extent.max(Vec3::splat(floor));
    let margin = extent * 0.1;
    (
        lo - Vec3::new(margin.x, 0.0, margin.z),
        lo + extent + margin,
    )
}

/// The range at which `count` lights uniform in the box reach [`ADDED_LIGHT_COVERAGE`]
/// lights per point on average: count × (4/3)πr³ = coverage × volume.
pub(crate) fn default_added_range(lo: Vec3, hi: Vec3, count: u32) -> f32 {
    let (lo, hi) = light_box(lo, hi);
    let e = hi - lo;
    let volume = e.x * e.y * e.z;
    let r =
        (3.0 * ADDED_LIGHT_COVERAGE * volume / (4.0 * std::f32::consts::PI * count as f32)).cbrt();
    r.max(e.length() * 1e-3)
}

/// Scatter `add.count` point lights over the scene's bounds (seeded by `seed`).
pub fn add_lights(scene: &mut Scene, add: &AddLights, seed: u64) -> Result<()> {
    check_add_lights(add)?;
    if scene.lights.len() as u64 + u64::from(add.count) > u64::from(MAX_LIGHTS) {
        return Err(Error::invalid(
            "--add-lights",
            format!(
                "{} lights and {} more exceed the maximum of {MAX_LIGHTS}",
                scene.lights.len(),
                add.count
            ),
        ));
    }
    let (lo, hi) = bounds(scene)
        .ok_or_else(|| Error::invalid("--add-lights", "the scene has no geometry to fill"))?;
    let range = add
        .range
        .unwrap_or_else(|| default_added_range(lo, hi, add.count));
    let (lo, hi) = light_box(lo, hi);
    let intensity = added_intensity(&scene.lighting, range);
    let mut rng = Rng::new(seed ^ 0xadd_11647);
    for _ in 0..add.count {
        let position = Vec3::new(
            rng.range(lo.x, hi.x),
            rng.range(lo.y, hi.y),
            rng.range(lo.z, hi.z),
        );
        let color = random_light_color(&mut rng);
        scene.lights.push(SceneLight {
            light: Light::point(position, color, intensity, range),
            anchor: LightAnchor::World,
        });
    }
    Ok(())
}
