//! Scenes as plain CPU data: meshes, materials, point lights, objects with motion, and a camera
//! path. [`Scene::frame`] evaluates the animation at one frame; [`Scene::geometry`] bakes the
//! frame's objects into one world-space vertex/index list for the GPU. Scenes come from the
//! [`catalog`] or from glTF files ([`gltf`]), opened through [`source::open`].

mod camera;
pub mod catalog;
pub mod gltf;
mod lighting;
mod mesh;
mod raster;
mod rng;
pub mod source;
mod view;

pub use camera::{Camera, CameraPath};
pub use catalog::{SceneInfo, SceneParams, SCENES};
pub(crate) use lighting::{derive_ranges, DerivedRanges};
pub use lighting::{Brdf, LightUnits, Lighting, Shading, Shadows, SpotCone};
pub(crate) use mesh::bounds_of;
pub use mesh::Mesh;
pub use raster::{rasterize, Fragment};
pub use rng::Rng;
pub use source::{open, AddLights, FileContents, Opened, SceneRequest};
pub use view::{SpotCull, ViewLight, ViewSetup};

use crate::consts::{MATERIAL_FLAG_TRANSPARENT, MAX_LIGHTS};
use crate::error::{Error, Result};
use crate::gpu_types::{GpuLight, GpuMaterial, GpuVertex, POINT_LIGHT_COS};
use glam::{Mat4, Quat, Vec3};

/// Blinn-Phong material. A `transparent` material is drawn after the opaque geometry,
/// back to front, blended with `alpha` (its fragments' coverage).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Diffuse reflectance (linear RGB), the colour the lights' `n·l` term is multiplied by.
    pub diffuse: Vec3,
    /// Specular colour (linear RGB): the Blinn-Phong highlight's weight, or `F0` under GGX.
    pub specular: Vec3,
    /// Blinn-Phong exponent `s` of the highlight; GGX reads it as the roughness
    /// `α = √(2 / (s + 2))`.
    pub shininess: f32,
    /// Light the surface emits (linear RGB), added whatever the lights.
    pub emissive: Vec3,
    /// Colour (linear RGB) the scene's constant ambient light (`consts::SCENE_AMBIENT`) is
    /// multiplied by.
    pub ambient: Vec3,
    /// Opacity from 0 to 1 (times the base-colour texture's): a transparent material's blend
    /// coverage, and what `alpha_cutoff` tests.
    pub alpha: f32,
    /// Drawn blended after the opaque geometry, back to front, instead of opaque.
    pub transparent: bool,
    /// How the material responds to the view (its shader).
    pub shader: MaterialShader,
    /// Index into [`Scene::textures`] of a base-colour texture multiplying the diffuse and
    /// ambient colours and the alpha (glTF's `baseColorTexture`), sampled at the vertices'
    /// UVs.
    pub texture: Option<u32>,
    /// Index into [`Scene::textures`] of a texture multiplying the emissive colour (glTF's
    /// `emissiveTexture`), sampled as the base colour's is.
    pub emissive_texture: Option<u32>,
    /// glTF's metallic-roughness inputs, for a file's material: the diffuse and specular
    /// colours and the exponent above are what they give untextured, and the shader derives
    /// them per sample from these, the textures and the vertex colour.
    pub metallic_roughness: Option<MetallicRoughness>,
    /// A tangent-space normal texture (linear, in [`Scene::textures`]) and its scale.
    pub normal_texture: Option<(u32, f32)>,
    /// An occlusion texture (R, linear) and its strength on the ambient term.
    pub occlusion_texture: Option<(u32, f32)>,
    /// Bit `consts::TEXTURE_SLOT_*` set: that texture reads texture coordinate set 1.
    pub uv_sets: u32,
    /// Each texture's wrapping, 4 bits a slot (`GpuMaterial::wraps`).
    pub wraps: u32,
    /// Bit `consts::TEXTURE_SLOT_*` set: that texture is magnified nearest-texel.
    pub nearest: u32,
    /// Per texture slot, its coordinates' transform (glTF's `KHR_texture_transform`).
    pub uv_transforms: [glam::Affine2; 5],
    /// Alpha test (glTF's `MASK`): fragments whose alpha (`alpha` × the texture's) is below
    /// this are discarded in every pass, depth passes included.
    pub alpha_cutoff: Option<f32>,
}

/// glTF's metallic-roughness material inputs (§3.9.2), applied per sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MetallicRoughness {
    /// The base colour factor (its alpha is the material's `alpha`).
    pub base: Vec3,
    /// Metalness from 0 (dielectric) to 1 (metal), glTF's `metallicFactor`.
    pub metallic: f32,
    /// Perceptual roughness from 0 (smooth) to 1 (rough), glTF's `roughnessFactor`; the GGX
    /// `α` is its square.
    pub roughness: f32,
    /// A texture whose B channel scales `metallic` and G `roughness` (linear, in
    /// [`Scene::textures`]).
    pub texture: Option<u32>,
}

/// A texture: sRGB-encoded RGBA8, rows top to bottom (UV (0, 0) is its first texel, as in
/// glTF). Linear data (normals, metallic-roughness, occlusion) is stored sRGB-encoded too, so
/// the sampler's decode gives back the file's values.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// `width × height` texels of 4 bytes (R, G, B, A), row by row from the top.
    pub rgba: Vec<u8>,
}

/// A material's shader (tiled-forward-shading §4.7). Each changes only the colour the one
/// light function's diffuse term is multiplied by, as a function of the view angle (see
/// `apply_material` in `shading/lighting.wgsl`), so every pipeline shades it the same.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum MaterialShader {
    /// Blinn-Phong with the material's own colours.
    #[default]
    Standard,
    /// Two-colour car paint: the diffuse colour turns toward `flip` at grazing angles,
    /// `(1 - n·v)^power`.
    CarPaint {
        /// The colour (linear RGB) the diffuse colour turns toward at grazing angles.
        flip: Vec3,
        /// Exponent on `1 - n·v`: larger keeps the flip closer to the silhouette.
        power: f32,
    },
    /// A rim: `color × (1 - n·v)^power` added to the diffuse colour, lit by the lights.
    Rim {
        /// The rim's colour (linear RGB), at full strength where the surface is seen edge-on.
        color: Vec3,
        /// Exponent on `1 - n·v`: larger makes the rim thinner.
        power: f32,
    },
}

