//! glTF files written by the tests: a small writer (typed arrays into one binary buffer,
//! meshes, nodes, materials, KHR_lights_punctual lights, cameras) that emits a `.gltf` with a
//! base64 buffer or a `.glb`, and the fixture scenes the loader and pipeline tests use.

use glam::Quat;
use serde_json::{json, Value};

#[derive(Default, Clone)]
pub struct GltfWriter {
    pub bin: Vec<u8>,
    pub accessors: Vec<Value>,
    pub views: Vec<Value>,
    pub meshes: Vec<Value>,
    pub nodes: Vec<Value>,
    pub materials: Vec<Value>,
    pub lights: Vec<Value>,
    pub cameras: Vec<Value>,
    pub images: Vec<Value>,
    pub textures: Vec<Value>,
    pub roots: Vec<usize>,
}

fn b64(bytes: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in bytes.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
            | u32::from(*c.get(2).unwrap_or(&0));
        for i in 0..4 {
            if i <= c.len() {
                out.push(T[(n >> (18 - 6 * i) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

impl GltfWriter {
    fn view(&mut self, data: &[u8]) -> usize {
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        self.views
            .push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": data.len()}));
        self.bin.extend_from_slice(data);
        self.views.len() - 1
    }

    /// A float accessor of `kind` (VEC2, VEC3).
    pub fn floats(&mut self, data: &[f32], kind: &str) -> usize {
        let comps = match kind {
            "VEC2" => 2,
            "VEC3" => 3,
            "VEC4" => 4,
            _ => 1,
        };
        let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes);
        let mut acc = json!({"bufferView": view, "componentType": 5126, "count": data.len() / comps, "type": kind});
        if kind == "VEC3" {
            let mut lo = [f32::INFINITY; 3];
            let mut hi = [f32::NEG_INFINITY; 3];
            for p in data.chunks_exact(3) {
                for c in 0..3 {
                    lo[c] = lo[c].min(p[c]);
                    hi[c] = hi[c].max(p[c]);
                }
            }
            acc["min"] = json!(lo);
            acc["max"] = json!(hi);
        }
        self.accessors.push(acc);
        self.accessors.len() - 1
    }

    pub fn indices(&mut self, data: &[u16]) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.accessors.push(json!({"bufferView": view, "componentType": 5123, "count": data.len(), "type": "SCALAR"}));
        self.accessors.len() - 1
    }

    /// A mesh of one primitive; returns the mesh index.
    pub fn mesh(
        &mut self,
        positions: &[f32],
        normals: Option<&[f32]>,
        indices: Option<&[u16]>,
        material: Option<usize>,
        mode: u32,
    ) -> usize {
        let pos = self.floats(positions, "VEC3");
        let mut prim = json!({"attributes": {"POSITION": pos}, "mode": mode});
        if let Some(n) = normals {
            prim["attributes"]["NORMAL"] = json!(self.floats(n, "VEC3"));
        }
        if let Some(i) = indices {
            prim["indices"] = json!(self.indices(i));
        }
        if let Some(m) = material {
            prim["material"] = json!(m);
        }
        self.meshes.push(json!({"primitives": [prim]}));
        self.meshes.len() - 1
    }

    /// A texture from a PNG in the buffer; returns the texture index.
    pub fn png(&mut self, img: &image::RgbaImage) -> usize {
        let mut png = Vec::new();
        img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .unwrap();
        let view = self.view(&png);
        self.images
            .push(json!({"bufferView": view, "mimeType": "image/png"}));
        self.textures
            .push(json!({"source": self.images.len() - 1, "sampler": 0}));
        self.textures.len() - 1
    }

    /// A mesh of one indexed triangle primitive with UVs.
    pub fn textured_mesh(
        &mut self,
        positions: &[f32],
        normals: &[f32],
        uvs: &[f32],
        indices: &[u16],
        material: usize,
    ) -> usize {
        let m = self.mesh(positions, Some(normals), Some(indices), Some(material), 4);
        let uv = self.floats(uvs, "VEC2");
        self.meshes[m]["primitives"][0]["attributes"]["TEXCOORD_0"] = json!(uv);
        m
    }

    pub fn material(&mut self, m: Value) -> usize {
        self.materials.push(m);
        self.materials.len() - 1
    }

    pub fn node(&mut self, n: Value) -> usize {
        self.nodes.push(n);
        self.nodes.len() - 1
    }

    pub fn light(&mut self, l: Value) -> usize {
        self.lights.push(l);
        self.lights.len() - 1
    }

    pub fn document(&self, buffer: Value) -> Value {
        let mut doc = json!({
            "asset": {"version": "2.0", "generator": "lightgrid tests"},
            "scene": 0,
            "scenes": [{"nodes": self.roots}],
            "nodes": self.nodes,
            "meshes": self.meshes,
            "materials": self.materials,
            "accessors": self.accessors,
            "bufferViews": self.views,
            "buffers": [buffer],
        });
        if !self.lights.is_empty() {
            doc["extensionsUsed"] = json!(["KHR_lights_punctual"]);
            doc["extensions"] = json!({"KHR_lights_punctual": {"lights": self.lights}});
        }
        if !self.cameras.is_empty() {
            doc["cameras"] = json!(self.cameras);
        }
        if !self.textures.is_empty() {
            doc["images"] = json!(self.images);
            doc["textures"] = json!(self.textures);
            doc["samplers"] = json!([{}]);
        }
        doc
    }

    /// The `.gltf` text, its buffer a base64 data: URI.
    pub fn gltf(&self) -> Vec<u8> {
        let uri = format!("data:application/octet-stream;base64,{}", b64(&self.bin));
        serde_json::to_vec_pretty(&self.document(json!({"byteLength": self.bin.len(), "uri": uri})))
            .unwrap()
    }

    /// The `.glb` bytes of a document (its buffer 0 the BIN chunk).
    pub fn glb_of(doc: &Value, bin: &[u8]) -> Vec<u8> {
        let mut json = serde_json::to_vec(doc).unwrap();
        while json.len() % 4 != 0 {
            json.push(b' ');
        }
        let mut bin = bin.to_vec();
        while bin.len() % 4 != 0 {
            bin.push(0);
        }
        let total = (12 + 8 + json.len() + 8 + bin.len()) as u32;
        let mut out = b"glTF".to_vec();
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&total.to_le_bytes());
        out.extend_from_slice(&(json.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&json);
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
        out
    }

    pub fn glb(&self) -> Vec<u8> {
        Self::glb_of(
            &self.document(json!({"byteLength": self.bin.len()})),
            &self.bin,
        )
    }
}

/// A unit cube's 24 vertices (positions, normals) and 36 indices, centred at the origin.
pub fn cube() -> (Vec<f32>, Vec<f32>, Vec<u16>) {
    let mut p = Vec::new();
    let mut n = Vec::new();
    let mut idx = Vec::new();
    let faces: [([f32; 3], [f32; 3], [f32; 3]); 6] = [
        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
        ([-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
        ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
        ([0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]),
    ];
    for (normal, u, v) in faces {
        let base = (p.len() / 3) as u16;
        for (a, b) in [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)] {
            for c in 0..3 {
                p.push(normal[c] * 0.5 + u[c] * a + v[c] * b);
                n.push(normal[c]);
            }
        }
        idx.extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
    }
    (p, n, idx)
}

/// The fixture room: a ground quad; a node hierarchy (a rotated, translated parent with a
/// scaled child cube and a grandchild cube); a mirrored instance (negative scale); a
/// triangle-strip wall without normals; a non-indexed, normal-less triangle; a transparent
/// (BLEND) cube; a metallic material; a MASK material below its cutoff (never drawn); point
/// lights (with and without a range) and spot lights through KHR_lights_punctual; a camera.
pub fn room() -> GltfWriter {
    let mut w = GltfWriter::default();
    let ground_m = w.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.6, 0.55, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.7}}));
    let red = w.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.1, 0.1, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.4}}));
    let metal = w.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.8, 0.3, 1.0], "metallicFactor": 1.0, "roughnessFactor": 0.3}}));
    let glass = w.material(json!({"alphaMode": "BLEND", "pbrMetallicRoughness": {"baseColorFactor": [0.3, 0.6, 0.9, 0.4], "metallicFactor": 0.0, "roughnessFactor": 0.1}}));
    let hidden = w.material(json!({"alphaMode": "MASK", "alphaCutoff": 0.5, "pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.0, 1.0, 0.2]}}));
    let glow = w.material(json!({"emissiveFactor": [0.2, 0.05, 0.0], "pbrMetallicRoughness": {"baseColorFactor": [0.3, 0.3, 0.3, 1.0], "metallicFactor": 0.0}}));

    let ground = w.mesh(
        &[
            -10.0, 0.0, -10.0, 10.0, 0.0, -10.0, 10.0, 0.0, 10.0, -10.0, 0.0, 10.0,
        ],
        Some(&[0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0]),
        Some(&[0, 2, 1, 0, 3, 2]),
        Some(ground_m),
        4,
    );
    let (cp, cn, ci) = cube();
    let red_cube = w.mesh(&cp, Some(&cn), Some(&ci), Some(red), 4);
    let metal_cube = w.mesh(&cp, Some(&cn), Some(&ci), Some(metal), 4);
    let glass_cube = w.mesh(&cp, Some(&cn), Some(&ci), Some(glass), 4);
    let hidden_cube = w.mesh(&cp, Some(&cn), Some(&ci), Some(hidden), 4);
    // A strip wall (two triangles from four vertices), no normals: they are computed.
    let wall = w.mesh(
        &[
            -6.0, 0.0, -6.0, -6.0, 3.0, -6.0, -2.0, 0.0, -6.5, -2.0, 3.0, -6.5,
        ],
        None,
        None,
        Some(glow),
        5,
    );
    // A lone non-indexed triangle without a material (the specification's default one).
    let tri = w.mesh(
        &[3.0, 0.0, 4.0, 5.0, 0.0, 4.0, 4.0, 2.5, 4.0],
        None,
        None,
        None,
        4,
    );

    let grandchild = w.node(
        json!({"mesh": metal_cube, "translation": [0.0, 1.5, 0.0], "scale": [0.6, 0.6, 0.6]}),
    );
    let child = w.node(json!({"mesh": red_cube, "scale": [1.5, 2.0, 1.5], "translation": [0.0, 1.0, 0.0], "children": [grandchild]}));
    let parent = w.node(
        json!({"translation": [-2.0, 0.0, 1.0], "rotation": rot_y(45.0), "children": [child]}),
    );
    // Mirrored in x (determinant < 0): its winding is flipped back on load.
    let mirrored = w.node(json!({"mesh": metal_cube, "matrix": [-1.2, 0.0, 0.0, 0.0, 0.0, 1.2, 0.0, 0.0, 0.0, 0.0, 1.2, 0.0, 3.0, 0.6, -2.0, 1.0]}));
    let glass_node = w.node(
        json!({"mesh": glass_cube, "translation": [1.0, 1.2, 2.5], "scale": [1.4, 1.4, 1.4]}),
    );
    let hidden_node = w.node(json!({"mesh": hidden_cube, "translation": [0.0, 0.5, 5.0]}));
    let ground_node = w.node(json!({"mesh": ground}));
    let wall_node = w.node(json!({"mesh": wall}));
    let tri_node = w.node(json!({"mesh": tri}));

    let mut light_nodes = Vec::new();
    let points = [
        ([-4.0, 2.0, 3.0], [1.0, 0.8, 0.6], 6.0, Some(7.0)),
        ([2.0, 1.5, -1.0], [0.5, 0.7, 1.0], 4.0, Some(6.0)),
        ([0.0, 4.0, 0.0], [1.0, 1.0, 1.0], 0.5, None),
        ([5.0, 0.8, 3.0], [1.0, 0.4, 0.2], 3.0, Some(5.0)),
    ];
    for (pos, colour, intensity, range) in points {
        let mut l = json!({"type": "point", "color": colour, "intensity": intensity});
        if let Some(r) = range {
            l["range"] = json!(r);
        }
        let li = w.light(l);
        light_nodes.push(w.node(
            json!({"translation": pos, "extensions": {"KHR_lights_punctual": {"light": li}}}),
        ));
    }
    // Spots: one pointing straight down (rotation -90° about x turns -z into -y), one
    // aimed sideways through a parent's rotation.
    let down = w.light(json!({"type": "spot", "color": [1.0, 0.9, 0.7], "intensity": 20.0, "range": 9.0, "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.5}}));
    light_nodes.push(w.node(json!({"translation": [-1.0, 6.0, -3.0], "rotation": rot_x(-90.0), "extensions": {"KHR_lights_punctual": {"light": down}}})));
    let side = w.light(json!({"type": "spot", "color": [0.3, 1.0, 0.4], "intensity": 15.0, "range": 12.0, "spot": {"outerConeAngle": 0.6}}));
    let side_node = w.node(json!({"translation": [0.0, 1.0, 0.0], "extensions": {"KHR_lights_punctual": {"light": side}}}));
    light_nodes.push(w.node(
        json!({"translation": [7.0, 0.5, 0.0], "rotation": rot_y(60.0), "children": [side_node]}),
    ));

    w.cameras.push(json!({"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.1, "zfar": 60.0, "aspectRatio": 1.6}}));
    // The camera at (4, 7, 13) looking down toward the origin: a rotation about x of -25°
    // after one about y of 17°.
    let q = (Quat::from_rotation_y(17f32.to_radians())
        * Quat::from_rotation_x(-25f32.to_radians()))
    .to_array();
    let camera = w.node(json!({"camera": 0, "translation": [4.0, 7.0, 13.0], "rotation": q}));

    w.roots = vec![
        ground_node,
        parent,
        mirrored,
        glass_node,
        hidden_node,
        wall_node,
        tri_node,
        camera,
    ];
    w.roots.extend(light_nodes);
    w
}

/// A rotation of `deg` degrees about y, as glTF's [x, y, z, w].
fn rot_y(deg: f32) -> [f32; 4] {
    Quat::from_rotation_y(deg.to_radians()).to_array()
}

/// A rotation of `deg` degrees about x.
fn rot_x(deg: f32) -> [f32; 4] {
    Quat::from_rotation_x(deg.to_radians()).to_array()
}

/// A checkerboard `n` × `n` texels of `cells` squares, colours `a` and `b` (RGBA).
pub fn checker(n: u32, cells: u32, a: [u8; 4], b: [u8; 4]) -> image::RgbaImage {
    image::RgbaImage::from_fn(n, n, |x, y| {
        let odd = (x * cells / n + y * cells / n) % 2 == 1;
        image::Rgba(if odd { b } else { a })
    })
}

/// The textured fixture: a ground under an opaque checkerboard (UVs repeating 4 times), a
/// cube with a MASK texture whose transparent squares are holes (you see through them), and
/// a BLEND pane whose texture's alpha varies; point lights and a camera.
pub fn textured() -> GltfWriter {
    let mut w = GltfWriter::default();
    let board = w.png(&checker(64, 8, [230, 220, 200, 255], [40, 60, 120, 255]));
    let holes = w.png(&checker(32, 4, [200, 60, 40, 255], [0, 0, 0, 0]));
    let tint = w.png(&image::RgbaImage::from_fn(16, 16, |x, _| {
        image::Rgba([80, 200, 120, (x * 16) as u8])
    }));
    let ground_m = w.material(json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": board}, "metallicFactor": 0.0, "roughnessFactor": 0.8}}));
    let mask_m = w.material(json!({"alphaMode": "MASK", "alphaCutoff": 0.5, "doubleSided": true, "pbrMetallicRoughness": {"baseColorTexture": {"index": holes}, "metallicFactor": 0.0, "roughnessFactor": 0.5}}));
    let blend_m = w.material(json!({"alphaMode": "BLEND", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 0.9], "baseColorTexture": {"index": tint}, "metallicFactor": 0.0, "roughnessFactor": 0.2}}));
    let ground = w.textured_mesh(
        &[
            -8.0, 0.0, -8.0, 8.0, 0.0, -8.0, 8.0, 0.0, 8.0, -8.0, 0.0, 8.0,
        ],
        &[0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0],
        &[0.0, 0.0, 4.0, 0.0, 4.0, 4.0, 0.0, 4.0],
        &[0, 2, 1, 0, 3, 2],
        ground_m,
    );
    let (cp, cn, ci) = cube();
    // Each face's UVs from its 4 vertices' order: (0,0) (1,0) (1,1) (0,1).
    let cuv: Vec<f32> = (0..6)
        .flat_map(|_| [0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0])
        .collect();
    let cage = w.textured_mesh(&cp, &cn, &cuv, &ci, mask_m);
    let pane = w.textured_mesh(
        &[-3.0, 0.0, 2.0, 1.0, 0.0, 2.0, 1.0, 3.0, 2.0, -3.0, 3.0, 2.0],
        &[0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0],
        &[0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0],
        &[0, 1, 2, 0, 2, 3],
        blend_m,
    );
    let g = w.node(json!({"mesh": ground}));
    let c =
        w.node(json!({"mesh": cage, "translation": [1.5, 1.6, -1.0], "scale": [3.0, 3.0, 3.0]}));
    let p = w.node(json!({"mesh": pane}));
    let mut roots = vec![g, c, p];
    for (pos, colour, range) in [
        ([0.0, 4.0, 0.0], [1.0, 1.0, 1.0], 14.0),
        ([1.5, 1.6, -1.0], [1.0, 0.8, 0.5], 5.0),
        ([-5.0, 2.0, 4.0], [0.6, 0.7, 1.0], 9.0),
    ] {
        let l =
            w.light(json!({"type": "point", "color": colour, "intensity": 8.0, "range": range}));
        roots.push(w.node(
            json!({"translation": pos, "extensions": {"KHR_lights_punctual": {"light": l}}}),
        ));
    }
    w.cameras.push(
        json!({"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "zfar": 50.0}}),
    );
    let q = (Quat::from_rotation_y(15f32.to_radians())
        * Quat::from_rotation_x(-30f32.to_radians()))
    .to_array();
    roots.push(w.node(json!({"camera": 0, "translation": [3.0, 6.0, 11.0], "rotation": q})));
    w.roots = roots;
    w
}

/// A scene written for another engine, as a user brings one: 100 boxes on a 60 m ground
/// and `lights` point lights of 4,000 cd with range 6 (KHR_lights_punctual's units: candela,
/// inverse-square), 0.5 to 2 m above the ground in seeded colours, metallic-roughness
/// materials, a camera looking over the field.
pub fn engine_street(lights: usize) -> GltfWriter {
    let mut w = GltfWriter::default();
    let ground_m = w.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.8}}));
    let box_m = w.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.7, 0.6, 1.0], "metallicFactor": 0.2, "roughnessFactor": 0.5}}));
    let ground = w.mesh(
        &[
            -30.0, 0.0, -30.0, 30.0, 0.0, -30.0, 30.0, 0.0, 30.0, -30.0, 0.0, 30.0,
        ],
        Some(&[0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0]),
        Some(&[0, 2, 1, 0, 3, 2]),
        Some(ground_m),
        4,
    );
    let (cp, cn, ci) = cube();
    let boxes = w.mesh(&cp, Some(&cn), Some(&ci), Some(box_m), 4);
    let mut roots = vec![w.node(json!({"mesh": ground}))];
    for i in 0..100 {
        let (x, z) = ((i % 10) as f32 * 5.5 - 24.75, (i / 10) as f32 * 5.5 - 24.75);
        roots.push(w.node(json!({"mesh": boxes, "translation": [x, 0.5, z]})));
    }
    // A small LCG: the same field every run.
    let mut seed = 0x2545_f491_u32;
    let mut next = || {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (seed >> 8) as f32 / (1u32 << 24) as f32
    };
    for _ in 0..lights {
        let pos = [
            next() * 56.0 - 28.0,
            0.5 + next() * 1.5,
            next() * 56.0 - 28.0,
        ];
        let colour = [0.3 + 0.7 * next(), 0.3 + 0.7 * next(), 0.3 + 0.7 * next()];
        let l =
            w.light(json!({"type": "point", "color": colour, "intensity": 4000.0, "range": 6.0}));
        roots.push(w.node(
            json!({"translation": pos, "extensions": {"KHR_lights_punctual": {"light": l}}}),
        ));
    }
    w.cameras.push(
        json!({"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.05, "zfar": 1000000.0}}),
    );
    let q = Quat::from_rotation_x(-35f32.to_radians()).to_array();
    roots.push(w.node(json!({"camera": 0, "translation": [0.0, 18.0, 34.0], "rotation": q})));
    w.roots = roots;
    w
}
