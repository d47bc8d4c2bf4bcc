//! How a scene's lights are measured and which BRDF its materials were made for
//! ([`Lighting`]), and what the renderer uploads from that: each light's radiance times one
//! factor ([`Lighting::light_scale`]), and the BRDF and falloff the one light function is
//! made for ([`Shading`]: constants in `shading/lighting.wgsl`).
//!
//! Two kinds of scenes meet here. The catalog reproduces the papers: Blinn-Phong, lights in
//! the papers' own units with the smooth window `(1 − (d/r)²)²` and no inverse-square term
//! (tiled-shading §1.1). A glTF file made for another engine means KHR_lights_punctual:
//! point and spot intensity in candela, inverse-square falloff with `range` as a smooth
//! cut-off (the specification's recommended window, `clamp(1 − (d/r)⁴, 0, 1)² / d²`), and the
//! metallic-roughness material of glTF 2.0's appendix B (GGX, Smith height-correlated
//! visibility, Schlick Fresnel, Lambert diffuse).

use super::{Light, Rng, Scene};
use glam::Vec3;

/// The shading model of the one light function (`--brdf`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Brdf {
    /// Blinn-Phong, as the papers shade: `kd (n·l) + ks (n·h)^s (n·l)` times the light.
    Phong,
    /// glTF's metallic-roughness BRDF: Lambert `(1 − F) c_diff / π` plus `F·D·V` with the
    /// GGX distribution `D`, Smith height-correlated visibility `V` and Schlick's Fresnel `F`
    /// (the material's specular colour is `F0`, its exponent `s` the roughness
    /// `α = √(2 / (s + 2))`, the usual Blinn-Phong ↔ GGX correspondence the glTF import uses
    /// the other way).
    Ggx,
}

impl Brdf {
    /// The BRDF's `--brdf` value (and serialized name): `phong` or `ggx`.
    pub fn name(self) -> &'static str {
        match self {
            Brdf::Phong => "phong",
            Brdf::Ggx => "ggx",
        }
    }

    /// The shaders' value (`consts::BRDF_*`).
    pub fn gpu(self) -> u32 {
        match self {
            Brdf::Phong => crate::consts::BRDF_PHONG,
            Brdf::Ggx => crate::consts::BRDF_GGX,
        }
    }
}

/// A spot's angular window between its inner and outer cones, with `t` the linear ramp
/// `clamp((cos θ − cos outer) / (cos inner − cos outer), 0, 1)`. Both are 1 inside the inner
/// cone and exactly 0 at the outer one, so culling by the outer cone is exact for either.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum SpotCone {
    /// The papers' (and the catalog's): `t² (3 − 2t)`. Also what a lightgrid file's lighting
    /// record without a spot field (an earlier lightgrid's) was rendered with.
    #[default]
    Smoothstep,
    /// KHR_lights_punctual's (and its sample viewer's, Bevy's, three.js's): `t²`.
    Squared,
}

impl SpotCone {
    /// The shaders' value (`consts::SPOT_CONE_*`).
    pub fn gpu(self) -> u32 {
        match self {
            SpotCone::Smoothstep => crate::consts::SPOT_CONE_SMOOTHSTEP,
            SpotCone::Squared => crate::consts::SPOT_CONE_SQUARED,
        }
    }
}

/// What a light's colour × intensity means.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LightUnits {
    /// The papers' units: the light's radiance as a white diffuse surface facing it would
    /// show it under Blinn-Phong, windowed by `(1 − (d/r)²)²` with no inverse-square term.
    Papers,
    /// KHR_lights_punctual's: luminous intensity in candela, illuminance `I / d²` windowed by
    /// `clamp(1 − (d/r)⁴, 0, 1)²` (distances below `MIN_LIGHT_DISTANCE_SQ`'s root count as
    /// it: a light inside a surface does not make it infinite).
    ///
    /// `MIN_LIGHT_DISTANCE_SQ`: crate::consts::MIN_LIGHT_DISTANCE_SQ
    Photometric,
}

impl LightUnits {
    /// The range window at `x` = (d / range)², as `distance_falloff` in `lighting.wgsl` applies
    /// it (before the inverse square of photometric lights): the papers' `(1 − x)²`, or
    /// KHR_lights_punctual's `clamp(1 − x², 0, 1)²`.
    pub fn window(self, x: f64) -> f64 {
        match self {
            LightUnits::Papers => (1.0 - x).clamp(0.0, 1.0).powi(2),
            LightUnits::Photometric => (1.0 - x * x).clamp(0.0, 1.0).powi(2),
        }
    }