impl MaterialShader {
    /// `consts::MATERIAL_SHADER_*`, the second colour and the exponent.
    pub fn gpu(self) -> (u32, Vec3, f32) {
        use crate::consts::{
            MATERIAL_SHADER_CAR_PAINT, MATERIAL_SHADER_RIM, MATERIAL_SHADER_STANDARD,
        };
        match self {
            MaterialShader::Standard => (MATERIAL_SHADER_STANDARD, Vec3::ZERO, 1.0),
            MaterialShader::CarPaint { flip, power } => (MATERIAL_SHADER_CAR_PAINT, flip, power),
            MaterialShader::Rim { color, power } => (MATERIAL_SHADER_RIM, color, power),
        }
    }
}

impl Material {
    /// An opaque material with ambient equal to diffuse and a modest white specular.
    pub fn plain(diffuse: Vec3, specular: f32, shininess: f32) -> Self {
        Material {
            diffuse,
            specular: Vec3::splat(specular),
            shininess,
            emissive: Vec3::ZERO,
            ambient: diffuse,
            alpha: 1.0,
            transparent: false,
            shader: MaterialShader::Standard,
            texture: None,
            emissive_texture: None,
            metallic_roughness: None,
            normal_texture: None,
            occlusion_texture: None,
            uv_sets: 0,
            wraps: 0,
            nearest: 0,
            uv_transforms: [glam::Affine2::IDENTITY; 5],
            alpha_cutoff: None,
        }
    }

    /// The textures the material reads, by index into [`Scene::textures`].
    pub fn textures(&self) -> impl Iterator<Item = u32> {
        [
            self.texture,
            self.emissive_texture,
            self.metallic_roughness.and_then(|m| m.texture),
            self.normal_texture.map(|t| t.0),
            self.occlusion_texture.map(|t| t.0),
        ]
        .into_iter()
        .flatten()
    }

    /// Does the material read inputs per sample beyond its base colour (texture and vertex
    /// colours): glTF's metallic-roughness model, or a normal, occlusion or emissive texture?
    pub fn reads_per_sample_inputs(&self) -> bool {
        self.metallic_roughness.is_some()
            || self.emissive_texture.is_some()
            || self.normal_texture.is_some()
            || self.occlusion_texture.is_some()
    }

    /// A transparent material (glass, bubbles): tinted diffuse, a sharp white highlight,
    /// `alpha` coverage.
    pub fn glass(tint: Vec3, alpha: f32) -> Self {
        Material {
            ambient: tint * 0.5,
            alpha,
            transparent: true,
            ..Material::plain(tint, 0.8, 96.0)
        }
    }

    /// The material as the shaders read it (texture indices plus one, 0 for none; UV
    /// transforms as rows of a 2×3 matrix).
    pub fn to_gpu(&self) -> GpuMaterial {
        let (shader, paint, paint_power) = self.shader.gpu();
        let mr = self.metallic_roughness;
        GpuMaterial {
            diffuse: self.diffuse.to_array(),
            alpha: self.alpha,
            specular: self.specular.to_array(),
            shininess: self.shininess,
            emissive: self.emissive.to_array(),
            flags: if self.transparent {
                MATERIAL_FLAG_TRANSPARENT
            } else {
                0
            } | if mr.is_some() {
                crate::consts::MATERIAL_FLAG_METALLIC_ROUGHNESS
            } else {
                0
            },
            ambient: self.ambient.to_array(),
            paint_power,
            paint: paint.to_array(),
            shader,
            texture: self.texture.map_or(0, |t| t + 1),
            alpha_cutoff: self.alpha_cutoff.unwrap_or(0.0),
            emissive_texture: self.emissive_texture.map_or(0, |t| t + 1),
            nearest: self.nearest,
            base: mr.map_or([0.0; 3], |m| m.base.to_array()),
            metallic: mr.map_or(0.0, |m| m.metallic),
            roughness: mr.map_or(0.0, |m| m.roughness),
            normal_scale: self.normal_texture.map_or(1.0, |t| t.1),
            occlusion_strength: self.occlusion_texture.map_or(0.0, |t| t.1),
            metal_rough_texture: mr.and_then(|m| m.texture).map_or(0, |t| t + 1),
            normal_texture: self.normal_texture.map_or(0, |t| t.0 + 1),
            occlusion_texture: self.occlusion_texture.map_or(0, |t| t.0 + 1),
            uv_sets: self.uv_sets,
            wraps: self.wraps,
            uv_transforms: {
                // Six floats a slot, row-major 2x3.
                let mut flat = [0.0f32; 32];
                for (slot, t) in self.uv_transforms.iter().enumerate() {
                    let (m, o) = (t.matrix2, t.translation);
                    flat[6 * slot..6 * slot + 6].copy_from_slice(&[
                        m.x_axis.x, m.y_axis.x, o.x, m.x_axis.y, m.y_axis.y, o.y,
                    ]);
                }
                let mut rows = [[0.0; 4]; 8];
                for (i, r) in rows.iter_mut().enumerate() {
                    r.copy_from_slice(&flat[4 * i..4 * i + 4]);
                }
                rows
            },
        }
    }
}

/// A light with a finite range: it contributes nothing at or beyond `range`. A point light
/// shines in every direction; a spot light (`spot`) only inside its outer cone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Position in world space; in a [`SceneLight`] anchored to an object or a track, in that
    /// anchor's frame; camera-relative after [`Light::relative_to`].
    pub position: Vec3,
    /// Colour (linear RGB); colour × `intensity` is the light's radiance.
    pub color: Vec3,
    /// Strength multiplying `color`, in the scene's [`LightUnits`] (candela for photometric
    /// lights).
    pub intensity: f32,
    /// Distance from `position`, in scene units, at and beyond which the light adds nothing.
    pub range: f32,
    /// The cone of a spot light; `None` for a point light.
    pub spot: Option<Spot>,
}

