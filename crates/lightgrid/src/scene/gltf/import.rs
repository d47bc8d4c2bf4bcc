//! A parsed glTF document to a lightgrid [`Scene`]: the scene's node hierarchy walked once
//! (cycles and nodes with two parents refused), every triangle primitive instanced as an
//! object, metallic-roughness materials mapped to the light function's terms (rendered with
//! GGX by default), KHR_lights_punctual lights placed in their photometric units, and a
//! camera path fitted to the scene.

use super::animation;
use super::json::{LightDef, MaterialDef, Node, Primitive, TextureRef};
use super::read::{Document, Res};
use super::{LoadOptions, EXTENSIONS_READ, MAX_TRIANGLES, MAX_VERTICES};
use crate::scene::{
    bounds_of, CameraPath, Light, LightAnchor, Lighting, Material, MaterialShader, Mesh, Motion,
    Object, Scene, SceneLight, Spot, Texture,
};
use glam::{Mat4, Quat, Vec2, Vec3, Vec4};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

/// Frames of the orbit a loaded scene's camera follows (as long as the robots animation).
pub const ORBIT_FRAMES: u32 = crate::scene::catalog::ROBOTS_FRAMES;
/// Keys of the orbit (Catmull-Rom between them stays within 1% of the circle).
const ORBIT_KEYS: u32 = 16;
/// Width of a loaded scene's default frame (its height from the camera's aspect, else 16:9).
const DEFAULT_WIDTH: u32 = 640;

/// Everything the walk collects before the scene is assembled.
#[derive(Default)]
struct Walk {
    objects: Vec<Object>,
    meshes: Vec<Mesh>,
    /// (glTF mesh, primitive, winding flipped) → index into `meshes`, or `None` if skipped.
    cache: HashMap<(usize, usize, bool), Option<usize>>,
    /// (camera or light index, world transform, node).
    cameras: Vec<(usize, Mat4, usize)>,
    lights: Vec<(usize, Mat4, usize)>,
    /// The nodes walked, parents before children: (node, parent).
    order: Vec<(usize, Option<usize>)>,
    /// The node that placed each of `objects`.
    object_nodes: Vec<usize>,
    /// Vertices and indices read from accessors, and baked into objects: each bounded.
    read_vertices: u64,
    read_indices: u64,
    baked_vertices: u64,
    baked_triangles: u64,
    warnings: Vec<String>,
    warned: std::collections::HashSet<String>,
    more_warnings: usize,
}

/// Warnings kept; the rest are counted ("and N more").
const MAX_WARNINGS: usize = 50;

impl Walk {
    fn warn(&mut self, w: String) {
        if self.warned.insert(w.clone()) {
            if self.warnings.len() < MAX_WARNINGS {
                self.warnings.push(w);
            } else {
                self.more_warnings += 1;
            }
        }
    }

    /// The warnings, the last saying how many more there were.
    fn finish_warnings(&mut self) -> Vec<String> {
        let mut w = std::mem::take(&mut self.warnings);
        if self.more_warnings > 0 {
            w.push(format!("... and {} more warnings", self.more_warnings));
        }
        w
    }
}

/// The lightgrid material a file exported by lightgrid carries in `extras.lightgrid`, so
/// that export → load gives back the exact material (glTF's PBR model cannot express
/// Blinn-Phong's independent specular colour or the material shaders).
#[derive(Serialize, Deserialize)]
pub(super) struct ExactMaterial {
    pub diffuse: [f32; 3],
    pub specular: [f32; 3],
    pub shininess: f32,
    pub emissive: [f32; 3],
    pub ambient: [f32; 3],
    pub alpha: f32,
    pub transparent: bool,
    /// "standard", "car_paint" or "rim".
    pub shader: String,
    pub paint: [f32; 3],
    pub paint_power: f32,
    /// The alpha test's cutoff (the texture is the glTF material's `baseColorTexture`).
    #[serde(default)]
    pub alpha_cutoff: Option<f32>,
    /// A file's metallic-roughness inputs (base colour, metallic, roughness), so an exported
    /// file's material is still derived per sample when read back.
    #[serde(default)]
    pub metallic_roughness: Option<([f32; 3], f32, f32)>,
}

impl ExactMaterial {
    pub(super) fn from_material(m: &Material) -> ExactMaterial {
        let (shader, paint, paint_power) = match m.shader {
            MaterialShader::Standard => ("standard", Vec3::ZERO, 1.0),
            MaterialShader::CarPaint { flip, power } => ("car_paint", flip, power),
            MaterialShader::Rim { color, power } => ("rim", color, power),
        };
        ExactMaterial {
            diffuse: m.diffuse.to_array(),
            specular: m.specular.to_array(),
            shininess: m.shininess,
            emissive: m.emissive.to_array(),
            ambient: m.ambient.to_array(),
            alpha: m.alpha,
            transparent: m.transparent,
            shader: shader.into(),
            paint: paint.to_array(),
            paint_power,
            alpha_cutoff: m.alpha_cutoff,
            metallic_roughness: (m.metallic_roughness)
                .map(|p| (p.base.to_array(), p.metallic, p.roughness)),
        }
    }

    fn to_material(&self) -> Option<Material> {
        let paint = Vec3::from(self.paint);
        let shader = match self.shader.as_str() {
            "standard" => MaterialShader::Standard,
            "car_paint" => MaterialShader::CarPaint {
                flip: paint,
                power: self.paint_power,
            },
            "rim" => MaterialShader::Rim {
                color: paint,
                power: self.paint_power,
            },
            _ => return None,
        };
        let m = Material {
            diffuse: self.diffuse.into(),
            specular: self.specular.into(),
            shininess: self.shininess,
            emissive: self.emissive.into(),
            ambient: self.ambient.into(),
            alpha: self.alpha,
            transparent: self.transparent,
            shader,
            texture: None,
            emissive_texture: None,
            metallic_roughness: self
                .metallic_roughness
                .and_then(|(base, metallic, roughness)| {
                    let ok = base
                        .iter()
                        .chain([&metallic, &roughness])
                        .all(|v| (0.0..=1.0e6).contains(v));
                    ok.then(|| crate::scene::MetallicRoughness {
                        base: base.into(),
                        metallic: metallic.min(1.0),
                        roughness: roughness.min(1.0),
                        texture: None,
                    })
                }),
            alpha_cutoff: self.alpha_cutoff.filter(|c| c.is_finite()),
            // No textures: `map_material` adds the file's.
            ..Material::plain(Vec3::ONE, 0.0, 1.0)
        };
        material_is_sane(&m).then_some(m)
    }
}

fn material_is_sane(m: &Material) -> bool {
    let colours = [m.diffuse, m.specular, m.emissive, m.ambient];
    colours
        .iter()
        .all(|c| c.is_finite() && c.min_element() >= 0.0)
        && m.shininess.is_finite()
        && m.shininess >= 0.0
        && (0.0..=1.0).contains(&m.alpha)
}

/// The largest emissive colour read (`emissiveFactor` × KHR_materials_emissive_strength), as a
/// light's radiance is bounded: sums over a pixel stay finite in f32.
const MAX_EMISSIVE: f32 = 1e12;

/// glTF's metallic-roughness material (§3.9.2) to Blinn-Phong, by one documented rule:
/// diffuse = base × (1 − metallic); specular = mix(0.04, base, metallic) (the dielectric F0
/// of the specification's BRDF, metals tinted); shininess = 2/α² − 2 with α = roughness²
/// (the Blinn-Phong exponent whose lobe matches GGX of that α), from `MIN_SHININESS` (just
/// above 0, roughness 1) to `MAX_SHININESS` (2048, roughness 0.18); ambient =
/// base; emissive = emissiveFactor × KHR_materials_emissive_strength, times the
/// `emissiveTexture` where there is one. `BLEND` is drawn transparent with the base alpha.
/// The material lightgrid exported into `extras.lightgrid` (its own Blinn-Phong material,
/// exactly), with the file's metallic-roughness texture where it has the factors; None (a
/// warning if it was malformed) for the glTF material.
fn exact_material(
    def: &MaterialDef,
    index: usize,
    mr_texture: Option<u32>,
    walk: &mut Walk,
) -> Option<Material> {
    if let Some(exact) = def
        .extras
        .as_ref()
        .and_then(|e| e.get("lightgrid"))
        .map(ExactMaterial::deserialize)
    {
        match exact.ok().and_then(|e| e.to_material()) {
            Some(m) => {
                let mr = match (m.metallic_roughness, mr_texture) {
                    (Some(p), texture) => Some(crate::scene::MetallicRoughness { texture, ..p }),
                    (None, Some(_)) => {
                        walk.warn(format!("material {index}: its metallicRoughnessTexture is not applied to lightgrid's own Blinn-Phong material (extras.lightgrid)"));
                        None
                    }
                    (None, None) => None,
                };
                return Some(Material {
                    metallic_roughness: mr,
                    ..m
                });
            }
            None => walk.warn(format!(
                "material {index}: its extras.lightgrid is malformed; the glTF material is used"
            )),
        }
    }
    None
}