    /// The shaders' value (`consts::FALLOFF_*`).
    pub fn falloff(self) -> u32 {
        match self {
            LightUnits::Papers => crate::consts::FALLOFF_WINDOW,
            LightUnits::Photometric => crate::consts::FALLOFF_INVERSE_SQUARE,
        }
    }
}

/// How lights cast shadows (`--shadows`; `crate::shadows`).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Shadows {
    /// No shadows: every light reaches every sample in its range (every result before
    /// shadows landed).
    #[default]
    Off,
    /// One ray from each shaded sample to each shadow-casting light that would light it,
    /// through a hierarchy over the opaque triangles (Forward+ §6).
    Rays,
    /// Shadow maps: a cube per point light, a face per spot, all in flight in one atlas
    /// (`crate::shadows::maps`).
    Maps,
}

impl Shadows {
    /// Every shadow mode, in the order `--shadows` lists them.
    pub const ALL: [Shadows; 3] = [Shadows::Off, Shadows::Rays, Shadows::Maps];

    /// The mode's `--shadows` value: `off`, `rays` or `maps`.
    pub fn name(self) -> &'static str {
        match self {
            Shadows::Off => "off",
            Shadows::Rays => "rays",
            Shadows::Maps => "maps",
        }
    }

    /// The shaders' value (`consts::SHADOWS_*`).
    pub fn gpu(self) -> u32 {
        match self {
            Shadows::Off => crate::consts::SHADOWS_OFF,
            Shadows::Rays => crate::consts::SHADOWS_RAYS,
            Shadows::Maps => crate::consts::SHADOWS_MAPS,
        }
    }
}

/// What a pipeline's shaders are made for: the BRDF, the lights' units (their falloff), the
/// shadows and whether materials read inputs beyond their base colour. The shaders take them
/// as constants (`ComposedShader::specialized`), so a renderer makes its pipelines again when a
/// scene, `--brdf` or `--shadows` changes them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Shading {
    /// The BRDF the light function evaluates.
    pub brdf: Brdf,
    /// The lights' units, which pick the distance falloff ([`LightUnits::falloff`]).
    pub units: LightUnits,
    /// How lights cast shadows.
    pub shadows: Shadows,
    /// With shadow maps: the pipeline re-uses one light's maps (the classic deferred
    /// family's light volumes, `crate::shadows::maps`), so a face's tile is its cube face's.
    pub reuse_maps: bool,
    /// The spots' window between their cones (the scene's [`Lighting::spot_cone`]).
    pub spot_cone: SpotCone,
    /// Some material reads inputs per sample beyond its base colour
    /// ([`super::Material::reads_per_sample_inputs`]); without, the geometry stage is made
    /// without those reads (`passes/geometry.wgsl`'s `MATERIAL_INPUTS`).
    pub material_inputs: bool,
}

impl Default for Shading {
    /// The catalog's: Blinn-Phong in the papers' units, no shadows.
    fn default() -> Self {
        Shading {
            brdf: Brdf::Phong,
            units: LightUnits::Papers,
            shadows: Shadows::Off,
            reuse_maps: false,
            spot_cone: SpotCone::Smoothstep,
            material_inputs: false,
        }
    }
}

impl Shading {
    /// Every combination (the shader tests validate each).
    pub fn all() -> Vec<Shading> {
        let mut out = Vec::new();
        for shadows in Shadows::ALL {
            for units in [LightUnits::Papers, LightUnits::Photometric] {
                for brdf in [Brdf::Phong, Brdf::Ggx] {
                    for reuse_maps in [false, true] {
                        if reuse_maps && shadows != Shadows::Maps {
                            continue;
                        }
                        for material_inputs in [false, true] {
                            for spot_cone in [SpotCone::Smoothstep, SpotCone::Squared] {
                                out.push(Shading {
                                    brdf,
                                    units,
                                    shadows,
                                    reuse_maps,
                                    spot_cone,
                                    material_inputs,
                                });
                            }
                        }
                    }
                }
            }
        }
        out
    }

    /// A scene's shading with `--brdf` `brdf` (`None`: auto, the scene's own) and `--shadows`.
    pub fn of(scene: &super::Scene, brdf: Option<Brdf>, shadows: Shadows) -> Shading {
        Shading {
            brdf: brdf.unwrap_or(scene.lighting.brdf),
            units: scene.lighting.units,
            shadows,
            reuse_maps: false,
            spot_cone: scene.lighting.spot_cone,
            material_inputs: scene.materials.iter().any(|m| m.reads_per_sample_inputs()),
        }
    }

    /// The same shading for a pipeline that re-uses one light's shadow maps.
    pub fn reusing_maps(self) -> Shading {
        Shading {
            reuse_maps: true,
            ..self
        }
    }