/// A spot light's cone: full intensity within `cos_inner` of `direction`, a smooth falloff to
/// zero at `cos_outer` (tiled-deferred-tricks, Trick 2's spot lights), nothing outside.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spot {
    /// Unit axis of the cone, from the light outwards.
    pub direction: Vec3,
    /// Cosine of the inner cone's half-angle: full intensity at angles from `direction` within it.
    pub cos_inner: f32,
    /// Cosine of the outer cone's half-angle (below `cos_inner`): no light at or beyond it.
    pub cos_outer: f32,
}

/// Narrowest gap between a spot's inner and outer cosines (the falloff must have a width).
pub(crate) const SPOT_MIN_FALLOFF: f32 = 1e-4;

impl Spot {
    /// A cone around `direction` (need not be unit length) with half-angles `inner` < `outer`
    /// in radians, `outer` at most π.
    pub fn new(direction: Vec3, inner: f32, outer: f32) -> Spot {
        // A cone narrower than the falloff's width still has one.
        let cos_outer = outer.cos().min(1.0 - SPOT_MIN_FALLOFF);
        Spot {
            direction: direction.normalize_or(Vec3::NEG_Y),
            cos_inner: inner.cos().max(cos_outer + SPOT_MIN_FALLOFF),
            cos_outer,
        }
    }
}

/// The bounds a light's numbers are checked against ([`Light::check_values`]), so that what
/// the shaders compute from them stays finite in f32: the radiance (colour × intensity, what
/// is uploaded) summed over [`MAX_LIGHTS`] lights (2^20 × 1e12 ≈ 1e18), even divided by the
/// light pre-pass's smallest luminance (1e-8: 1e26), stays below f32's 3.4e38; the squared
/// range the falloff divides by stays a normal f32 (1e-12 to 1e24), and so do squared
/// distances between light positions within the coordinate bound. A tiny range is refused
/// rather than turned into an infinite falloff or intensity.
pub(crate) struct LightLimits {
    /// Largest radiance component (colour × intensity).
    pub max_radiance: f32,
    /// Smallest and largest range, in scene units.
    pub min_range: f32,
    pub max_range: f32,
    /// Largest absolute coordinate of a light's position.
    pub max_coordinate: f32,
}