/// The textures a glTF material reads, each in its slot (`TEXTURE_SLOT_*`: ours, its
/// coordinate set, wrapping, filtering and `KHR_texture_transform`), with the normal
/// texture's scale and the occlusion texture's strength.
struct TextureSlots {
    texture: Option<u32>,
    emissive: Option<u32>,
    metal_rough: Option<u32>,
    normal: Option<(u32, f32)>,
    occlusion: Option<(u32, f32)>,
    uv_sets: u32,
    wraps: u32,
    nearest: u32,
    uv_transforms: [glam::Affine2; 5],
}

impl TextureSlots {
    fn load(def: &MaterialDef, index: usize, textures: &mut TextureLoader) -> Res<TextureSlots> {
        let pbr = def.pbr_metallic_roughness.as_ref();
        // Each texture a material reads, in its slot: ours, its coordinate set and wrapping.
        let mut uv_sets = 0;
        let mut wraps = 0;
        let mut nearest = 0;
        let mut uv_transforms = [glam::Affine2::IDENTITY; 5];
        let mut slot = |r: Option<&TextureRef>, slot: u32, linear: bool| -> Res<Option<u32>> {
            let Some(r) = r else { return Ok(None) };
            let t = textures.load(r.index, index, linear)?;
            let (transform, set) = texture_transform(r)
                .map_err(|e| format!("material {index}: KHR_texture_transform: {e}"))?;
            uv_transforms[slot as usize] = transform;
            uv_sets |= u32::from(set == 1) << slot;
            wraps |= t.wrap << (4 * slot);
            nearest |= u32::from(t.nearest) << slot;
            Ok(Some(t.index))
        };
        use crate::consts::{
            TEXTURE_SLOT_BASE, TEXTURE_SLOT_EMISSIVE, TEXTURE_SLOT_METAL_ROUGH,
            TEXTURE_SLOT_NORMAL, TEXTURE_SLOT_OCCLUSION,
        };
        let texture = slot(
            pbr.and_then(|p| p.base_color_texture.as_ref()),
            TEXTURE_SLOT_BASE,
            false,
        )?;
        let emissive_texture = slot(def.emissive_texture.as_ref(), TEXTURE_SLOT_EMISSIVE, false)?;
        let mr_texture = slot(
            pbr.and_then(|p| p.metallic_roughness_texture.as_ref()),
            TEXTURE_SLOT_METAL_ROUGH,
            true,
        )?;
        let normal = slot(def.normal_texture.as_ref(), TEXTURE_SLOT_NORMAL, true)?;
        let occlusion = slot(def.occlusion_texture.as_ref(), TEXTURE_SLOT_OCCLUSION, true)?;
        let scale = def
            .normal_texture
            .as_ref()
            .and_then(|t| t.scale)
            .unwrap_or(1.0);
        let strength = (def.occlusion_texture.as_ref())
            .and_then(|t| t.strength)
            .unwrap_or(1.0);
        if !scale.is_finite() || !(0.0..=1.0).contains(&strength) {
            return Err(format!(
                "material {index}: normalTexture.scale must be finite and occlusionTexture.strength 0 to 1 (found {scale}, {strength})"
            ));
        }
        Ok(TextureSlots {
            texture,
            emissive: emissive_texture,
            metal_rough: mr_texture,
            normal: normal.map(|t| (t, scale)),
            occlusion: occlusion.map(|t| (t, strength)),
            uv_sets,
            wraps,
            nearest,
            uv_transforms,
        })
    }

    /// `m` reading these textures.
    fn apply(&self, m: Material) -> Material {
        Material {
            texture: self.texture,
            emissive_texture: self.emissive,
            normal_texture: self.normal,
            occlusion_texture: self.occlusion,
            uv_sets: self.uv_sets,
            wraps: self.wraps,
            nearest: self.nearest,
            uv_transforms: self.uv_transforms,
            ..m
        }
    }
}

fn map_material(
    def: &MaterialDef,
    index: usize,
    textures: &mut TextureLoader,
    walk: &mut Walk,
) -> Res<Material> {
    let pbr = def.pbr_metallic_roughness.as_ref();
    let slots = TextureSlots::load(def, index, textures)?;
    let (texture, mr_texture) = (slots.texture, slots.metal_rough);
    let textured = |m: Material| slots.apply(m);
    if let Some(m) = exact_material(def, index, mr_texture, walk) {
        return Ok(textured(m));
    }
    let base = pbr.and_then(|p| p.base_color_factor).unwrap_or([1.0; 4]);
    let metallic = pbr.and_then(|p| p.metallic_factor).unwrap_or(1.0);
    let roughness = pbr.and_then(|p| p.roughness_factor).unwrap_or(1.0);
    // KHR_materials_emissive_strength scales the factor past 1 (physical units).
    let strength = (def.extensions.as_ref())
        .and_then(|e| e.emissive_strength.as_ref())
        .and_then(|s| s.emissive_strength)
        .unwrap_or(1.0);
    let emissive = def
        .emissive_factor
        .unwrap_or([0.0; 3])
        .map(|c| c * strength);
    let numbers = base.iter().chain(&emissive).chain([&metallic, &roughness]);
    for v in numbers {
        if !v.is_finite() || *v < 0.0 {
            return Err(format!(
                "material {index}: factors must be finite and non-negative (found {v})"
            ));
        }
    }
    if let Some(e) = emissive.iter().find(|&&e| e > MAX_EMISSIVE) {
        return Err(format!(
            "material {index}: emissive factor × strength {e} is above {MAX_EMISSIVE:e} (sums of light must stay finite)"
        ));
    }
    let (metallic, roughness) = (metallic.min(1.0), roughness.min(1.0));
    let colour = Vec3::new(base[0], base[1], base[2]);
    let alpha_g = (roughness * roughness).max(1e-3);
    let mode = def.alpha_mode.as_deref().unwrap_or("OPAQUE");
    let transparent = match mode {
        "OPAQUE" | "MASK" => false,
        "BLEND" => true,
        other => {
            return Err(format!(
                "material {index}: alphaMode '{other}' is not OPAQUE, MASK or BLEND"
            ))
        }
    };
    // MASK (§3.9.4): a constant alpha is tested here (`masked_out`); a texture's per texel.
    let cutoff = def.alpha_cutoff.unwrap_or(0.5);
    if !cutoff.is_finite() || cutoff < 0.0 {
        return Err(format!(
            "material {index}: alphaCutoff {cutoff} is not a non-negative number"
        ));
    }
    let alpha_tested = mode == "MASK" && texture.is_some();
    Ok(textured(Material {
        diffuse: colour * (1.0 - metallic),
        specular: Vec3::splat(0.04).lerp(colour, metallic),
        shininess: (2.0 / (alpha_g * alpha_g) - 2.0)
            .clamp(crate::consts::MIN_SHININESS, crate::consts::MAX_SHININESS),
        emissive: emissive.into(),
        ambient: colour,
        alpha: if transparent || alpha_tested {
            base[3].min(1.0)
        } else {
            1.0
        },
        transparent,
        shader: MaterialShader::Standard,
        metallic_roughness: Some(crate::scene::MetallicRoughness {
            base: colour,
            metallic,
            roughness,
            texture: mr_texture,
        }),
        alpha_cutoff: alpha_tested.then_some(cutoff),
        // The textures, their sets, wrapping and transforms: `textured`.
        ..Material::plain(Vec3::ONE, 0.0, 1.0)
    }))
}

/// The file's textures as scene textures, each image decoded once (PNG or JPEG, with
/// `image_io::decode_image`'s limits).
struct TextureLoader<'a> {
    doc: &'a Document,
    /// (image, linear data) → our texture: an image read as colour and as data is two.
    by_image: HashMap<(usize, bool), u32>,
    textures: Vec<Texture>,
}