    /// The light function's `SHADING_SHADOWS` (`consts::SHADOWS_*`).
    pub fn shadows_gpu(self) -> u32 {
        if self.shadows == Shadows::Maps && self.reuse_maps {
            crate::consts::SHADOWS_MAPS_REUSED
        } else {
            self.shadows.gpu()
        }
    }
}

/// A scene's lighting conventions: its lights' units, the BRDF its materials were made for
/// (what `--brdf auto` renders), and the exposure that turns its light into display units.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Lighting {
    /// What the lights' colour × intensity means (and so their falloff with distance).
    pub units: LightUnits,
    /// The BRDF the materials were made for: what `--brdf auto` renders with.
    pub brdf: Brdf,
    /// The spots' window between their cones.
    #[serde(default)]
    pub spot_cone: SpotCone,
    /// Multiplies every light's radiance before shading (`--exposure`): for photometric
    /// scenes the display value of one lux on a white diffuse surface, times π.
    pub exposure: f32,
}

impl Default for Lighting {
    /// The catalog's: the papers' units and Blinn-Phong, exposure 1.
    fn default() -> Self {
        Lighting {
            units: LightUnits::Papers,
            brdf: Brdf::Phong,
            spot_cone: SpotCone::Smoothstep,
            exposure: 1.0,
        }
    }
}

/// Distance at which the automatic exposure reads a light without a range of its own: a
/// room-scale two metres.
pub(crate) const AUTO_EXPOSURE_DISTANCE: f32 = 2.0;

impl Lighting {
    /// A glTF file's: photometric lights, GGX, and exposure 1 until `auto_exposure` sets it.
    pub fn photometric() -> Lighting {
        Lighting {
            units: LightUnits::Photometric,
            brdf: Brdf::Ggx,
            spot_cone: SpotCone::Squared,
            exposure: 1.0,
        }
    }

    /// The factor each light's colour × intensity is multiplied by when uploaded, for shading
    /// with `brdf`: the exposure, and π between the conventions. The papers' units are the
    /// radiance a white Lambert surface facing the light shows under Blinn-Phong, whose
    /// diffuse term `kd (n·l)` has no 1/π; GGX's Lambert term is `c_diff / π`, so under GGX
    /// papers' lights are π times brighter as irradiance (a white surface looks the same in
    /// both BRDFs), and photometric lights under Blinn-Phong are π times dimmer.
    pub fn light_scale(&self, brdf: Brdf) -> f32 {
        let convention = match (self.units, brdf) {
            (LightUnits::Papers, Brdf::Phong) | (LightUnits::Photometric, Brdf::Ggx) => 1.0,
            (LightUnits::Papers, Brdf::Ggx) => std::f32::consts::PI,
            (LightUnits::Photometric, Brdf::Phong) => std::f32::consts::FRAC_1_PI,
        };
        self.exposure * convention
    }
}

/// Probe points the automatic exposure reads, at most: fewer with many lights, so a
/// million-light file costs about 2^24 light evaluations to open.
const EXPOSURE_PROBES: usize = 256;

/// The automatic exposure of a scene's photometric lights: the typical lit surface shows
/// mid-grey. Probe points are drawn on the opaque surfaces at frame 0 (area-weighted,
/// seeded); each sums the illuminance every light gives it (`I / d²`, the range window,
/// `|n·l|`, a spot's cone; no occlusion), and a white Lambert surface at the median lit probe
/// shows radiance 1/π, which the tone curve maps to 0.27 (sRGB level 143): pools of light
/// keep room above and below, however many lights overlap. With no probe lit (lights away
/// from every surface), [`light_exposure`] reads the lights alone. `ranged[i]`: whether
/// light `i` had its own range in the file.
pub(crate) fn auto_exposure(scene: &Scene, ranged: &[bool]) -> f32 {
    let lights: Vec<Light> = scene.lights.iter().map(|l| l.light).collect();
    let probes = surface_probes(scene, probe_count(lights.len()));
    let lit: Vec<f64> = probes
        .iter()
        .map(|&(p, n)| illuminance(&lights, p, n))
        .collect();
    median_exposure(lit).unwrap_or_else(|| {
        let with: Vec<(Light, bool)> = lights
            .iter()
            .zip(ranged.iter().chain(std::iter::repeat(&true)))
            .map(|(l, r)| (*l, *r))
            .collect();
        light_exposure(&with)
    })
}

/// Probe points read for `lights` lights: fewer with many, so a million-light file costs
/// about 2^24 light evaluations.
fn probe_count(lights: usize) -> usize {
    EXPOSURE_PROBES.min((1 << 24) / lights.max(1)).max(16)
}