/// A number in a message: plain where that reads well, else with an exponent (f32's
/// `Display` writes 1e30 with all its digits).
pub fn show(v: f32) -> String {
    let a = v.abs();
    if a == 0.0 || !a.is_finite() || (1e-4..1e6).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// A product computed in f64 (it may be past f32), to four significant digits: `1e40`.
fn show_f64(v: f64) -> String {
    let s = format!("{v:.3e}");
    match s.split_once('e') {
        Some((m, e)) => format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.')),
        None => s,
    }
}

/// [`show`] for the three parts of a vector: `[x, y, z]`.
pub(crate) fn show3(v: Vec3) -> String {
    format!("[{}, {}, {}]", show(v.x), show(v.y), show(v.z))
}

pub(crate) const LIGHT_LIMITS: LightLimits = LightLimits {
    max_radiance: 1e12,
    min_range: 1e-6,
    max_range: 1e12,
    max_coordinate: 1e12,
};

impl Light {
    /// What is wrong with the light's numbers, with the values, or nothing: a range and
    /// position within `LIGHT_LIMITS`, finite non-negative colour and intensity whose
    /// product (the radiance) is within them. Shared by the scene's validation
    /// and the glTF import, which names the file and the light.
    pub fn check_values(&self) -> std::result::Result<(), String> {
        let lim = &LIGHT_LIMITS;
        // The range first: an intensity derived from it (glTF candela) is only as good as it.
        if !self.range.is_finite() || self.range <= 0.0 {
            return Err(format!(
                "range {} must be a positive number",
                show(self.range)
            ));
        }
        if self.range < lim.min_range {
            return Err(format!(
                "range {:e} is too small (at least {:e}: its square must stay a normal f32)",
                self.range, lim.min_range
            ));
        }
        if self.range > lim.max_range {
            return Err(format!(
                "range {:e} is too large (at most {:e})",
                self.range, lim.max_range
            ));
        }
        if !self.position.is_finite() || self.position.abs().max_element() > lim.max_coordinate {
            return Err(format!(
                "position {} is not finite or beyond ±{:e}",
                show3(self.position),
                lim.max_coordinate
            ));
        }
        if !self.color.is_finite() || self.color.min_element() < 0.0 {
            return Err(format!(
                "colour {} must be finite and non-negative",
                show3(self.color)
            ));
        }
        if !self.intensity.is_finite() || self.intensity < 0.0 {
            return Err(format!(
                "intensity {} must be finite and non-negative",
                show(self.intensity)
            ));
        }
        // In f64: the f32 product itself may overflow to infinity.
        let radiance = f64::from(self.color.max_element()) * f64::from(self.intensity);
        if radiance > f64::from(lim.max_radiance) {
            return Err(format!(
                "radiance (colour {} × intensity {}) of {} exceeds {:e}",
                show3(self.color),
                show(self.intensity),
                show_f64(radiance),
                lim.max_radiance
            ));
        }
        Ok(())
    }

    /// A point light.
    pub fn point(position: Vec3, color: Vec3, intensity: f32, range: f32) -> Light {
        Light {
            position,
            color,
            intensity,
            range,
            spot: None,
        }
    }

    /// The smallest sphere around everything the light reaches: its range sphere, or for a
    /// spot the tightest sphere around the cone's spherical sector. With half-angle θ ≤ 45°
    /// the sphere through the apex and the rim of the cap (centre r/(2 cos θ) along the axis,
    /// radius the same); up to 90°, the sphere around the rim's disc (centre r cos θ along the
    /// axis, radius r sin θ), which holds the apex and the cap's tip too; wider cones reach
    /// behind the apex and keep the range sphere.
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        let Some(spot) = self.spot else {
            return (self.position, self.range);
        };
        let (c, r) = (spot.cos_outer, self.range);
        if c >= std::f32::consts::FRAC_1_SQRT_2 {
            let t = r / (2.0 * c);
            (self.position + spot.direction * t, t)
        } else if c > 0.0 {
            let sin = (1.0 - c * c).max(0.0).sqrt();
            (self.position + spot.direction * (r * c), r * sin)
        } else {
            (self.position, r)
        }
    }

    /// Does the light reach world point `p`: inside its range and, for a spot, inside its
    /// outer cone (the light function's angular factor is positive exactly there)?
    pub fn reaches(&self, p: Vec3) -> bool {
        let cone = self.spot.map(|s| (s.direction, s.cos_outer));
        view::reaches(p - self.position, self.range, cone)
    }

    /// The same light with `origin` moved to the origin: in camera-relative space for the
    /// eye (`ViewSetup::relative`). Everything derived from it (the bounding sphere of a
    /// spot) is then computed near the origin, where f32 is precise.
    pub fn relative_to(&self, origin: Vec3) -> Light {
        Light {
            position: self.position - origin,
            ..*self
        }
    }

    /// The light as the GPU reads it (in camera-relative space: [`Self::relative_to`]).
    pub fn to_gpu(&self) -> GpuLight {
        self.to_gpu_scaled(1.0)
    }

    /// [`Self::to_gpu`] with the radiance times `scale` (`Lighting::light_scale`: the
    /// exposure and the BRDF's convention).
    pub fn to_gpu_scaled(&self, scale: f32) -> GpuLight {
        let (direction, cos_outer, cos_inner) = match self.spot {
            None => (Vec3::ZERO, POINT_LIGHT_COS, POINT_LIGHT_COS),
            Some(s) => (s.direction, s.cos_outer, s.cos_inner),
        };
        GpuLight {
            position: self.position.to_array(),
            range: self.range,
            radiance: (self.color * (self.intensity * scale)).to_array(),
            cos_inner,
            direction: direction.to_array(),
            cos_outer,
        }
    }

    /// The bounding sphere as the GPU's `light_bounds` entry: centre and radius.
    pub fn bounds_gpu(&self) -> [f32; 4] {
        let (c, r) = self.bounding_sphere();
        [c.x, c.y, c.z, r]
    }

    /// Finite position, colour and intensity within `LIGHT_LIMITS`' bounds, a range within
    /// them, and for a spot a unit direction and cosines with -1 ≤ outer < inner ≤ 1.
    pub fn validate(&self, index: usize) -> Result<()> {
        self.check_values()
            .map_err(|reason| Error::invalid("light", format!("light {index}: {reason}")))?;
        if let Some(s) = self.spot {
            let unit = s.direction.is_finite() && (s.direction.length() - 1.0).abs() < 1e-3;
            let cones = s.cos_outer >= -1.0
                && s.cos_inner <= 1.0
                && s.cos_inner - s.cos_outer >= SPOT_MIN_FALLOFF * 0.5;
            if !unit || !cones {
                return Err(Error::invalid(
                    "light",
                    format!(
                        "spot light {index} needs a unit direction and an inner cone narrower than its outer cone (at most 180°)"
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// A closed polyline in the xz plane that something walks along.
#[derive(Clone, Debug)]
pub struct Path {
    /// The corners in order, in world space; the last joins back to the first.
    pub points: Vec<Vec3>,
}

impl Path {
    /// Length of the whole loop (the closing segment included), in scene units.
    pub fn length(&self) -> f32 {
        self.segments().map(|(a, b)| a.distance(b)).sum()
    }

    fn segments(&self) -> impl Iterator<Item = (Vec3, Vec3)> + '_ {
        let n = self.points.len();
        (0..n).map(move |i| (self.points[i], self.points[(i + 1) % n]))
    }

    /// Position and unit direction at arc length `s` (wraps around).
    pub fn sample(&self, s: f32) -> (Vec3, Vec3) {
        let len = self.length();
        let mut s = s.rem_euclid(len);
        for (a, b) in self.segments() {
            let d = a.distance(b);
            if s <= d && d > 0.0 {
                let dir = (b - a) / d;
                return (a + dir * s, dir);
            }
            s -= d;
        }
        let (a, b) = self.segments().last().expect("path has points");
        (b, (b - a).normalize_or_zero())
    }
}

/// How an object moves over the animation.
#[derive(Clone, Debug)]
pub enum Motion {
    /// Does not move: `Object::local` places it in the world.
    Static,
    /// Walks along `paths[path]` at `speed` units per frame, starting at arc length `start`,
    /// facing the direction of travel.
    Walk {
        /// Index into [`Scene::paths`].
        path: usize,
        /// Arc length travelled per frame, in scene units.
        speed: f32,
        /// Arc length along the path at frame 0, in scene units.
        start: f32,
    },
    /// Moves as [`Scene::tracks`]`[track]` says: one transform per frame, applied to `local`
    /// (a file's own animation; the last frame's is held after it).
    Track(usize),
}

/// A mesh placed in the world with a material.
#[derive(Clone, Debug)]
pub struct Object {
    /// Index into [`Scene::meshes`].
    pub mesh: usize,
    /// Index into [`Scene::materials`].
    pub material: usize,
    /// Placement relative to the motion's frame (or the world, for static objects).
    pub local: Mat4,
    /// How the object moves over the animation.
    pub motion: Motion,
}

impl Object {
    /// Does the object stay where `local` puts it?
    pub fn is_static(&self) -> bool {
        matches!(self.motion, Motion::Static)
    }
}

/// Where a light sits: fixed in the world, or carried by an object.
#[derive(Clone, Copy, Debug)]
pub enum LightAnchor {
    /// Fixed: `light.position` is in world space.
    World,
    /// Offset from the object's motion frame.
    Object(usize),
    /// Moved by [`Scene::tracks`]`[t]` (a light on a file's animated node).
    Track(usize),
    /// Circling a vertical axis: at frame 0 where `light.position` says, then around a
    /// circle of `radius` through it, a turn every `frames_per_turn` frames, the axis at
    /// angle `phase` from it (the Forward+ demo's moving lights).
    Circle {
        /// Radius of the circle, in scene units.
        radius: f32,
        /// Frames per full turn (at least 1 is used).
        frames_per_turn: f32,
        /// Angle in radians, in the xz plane from +x toward +z, of the frame-0 position as
        /// seen from the axis.
        phase: f32,
    },
}

/// Where a light on [`LightAnchor::Circle`] is at `frame`, starting at `start`.
fn circle_position(start: Vec3, radius: f32, frames_per_turn: f32, phase: f32, frame: u32) -> Vec3 {
    let turn = std::f32::consts::TAU * frame as f32 / frames_per_turn.max(1.0);
    let at = |a: f32| Vec3::new(a.cos(), 0.0, a.sin()) * radius;
    // The offset first, so frame 0 is exactly the start.
    start + (at(phase + turn) - at(phase))
}

/// One of a scene's lights and what carries it through the animation.
#[derive(Clone, Copy, Debug)]
pub struct SceneLight {
    /// For `LightAnchor::Object`, `light.position` is relative to the object.
    pub light: Light,
    /// What moves the light from frame to frame (nothing, for [`LightAnchor::World`]).
    pub anchor: LightAnchor,
}

/// A complete scene.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The catalog scene's name, or the file's stem; messages name the scene by it.
    pub name: String,
    /// The meshes objects place, each in its own object space.
    pub meshes: Vec<Mesh>,
    /// The materials objects use (at most `consts::MAX_MATERIALS`).
    pub materials: Vec<Material>,
    /// Every placed mesh.
    pub objects: Vec<Object>,
    /// The loops [`Motion::Walk`] objects follow.
    pub paths: Vec<Path>,
    /// Every light with its anchor (at least one, at most [`MAX_LIGHTS`]).
    pub lights: Vec<SceneLight>,
    /// Base-colour textures the materials name (loaded scenes; the catalog has none).
    pub textures: Vec<Texture>,
    /// The camera over the animation; its last key sets the frame count.
    pub camera_path: CameraPath,
    /// Frame size used when the user gives none.
    pub default_size: (u32, u32),
    /// Its lights' units, its materials' BRDF and its exposure (the catalog's: the papers').
    pub lighting: Lighting,
    /// The lights (by index) a file gave no range, with the range lightgrid derived
    /// (`lighting::derive_ranges`); empty for the catalog.
    pub derived_ranges: Vec<(usize, f32)>,
    /// Per-frame transforms of [`Motion::Track`] objects and [`LightAnchor::Track`] lights
    /// (a file's own animation); empty for the catalog.
    pub tracks: Vec<Vec<Mat4>>,
}

/// The frame's geometry in world space: opaque triangles first (grouped by material shader),
/// then the transparent objects' triangles, object by object from the farthest to the
/// nearest.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Geometry {
    /// The baked objects' vertices, positions and normals in world space.
    pub vertices: Vec<GpuVertex>,
    /// Three vertex indices per triangle; `vertices[0]` has index `base`, the vertex the
    /// geometry was baked to start at (0 for [`Scene::geometry`]).
    pub indices: Vec<u32>,
    /// `indices[..opaque_indices]` are opaque, the rest transparent, back to front.
    pub opaque_indices: usize,
    /// Runs of indices drawn with one material shader, in drawing order (the opaque runs
    /// first): forward pipelines switch pipelines between runs (per-material draws).
    pub draws: Vec<Draw>,
}

/// A run of indices whose triangles all use one material shader.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Draw {
    /// `consts::MATERIAL_SHADER_*`.
    pub shader: u32,
    /// The run's materials are alpha tested (a depth-only pass needs a fragment stage).
    pub alpha_test: bool,
    /// Position of the run's first index in [`Geometry::indices`].
    pub first: u32,
    /// Number of indices in the run (three per triangle).
    pub count: u32,
}

impl Draw {
    /// The same run, its indices `offset` further on.
    pub fn offset(self, offset: u32) -> Draw {
        Draw {
            first: self.first + offset,
            ..self
        }
    }
}

impl Geometry {
    /// The transparent triangles in world space (the analysis rasterizes them); `base` is
    /// the vertex the geometry's indices start at.
    pub fn transparent_triangles(&self, base: u32) -> Vec<[Vec3; 3]> {
        self.indices[self.opaque_indices..]
            .chunks_exact(3)
            .map(|t| {
                [t[0], t[1], t[2]].map(|i| Vec3::from(self.vertices[(i - base) as usize].position))
            })
            .collect()
    }

    /// The runs of opaque indices, and of transparent ones.
    pub fn split_draws(&self) -> (&[Draw], &[Draw]) {
        let n = self
            .draws
            .iter()
            .take_while(|d| (d.first as usize) < self.opaque_indices)
            .count();
        self.draws.split_at(n)
    }
}

/// The scene evaluated at one frame.
#[derive(Clone, Debug)]
pub struct FrameState {
    /// The frame evaluated.
    pub frame: u32,
    /// The camera at this frame.
    pub camera: Camera,
    /// Every light at this frame in world space, in [`Scene::lights`]' order.
    pub lights: Vec<Light>,
    /// World transform of each object.
    pub transforms: Vec<Mat4>,
}

impl Scene {
    /// Number of frames in the animation: the camera path's (last key frame + 1).
    pub fn frame_count(&self) -> u32 {
        self.camera_path.frame_count()
    }

    /// Refuse a frame past the end of the animation.
    pub fn check_frame(&self, frame: u32) -> Result<()> {
        let frames = self.frame_count();
        if frame >= frames {
            return Err(Error::invalid(
                "frame",
                format!(
                    "{frame} is past the end of {} (frames 0..={})",
                    self.name,
                    frames - 1
                ),
            ));
        }
        Ok(())
    }

    fn motion_transform(&self, motion: &Motion, frame: u32) -> Mat4 {
        match motion {
            Motion::Static => Mat4::IDENTITY,
            Motion::Track(t) => self.track_at(*t, frame),
            Motion::Walk { path, speed, start } => {
                let (pos, dir) = self.paths[*path].sample(start + speed * frame as f32);
                // Object space faces +z; turn it toward the direction of travel.
                let yaw = dir.x.atan2(dir.z);
                Mat4::from_rotation_translation(Quat::from_rotation_y(yaw), pos)
            }
        }
    }

    /// Track `t`'s transform at `frame` (the last one past its end; identity for a track that
    /// does not exist or is empty).
    fn track_at(&self, t: usize, frame: u32) -> Mat4 {
        let track = self.tracks.get(t).map_or(&[][..], Vec::as_slice);
        track
            .get(frame as usize)
            .or(track.last())
            .copied()
            .unwrap_or(Mat4::IDENTITY)
    }

    /// Evaluate the animation at `frame` (frames past the end hold the last camera key).
    pub fn frame(&self, frame: u32) -> FrameState {
        let motion: Vec<Mat4> = self
            .objects
            .iter()
            .map(|o| self.motion_transform(&o.motion, frame))
            .collect();
        let transforms = self
            .objects
            .iter()
            .zip(&motion)
            .map(|(o, m)| *m * o.local)
            .collect();
        let lights = self
            .lights
            .iter()
            .map(|l| match l.anchor {
                LightAnchor::World => l.light,
                LightAnchor::Circle {
                    radius,
                    frames_per_turn,
                    phase,
                } => Light {
                    position: circle_position(
                        l.light.position,
                        radius,
                        frames_per_turn,
                        phase,
                        frame,
                    ),
                    ..l.light
                },
                LightAnchor::Track(t) => {
                    let m = self.track_at(t, frame);
                    Light {
                        position: m.transform_point3(l.light.position),
                        spot: l.light.spot.map(|s| Spot {
                            direction: m.transform_vector3(s.direction).normalize_or(s.direction),
                            ..s
                        }),
                        ..l.light
                    }
                }
                LightAnchor::Object(o) => Light {
                    position: motion[o].transform_point3(l.light.position),
                    spot: l.light.spot.map(|s| Spot {
                        direction: motion[o]
                            .transform_vector3(s.direction)
                            .normalize_or(s.direction),
                        ..s
                    }),
                    ..l.light
                },
            })
            .collect();
        FrameState {
            frame,
            camera: self.camera_path.at(frame),
            lights,
            transforms,
        }
    }

    /// Is the object opaque and fixed: part of the geometry uploaded once?
    fn is_static_opaque(&self, o: &Object) -> bool {
        o.is_static() && !self.is_transparent(o)
    }

    /// Is the object drawn blended, after the opaque geometry?
    pub fn is_transparent(&self, o: &Object) -> bool {
        self.materials[o.material].transparent
    }

    /// Does the scene have transparent objects?
    pub fn has_transparency(&self) -> bool {
        self.objects.iter().any(|o| self.is_transparent(o))
    }

    /// All objects of the frame in world space: the static opaque objects first
    /// ([`Scene::static_geometry`]), then [`Scene::frame_geometry`]'s.
    pub fn geometry(&self, state: &FrameState) -> Geometry {
        let mut g = self.static_geometry();
        let moving = self.frame_geometry(state, g.vertices.len() as u32);
        let offset = g.indices.len() as u32;
        g.opaque_indices += moving.opaque_indices;
        g.draws
            .extend(moving.draws.iter().map(|d| d.offset(offset)));
        g.vertices.extend(moving.vertices);
        g.indices.extend(moving.indices);
        g
    }

    /// The opaque objects that never move, in world space, grouped by material shader: the
    /// same every frame, so a renderer uploads them once.
    pub fn static_geometry(&self) -> Geometry {
        let mut items: Vec<(usize, Mat4)> = self
            .objects
            .iter()
            .enumerate()
            .filter(|(_, o)| self.is_static_opaque(o))
            .map(|(i, o)| (i, o.local))
            .collect();
        items.sort_by_key(|&(i, _)| self.shader_of(i));
        let mut out = Geometry::default();
        self.bake_runs(&items, 0, &mut out);
        out.opaque_indices = out.indices.len();
        out
    }

    /// What changes per frame, with indices starting at vertex `base` (where it follows the
    /// static geometry): the moving opaque objects (grouped by material shader), then every
    /// transparent object, sorted back to front ([`Scene::transparent_order`]; tiled-shading
    /// §4: blending needs the order; objects that intersect can still sort wrong).
    pub fn frame_geometry(&self, state: &FrameState, base: u32) -> Geometry {
        let mut moving: Vec<(usize, Mat4)> = self
            .objects
            .iter()
            .enumerate()
            .filter(|(_, o)| !o.is_static() && !self.is_transparent(o))
            .map(|(i, _)| (i, state.transforms[i]))
            .collect();
        moving.sort_by_key(|&(i, _)| self.shader_of(i));
        let mut out = Geometry::default();
        self.bake_runs(&moving, base, &mut out);
        out.opaque_indices = out.indices.len();
        let transparent: Vec<(usize, Mat4)> = self
            .transparent_order(state)
            .into_iter()
            .map(|i| (i, state.transforms[i]))
            .collect();
        self.bake_runs(&transparent, base, &mut out);
        out
    }

    /// The material shader id of object `i`, and whether it is alpha tested: what a run of
    /// one draw shares.
    fn shader_of(&self, i: usize) -> (u32, bool) {
        let m = &self.materials[self.objects[i].material];
        (m.shader.gpu().0, m.alpha_cutoff.is_some())
    }

    /// Bake objects in order, merging consecutive ones with one shader into one draw (never
    /// into a draw from before this call: opaque and transparent runs stay apart).
    fn bake_runs(&self, items: &[(usize, Mat4)], base: u32, out: &mut Geometry) {
        let earlier = out.draws.len();
        for &(i, m) in items {
            let first = out.indices.len() as u32;
            self.bake(&self.objects[i], m, base, out);
            let count = out.indices.len() as u32 - first;
            let (shader, alpha_test) = self.shader_of(i);
            let mergeable = out.draws.len() > earlier;
            match out.draws.last_mut() {
                Some(d)
                    if mergeable
                        && (d.shader, d.alpha_test) == (shader, alpha_test)
                        && d.first + d.count == first =>
                {
                    d.count += count
                }
                _ => out.draws.push(Draw {
                    shader,
                    alpha_test,
                    first,
                    count,
                }),
            }
        }
    }

    /// The transparent objects, farthest first: by the distance from the camera to the
    /// centre of each object's bounds (ties by index).
    pub fn transparent_order(&self, state: &FrameState) -> Vec<usize> {
        let eye = state.camera.eye;
        let mut order: Vec<(f32, usize)> = self
            .objects
            .iter()
            .enumerate()
            .filter(|(_, o)| self.is_transparent(o))
            .map(|(i, o)| {
                let centre = state.transforms[i].transform_point3(self.meshes[o.mesh].centre());
                (-centre.distance_squared(eye), i)
            })
            .collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        order.into_iter().map(|(_, i)| i).collect()
    }

    /// A hash of everything a renderer uploads once per scene or bakes each frame from the
    /// scene rather than from the [`FrameState`]: every mesh, every object's mesh, material
    /// and placement, the materials and every texel. Two scenes with one fingerprint render
    /// the same frame from the same state (`Renderer::render` compares them with it).
    pub fn content_fingerprint(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        let words = |h: &mut std::collections::hash_map::DefaultHasher, v: &[f32]| {
            bytemuck::cast_slice::<f32, u32>(v).hash(h)
        };
        for mesh in &self.meshes {
            mesh.indices.hash(&mut h);
            words(&mut h, bytemuck::cast_slice(&mesh.positions));
            words(&mut h, bytemuck::cast_slice(&mesh.normals));
            words(&mut h, bytemuck::cast_slice(&mesh.uvs));
            words(&mut h, bytemuck::cast_slice(&mesh.tangents));
            words(&mut h, bytemuck::cast_slice(&mesh.colors));
            words(&mut h, bytemuck::cast_slice(&mesh.uvs1));
        }
        for o in &self.objects {
            (o.mesh, o.material, o.is_static()).hash(&mut h);
            words(&mut h, &o.local.to_cols_array());
        }
        for m in &self.materials {
            words(&mut h, bytemuck::cast_slice(&[m.to_gpu()]));
            m.alpha_cutoff.is_some().hash(&mut h);
        }
        for t in &self.textures {
            (t.width, t.height, &t.rgba).hash(&mut h);
        }
        let l = self.lighting;
        (l.units, l.brdf, l.exposure.to_bits()).hash(&mut h);
        h.finish()
    }

    /// The vertices and indices [`Scene::frame_geometry`] bakes every frame (the moving and
    /// the transparent objects'): the room a renderer leaves after the static geometry.
    pub fn frame_geometry_len(&self) -> (usize, usize) {
        self.objects
            .iter()
            .filter(|o| !self.is_static_opaque(o))
            .map(|o| &self.meshes[o.mesh])
            .fold((0, 0), |(v, i), m| {
                (v + m.positions.len(), i + m.indices.len())
            })
    }

    fn bake(&self, o: &Object, m: Mat4, base: u32, out: &mut Geometry) {
        let (vertices, indices) = (&mut out.vertices, &mut out.indices);
        let mesh = &self.meshes[o.mesh];
        let first = base + vertices.len() as u32;
        let nm = glam::Mat3::from_mat4(m).inverse().transpose();
        // A tangent turns with the surface (not as a normal does); a mirroring transform
        // turns the bitangent's handedness.
        let handed = if m.determinant() < 0.0 { -1.0 } else { 1.0 };
        for i in 0..mesh.positions.len() {
            let tangent = mesh.tangents.get(i).map_or([0; 4], |t| {
                let xyz = m.transform_vector3(t.truncate()).normalize_or_zero();
                xyz.extend(t.w.signum() * handed)
                    .to_array()
                    .map(crate::gpu_types::snorm16)
            });
            vertices.push(GpuVertex {
                position: m.transform_point3(mesh.positions[i]).to_array(),
                normal: (nm * mesh.normals[i]).normalize_or_zero().to_array(),
                uv: mesh.uvs[i].to_array(),
                material: o.material as u32,
                tangent,
                color: mesh
                    .colors
                    .get(i)
                    .map_or([255; 4], |c| c.to_array().map(crate::gpu_types::unorm8)),
                uv1: mesh.uvs1.get(i).unwrap_or(&mesh.uvs[i]).to_array(),
            });
        }
        indices.extend(mesh.indices.iter().map(|i| i + first));
    }

    /// Check the scene is renderable: lights valid and within [`MAX_LIGHTS`], indices in
    /// range, materials referenced exist.
    pub fn validate(&self) -> Result<()> {
        if self.lights.is_empty() {
            return Err(Error::invalid(
                "scene",
                format!("{} has no lights", self.name),
            ));
        }
        if self.lights.len() > MAX_LIGHTS as usize {
            return Err(Error::invalid(
                "scene",
                format!(
                    "{} lights exceed the maximum of {MAX_LIGHTS}",
                    self.lights.len()
                ),
            ));
        }
        for (i, l) in self.lights.iter().enumerate() {
            l.light.validate(i)?;
        }
        self.validate_structure()
    }

    /// What a renderer needs of a scene to bake it (`Renderer::set_scene`): an exposure within
    /// `source::MAX_EXPOSURE`, every index in
    /// range (objects to meshes and materials, materials to textures, triangles to vertices),
    /// one normal and one UV per position, and the table sizes within the GPU's limits.
    pub fn validate_structure(&self) -> Result<()> {
        let e = self.lighting.exposure;
        if !(e.is_finite() && e > 0.0 && e <= source::MAX_EXPOSURE) {
            return Err(Error::invalid(
                "scene",
                format!(
                    "{}'s exposure {} is not a positive number up to {:e}",
                    self.name,
                    show(e),
                    source::MAX_EXPOSURE
                ),
            ));
        }
        if self.materials.len() > crate::consts::MAX_MATERIALS {
            return Err(Error::invalid(
                "scene",
                format!(
                    "{} materials exceed the maximum of {}",
                    self.materials.len(),
                    crate::consts::MAX_MATERIALS
                ),
            ));
        }
        for (i, m) in self.materials.iter().enumerate() {
            let bad_texture = m.textures().any(|t| t as usize >= self.textures.len());
            if bad_texture {
                return Err(Error::invalid(
                    "scene",
                    format!("material {i} names a missing texture"),
                ));
            }
        }
        if self.textures.len() > crate::consts::MAX_TEXTURES {
            return Err(Error::invalid(
                "scene",
                format!(
                    "{} textures exceed the maximum of {}",
                    self.textures.len(),
                    crate::consts::MAX_TEXTURES
                ),
            ));
        }
        for (i, t) in self.textures.iter().enumerate() {
            let texels = u64::from(t.width) * u64::from(t.height);
            if t.width == 0 || t.height == 0 || t.rgba.len() as u64 != texels * 4 {
                return Err(Error::invalid(
                    "scene",
                    format!("texture {i} is not {}x{} RGBA8", t.width, t.height),
                ));
            }
        }
        for (i, o) in self.objects.iter().enumerate() {
            let mesh = self.meshes.get(o.mesh).ok_or_else(|| {
                Error::invalid("scene", format!("object {i} references a missing mesh"))
            })?;
            if o.material >= self.materials.len() {
                return Err(Error::invalid(
                    "scene",
                    format!("object {i} references a missing material"),
                ));
            }
            if mesh.normals.len() != mesh.positions.len() || mesh.uvs.len() != mesh.positions.len()
            {
                return Err(Error::invalid(
                    "scene",
                    format!(
                        "mesh {} has {} positions but {} normals and {} UVs",
                        o.mesh,
                        mesh.positions.len(),
                        mesh.normals.len(),
                        mesh.uvs.len()
                    ),
                ));
            }
            if mesh
                .indices
                .iter()
                .any(|&v| v as usize >= mesh.positions.len())
            {
                return Err(Error::invalid(
                    "scene",
                    format!("mesh {} has an index out of range", o.mesh),
                ));
            }
        }
        Ok(())
    }

    /// Every material as the shaders read it ([`Material::to_gpu`]), in index order.
    pub fn materials_gpu(&self) -> Vec<GpuMaterial> {
        self.materials.iter().map(Material::to_gpu).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn error(l: &Light) -> String {
        l.validate(3).unwrap_err().to_string()
    }

    #[test]
    fn light_values_are_checked_as_products_with_their_values() {
        let ok = Light::point(Vec3::ZERO, Vec3::ONE, 10.0, 5.0);
        ok.validate(0).unwrap();
        // Each finite, the product past f32 (and far past the bound).
        let e = error(&Light {
            color: Vec3::splat(1e30),
            intensity: 1e10,
            ..ok
        });
        assert!(
            e.contains("light 3: radiance (colour [1e30, 1e30, 1e30] × intensity 1e10) of 1e40 exceeds 1e12"),
            "{e}"
        );
        // Just inside and just outside the bound.
        let at = LIGHT_LIMITS.max_radiance;
        Light {
            intensity: at,
            ..ok
        }
        .validate(0)
        .unwrap();
        assert!(error(&Light {
            intensity: at * 1.01,
            ..ok
        })
        .contains("radiance"));
        // What the GPU gets from a light inside the bounds is finite, squares included.
        let big = Light {
            position: Vec3::splat(LIGHT_LIMITS.max_coordinate),
            color: Vec3::ONE,
            intensity: at,
            range: LIGHT_LIMITS.max_range,
            spot: None,
        };
        big.validate(0).unwrap();
        let g = big.to_gpu();
        assert!(g.radiance.iter().all(|c| c.is_finite()));
        assert!((g.range * g.range).is_finite());
        let (c, r) = big.bounding_sphere();
        assert!(c.is_finite() && (r * r).is_finite() && (2.0 * c).length_squared().is_finite());
        let tiny = LIGHT_LIMITS.min_range;
        assert!((tiny * tiny).is_normal());
    }

    #[test]
    fn a_tiny_range_is_named_as_the_cause() {
        let ok = Light::point(Vec3::ZERO, Vec3::ONE, 10.0, 5.0);
        let e = error(&Light { range: 1e-30, ..ok });
        assert!(e.contains("range 1e-30 is too small"), "{e}");
        let e = error(&Light { range: 1e30, ..ok });
        assert!(e.contains("range 1e30 is too large"), "{e}");
        let e = error(&Light {
            range: f32::NAN,
            ..ok
        });
        assert!(e.contains("range NaN must be a positive number"), "{e}");
        let e = error(&Light {
            intensity: -1.0,
            ..ok
        });
        assert!(
            e.contains("intensity -1 must be finite and non-negative"),
            "{e}"
        );
        let e = error(&Light {
            position: Vec3::new(0.0, 2e12, 0.0),
            ..ok
        });
        assert!(e.contains("position [0, 2e12, 0]"), "{e}");
    }

    /// What the renderer uploads once per scene or bakes from the scene changes the
    /// fingerprint, down to one texel; what a frame's state carries does not.
    #[test]
    fn the_content_fingerprint_sees_every_uploaded_byte_and_nothing_else() {
        let mut base = catalog::build("robots-few", &catalog::SceneParams::default()).unwrap();
        base.textures.push(Texture {
            width: 4,
            height: 4,
            rgba: vec![200; 64],
        });
        let fp = base.content_fingerprint();
        let moving = base.objects.iter().position(|o| !o.is_static()).unwrap();
        let static_ = base.objects.iter().position(|o| o.is_static()).unwrap();
        type Change = Box<dyn Fn(&mut Scene)>;
        let changed: Vec<(&str, Change)> = vec![
            ("a texel", Box::new(|s| s.textures[0].rgba[1] = 7)),
            (
                "a moving object's mesh",
                Box::new(move |s| {
                    let m = s.objects[moving].mesh;
                    s.meshes[m].positions[0].x += 0.5;
                }),
            ),
            (
                "a static object's placement",
                Box::new(move |s| s.objects[static_].local.w_axis.x += 1.0),
            ),
            (
                "a material's alpha test",
                Box::new(|s| s.materials[0].alpha_cutoff = Some(0.0)),
            ),
            (
                "a material's colour",
                Box::new(|s| s.materials[0].diffuse.x += 0.25),
            ),
            (
                "an object made static",
                Box::new(move |s| s.objects[moving].motion = Motion::Static),
            ),
        ];
        for (what, change) in &changed {
            let mut s = base.clone();
            change(&mut s);
            assert_ne!(s.content_fingerprint(), fp, "{what}");
        }
        let mut same = base.clone();
        same.lights.truncate(1);
        same.camera_path.keys[0].1.x += 3.0;
        same.name = "renamed".into();
        assert_eq!(
            same.content_fingerprint(),
            fp,
            "lights, camera and name are state"
        );
    }

    #[test]
    fn the_room_left_for_a_frame_is_what_a_frame_bakes() {
        let scene = catalog::build("robots-many", &catalog::SceneParams::default()).unwrap();
        for frame in [0, 40] {
            let g = scene.frame_geometry(&scene.frame(frame), 0);
            assert_eq!(
                scene.frame_geometry_len(),
                (g.vertices.len(), g.indices.len())
            );
        }
        assert!(
            scene.frame_geometry_len().0 > 0,
            "robots-many has moving robots"
        );
    }
}