/// A texture a material reads: ours, its sampler's wrapping (4 bits: u, then v) and whether
/// it magnifies nearest-texel.
#[derive(Clone, Copy)]
struct Loaded {
    index: u32,
    wrap: u32,
    nearest: bool,
}

/// A texture reference's `KHR_texture_transform` (§ of the extension: translation × rotation
/// × scale on the coordinates, rotation counter-clockwise in UV space) and the coordinate set
/// it reads (the extension's `texCoord` overrides the reference's).
fn texture_transform(r: &TextureRef) -> Res<(glam::Affine2, u32)> {
    let Some(t) = r.extensions.as_ref().and_then(|e| e.transform.as_ref()) else {
        return Ok((glam::Affine2::IDENTITY, r.set()));
    };
    let offset = glam::Vec2::from(t.offset.unwrap_or([0.0, 0.0]));
    let rotation = t.rotation.unwrap_or(0.0);
    let scale = glam::Vec2::from(t.scale.unwrap_or([1.0, 1.0]));
    if !(offset.is_finite() && rotation.is_finite() && scale.is_finite()) {
        return Err("offset, rotation and scale must be finite".into());
    }
    let (sin, cos) = rotation.sin_cos();
    // The extension's rotation matrix is [[cos, sin], [-sin, cos]] (columns as written).
    let rotate = glam::Mat2::from_cols(glam::Vec2::new(cos, -sin), glam::Vec2::new(sin, cos));
    let m = rotate * glam::Mat2::from_diagonal(scale);
    Ok((glam::Affine2::from_mat2_translation(m, offset), r.set()))
}

/// Encode a linear value (0-255) as the sRGB byte the GPU's sRGB decode turns back into it.
fn srgb_encoded(v: u8) -> u8 {
    let x = f32::from(v) / 255.0;
    let e = if x <= 0.003_130_8 {
        x * 12.92
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    };
    (e * 255.0).round().clamp(0.0, 255.0) as u8
}

/// A glTF sampler wrap mode (10497 repeat, 33071 clamp to edge, 33648 mirrored repeat) as
/// `consts::WRAP_*`.
fn wrap_mode(w: Option<u32>) -> Res<u32> {
    match w.unwrap_or(10497) {
        10497 => Ok(crate::consts::WRAP_REPEAT),
        33071 => Ok(crate::consts::WRAP_CLAMP),
        33648 => Ok(crate::consts::WRAP_MIRROR),
        other => Err(format!("wrap mode {other} is not 10497, 33071 or 33648")),
    }
}

impl TextureLoader<'_> {
    /// Our texture for glTF texture `index` (named by material `material`): colour
    /// (sRGB) or, with `linear`, data stored so that the sRGB decode gives its values back.
    fn load(&mut self, index: usize, material: usize, linear: bool) -> Res<Loaded> {
        let what = format!("material {material}");
        let def = self
            .doc
            .root
            .textures
            .get(index)
            .ok_or_else(|| format!("{what}: texture {index} does not exist"))?;
        let source = def.source.ok_or_else(|| {
            format!("{what}: texture {index} has no source image (an extension's?)")
        })?;
        let mut wrap = 0;
        let mut nearest = false;
        if let Some(s) = def.sampler {
            let sampler = self
                .doc
                .root
                .samplers
                .get(s)
                .ok_or_else(|| format!("texture {index}: sampler {s} does not exist"))?;
            let bad = |e: String| format!("texture {index}: sampler {s}: {e}");
            wrap = wrap_mode(sampler.wrap_s).map_err(bad)?
                | wrap_mode(sampler.wrap_t).map_err(bad)? << 2;
            nearest = sampler.mag_filter == Some(9728);
        }
        if let Some(&t) = self.by_image.get(&(source, linear)) {
            return Ok(Loaded {
                index: t,
                wrap,
                nearest,
            });
        }
        if self.textures.len() >= crate::consts::MAX_TEXTURES {
            return Err(format!(
                "more than {} textures",
                crate::consts::MAX_TEXTURES
            ));
        }
        let image = self
            .doc
            .root
            .images
            .get(source)
            .ok_or_else(|| format!("texture {index}: image {source} does not exist"))?;
        let what = format!("image {source}");
        let bytes = match (&image.uri, image.buffer_view) {
            (Some(uri), _) => self.doc.fetch(uri, &what)?,
            (None, Some(v)) => std::rc::Rc::new(self.doc.view(v, &what)?.1.to_vec()),
            (None, None) => return Err(format!("{what} has neither a uri nor a bufferView")),
        };
        let mut rgba = crate::image_io::decode_image(&bytes, &what).map_err(|e| e.to_string())?;
        // Keep at most MAX_TEXTURE_EDGE texels a side (the GPU array's largest layer).
        let edge = crate::consts::MAX_TEXTURE_EDGE;
        let (w, h) = rgba.dimensions();
        if w.max(h) > edge {
            let scale = edge as f32 / w.max(h) as f32;
            let (nw, nh) = (
                ((w as f32 * scale).round() as u32).max(1),
                ((h as f32 * scale).round() as u32).max(1),
            );
            rgba = image::imageops::resize(&rgba, nw, nh, image::imageops::FilterType::Triangle);
        }
        if linear {
            for p in rgba.pixels_mut() {
                for c in &mut p.0[..3] {
                    *c = srgb_encoded(*c);
                }
            }
        }
        self.textures.push(Texture {
            width: rgba.width(),
            height: rgba.height(),
            rgba: rgba.into_raw(),
        });
        let t = self.textures.len() as u32 - 1;
        self.by_image.insert((source, linear), t);
        Ok(Loaded {
            index: t,
            wrap,
            nearest,
        })
    }
}

/// Is a `MASK` material's constant alpha below its cutoff (every fragment discarded, §3.9.4)?
fn masked_out(def: &MaterialDef) -> bool {
    let alpha = def
        .pbr_metallic_roughness
        .as_ref()
        .and_then(|p| p.base_color_factor)
        .map_or(1.0, |b| b[3]);
    // A texture's alpha multiplies the factor and is at most 1: the test holds with one too.
    def.alpha_mode.as_deref() == Some("MASK") && alpha < def.alpha_cutoff.unwrap_or(0.5)
}

/// A node's local transform (§3.5.3: `matrix`, or translation × rotation × scale).
fn local_matrix(node: &Node, index: usize) -> Res<Mat4> {
    let m = match node.matrix {
        Some(m) => Mat4::from_cols_array(&m),
        None => {
            let t = Vec3::from(node.translation.unwrap_or([0.0; 3]));
            let r = node.rotation.unwrap_or([0.0, 0.0, 0.0, 1.0]);
            let s = Vec3::from(node.scale.unwrap_or([1.0; 3]));
            let q = Quat::from_array(r);
            if !q.is_finite() || q.length_squared() < 1e-12 {
                return Err(format!("node {index}: rotation {r:?} is not a quaternion"));
            }
            Mat4::from_scale_rotation_translation(s, q.normalize(), t)
        }
    };
    if !m.is_finite() {
        return Err(format!(
            "node {index}: its transform has a NaN or infinite number"
        ));
    }
    Ok(m)
}

/// Triangles of a primitive's vertex sequence (§3.7.2.1: list, strip or fan).
fn triangulate(mode: u32, seq: &[u32]) -> Vec<u32> {
    let n = seq.len();
    let mut out = Vec::with_capacity(n.saturating_sub(2) * 3);
    match mode {
        5 => {
            for i in 0..n.saturating_sub(2) {
                if i % 2 == 0 {
                    out.extend_from_slice(&[seq[i], seq[i + 1], seq[i + 2]]);
                } else {
                    out.extend_from_slice(&[seq[i + 1], seq[i], seq[i + 2]]);
                }
            }
        }
        6 => {
            for i in 1..n.saturating_sub(1) {
                out.extend_from_slice(&[seq[0], seq[i], seq[i + 1]]);
            }
        }
        _ => out.extend_from_slice(&seq[..n - n % 3]),
    }
    out
}

/// Area-weighted vertex normals of a triangle list: the stand-in for a zero normal a file
/// gives.
fn computed_normals(positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let mut n = vec![Vec3::ZERO; positions.len()];
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| positions[i as usize]);
        let face = (b - a).cross(c - a);
        for &i in t {
            n[i as usize] += face;
        }
    }
    n.into_iter().map(|v| v.normalize_or(Vec3::Y)).collect()
}