/// The illuminance photometric `lights` give a surface at `p` facing `n` (luminance-weighted:
/// `I / d²`, the range window, `|n·l|`, a spot's cone; no occlusion).
fn illuminance(lights: &[Light], p: Vec3, n: Vec3) -> f64 {
    lights
        .iter()
        .filter(|l| l.reaches(p))
        .map(|l| {
            let to = l.position - p;
            let d2 = to.length_squared();
            let window = LightUnits::Photometric.window(f64::from(d2 / (l.range * l.range)));
            let cos = f64::from(n.dot(to / d2.sqrt().max(1e-6)).abs());
            f64::from(l.intensity) * f64::from(luminance(l.color)) * window * cos
                / f64::from(d2.max(crate::consts::MIN_LIGHT_DISTANCE_SQ))
        })
        .sum()
}

/// Half the darkest step of an 8-bit sRGB display, as linear radiance (the sRGB curve's
/// linear segment, 1/12.92; the tone curve `1 − e^−x` has slope 1 at black): a light
/// without a range is cut where it shows less than this on a white surface facing it.
pub(crate) const VISIBLE_RADIANCE: f64 = 0.5 / 255.0 / 12.92;

/// The ranges [`derive_ranges`] gave.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct DerivedRanges {
    /// (light index, range) for each light the file gave no range.
    pub ranges: Vec<(usize, f32)>,
    /// How many of them the scene's bounds capped.
    pub capped: usize,
    /// Whether any light shows at least [`VISIBLE_RADIANCE`] on a probed surface.
    pub visible: bool,
}

/// Ranges for the photometric lights a file gave none (`ranged[i]` false; KHR_lights_punctual
/// reads a missing range as infinite): the distance where the light shows
/// [`VISIBLE_RADIANCE`] on a white Lambert surface facing it at the scene's exposure,
/// `√(exposure · I · max(colour) / (π · VISIBLE_RADIANCE))`, so it scales with the scene's
/// units and its exposure; capped at the farthest corner of the scene's bounds from the
/// light (past that it lights nothing). With `auto` (the automatic exposure) the exposure is
/// read with every such light reaching the whole scene, the ranges derived from it, and the
/// exposure read again with them.
pub(crate) fn derive_ranges(scene: &mut Scene, ranged: &[bool], auto: bool) -> DerivedRanges {
    let limits = &super::LIGHT_LIMITS;
    let clamp = |r: f64| (r as f32).clamp(limits.min_range, limits.max_range);
    let bounds = super::source::bounds(scene);
    let unranged: Vec<usize> = (0..scene.lights.len())
        .filter(|&i| !ranged.get(i).copied().unwrap_or(true))
        .collect();
    let cap = |p: Vec3| -> f32 {
        let Some((lo, hi)) = bounds else {
            return limits.max_range;
        };
        let far = Vec3::new(
            (p.x - lo.x).abs().max((p.x - hi.x).abs()),
            (p.y - lo.y).abs().max((p.y - hi.y).abs()),
            (p.z - lo.z).abs().max((p.z - hi.z).abs()),
        );
        clamp(f64::from(far.length()) * 1.01)
    };
    let caps: Vec<f32> = (unranged.iter())
        .map(|&i| cap(scene.lights[i].light.position))
        .collect();
    for (&i, &c) in unranged.iter().zip(&caps) {
        scene.lights[i].light.range = c;
    }
    if auto {
        scene.lighting.exposure = auto_exposure(scene, ranged);
    }
    let exposure = f64::from(scene.lighting.exposure);
    let mut derived = DerivedRanges::default();
    for (&i, &c) in unranged.iter().zip(&caps) {
        let l = &mut scene.lights[i].light;
        let peak = f64::from(l.intensity) * f64::from(l.color.max_element());
        let r = (exposure * peak / (std::f64::consts::PI * VISIBLE_RADIANCE)).sqrt();
        let range = clamp(r).min(c);
        derived.capped += usize::from(range == c);
        l.range = range;
        derived.ranges.push((i, range));
    }
    if auto && !unranged.is_empty() {
        scene.lighting.exposure = auto_exposure(scene, ranged);
    }
    let lights: Vec<Light> = scene.lights.iter().map(|l| l.light).collect();
    let exposure = f64::from(scene.lighting.exposure);
    let probes = surface_probes(scene, probe_count(lights.len()));
    derived.visible = probes.iter().any(|&(p, n)| {
        exposure * illuminance(&lights, p, n) / std::f64::consts::PI >= VISIBLE_RADIANCE
    });
    derived
}

