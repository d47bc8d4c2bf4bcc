//! A CPU reference that reads a glTF file itself: its own small reader (the GLB container, the
//! JSON through serde_json, float positions and normals, integer indices, the node hierarchy,
//! materials, KHR_lights_punctual and the camera) and the specification's definitions, in f64
//! throughout. Nothing is taken from lightgrid's import: a wrong conversion there (roughness to
//! α, candela to the shader's units, a spot's cone, a node's transform) shows as a pixel that
//! differs from this one.
//!
//! What it applies, from the glTF 2.0 specification and KHR_lights_punctual:
//! - α = roughness², F0 = mix(0.04, base, metallic), c_diff = base × (1 − metallic), and
//!   Appendix B's BRDF `(1 − F) c_diff / π + F·D·V` (GGX D, height-correlated Smith V,
//!   Schlick F);
//! - a light's illuminance `colour × intensity / d²` (candela; README's `max(d², 10⁻⁴)`),
//!   windowed by `clamp(1 − (d/r)⁴, 0, 1)²` where it has a range, a spot's `t²` between its
//!   cones;
//! - the node hierarchy (matrix, or translation × rotation × scale), the camera along its
//!   node's −z with +y up and its `yfov`; buffers in the GLB, as data URIs or as files;
//!   points and lines are no surface; a normal that is zero is the face's.
//!
//! Lights, an exposure and a view that a renderer adds to a file (`--add-lights`, the
//! automatic exposure, a camera fitted to a file without one) are handed over by the test:
//! they are the renderer's choices, not the file's.
//!
//! What lightgrid states in its README and the reference writes out here: the ambient term
//! (0.04 × the base colour, unscaled by the exposure), the tone curve `1 − e^(−x)` and the
//! sRGB encoding. The exposure is the caller's (a test sets it on the scene and passes it
//! here, so the automatic exposure's rule is not part of the check).

use glam::{DMat4, DQuat, DVec3};
use serde_json::Value;

/// The ambient light that multiplies a material's base colour (README, "Light units").
const AMBIENT: f64 = 0.04;

/// A triangle of the file, in world space.
struct Triangle {
    p: [DVec3; 3],
    n: Option<[DVec3; 3]>,
    material: Option<usize>,
    /// Its material blends (`alphaMode` BLEND): the reference does not judge what it covers.
    blended: bool,
}

/// A punctual light of the file, in world space.
struct Light {
    position: DVec3,
    /// The direction the light points (the node's −z).
    direction: DVec3,
    radiant: DVec3,
    range: Option<f64>,
    /// Cosines of a spot's inner and outer cone angles.
    cone: Option<(f64, f64)>,
}

/// A material's metallic-roughness inputs.
#[derive(Clone, Copy)]
struct Material {
    base: DVec3,
    metallic: f64,
    roughness: f64,
    emissive: DVec3,
    blended: bool,
    /// `alphaMode` MASK with the base colour's alpha under the cutoff: never drawn.
    cut: bool,
}

const DEFAULT_MATERIAL: Material = Material {
    base: DVec3::ONE,
    metallic: 1.0,
    roughness: 1.0,
    emissive: DVec3::ZERO,
    blended: false,
    cut: false,
};

/// A glTF file as the reference sees it.
pub struct FileReference {
    triangles: Vec<Triangle>,
    materials: Vec<Material>,
    lights: Vec<Light>,
    eye: DVec3,
    /// Right, up and forward of the camera.
    basis: [DVec3; 3],
    tan_half_fov: f64,
    near: f64,
    exposure: f64,
    size: (u32, u32),
}

fn floats(v: &Value, key: &str, default: &[f64]) -> Vec<f64> {
    v.get(key).and_then(Value::as_array).map_or_else(
        || default.to_vec(),
        |a| a.iter().map(|x| x.as_f64().unwrap()).collect(),
    )
}

fn number(v: &Value, key: &str, default: f64) -> f64 {
    v.get(key).and_then(Value::as_f64).unwrap_or(default)
}

fn vec3(a: &[f64]) -> DVec3 {
    DVec3::new(a[0], a[1], a[2])
}