fn vec3s(flat: &[f32]) -> Vec<Vec3> {
    flat.chunks_exact(3).map(Vec3::from_slice).collect()
}

/// The mesh of one triangle primitive, or `None` (with a warning) for points and lines.
/// The primitive's positions (accessor `pos_acc`), all finite; counted against the file's
/// vertex limit.
fn file_positions(doc: &Document, pos_acc: usize, what: &str, walk: &mut Walk) -> Res<Vec<Vec3>> {
    let count = doc.root.accessors.get(pos_acc).map_or(0, |a| a.count);
    walk.read_vertices = walk.read_vertices.saturating_add(count);
    if walk.read_vertices > MAX_VERTICES as u64 {
        return Err(format!(
            "{what}: the file's meshes have more than {MAX_VERTICES} vertices"
        ));
    }
    let positions = vec3s(&doc.read_floats(pos_acc, 3, &format!("{what} POSITION"))?);
    if positions.iter().any(|p| !p.is_finite()) {
        return Err(format!(
            "{what}: POSITION (accessor {pos_acc}) has a NaN or infinite coordinate"
        ));
    }
    Ok(positions)
}

/// The texture coordinate sets (0 and 1) the primitive's material reads, a warning for each
/// the primitive lacks.
fn texture_sets(
    material: Option<&MaterialDef>,
    prim: &Primitive,
    what: &str,
    walk: &mut Walk,
) -> Vec<u32> {
    let mut sets = material.map_or(Vec::new(), material_sets);
    sets.retain(|&s| s <= 1);
    for set in sets.iter().map(|s| format!("TEXCOORD_{s}")) {
        if !prim.attributes.contains_key(&set) {
            walk.warn(format!(
                "{what}: textured without {set}; its texture is sampled at one texel"
            ));
        }
    }
    sets
}

/// The primitive's index sequence (its accessor's, or every vertex in order), each index
/// within `vertices`; counted against the file's triangle limit.
fn index_sequence(
    doc: &Document,
    prim: &Primitive,
    what: &str,
    walk: &mut Walk,
    vertices: usize,
) -> Res<Vec<u32>> {
    let Some(i) = prim.indices else {
        return Ok((0..vertices as u32).collect());
    };
    let n = doc.root.accessors.get(i).map_or(0, |a| a.count);
    walk.read_indices = walk.read_indices.saturating_add(n);
    if walk.read_indices > 3 * MAX_TRIANGLES as u64 {
        return Err(format!(
            "{what}: the file's meshes have more than {MAX_TRIANGLES} triangles"
        ));
    }
    let seq = doc.read_indices(i, &format!("{what} indices"))?;
    if let Some(bad) = seq.iter().find(|&&v| v as usize >= vertices) {
        return Err(format!(
            "{what}: index {bad} (accessor {i}) is out of range for {vertices} vertices"
        ));
    }
    Ok(seq)
}

/// The primitive's `TEXCOORD_k`, one finite UV per vertex, or None without it.
fn uv_set(
    doc: &Document,
    prim: &Primitive,
    k: u32,
    vertices: usize,
    what: &str,
) -> Res<Option<Vec<Vec2>>> {
    let set = format!("TEXCOORD_{k}");
    let Some(&a) = prim.attributes.get(&set) else {
        return Ok(None);
    };
    let uv: Vec<Vec2> = doc
        .read_floats(a, 2, &format!("{what} {set}"))?
        .chunks_exact(2)
        .map(|c| Vec2::new(c[0], c[1]))
        .collect();
    if uv.len() != vertices || uv.iter().any(|v| !v.is_finite()) {
        return Err(format!(
            "{what}: {set} (accessor {a}) needs one finite UV per vertex"
        ));
    }
    Ok(Some(uv))
}

/// The file's tangents (accessor `a`), one finite tangent per vertex.
fn file_tangents(doc: &Document, a: usize, vertices: usize, what: &str) -> Res<Vec<Vec4>> {
    let t: Vec<Vec4> = doc
        .read_floats(a, 4, &format!("{what} TANGENT"))?
        .chunks_exact(4)
        .map(Vec4::from_slice)
        .collect();
    if t.len() != vertices || t.iter().any(|v| !v.is_finite()) {
        return Err(format!(
            "{what}: TANGENT (accessor {a}) needs one finite tangent per vertex"
        ));
    }
    Ok(t)
}

/// The file's normals (accessor `a`), one finite normal per vertex; a zero normal, which
/// cannot be normalized, is the faces' around it.
fn file_normals(
    doc: &Document,
    a: usize,
    positions: &[Vec3],
    indices: &[u32],
    what: &str,
) -> Res<Vec<Vec3>> {
    let n = vec3s(&doc.read_floats(a, 3, &format!("{what} NORMAL"))?);
    if n.len() != positions.len() || n.iter().any(|v| !v.is_finite()) {
        return Err(format!(
            "{what}: NORMAL (accessor {a}) needs one finite normal per vertex"
        ));
    }
    let around = computed_normals(positions, indices);
    Ok(n.iter()
        .zip(&around)
        .map(|(v, c)| v.try_normalize().unwrap_or(*c))
        .collect())
}

fn primitive_mesh(
    doc: &Document,
    (mi, pi): (usize, usize),
    prim: &Primitive,
    flipped: bool,
    walk: &mut Walk,
) -> Res<Option<Mesh>> {
    let what = format!("mesh {mi} primitive {pi}");
    let mode = prim.mode.unwrap_or(4);
    match mode {
        4..=6 => {}
        0..=3 => {
            walk.warn(format!(
                "{what}: points and lines (mode {mode}) are not drawn; skipped"
            ));
            return Ok(None);
        }
        _ => return Err(format!("{what}: mode {mode} is not a glTF primitive mode")),
    }
    let Some(&pos_acc) = prim.attributes.get("POSITION") else {
        walk.warn(format!("{what}: no POSITION attribute; skipped"));
        return Ok(None);
    };
    let positions = file_positions(doc, pos_acc, &what, walk)?;
    let seq = index_sequence(doc, prim, &what, walk, positions.len())?;
    let indices = triangulate(mode, &seq);
    if indices.is_empty() {
        walk.warn(format!("{what}: no triangles; skipped"));
        return Ok(None);
    }
    // The texture coordinate sets the primitive's material reads, each checked for.
    let material = prim.material.and_then(|m| doc.root.materials.get(m));
    let sets = texture_sets(material, prim, &what, walk);
    let uvs = uv_set(doc, prim, 0, positions.len(), &what)?
        .unwrap_or_else(|| vec![Vec2::ZERO; positions.len()]);
    let uvs1 = match sets.contains(&1) {
        true => uv_set(doc, prim, 1, positions.len(), &what)?.unwrap_or_default(),
        false => Vec::new(),
    };
    let colors = match prim.attributes.get("COLOR_0") {
        Some(&a) => vertex_colours(doc, a, positions.len(), &what)?,
        None => Vec::new(),
    };
    let normal_texture = material.and_then(|m| m.normal_texture.as_ref());
    let tangents = match (normal_texture, prim.attributes.get("TANGENT")) {
        (Some(_), Some(&a)) => file_tangents(doc, a, positions.len(), &what)?,
        _ => Vec::new(),
    };
    let mut mesh = match prim.attributes.get("NORMAL") {
        Some(&a) => {
            let normals = file_normals(doc, a, &positions, &indices, &what)?;
            Mesh {
                positions,
                normals,
                uvs,
                indices,
                tangents,
                colors,
                uvs1,
            }
        }
        None => {
            if indices.len() > MAX_VERTICES as usize {
                return Err(format!(
                    "{what}: {} corners would be more than {MAX_VERTICES} vertices with flat normals",
                    indices.len()
                ));
            }
            let welded = Mesh {
                positions,
                normals: Vec::new(),
                uvs,
                indices,
                tangents,
                colors,
                uvs1,
            };
            flat_mesh(&welded)
        }
    };
    // A normal texture without the file's tangents: MikkTSpace's (glTF §3.7.2.1), on the
    // texture's coordinate set, each corner its own vertex (its tangent is the corner's).
    if let Some(t) = normal_texture.filter(|_| mesh.tangents.is_empty()) {
        if mesh.indices.len() > MAX_VERTICES as usize {
            return Err(format!(
                "{what}: {} corners would be more than {MAX_VERTICES} vertices with generated tangents",
                mesh.indices.len()
            ));
        }
        mesh = with_generated_tangents(&unwelded(&mesh), t.set());
    }
    // Normals come from the file's winding; only then is it flipped for a mirroring
    // transform.
    if flipped {
        mesh.flip_winding();
    }
    Ok(Some(mesh))
}