/// The exposure that shows the median of the positive finite illuminances `e` as 1, or None
/// without one.
fn median_exposure(mut e: Vec<f64>) -> Option<f32> {
    e.retain(|e| e.is_finite() && *e > 0.0);
    e.sort_by(f64::total_cmp);
    let median = *e.get(e.len() / 2)?;
    Some((1.0 / median).clamp(1e-12, 1e6) as f32)
}

fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// Up to `n` points with their unit normals on the scene's opaque surfaces at frame 0,
/// area-weighted, from a fixed seed.
fn surface_probes(scene: &Scene, n: usize) -> Vec<(Vec3, Vec3)> {
    let g = scene.geometry(&scene.frame(0));
    let tris: Vec<[Vec3; 3]> = g.indices[..g.opaque_indices]
        .chunks_exact(3)
        .map(|t| [0, 1, 2].map(|k| Vec3::from(g.vertices[t[k] as usize].position)))
        .collect();
    let mut cumulative = Vec::with_capacity(tris.len());
    let mut total = 0.0f64;
    for [a, b, c] in &tris {
        total += f64::from((*b - *a).cross(*c - *a).length() * 0.5);
        cumulative.push(total);
    }
    if !(total > 0.0 && total.is_finite()) {
        return Vec::new();
    }
    let mut rng = Rng::new(0xe4_905e);
    (0..n)
        .filter_map(|_| {
            let at = f64::from(rng.unit()) * total;
            let i = cumulative.partition_point(|&c| c < at).min(tris.len() - 1);
            let [a, b, c] = tris[i];
            let (mut u, mut v) = (rng.unit(), rng.unit());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let n = (b - a).cross(c - a).try_normalize()?;
            Some((a + (b - a) * u + (c - a) * v, n))
        })
        .collect()
}

/// The automatic exposure from the lights alone (`(light, has its own range)`): a white
/// diffuse surface at half the range of the median light (by the illuminance it gives
/// there; [`AUTO_EXPOSURE_DISTANCE`] for lights whose range was derived, not given) shows
/// radiance 1/π: mid-grey, as [`auto_exposure`] puts its median probe.
pub(crate) fn light_exposure(lights: &[(Light, bool)]) -> f32 {
    let e = lights
        .iter()
        .map(|(l, ranged)| {
            // Half the range, where the window is (1 − (1/2)⁴)².
            let (d, window) = if *ranged {
                let half = f64::from(l.range) * 0.5;
                (half, LightUnits::Photometric.window(0.25))
            } else {
                (f64::from(AUTO_EXPOSURE_DISTANCE), 1.0)
            };
            f64::from(l.intensity) * f64::from(luminance(l.color)) * window / (d * d)
        })
        .collect();
    median_exposure(e).unwrap_or(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn a_white_surface_looks_the_same_in_both_brdfs_of_one_scene() {
        for units in [LightUnits::Papers, LightUnits::Photometric] {
            let l = Lighting {
                units,
                brdf: Brdf::Phong,
                spot_cone: SpotCone::Smoothstep,
                exposure: 2.0,
            };
            // Phong's diffuse kd·E against GGX's kd/π·E.
            let phong = l.light_scale(Brdf::Phong);
            let ggx = l.light_scale(Brdf::Ggx) / std::f32::consts::PI;
            assert!((phong - ggx).abs() < 1e-6, "{units:?}: {phong} {ggx}");
        }
        let photometric = Lighting::photometric();
        assert_eq!(photometric.light_scale(Brdf::Ggx), photometric.exposure);
    }

    #[test]
    fn without_a_lit_surface_the_median_light_at_half_its_range_shows_mid_grey() {
        let light = |cd: f32, range: f32| Light::point(Vec3::ZERO, Vec3::ONE, cd, range);
        // 4,000 cd, range 6: 4000 × 0.8789 / 9 lux at 3 m.
        let e = light_exposure(&[(light(4000.0, 6.0), true)]);
        let want = 9.0 / (4000.0 * 0.878_906_25);
        assert!((e - want).abs() < want * 1e-5, "{e} {want}");
        // The median, not the mean: one very bright light does not darken the rest.
        let e3 = light_exposure(&[
            (light(4000.0, 6.0), true),
            (light(4000.0, 6.0), true),
            (light(4e9, 6.0), true),
        ]);
        assert!((e3 - want).abs() < want * 1e-5);
        // A range-less light is read at two metres.
        let e = light_exposure(&[(light(100.0, 70.0), false)]);
        assert!((e - 0.04).abs() < 1e-6, "{e}");
        assert_eq!(light_exposure(&[]), 1.0);
    }
}
