//! A scene at one frame as a glTF 2.0 binary (`lightgrid export`): one node per object (its
//! world transform at that frame), one mesh per (mesh, material) pair, metallic-roughness
//! approximations of the materials for other engines with lightgrid's exact material in
//! `extras.lightgrid`, the frame's lights through KHR_lights_punctual with their ranges, and
//! the frame's camera.

use super::import::ExactMaterial;
use super::LIGHT_MATCH_FRACTION;
use super::{MAX_FILE_BYTES, MAX_JSON_BYTES, MAX_TRIANGLES, MAX_VERTICES};
use crate::error::{Error, Result};
use crate::scene::LightUnits;
use crate::scene::{bounds_of, FrameState, Light, Material, Mesh, Scene};
use glam::{Mat4, Quat, Vec3};
use serde_json::{json, Value};
use std::collections::HashMap;

/// Appends typed arrays to the binary chunk, each its own buffer view and accessor.
#[derive(Default)]
struct Bin {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Bin {
    /// A tightly packed accessor of `count` elements of `kind`; returns its index.
    fn push(&mut self, data: &[u8], target: u32, accessor: Value) -> usize {
        while self.bytes.len() % 4 != 0 {
            self.bytes.push(0);
        }
        self.views.push(json!({
            "buffer": 0,
            "byteOffset": self.bytes.len(),
            "byteLength": data.len(),
            "target": target,
        }));
        self.bytes.extend_from_slice(data);
        let mut accessor = accessor;
        accessor["bufferView"] = json!(self.views.len() - 1);
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    fn vec3s(&mut self, v: &[Vec3], bounds: bool) -> usize {
        let mut acc = json!({"componentType": 5126, "count": v.len(), "type": "VEC3"});
        if let Some((lo, hi)) = bounds_of(v.iter().copied()).filter(|_| bounds) {
            acc["min"] = json!(lo.to_array());
            acc["max"] = json!(hi.to_array());
        }
        self.push(bytemuck::cast_slice(v), 34962, acc)
    }
}

/// Is `m` a translation × rotation × scale (what a glTF node matrix must be)?
fn is_trs(m: &Mat4) -> bool {
    let (s, r, t) = m.to_scale_rotation_translation();
    let back = Mat4::from_scale_rotation_translation(s, r, t);
    let size = m.to_cols_array().iter().fold(1.0f32, |a, v| a.max(v.abs()));
    m.is_finite() && back.abs_diff_eq(*m, size * 1e-5)
}

/// One mesh of one primitive: positions (with bounds), normals, UVs, indices.
fn mesh_json(bin: &mut Bin, m: &Mesh, material: usize, flip: bool) -> Value {
    let rewound;
    let m = if flip {
        let mut copy = m.clone();
        copy.flip_winding();
        rewound = copy;
        &rewound
    } else {
        m
    };
    let pos = bin.vec3s(&m.positions, true);
    let nor = bin.vec3s(&m.normals, false);
    let uv = bin.push(
        bytemuck::cast_slice(&m.uvs),
        34962,
        json!({"componentType": 5126, "count": m.uvs.len(), "type": "VEC2"}),
    );
    let idx = bin.push(
        bytemuck::cast_slice(&m.indices),
        34963,
        json!({"componentType": 5125, "count": m.indices.len(), "type": "SCALAR"}),
    );
    json!({"primitives": [{
        "attributes": {"POSITION": pos, "NORMAL": nor, "TEXCOORD_0": uv},
        "indices": idx,
        "material": material,
        "mode": 4,
    }]})
}

/// glTF's factors are in [0, 1].
fn unit(v: Vec3) -> [f32; 3] {
    v.clamp(Vec3::ZERO, Vec3::ONE).to_array()
}

/// A metallic-roughness approximation of a Blinn-Phong material (the inverse of the import
/// rule for a dielectric: base colour = diffuse, roughness from the shininess), with the exact
/// material in `extras.lightgrid`.
fn material_json(m: &Material) -> Value {
    let alpha_g = (2.0 / (m.shininess.max(1.0) + 2.0)).sqrt();
    let base = unit(m.diffuse);
    let mut v = json!({
        "pbrMetallicRoughness": {
            "baseColorFactor": [base[0], base[1], base[2], m.alpha.clamp(0.0, 1.0)],
            "metallicFactor": 0.0,
            "roughnessFactor": alpha_g.sqrt().clamp(0.0, 1.0),
        },
        "emissiveFactor": unit(m.emissive),
        "doubleSided": true,
        "extras": {"lightgrid": ExactMaterial::from_material(m)},
    });
    if m.transparent {
        v["alphaMode"] = json!("BLEND");
    }
    if let Some(cutoff) = m.alpha_cutoff {
        v["alphaMode"] = json!("MASK");
        v["alphaCutoff"] = json!(cutoff);
    }
    if let Some(t) = m.texture {
        v["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": t});
    }
    if let Some(t) = m.emissive_texture {
        v["emissiveTexture"] = json!({"index": t});
    }
    v
}

/// What the import counts against its limits, counted as the export writes it: accessors
/// read (POSITION elements, index elements) and what the instances bake.
#[derive(Default)]
struct Counts {
    read_vertices: u64,
    read_indices: u64,
    baked_vertices: u64,
    baked_triangles: u64,
}

impl Counts {
    /// Refuse a file the import would refuse: the same constants, checked before anything is
    /// written (a 1M-light scene's JSON part is far past [`MAX_JSON_BYTES`]).
    fn check(&self, json_bytes: u64, file_bytes: u64, lights: usize) -> Result<()> {
        let refuse = |what: String| {
            Err(Error::invalid(
                "export",
                format!("{what}, which lightgrid's own import refuses; export fewer lights or less geometry"),
            ))
        };
        if json_bytes > MAX_JSON_BYTES {
            return refuse(format!(
                "the JSON part would have {json_bytes} bytes ({lights} lights), more than the {} MiB a file may have",
                MAX_JSON_BYTES >> 20
            ));
        }
        if file_bytes > MAX_FILE_BYTES {
            return refuse(format!(
                "the file would have {file_bytes} bytes, more than {} MiB",
                MAX_FILE_BYTES >> 20
            ));
        }
        let (v, t) = (u64::from(MAX_VERTICES), u64::from(MAX_TRIANGLES));
        if self.read_vertices > v || self.baked_vertices > v {
            return refuse(format!(
                "its meshes would have {} vertices ({} in its instances), more than {v}",
                self.read_vertices, self.baked_vertices
            ));
        }
        if self.read_indices > 3 * t || self.baked_triangles > t {
            return refuse(format!(
                "its meshes would have {} triangles ({} in its instances), more than {t}",
                self.read_indices / 3,
                self.baked_triangles
            ));
        }
        Ok(())
    }
}

/// What [`export`] does not write of `scene`, one line each (a file's per-sample inputs):
/// the command says so before it writes.
pub fn export_losses(scene: &Scene) -> Vec<String> {
    let which = |has: &dyn Fn(&Material) -> bool| -> Vec<usize> {
        (scene.materials.iter().enumerate())
            .filter(|(_, m)| has(m))
            .map(|(i, _)| i)
            .collect()
    };
    let mut out = Vec::new();
    let mut say = |indices: Vec<usize>, what: &str| {
        if !indices.is_empty() {
            out.push(format!("{what} of materials {indices:?} are not exported"));
        }
    };
    say(
        which(&|m| m.metallic_roughness.is_some_and(|p| p.texture.is_some())),
        "metallic-roughness textures",
    );
    say(which(&|m| m.normal_texture.is_some()), "normal textures");
    say(
        which(&|m| m.occlusion_texture.is_some()),
        "occlusion textures",
    );
    say(which(&|m| m.uv_sets != 0), "textures on coordinate set 1");
    say(
        which(&|m| m.wraps != 0),
        "clamped or mirrored texture wrapping",
    );
    if scene.meshes.iter().any(|m| !m.colors.is_empty()) {
        out.push("vertex colours are not exported".into());
    }
    out
}

/// Each object's node and its mesh (shared by the objects drawing one mesh with one
/// material at a translation-rotation-scale matrix; baked into world space otherwise), and
/// what was written.
fn object_nodes(
    scene: &Scene,
    state: &FrameState,
    bin: &mut Bin,
) -> (Vec<Value>, Vec<Value>, Counts) {
    let mut meshes = Vec::new();
    let mut mesh_of: HashMap<(usize, usize, bool), usize> = HashMap::new();
    let mut nodes = Vec::new();
    let mut counts = Counts::default();
    for (i, o) in scene.objects.iter().enumerate() {
        if scene.meshes[o.mesh].indices.is_empty() {
            continue; // glTF accessors hold at least one element
        }
        let m = state.transforms[i];
        // A node's matrix must be translation × rotation × scale (§3.5.3); a sheared one
        // (a rotated child of a non-uniformly scaled parent, from a loaded file) is baked
        // into a mesh of its own instead.
        let trs = is_trs(&m);
        // A mirroring matrix turns a file's winding for its readers (§3.7.4), and a scene's
        // mesh is wound as drawn: write such a mesh wound back, so readers turn it again.
        let flip = trs && m.determinant() < 0.0;
        let key = (o.mesh, o.material, flip);
        let shared = mesh_of.get(&key).copied();
        let mi = match (trs, shared) {
            (true, Some(mi)) => mi,
            _ => {
                let baked;
                let mesh = if trs {
                    &scene.meshes[o.mesh]
                } else {
                    let mut world = Mesh::default();
                    world.append(&scene.meshes[o.mesh], m);
                    baked = world;
                    &baked
                };
                meshes.push(mesh_json(bin, mesh, o.material, flip));
                counts.read_vertices += mesh.positions.len() as u64;
                counts.read_indices += mesh.indices.len() as u64;
                if trs {
                    mesh_of.insert(key, meshes.len() - 1);
                }
                meshes.len() - 1
            }
        };
        let written = &scene.meshes[o.mesh];
        counts.baked_vertices += written.positions.len() as u64;
        counts.baked_triangles += written.indices.len() as u64 / 3;
        let mut node = json!({"name": format!("object {i}"), "mesh": mi});
        // The specification asks not to write the identity.
        if trs && m != Mat4::IDENTITY {
            node["matrix"] = json!(m.to_cols_array());
        }
        nodes.push(node);
    }
    (meshes, nodes, counts)
}

/// A light's KHR_lights_punctual definition (glTF's candela and cone angles, lightgrid's
/// exact numbers in `extras.lightgrid`) and its node.
fn light_json(scene: &Scene, i: usize, l: &Light) -> Result<(Value, Value)> {
    let mut def = json!({
        "type": if l.spot.is_some() { "spot" } else { "point" },
        "color": unit(l.color),
        "intensity": candela(scene.lighting.units, l),
        "range": l.range,
        "extras": {"lightgrid": {"intensity": l.intensity, "color": l.color.to_array()}},
    });
    let mut node = json!({
        "name": format!("light {i}"),
        "translation": l.position.to_array(),
        "extensions": {"KHR_lights_punctual": {"light": i}},
    });
    if let Some(s) = l.spot {
        // glTF's widest cone is π/2 from the axis (a rounding below 0 is that cone).
        if s.cos_outer < -1e-6 {
            return Err(Error::invalid(
                "export",
                format!("spot light {i} is wider than glTF's largest cone (90° from its axis)"),
            ));
        }
        def["spot"] = json!({
            "innerConeAngle": s.cos_inner.clamp(0.0, 1.0).acos(),
            "outerConeAngle": s.cos_outer.clamp(0.0, 1.0).acos(),
        });
        def["extras"]["lightgrid"]["cos_inner"] = json!(s.cos_inner);
        def["extras"]["lightgrid"]["cos_outer"] = json!(s.cos_outer);
        let q = Quat::from_rotation_arc(Vec3::NEG_Z, s.direction);
        node["rotation"] = json!(q.to_array());
    }
    Ok((def, node))
}

/// Every scene texture as a PNG image in the binary chunk.
fn images_json(scene: &Scene, bin: &mut Bin) -> Result<Vec<Value>> {
    let mut images = Vec::new();
    for (i, t) in scene.textures.iter().enumerate() {
        let img = image::RgbaImage::from_raw(t.width, t.height, t.rgba.clone())
            .ok_or_else(|| Error::invalid("export", format!("texture {i} is not RGBA8")))?;
        let mut png = Vec::new();
        img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .map_err(|e| Error::invalid("export", format!("texture {i}: {e}")))?;
        while bin.bytes.len() % 4 != 0 {
            bin.bytes.push(0);
        }
        bin.views
            .push(json!({"buffer": 0, "byteOffset": bin.bytes.len(), "byteLength": png.len()}));
        bin.bytes.extend_from_slice(&png);
        images.push(json!({"bufferView": bin.views.len() - 1, "mimeType": "image/png"}));
    }
    Ok(images)
}

/// The GLB bytes of `scene` at `frame`, for frames of `size` (the camera's aspect ratio).
pub fn export(scene: &Scene, frame: u32, size: (u32, u32)) -> Result<Vec<u8>> {
    scene.validate()?;
    scene.check_frame(frame)?;
    let state = scene.frame(frame);
    let mut bin = Bin::default();
    let (meshes, mut nodes, counts) = object_nodes(scene, &state, &mut bin);
    if meshes.is_empty() {
        return Err(Error::invalid(
            "export",
            format!("{} has no triangles to export", scene.name),
        ));
    }
    let mut lights = Vec::new();
    for (i, l) in state.lights.iter().enumerate() {
        let (def, node) = light_json(scene, i, l)?;
        lights.push(def);
        nodes.push(node);
    }
    let cam = state.camera;
    let aspect = size.0 as f32 / size.1.max(1) as f32;
    nodes.push(json!({
        "name": "camera",
        "camera": 0,
        "matrix": cam.view().inverse().to_cols_array(),
    }));
    let materials: Vec<Value> = scene.materials.iter().map(material_json).collect();
    // Textures as PNG images in the binary chunk, one glTF texture each (repeating).
    let images = images_json(scene, &mut bin)?;
    let textures: Vec<Value> = (0..images.len())
        .map(|i| json!({"source": i, "sampler": 0}))
        .collect();
    let mut root = json!({
        "asset": {"version": "2.0", "generator": "lightgrid export"},
        "extras": {"lightgrid": {"lighting": scene.lighting}},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": lights}},
        "scene": 0,
        "scenes": [{"name": scene.name, "nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "cameras": [{"type": "perspective", "perspective": {
            "yfov": cam.fov_y, "znear": cam.near, "zfar": cam.far, "aspectRatio": aspect,
        }}],
        "accessors": bin.accessors,
        "bufferViews": bin.views,
        "buffers": [{"byteLength": bin.bytes.len()}],
    });
    // glTF refuses empty arrays: the texture ones only where there are textures.
    if !images.is_empty() {
        root["images"] = json!(images);
        root["textures"] = json!(textures);
        root["samplers"] = json!([{"wrapS": 10497, "wrapT": 10497}]);
    }
    let mut json =
        serde_json::to_vec(&root).map_err(|e| Error::invalid("export", e.to_string()))?;
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let mut data = bin.bytes;
    while data.len() % 4 != 0 {
        data.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + data.len();
    counts.check(json.len() as u64, total as u64, state.lights.len())?;
    let total = u32::try_from(total).map_err(|_| {
        Error::invalid(
            "export",
            "the scene is larger than a GLB file can hold (4 GiB)",
        )
    })?;
    let mut out = Vec::with_capacity(total as usize);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&total.to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(&0x4E4F_534Au32.to_le_bytes());
    out.extend_from_slice(&json);
    out.extend_from_slice(&(data.len() as u32).to_le_bytes());
    out.extend_from_slice(&0x004E_4942u32.to_le_bytes());
    out.extend_from_slice(&data);
    Ok(out)
}

/// A light's glTF intensity in candela. A photometric scene's is its own; the papers' units
/// have no inverse-square term, so their light is matched to `I / d²` at
/// [`LIGHT_MATCH_FRACTION`] of the range, where the window is `(1 − f²)²`: another tool
/// shows it about as bright there. (lightgrid reads its own files back from
/// `extras.lightgrid`, exactly.)
fn candela(units: LightUnits, l: &crate::scene::Light) -> f32 {
    match units {
        LightUnits::Photometric => l.intensity,
        LightUnits::Papers => {
            let d = l.range * LIGHT_MATCH_FRACTION;
            let window = units.window(f64::from(LIGHT_MATCH_FRACTION * LIGHT_MATCH_FRACTION));
            l.intensity * d * d * window as f32
        }
    }
}