/// `m` with every corner its own vertex (each per-vertex array expanded alike).
fn unwelded(m: &Mesh) -> Mesh {
    fn pick<T: Copy>(v: &[T], idx: &[u32]) -> Vec<T> {
        if v.is_empty() {
            return Vec::new();
        }
        idx.iter().map(|&i| v[i as usize]).collect()
    }
    Mesh {
        positions: pick(&m.positions, &m.indices),
        normals: pick(&m.normals, &m.indices),
        uvs: pick(&m.uvs, &m.indices),
        tangents: pick(&m.tangents, &m.indices),
        colors: pick(&m.colors, &m.indices),
        uvs1: pick(&m.uvs1, &m.indices),
        indices: (0..m.indices.len() as u32).collect(),
    }
}

/// A triangle list without normals as the specification asks to shade it (§3.7.2.1: flat
/// normals): one vertex per corner, each with its face's normal.
fn flat_mesh(welded: &Mesh) -> Mesh {
    let mut m = unwelded(welded);
    m.normals = m
        .positions
        .chunks_exact(3)
        .flat_map(|t| [(t[1] - t[0]).cross(t[2] - t[0]).normalize_or(Vec3::Y); 3])
        .collect();
    m
}

/// An unwelded mesh (three vertices a triangle) with MikkTSpace tangents on coordinate set
/// `set`.
fn with_generated_tangents(m: &Mesh, set: u32) -> Mesh {
    struct Faces<'a> {
        mesh: &'a Mesh,
        uvs: &'a [Vec2],
        tangents: Vec<Vec4>,
    }
    impl mikktspace::Geometry for Faces<'_> {
        fn num_faces(&self) -> usize {
            self.mesh.positions.len() / 3
        }
        fn num_vertices_of_face(&self, _face: usize) -> usize {
            3
        }
        fn position(&self, face: usize, vert: usize) -> [f32; 3] {
            self.mesh.positions[face * 3 + vert].to_array()
        }
        fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
            self.mesh.normals[face * 3 + vert].to_array()
        }
        fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
            self.uvs[face * 3 + vert].to_array()
        }
        fn set_tangent_encoded(&mut self, tangent: [f32; 4], face: usize, vert: usize) {
            self.tangents[face * 3 + vert] = Vec4::from_array(tangent);
        }
    }
    let uvs = match set {
        1 if !m.uvs1.is_empty() => &m.uvs1,
        _ => &m.uvs,
    };
    let mut faces = Faces {
        mesh: m,
        uvs,
        tangents: vec![Vec4::ZERO; m.positions.len()],
    };
    // A degenerate mapping leaves zero tangents: the shader then keeps the vertex normal.
    mikktspace::generate_tangents(&mut faces);
    Mesh {
        tangents: faces.tangents,
        ..m.clone()
    }
}

/// `COLOR_0` as colours (VEC3 or VEC4, floats or normalized integers), checked.
fn vertex_colours(doc: &Document, a: usize, n: usize, what: &str) -> Res<Vec<Vec4>> {
    let comps = match doc.root.accessors.get(a).map(|acc| acc.kind.as_str()) {
        Some("VEC3") => 3,
        Some("VEC4") => 4,
        _ => {
            return Err(format!(
                "{what}: COLOR_0 (accessor {a}) is not VEC3 or VEC4"
            ))
        }
    };
    let c: Vec<Vec4> = doc
        .read_floats(a, comps, &format!("{what} COLOR_0"))?
        .chunks_exact(comps)
        .map(|c| Vec4::new(c[0], c[1], c[2], if comps == 4 { c[3] } else { 1.0 }))
        .collect();
    if c.len() != n || c.iter().any(|v| !v.is_finite() || v.min_element() < 0.0) {
        return Err(format!(
            "{what}: COLOR_0 (accessor {a}) needs one finite, non-negative colour per vertex"
        ));
    }
    Ok(c)
}

/// The texture coordinate sets a material's textures read.
fn material_sets(m: &MaterialDef) -> Vec<u32> {
    let pbr = m.pbr_metallic_roughness.as_ref();
    let refs = [
        pbr.and_then(|p| p.base_color_texture.as_ref()),
        pbr.and_then(|p| p.metallic_roughness_texture.as_ref()),
        m.emissive_texture.as_ref(),
        m.normal_texture.as_ref(),
        m.occlusion_texture.as_ref(),
    ];
    let mut sets: Vec<u32> = refs.iter().flatten().map(|t| t.set()).collect();
    sets.sort_unstable();
    sets.dedup();
    sets
}

/// Instance node `ni`'s mesh with world transform `world`.
fn instance_mesh(
    doc: &Document,
    mi: usize,
    world: Mat4,
    materials: &MaterialMap,
    walk: &mut Walk,
) -> Res<()> {
    let def = doc
        .root
        .meshes
        .get(mi)
        .ok_or_else(|| format!("mesh {mi} does not exist"))?;
    // Singular relative to the transform's own scale (a uniformly tiny model is fine).
    let det = world.determinant();
    let scale = world.x_axis.truncate().length()
        * world.y_axis.truncate().length()
        * world.z_axis.truncate().length();
    if !det.is_finite() || det.abs() <= scale * 1e-6 {
        walk.warn(format!(
            "an instance of mesh {mi} has a singular transform (zero scale); skipped"
        ));
        return Ok(());
    }
    // A mirroring transform turns the winding (§3.7.4), and the renderer's two-sided lighting
    // flips normals by the winding: flip the triangles back.
    let flipped = det < 0.0;
    for (pi, prim) in def.primitives.iter().enumerate() {
        let material = match prim.material {
            None => materials.default,
            Some(m) => match materials.by_gltf.get(m) {
                None => {
                    return Err(format!(
                        "mesh {mi} primitive {pi}: material {m} does not exist"
                    ))
                }
                Some(None) => continue,
                Some(Some(i)) => *i,
            },
        };
        let key = (mi, pi, flipped);
        let mesh = match walk.cache.get(&key) {
            Some(m) => *m,
            None => {
                let m = primitive_mesh(doc, (mi, pi), prim, flipped, walk)?.map(|mesh| {
                    walk.meshes.push(mesh);
                    walk.meshes.len() - 1
                });
                walk.cache.insert(key, m);
                m
            }
        };
        let Some(mesh) = mesh else { continue };
        let m = &walk.meshes[mesh];
        walk.baked_vertices += m.positions.len() as u64;
        walk.baked_triangles += m.triangle_count() as u64;
        if walk.baked_vertices > MAX_VERTICES as u64 || walk.baked_triangles > MAX_TRIANGLES as u64
        {
            return Err(format!(
                "the scene's instances add up to more than {MAX_VERTICES} vertices or {MAX_TRIANGLES} triangles"
            ));
        }
        walk.objects.push(Object {
            mesh,
            material,
            local: world,
            motion: Motion::Static,
        });
    }
    Ok(())
}

/// glTF materials as scene materials: `by_gltf[i]` is material i's index, `None` for a
/// `MASK` material whose constant alpha is under its cutoff (nothing of it is drawn).
struct MaterialMap {
    by_gltf: Vec<Option<usize>>,
    default: usize,
}