/// The bytes of an accessor's elements, each `size` bytes, in order.
fn elements<'b>(
    doc: &Value,
    buffers: &'b [Vec<u8>],
    accessor: usize,
    size: usize,
) -> Vec<&'b [u8]> {
    let a = &doc["accessors"][accessor];
    let view = &doc["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
    let bin = &buffers[view["buffer"].as_u64().unwrap() as usize];
    let start = number(view, "byteOffset", 0.0) as usize + number(a, "byteOffset", 0.0) as usize;
    let stride = view
        .get("byteStride")
        .and_then(Value::as_u64)
        .map_or(size, |s| s as usize);
    let count = a["count"].as_u64().unwrap() as usize;
    (0..count)
        .map(|i| &bin[start + i * stride..start + i * stride + size])
        .collect()
}

/// A float accessor of `n` components per element.
fn read_floats(doc: &Value, bin: &[Vec<u8>], accessor: usize, n: usize) -> Vec<Vec<f64>> {
    assert_eq!(
        doc["accessors"][accessor]["componentType"], 5126,
        "float data only"
    );
    elements(doc, bin, accessor, 4 * n)
        .into_iter()
        .map(|e| {
            e.chunks_exact(4)
                .map(|c| f64::from(f32::from_le_bytes(c.try_into().unwrap())))
                .collect()
        })
        .collect()
}

/// An index accessor (unsigned bytes, shorts or ints).
fn read_indices(doc: &Value, bin: &[Vec<u8>], accessor: usize) -> Vec<usize> {
    let size = match doc["accessors"][accessor]["componentType"]
        .as_u64()
        .unwrap()
    {
        5121 => 1,
        5123 => 2,
        5125 => 4,
        other => panic!("index component type {other}"),
    };
    elements(doc, bin, accessor, size)
        .into_iter()
        .map(|e| match size {
            1 => usize::from(e[0]),
            2 => usize::from(u16::from_le_bytes(e.try_into().unwrap())),
            _ => u32::from_le_bytes(e.try_into().unwrap()) as usize,
        })
        .collect()
}

/// A node's own transform: its matrix, or translation × rotation × scale.
fn local_transform(node: &Value) -> DMat4 {
    if node.get("matrix").is_some() {
        let m = floats(node, "matrix", &[]);
        assert_eq!(m.len(), 16, "{m:?}");
        return DMat4::from_cols_array(&m.try_into().unwrap());
    }
    let t = vec3(&floats(node, "translation", &[0.0; 3]));
    let r = floats(node, "rotation", &[0.0, 0.0, 0.0, 1.0]);
    let s = vec3(&floats(node, "scale", &[1.0; 3]));
    DMat4::from_scale_rotation_translation(s, DQuat::from_xyzw(r[0], r[1], r[2], r[3]), t)
}

impl FileReference {
    /// The GLB `glb` rendered at `size` with the scene exposure `exposure`, seen from its
    /// first perspective camera.
    pub fn new(glb: &[u8], size: (u32, u32), exposure: f64) -> FileReference {
        let out = Self::of_glb(glb, size, exposure, None);
        assert!(out.near > 0.0, "the reference needs the file's camera");
        out
    }

    /// The file at `path` (`.glb`, or `.gltf` with its buffers as files beside it or data
    /// URIs), as [`new`](Self::new); without a perspective camera of its own the view is
    /// unset until [`set_camera`](Self::set_camera).
    pub fn open(path: &std::path::Path, size: (u32, u32), exposure: f64) -> FileReference {
        let bytes = std::fs::read(path).unwrap();
        if bytes.starts_with(b"glTF") {
            return Self::of_glb(&bytes, size, exposure, None);
        }
        let dir = path.parent().unwrap();
        Self::of_glb(
            &[],
            size,
            exposure,
            Some((serde_json::from_slice(&bytes).unwrap(), dir)),
        )
    }

    fn of_glb(
        glb: &[u8],
        size: (u32, u32),
        exposure: f64,
        gltf: Option<(Value, &std::path::Path)>,
    ) -> FileReference {
        let dir = gltf.as_ref().map(|g| g.1.to_path_buf());
        let (doc, bin): (Value, Vec<u8>) = match gltf {
            Some((doc, _)) => (doc, Vec::new()),
            None => {
                assert_eq!(&glb[..4], b"glTF", "a GLB");
                let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
                let bin = glb.get(20 + json_len + 8..).unwrap_or(&[]).to_vec();
                (
                    serde_json::from_slice(&glb[20..20 + json_len]).unwrap(),
                    bin,
                )
            }
        };
        // Buffers: the GLB's own (no URI), a data URI, or a file beside the document.
        let buffers: Vec<Vec<u8>> = doc["buffers"]
            .as_array()
            .into_iter()
            .flatten()
            .map(|b| match b.get("uri").and_then(Value::as_str) {
                None => bin.clone(),
                Some(uri) if uri.starts_with("data:") => base64(&uri[uri.find(",").unwrap() + 1..]),
                Some(uri) => std::fs::read(dir.as_ref().unwrap().join(uri)).unwrap(),
            })
            .collect();
        let bin = &buffers;
        let mut out = FileReference {
            triangles: Vec::new(),
            materials: Vec::new(),
            lights: Vec::new(),
            eye: DVec3::ZERO,
            basis: [DVec3::X, DVec3::Y, DVec3::NEG_Z],
            tan_half_fov: 0.0,
            near: 0.0,
            exposure,
            size,
        };
        for m in doc["materials"].as_array().into_iter().flatten() {
            let pbr = &m["pbrMetallicRoughness"];
            let strength = number(
                &m["extensions"]["KHR_materials_emissive_strength"],
                "emissiveStrength",
                1.0,
            );
            let base = floats(pbr, "baseColorFactor", &[1.0; 4]);
            let mode = m
                .get("alphaMode")
                .and_then(Value::as_str)
                .unwrap_or("OPAQUE");
            out.materials.push(Material {
                base: vec3(&base),
                metallic: number(pbr, "metallicFactor", 1.0),
                roughness: number(pbr, "roughnessFactor", 1.0),
                emissive: vec3(&floats(m, "emissiveFactor", &[0.0; 3])) * strength,
                blended: mode == "BLEND",
                cut: mode == "MASK" && base[3] < number(m, "alphaCutoff", 0.5),
            });
        }
        let scene = doc.get("scene").and_then(Value::as_u64).unwrap_or(0) as usize;
        let roots: Vec<usize> = doc["scenes"][scene]["nodes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|n| n.as_u64().unwrap() as usize)
            .collect();
        let mut camera = None;
        let mut stack: Vec<(usize, DMat4)> =
            roots.iter().rev().map(|&n| (n, DMat4::IDENTITY)).collect();
        while let Some((n, parent)) = stack.pop() {
            let node = &doc["nodes"][n];
            let world = parent * local_transform(node);
            if let Some(mesh) = node.get("mesh").and_then(Value::as_u64) {
                out.add_mesh(&doc, bin, mesh as usize, world);
            }
            if let Some(l) = node["extensions"]["KHR_lights_punctual"]["light"].as_u64() {
                out.add_light(
                    &doc["extensions"]["KHR_lights_punctual"]["lights"][l as usize],
                    world,
                );
            }
            let perspective = |c: u64| doc["cameras"][c as usize]["type"] == "perspective";
            if let (Some(c), None) = (node.get("camera").and_then(Value::as_u64), &camera) {
                if perspective(c) {
                    camera = Some((c as usize, world));
                }
            }
            for child in node["children"].as_array().into_iter().flatten().rev() {
                stack.push((child.as_u64().unwrap() as usize, world));
            }
        }
        if let Some((c, world)) = camera {
            let perspective = &doc["cameras"][c]["perspective"];
            let eye = world.transform_point3(DVec3::ZERO);
            let forward = world.transform_vector3(DVec3::NEG_Z);
            let up = world.transform_vector3(DVec3::Y);
            let (yfov, near) = (perspective["yfov"].as_f64(), perspective["znear"].as_f64());
            out.set_camera(eye, eye + forward, up, yfov.unwrap(), near.unwrap());
        }
        out
    }

    /// Has the view been set (the file's perspective camera, or [`set_camera`](Self::set_camera))?
    pub fn has_camera(&self) -> bool {
        self.near > 0.0
    }

    /// Look from `eye` toward `target` with `up` up, `fov_y` radians high, near plane `near`:
    /// for a file without a camera, the view its renderer chose.
    pub fn set_camera(&mut self, eye: DVec3, target: DVec3, up: DVec3, fov_y: f64, near: f64) {
        let forward = (target - eye).normalize();
        let right = forward.cross(up).normalize();
        self.eye = eye;
        self.basis = [right, right.cross(forward), forward];
        self.tan_half_fov = (fov_y * 0.5).tan();
        self.near = near;
    }

    /// A point light at `position` of `radiant` (colour × candela) and `range`: lights a
    /// renderer adds to a file (`--add-lights`).
    pub fn add_point_light(&mut self, position: DVec3, radiant: DVec3, range: f64) {
        self.lights.push(Light {
            position,
            direction: DVec3::NEG_Y,
            radiant,
            range: Some(range),
            cone: None,
        });
    }

    fn add_mesh(&mut self, doc: &Value, bin: &[Vec<u8>], mesh: usize, world: DMat4) {
        let normal_matrix = world.inverse().transpose();
        for p in doc["meshes"][mesh]["primitives"].as_array().unwrap() {
            let mode = number(p, "mode", 4.0) as u32;
            if mode < 4 {
                // Points and lines: not surfaces (renderers skip them, lightgrid warns).
                continue;
            }
            let attributes = &p["attributes"];
            let at = |name: &str| attributes[name].as_u64().map(|a| a as usize);
            let positions: Vec<DVec3> = read_floats(doc, bin, at("POSITION").unwrap(), 3)
                .iter()
                .map(|v| world.transform_point3(vec3(v)))
                .collect();
            let normals: Option<Vec<DVec3>> = at("NORMAL").map(|a| {
                read_floats(doc, bin, a, 3)
                    .iter()
                    .map(|v| normal_matrix.transform_vector3(vec3(v)).normalize())
                    .collect()
            });
            let indices = match p["indices"].as_u64() {
                Some(a) => read_indices(doc, bin, a as usize),
                None => (0..positions.len()).collect(),
            };
            let material = p["material"].as_u64().map(|m| m as usize);
            let m = material.map_or(DEFAULT_MATERIAL, |i| self.materials[i]);
            if m.cut {
                continue;
            }
            // Lists, strips and fans as §3.7.2.1 orders their corners.
            let corners: Vec<[usize; 3]> = match mode {
                4 => indices
                    .chunks_exact(3)
                    .map(|t| [t[0], t[1], t[2]])
                    .collect(),
                5 => (0..indices.len().saturating_sub(2))
                    .map(|i| {
                        let odd = i % 2;
                        [indices[i], indices[i + 1 + odd], indices[i + 2 - odd]]
                    })
                    .collect(),
                _ => (1..indices.len().saturating_sub(1))
                    .map(|i| [indices[i], indices[i + 1], indices[0]])
                    .collect(),
            };
            for t in corners {
                self.triangles.push(Triangle {
                    p: [t[0], t[1], t[2]].map(|i| positions[i]),
                    n: normals.as_ref().map(|n| [t[0], t[1], t[2]].map(|i| n[i])),
                    material,
                    blended: m.blended,
                });
            }
        }
    }

    fn add_light(&mut self, def: &Value, world: DMat4) {
        let kind = def["type"].as_str().unwrap();
        assert!(
            kind == "point" || kind == "spot",
            "{kind} lights are not drawn"
        );
        let cone = (kind == "spot").then(|| {
            let spot = &def["spot"];
            let inner = number(spot, "innerConeAngle", 0.0);
            let outer = number(spot, "outerConeAngle", std::f64::consts::FRAC_PI_4);
            (inner.cos(), outer.cos())
        });
        self.lights.push(Light {
            position: world.transform_point3(DVec3::ZERO),
            direction: world.transform_vector3(DVec3::NEG_Z).normalize(),
            radiant: vec3(&floats(def, "color", &[1.0; 3])) * number(def, "intensity", 1.0),
            range: def.get("range").and_then(Value::as_f64),
            cone,
        });
    }

    /// The ray through framebuffer position (x, y) (pixels, y down).
    pub fn ray(&self, x: f64, y: f64) -> DVec3 {
        let (w, h) = (f64::from(self.size.0), f64::from(self.size.1));
        let sx = (x / w * 2.0 - 1.0) * self.tan_half_fov * w / h;
        let sy = (1.0 - y / h * 2.0) * self.tan_half_fov;
        let [r, u, f] = self.basis;
        (r * sx + u * sy + f).normalize()
    }

    /// The nearest triangle the ray from the eye meets beyond the near plane, its distance,
    /// its barycentric weights, and the distance of the next triangle behind it; None where
    /// it meets none or a blended one first.
    fn hit(&self, d: DVec3) -> Option<(usize, f64, [f64; 3], f64)> {
        let mut hits: Vec<(usize, f64, [f64; 3])> = Vec::new();
        for (i, tri) in self.triangles.iter().enumerate() {
            let [a, b, c] = tri.p.map(|p| p - self.eye);
            let (e1, e2) = (b - a, c - a);
            let p = d.cross(e2);
            let det = e1.dot(p);
            if det.abs() < 1e-18 {
                continue;
            }
            let s = -a / det;
            let (u, q) = (s.dot(p), s.cross(e1));
            let v = d.dot(q);
            let t = e2.dot(q);
            if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t * d.dot(self.basis[2]) > self.near {
                hits.push((i, t, [1.0 - u - v, u, v]));
            }
        }
        hits.sort_by(|a, b| a.1.total_cmp(&b.1));
        let next = hits.get(1).map_or(f64::INFINITY, |h| h.1);
        let &(i, t, w) = hits.first()?;
        (!self.triangles[i].blended).then_some((i, t, w, next))
    }

    /// The pixel's linear radiance, or None where its surface is ambiguous (another triangle
    /// a third of a pixel off the centre, a second surface within 0.1 % of the depth) or
    /// there is none.
    pub fn radiance(&self, px: u32, py: u32) -> Option<DVec3> {
        let (x, y) = (f64::from(px) + 0.5, f64::from(py) + 0.5);
        let d = self.ray(x, y);
        let (triangle, t, w, next) = self.hit(d)?;
        if next < t * 1.001 {
            return None;
        }
        for (dx, dy) in [(-1.0, 0.0), (1.0, 0.0), (0.0, -1.0), (0.0, 1.0)] {
            if self.hit(self.ray(x + dx / 3.0, y + dy / 3.0))?.0 != triangle {
                return None;
            }
        }
        let tri = &self.triangles[triangle];
        let position = self.eye + d * t;
        let [a, b, c] = tri.p;
        let mut face = (b - a).cross(c - a).normalize();
        // A file's normal that is zero or not a number gives no direction: the face's.
        let mut normal = match tri.n {
            Some(n) => (n[0] * w[0] + n[1] * w[1] + n[2] * w[2]).normalize(),
            None => face,
        };
        if !normal.is_finite() {
            normal = face;
        }
        // The face's outside is the side its normals point to (a mirroring node reverses
        // the winding, not the normals).
        if face.dot(normal) < 0.0 {
            face = -face;
        }
        // Two-sided: a back face is lit from the side the camera sees.
        if face.dot(d) > 0.0 {
            normal = -normal;
        }
        let m = tri.material.map_or(DEFAULT_MATERIAL, |i| self.materials[i]);
        Some(self.shade(&m, position, normal))
    }

    /// glTF's BRDF at `position` under every light, plus the emissive and ambient terms.
    fn shade(&self, m: &Material, position: DVec3, n: DVec3) -> DVec3 {
        let v = (self.eye - position).normalize();
        let alpha = m.roughness * m.roughness;
        let a2 = alpha * alpha;
        let f0 = DVec3::splat(0.04).lerp(m.base, m.metallic);
        let c_diff = m.base * (1.0 - m.metallic);
        let mut sum = DVec3::ZERO;
        for light in &self.lights {
            let to_light = light.position - position;
            let d2 = to_light.length_squared();
            let window = match light.range {
                Some(r) => (1.0 - (d2 / (r * r)).powi(2)).clamp(0.0, 1.0).powi(2),
                None => 1.0,
            };
            let l = to_light / d2.sqrt();
            let n_dot_l = n.dot(l);
            if n_dot_l <= 0.0 || window <= 0.0 {
                continue;
            }
            let cone = match light.cone {
                None => 1.0,
                Some((inner, outer)) => {
                    let t = ((-l.dot(light.direction) - outer) / (inner - outer)).clamp(0.0, 1.0);
                    t * t
                }
            };
            // README: `I / max(d², 10⁻⁴)`, a light within a centimetre stays finite.
            let e = light.radiant * (window * cone / d2.max(1e-4));
            let h = (l + v).normalize();
            let n_dot_v = n.dot(v).clamp(0.0, 1.0);
            let n_dot_h = n.dot(h).clamp(0.0, 1.0);
            let d = a2 / (std::f64::consts::PI * (n_dot_h * n_dot_h * (a2 - 1.0) + 1.0).powi(2));
            let vis = 0.5
                / (n_dot_l * (n_dot_v * n_dot_v * (1.0 - a2) + a2).sqrt()
                    + n_dot_v * (n_dot_l * n_dot_l * (1.0 - a2) + a2).sqrt());
            let f = f0 + (DVec3::ONE - f0) * (1.0 - v.dot(h).clamp(0.0, 1.0)).powi(5);
            let brdf = (DVec3::ONE - f) * c_diff / std::f64::consts::PI + f * (d * vis);
            sum += brdf * e * n_dot_l;
        }
        sum * self.exposure + m.emissive + m.base * AMBIENT
    }
}

/// Standard base64 (RFC 4648), padding and whitespace ignored: a data URI's payload.
fn base64(text: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c}"),
    };
    let digits: Vec<u8> = text
        .bytes()
        .filter(|c| !c.is_ascii_whitespace() && *c != b'=')
        .map(value)
        .collect();
    let mut out = Vec::with_capacity(digits.len() * 3 / 4);
    for chunk in digits.chunks(4) {
        let n = chunk
            .iter()
            .enumerate()
            .fold(0u32, |n, (i, &d)| n | u32::from(d) << (18 - 6 * i));
        out.extend(&n.to_be_bytes()[1..chunk.len()]);
    }
    out
}