/// Walk the chosen scene's node trees depth first.
fn walk_nodes(doc: &Document, materials: &MaterialMap, walk: &mut Walk) -> Res<()> {
    let nodes = &doc.root.nodes;
    let roots: Vec<usize> = match (doc.root.scene, doc.root.scenes.is_empty()) {
        (Some(s), _) => doc
            .root
            .scenes
            .get(s)
            .ok_or_else(|| format!("the default scene {s} does not exist"))?
            .nodes
            .clone(),
        (None, false) => doc.root.scenes[0].nodes.clone(),
        (None, true) => {
            let mut child = vec![false; nodes.len()];
            for n in nodes {
                for &c in &n.children {
                    if let Some(slot) = child.get_mut(c) {
                        *slot = true;
                    }
                }
            }
            (0..nodes.len()).filter(|&i| !child[i]).collect()
        }
    };
    // A node is marked when it is first put on the stack, so a repeated child is refused
    // before the stack can grow with it.
    let mut seen = vec![false; nodes.len()];
    let mut mark = |ni: usize| -> Res<()> {
        match seen.get_mut(ni) {
            None => Err(format!("node {ni} does not exist")),
            Some(true) => Err(format!(
                "node {ni} is reached twice: the node graph has a cycle or a node with two parents (glTF nodes form trees)"
            )),
            Some(slot) => {
                *slot = true;
                Ok(())
            }
        }
    };
    let mut stack: Vec<(usize, Mat4, Option<usize>)> = Vec::new();
    for &r in roots.iter().rev() {
        mark(r)?;
        stack.push((r, Mat4::IDENTITY, None));
    }
    while let Some((ni, parent, parent_node)) = stack.pop() {
        walk.order.push((ni, parent_node));
        let node = &nodes[ni];
        let world = parent * local_matrix(node, ni)?;
        if !world.is_finite() {
            return Err(format!(
                "node {ni}: its world transform overflows (the hierarchy's scales multiply past f32)"
            ));
        }
        if let Some(mi) = node.mesh {
            let before = walk.objects.len();
            instance_mesh(doc, mi, world, materials, walk)?;
            let placed = walk.objects.len() - before;
            walk.object_nodes.extend(std::iter::repeat_n(ni, placed));
        }
        if let Some(c) = node.camera {
            walk.cameras.push((c, world, ni));
        }
        if let Some(l) = node.extensions.as_ref().and_then(|e| e.lights.as_ref()) {
            walk.lights.push((l.light, world, ni));
        }
        for &c in node.children.iter().rev() {
            mark(c)?;
            stack.push((c, world, Some(ni)));
        }
    }
    Ok(())
}

/// A file's light as lightgrid's.
struct MappedLight {
    light: Light,
    /// The file gave its range.
    ranged: bool,
    /// Its intensity is lightgrid's own, from `extras.lightgrid` (a file lightgrid exported).
    exact: bool,
}

/// A spot light's cone at its node's `world` transform (pointing down its −z): glTF's
/// angles, checked, or the exact cosines a file lightgrid exported carries.
fn spot_of(
    what: &str,
    world: Mat4,
    (inner, outer): (f32, f32),
    exact_cone: Option<(f32, f32)>,
) -> Res<Spot> {
    let ok = inner.is_finite()
        && outer.is_finite()
        && inner >= 0.0
        && inner < outer
        && outer <= std::f32::consts::FRAC_PI_2;
    if !ok {
        return Err(format!(
            "{what}: cone angles need 0 ≤ inner < outer ≤ π/2 (found {inner}, {outer})"
        ));
    }
    let dir = world.transform_vector3(Vec3::NEG_Z);
    let dir = dir
        .try_normalize()
        .ok_or_else(|| format!("{what}: its node's transform has no direction"))?;
    let mut spot = Spot::new(dir, inner, outer);
    if let Some((ci, co)) = exact_cone {
        if (-1.0..=1.0).contains(&co) && ci <= 1.0 && ci > co {
            (spot.cos_inner, spot.cos_outer) = (ci, co);
        }
    }
    Ok(spot)
}

/// A file's light as lightgrid's. Its intensity stays in candela (the scene's lights are
/// photometric: `Lighting::photometric`), unless the file lightgrid exported carries the
/// exact intensity in its own units.
fn map_light(
    def: &LightDef,
    index: usize,
    world: Mat4,
    walk: &mut Walk,
) -> Res<Option<MappedLight>> {
    let what = format!("light {index}");
    let colour = Vec3::from(def.color.unwrap_or([1.0; 3]));
    let candela = def.intensity.unwrap_or(1.0);
    if !colour.is_finite() || colour.min_element() < 0.0 || !candela.is_finite() || candela < 0.0 {
        return Err(format!(
            "{what}: colour and intensity must be finite and non-negative"
        ));
    }
    let spot = match def.kind.as_str() {
        "point" => None,
        "spot" => Some(
            def.spot
                .as_ref()
                .map_or((0.0, std::f32::consts::FRAC_PI_4), |s| {
                    (
                        s.inner_cone_angle.unwrap_or(0.0),
                        s.outer_cone_angle.unwrap_or(std::f32::consts::FRAC_PI_4),
                    )
                }),
        ),
        "directional" => {
            walk.warn(format!(
                "{what}: directional lights have no range (lightgrid's lights are bounded, tiled-shading §1.1); skipped"
            ));
            return Ok(None);
        }
        other => {
            return Err(format!(
                "{what}: type '{other}' is not point, spot or directional"
            ))
        }
    };
    let peak = candela * colour.max_element();
    if peak <= 0.0 {
        walk.warn(format!("{what}: zero intensity; skipped"));
        return Ok(None);
    }
    let range = match def.range {
        Some(r) if r.is_finite() && r > 0.0 => r,
        Some(r) => return Err(format!("{what}: range {r} is not a positive number")),
        // Infinite (KHR_lights_punctual): derived once the scene and its exposure are known
        // (`lighting::derive_ranges`); until then it reaches everything.
        None => crate::scene::LIGHT_LIMITS.max_range,
    };
    // A file lightgrid exported carries the exact numbers (the glTF ones are rounded through
    // the candela and angle conversions).
    let exact = def.extras.as_ref().and_then(|e| e.get("lightgrid"));
    let number = |key: &str| {
        exact
            .and_then(|v| v.get(key))
            .and_then(|v| v.as_f64())
            .map(|v| v as f32)
            .filter(|v| v.is_finite())
    };
    let intensity = number("intensity").filter(|v| *v >= 0.0).unwrap_or(candela);
    let colour = exact
        .and_then(|v| v.get("color"))
        .and_then(|v| serde_json::from_value::<[f32; 3]>(v.clone()).ok())
        .map(Vec3::from)
        .filter(|c| c.is_finite() && c.min_element() >= 0.0)
        .unwrap_or(colour);
    let position = world.transform_point3(Vec3::ZERO);
    let exact_cone = number("cos_inner").zip(number("cos_outer"));
    let spot = match spot {
        None => None,
        Some(angles) => Some(spot_of(&what, world, angles, exact_cone)?),
    };
    let light = Light {
        position,
        color: colour,
        intensity,
        range,
        spot,
    };
    light.check_values().map_err(|reason| {
        let derived = number("intensity").is_none()
            && (reason.starts_with("radiance") || reason.starts_with("intensity"));
        if derived {
            format!(
                "{what}: {reason} (from the intensity {} cd)",
                crate::scene::show(candela)
            )
        } else {
            format!("{what}: {reason}")
        }
    })?;
    Ok(Some(MappedLight {
        light,
        ranged: def.range.is_some(),
        exact: number("intensity").is_some_and(|v| v >= 0.0),
    }))
}

/// Where the camera path starts.
struct Start {
    eye: Vec3,
    target: Vec3,
    /// The camera's up (+y of its node; its roll).
    up: Vec3,
    fov: f32,
    near: f32,
    far: f32,
}

/// The camera `--camera` names (checked), else the first perspective camera a node places.
fn chosen_camera(
    doc: &Document,
    opts: &LoadOptions,
    walk: &mut Walk,
) -> Res<Option<(usize, Mat4, usize)>> {
    let Some(n) = opts.camera else {
        let first = walk.cameras.iter().copied().find(|(c, _, _)| {
            doc.root
                .cameras
                .get(*c)
                .is_some_and(|d| d.kind == "perspective")
        });
        if first.is_none() && !walk.cameras.is_empty() {
            walk.warn("no perspective camera (orthographic ones are not rendered); one is fitted to the scene".into());
        }
        return Ok(first);
    };
    if n >= doc.root.cameras.len() {
        return Err(format!(
            "--camera {n}: the file has {} camera(s)",
            doc.root.cameras.len()
        ));
    }
    let (world, node) = walk
        .cameras
        .iter()
        .find(|(c, _, _)| *c == n)
        .map(|(_, w, node)| (*w, *node))
        .ok_or_else(|| format!("--camera {n}: no node of the scene places camera {n}"))?;
    if doc.root.cameras[n].kind != "perspective" {
        let kind = &doc.root.cameras[n].kind;
        let article = match kind.starts_with(['a', 'e', 'i', 'o', 'u']) {
            true => "an",
            false => "a",
        };
        return Err(format!(
            "--camera {n}: {article} {kind} camera; only perspective cameras are rendered"
        ));
    }
    Ok(Some((n, world, node)))
}