/// Linear radiance to 8-bit sRGB: the tone curve `1 − e^(−x)`, then the sRGB encoding.
pub fn display(c: DVec3) -> [u8; 3] {
    let encode = |x: f64| {
        let x = 1.0 - (-x.max(0.0)).exp();
        let s = if x <= 0.003_130_8 {
            12.92 * x
        } else {
            1.055 * x.powf(1.0 / 2.4) - 0.055
        };
        (s.clamp(0.0, 1.0) * 255.0).round() as u8
    };
    [encode(c.x), encode(c.y), encode(c.z)]
}

/// Compare every `step`-th pixel of `image` with the reference: each clean pixel within
/// `tolerance` levels (panics naming the first that is not); how many were compared.
pub fn compare(
    reference: &FileReference,
    image: &image::RgbaImage,
    step: u32,
    tolerance: u8,
) -> usize {
    let mut checked = 0;
    for py in (0..reference.size.1).step_by(step as usize) {
        for px in (0..reference.size.0).step_by(step as usize) {
            let Some(radiance) = reference.radiance(px, py) else {
                continue;
            };
            let want = display(radiance);
            let got = image.get_pixel(px, py).0;
            let worst = (0..3).map(|c| got[c].abs_diff(want[c])).max().unwrap();
            assert!(
                worst <= tolerance,
                "pixel ({px}, {py}) is {:?}, the file's reference {want:?} (radiance {radiance})",
                &got[..3]
            );
            checked += 1;
        }
    }
    checked
}