/// The start at perspective camera `n` placed by `world`; its aspect ratio sets `size`.
fn placed_start(
    doc: &Document,
    (n, world): (usize, Mat4),
    (centre, radius): (Vec3, f32),
    size: &mut (u32, u32),
) -> Res<Start> {
    let p = doc.root.cameras[n]
        .perspective
        .as_ref()
        .ok_or_else(|| format!("camera {n}: perspective camera without \"perspective\""))?;
    let ok = p.yfov.is_finite()
        && p.yfov > 0.0
        && p.yfov < std::f32::consts::PI
        && p.znear.is_finite()
        && p.znear > 0.0
        && p.zfar.is_none_or(|f| f.is_finite() && f > p.znear);
    if !ok {
        return Err(format!(
            "camera {n}: needs 0 < yfov < π, znear > 0 and zfar > znear (finite)"
        ));
    }
    if let Some(a) = p.aspect_ratio {
        if a.is_finite() && (0.1..=10.0).contains(&a) {
            size.1 = ((DEFAULT_WIDTH as f32 / a).round() as u32).max(1);
        }
    }
    // The camera's full orientation (§3.10.1: it looks down its node's −z with +y up), roll
    // included; made orthogonal, as a node may scale its axes unevenly.
    let eye = world.transform_point3(Vec3::ZERO);
    let no_direction = || format!("camera {n}: its node's transform has no direction");
    let forward = world
        .transform_vector3(Vec3::NEG_Z)
        .try_normalize()
        .ok_or_else(no_direction)?;
    let up = world.transform_vector3(Vec3::Y);
    let up = (up - forward * up.dot(forward))
        .try_normalize()
        .ok_or_else(no_direction)?;
    // Without zfar, far enough for the whole scene from anywhere on the orbit.
    let far = p
        .zfar
        .unwrap_or(((eye.distance(centre) + radius) * 1.05).max(p.znear * 2.0));
    Ok(Start {
        eye,
        target: eye + forward * radius.max(1.0),
        up,
        fov: p.yfov,
        near: p.znear,
        far,
    })
}

/// A camera fitted to the bounding sphere: 50° high, from 25° above and 30° round.
fn fitted_start(centre: Vec3, radius: f32) -> Start {
    let fov = 50f32.to_radians();
    let dist = radius / (fov * 0.5).sin() * 1.05;
    let (el, az) = (25f32.to_radians(), 30f32.to_radians());
    let dir = Vec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos());
    let far = (dist + radius) * 1.05;
    Start {
        eye: centre + dir * dist,
        target: centre,
        up: Vec3::Y,
        fov,
        near: far / 1000.0,
        far,
    }
}

/// The orbit of [`ORBIT_FRAMES`] about the vertical axis through `centre`, from `start`
/// (frame 0 is exactly the start).
fn orbit(start: &Start, centre: Vec3) -> CameraPath {
    let keys = (0..=ORBIT_KEYS)
        .map(|k| {
            let turn = Quat::from_rotation_y(k as f32 / ORBIT_KEYS as f32 * std::f32::consts::TAU);
            let about = |p: Vec3| centre + turn * (p - centre);
            (
                k * (ORBIT_FRAMES - 1) / ORBIT_KEYS,
                about(start.eye),
                about(start.target),
            )
        })
        .collect();
    let ups = (0..=ORBIT_KEYS)
        .map(|k| {
            Quat::from_rotation_y(k as f32 / ORBIT_KEYS as f32 * std::f32::consts::TAU) * start.up
        })
        .collect();
    CameraPath {
        keys,
        ups,
        fov_y: start.fov,
        near: start.near,
        far: start.far,
    }
}

/// The camera path (an orbit from the chosen or a fitted camera) and the default size.
fn camera_path(
    doc: &Document,
    opts: &LoadOptions,
    walk: &mut Walk,
    sampled: Option<&Sampled>,
) -> Res<(CameraPath, (u32, u32))> {
    // The objects are static and placed by their world matrices.
    let placed = walk.objects.iter().flat_map(|o| {
        walk.meshes[o.mesh]
            .positions
            .iter()
            .map(move |p| o.local.transform_point3(*p))
    });
    let (lo, hi) = bounds_of(placed)
        .filter(|(lo, hi)| lo.is_finite() && hi.is_finite())
        .ok_or("the scene's geometry has no finite bounds")?;
    let centre = (lo + hi) * 0.5;
    let radius = ((hi - lo).length() * 0.5).max(1e-3);
    let mut size = (DEFAULT_WIDTH, DEFAULT_WIDTH * 9 / 16);
    let chosen = chosen_camera(doc, opts, walk)?;
    let start = match chosen {
        Some((n, world, _)) => placed_start(doc, (n, world), (centre, radius), &mut size)?,
        None => fitted_start(centre, radius),
    };
    let Some(sampled) = sampled else {
        return Ok((orbit(&start, centre), size));
    };
    // The file animates itself: its camera as authored, moving with its node if that is
    // animated, with no orbit added.
    let mut keys = Vec::new();
    let mut ups = Vec::new();
    let track = chosen.and_then(|(_, _, node)| sampled.track_of.get(&node));
    match (chosen, track) {
        (Some((n, world, _)), Some(&t)) => {
            for (f, m) in sampled.tracks[t].iter().enumerate() {
                let at = placed_start(doc, (n, *m * world), (centre, radius), &mut size)?;
                keys.push((f as u32, at.eye, at.target));
                ups.push(at.up);
            }
        }
        _ => {
            for f in [0, sampled.frames.saturating_sub(1)] {
                keys.push((f, start.eye, start.target));
                ups.push(start.up);
            }
        }
    }
    let path = CameraPath {
        keys,
        ups,
        fov_y: start.fov,
        near: start.near,
        far: start.far,
    };
    Ok((path, size))
}

/// Most transforms a file's animation is sampled into (frames × moving nodes that place
/// something): 128 MiB of matrices. A longer animation is cut to fit, with a warning.
const MAX_TRACK_MATRICES: usize = 1 << 21;

/// A file's animation sampled: one track (a transform per frame, from the node's place at
/// rest to its place at that frame) per animated node that places a mesh, a light or a
/// camera.
struct Sampled {
    frames: u32,
    track_of: HashMap<usize, usize>,
    tracks: Vec<Vec<Mat4>>,
}

/// Sample `anim` at every frame for the nodes `walk` placed things with; None when it moves
/// none of them.
fn sample(doc: &Document, anim: &animation::Animation, walk: &mut Walk) -> Res<Option<Sampled>> {
    let nodes = &doc.root.nodes;
    let mut moving = vec![false; nodes.len()];
    for &(n, parent) in &walk.order {
        moving[n] = anim.moves(n) || parent.is_some_and(|p| moving[p]);
    }
    let placing = (walk.object_nodes.iter().copied())
        .chain(walk.lights.iter().map(|l| l.2))
        .chain(walk.cameras.iter().map(|c| c.2));
    let owners: std::collections::BTreeSet<usize> = placing.filter(|&n| moving[n]).collect();
    if owners.is_empty() {
        return Ok(None);
    }
    let owners: Vec<usize> = owners.into_iter().collect();
    let mut frames = anim.frames();
    let fit = (MAX_TRACK_MATRICES / owners.len()).max(1) as u32;
    if frames > fit {
        walk.warn(format!(
            "the animation's {} moving nodes are sampled for {fit} frames of its {frames} (at most {MAX_TRACK_MATRICES} transforms are kept)",
            owners.len()
        ));
        frames = fit;
    }
    let mut rest = vec![Mat4::IDENTITY; nodes.len()];
    let mut rest_world = vec![Mat4::IDENTITY; nodes.len()];
    for &(n, parent) in &walk.order {
        rest[n] = local_matrix(&nodes[n], n)?;
        rest_world[n] = parent.map_or(Mat4::IDENTITY, |p| rest_world[p]) * rest[n];
    }
    let from_rest: Vec<Mat4> = owners.iter().map(|&n| rest_world[n].inverse()).collect();
    let mut tracks = vec![Vec::with_capacity(frames as usize); owners.len()];
    let mut world = rest_world.clone();
    for f in 0..frames {
        let t = f as f32 / animation::FPS;
        for &(n, parent) in &walk.order {
            if moving[n] {
                let local = anim.local(&nodes[n], n, rest[n], t);
                world[n] = parent.map_or(Mat4::IDENTITY, |p| world[p]) * local;
            }
        }
        for (i, &n) in owners.iter().enumerate() {
            let m = world[n] * from_rest[i];
            if !m.is_finite() {
                return Err(format!(
                    "node {n}: its animated transform at {t:.3} s is not finite"
                ));
            }
            tracks[i].push(m);
        }
    }
    let track_of = owners.iter().enumerate().map(|(i, &n)| (n, i)).collect();
    Ok(Some(Sampled {
        frames,
        track_of,
        tracks,
    }))
}

/// The scene a document describes.
/// Refuse a file that requires an extension lightgrid does not read, or more materials than
/// it renders; warn of every extension used and part not applied.
fn check_extensions(doc: &Document, walk: &mut Walk) -> Res<()> {
    for ext in &doc.root.extensions_required {
        if !EXTENSIONS_READ.contains(&ext.as_str()) {
            return Err(format!(
                "the file requires extension {ext}, which lightgrid does not read (it reads: {})",
                EXTENSIONS_READ.join(", ")
            ));
        }
    }
    for ext in &doc.root.extensions_used {
        if !EXTENSIONS_READ.contains(&ext.as_str()) {
            walk.warn(format!("extension {ext} is not read; ignored"));
        }
    }
    for w in super::unread::warnings(&doc.root) {
        walk.warn(w);
    }
    if doc.root.materials.len() >= crate::consts::MAX_MATERIALS {
        return Err(format!(
            "{} materials; at most {} are rendered",
            doc.root.materials.len(),
            crate::consts::MAX_MATERIALS - 1
        ));
    }
    Ok(())
}

/// Every material the file's primitives may use (the specification's default last, where a
/// primitive names none), how the file's indices map to them, and their textures.
fn read_materials(
    doc: &Document,
    walk: &mut Walk,
) -> Res<(Vec<Material>, MaterialMap, Vec<Texture>)> {
    let mut materials = Vec::new();
    let mut by_gltf = Vec::new();
    let mut textures = TextureLoader {
        doc,
        by_image: HashMap::new(),
        textures: Vec::new(),
    };
    for (i, def) in doc.root.materials.iter().enumerate() {
        if masked_out(def) {
            by_gltf.push(None);
            continue;
        }
        materials.push(map_material(def, i, &mut textures, walk)?);
        by_gltf.push(Some(materials.len() - 1));
    }
    // The specification's default material, for primitives without one (only if any).
    let needs_default = doc
        .root
        .meshes
        .iter()
        .flat_map(|m| &m.primitives)
        .any(|p| p.material.is_none());
    if needs_default {
        let default = MaterialDef::default();
        materials.push(map_material(&default, usize::MAX, &mut textures, walk)?);
    }
    let map = MaterialMap {
        by_gltf,
        default: materials.len().saturating_sub(1),
    };
    Ok((materials, map, textures.textures))
}

/// The lights the file's nodes place (world space), each with the animation track of its
/// node, if any.
#[allow(clippy::type_complexity)]
fn read_lights(
    doc: &Document,
    walk: &mut Walk,
    sampled: Option<&Sampled>,
) -> Res<(Vec<MappedLight>, Vec<Option<usize>>)> {
    let defs = doc
        .root
        .extensions
        .as_ref()
        .and_then(|e| e.lights.as_ref())
        .map_or(&[][..], |l| &l.lights[..]);
    let mut lights = Vec::new();
    let mut light_tracks = Vec::new();
    for (li, world, node) in walk.lights.clone() {
        let def = defs
            .get(li)
            .ok_or_else(|| format!("a node names light {li}, which does not exist"))?;
        if let Some(light) = map_light(def, li, world, walk)? {
            lights.push(light);
            light_tracks.push(sampled.and_then(|s| s.track_of.get(&node).copied()));
        }
        if lights.len() > crate::consts::MAX_LIGHTS as usize {
            return Err(format!("more than {} lights", crate::consts::MAX_LIGHTS));
        }
    }
    Ok((lights, light_tracks))
}

/// Say which lights had no range and what they were given, and when no light shows.
fn warn_derived(scene: &Scene, derived: &crate::scene::DerivedRanges, walk: &mut Walk) {
    if let (Some(lo), Some(hi)) = (
        derived.ranges.iter().map(|r| r.1).reduce(f32::min),
        derived.ranges.iter().map(|r| r.1).reduce(f32::max),
    ) {
        let between = match lo == hi {
            true => crate::scene::show(lo),
            false => format!("{} to {}", crate::scene::show(lo), crate::scene::show(hi)),
        };
        walk.warn(format!(
            "{} light(s) have no range (infinite in KHR_lights_punctual): each ends where it shows half a display level on a white surface at exposure {}, at {between} ({} capped by the scene's bounds; --stats lists each)",
            derived.ranges.len(),
            crate::scene::show(scene.lighting.exposure),
            derived.capped
        ));
    }
    if !derived.visible && !scene.lights.is_empty() {
        walk.warn(format!(
            "no light shows half a display level on any surface at exposure {}: the image holds ambient and emissive light only",
            crate::scene::show(scene.lighting.exposure)
        ));
    }
}

pub(super) fn import(doc: &Document, name: &str, opts: &LoadOptions) -> Res<(Scene, Vec<String>)> {
    let mut walk = Walk::default();
    check_extensions(doc, &mut walk)?;
    let (materials, map, textures) = read_materials(doc, &mut walk)?;
    walk_nodes(doc, &map, &mut walk)?;
    // The file's own animation, sampled per frame for what it moves.
    let mut notes = Vec::new();
    let animation = animation::read(doc, &mut |w| notes.push(w))?;
    for note in notes {
        walk.warn(note);
    }
    let sampled = match &animation {
        Some(a) => sample(doc, a, &mut walk)?,
        None => None,
    };
    if walk.objects.is_empty() {
        // Say why where the file has primitives that are not drawn.
        let skipped = walk.warned.iter().any(|w| w.contains("points and lines"));
        return Err(if skipped {
            "the scene has no triangles to render: its primitives are points and lines, which lightgrid does not draw".into()
        } else {
            "the scene has no triangles to render".into()
        });
    }
    let (lights, light_tracks) = read_lights(doc, &mut walk, sampled.as_ref())?;
    let mut exported = exported_lighting(doc, &mut walk);
    // A file an earlier lightgrid exported records no lighting, but every light carries
    // lightgrid's own intensity: the papers' units and Blinn-Phong, as it was made.
    if exported.is_none() && !lights.is_empty() && lights.iter().all(|l| l.exact) {
        walk.warn(
            "every light carries lightgrid's own intensity but the file records no lighting (an earlier lightgrid's export): read in the papers' units with Blinn-Phong".to_string(),
        );
        exported = Some(Lighting::default());
    }
    let ranged: Vec<bool> = lights.iter().map(|l| l.ranged).collect();
    let lights = lights
        .into_iter()
        .zip(light_tracks)
        .map(|(l, track)| SceneLight {
            light: l.light,
            anchor: track.map_or(LightAnchor::World, LightAnchor::Track),
        })
        .collect();
    let (camera_path, default_size) = camera_path(doc, opts, &mut walk, sampled.as_ref())?;
    if let Some(s) = &sampled {
        for (o, node) in walk.objects.iter_mut().zip(&walk.object_nodes) {
            if let Some(&t) = s.track_of.get(node) {
                o.motion = Motion::Track(t);
            }
        }
    }
    let mut scene = Scene {
        name: name.to_string(),
        meshes: std::mem::take(&mut walk.meshes),
        materials,
        objects: std::mem::take(&mut walk.objects),
        paths: Vec::new(),
        lights,
        textures,
        camera_path,
        default_size,
        lighting: exported.unwrap_or_else(Lighting::photometric),
        derived_ranges: Vec::new(),
        tracks: sampled.map_or_else(Vec::new, |s| s.tracks),
    };
    let derived = crate::scene::derive_ranges(&mut scene, &ranged, exported.is_none());
    warn_derived(&scene, &derived, &mut walk);
    scene.derived_ranges = derived.ranges;
    Ok((scene, walk.finish_warnings()))
}

/// The lighting conventions a file lightgrid exported records (`extras.lightgrid.lighting`),
/// if it is one: its lights then carry lightgrid's own intensities.
fn exported_lighting(doc: &Document, walk: &mut Walk) -> Option<Lighting> {
    let v = doc
        .root
        .extras
        .as_ref()?
        .get("lightgrid")?
        .get("lighting")?;
    match Lighting::deserialize(v) {
        Ok(l) if l.exposure.is_finite() && l.exposure > 0.0 => Some(l),
        _ => {
            walk.warn(
                "extras.lightgrid.lighting is malformed; the file's lights are read as photometric"
                    .to_string(),
            );
            None
        }
    }
}
