//! glTF as artists export it (README "glTF scenes"): what lightgrid does not apply is one
//! warning naming it, a glTF 1.0 file is refused as one, the emissive texture lights what it
//! says (in every pipeline), the camera keeps its full orientation (roll, straight down), and
//! a light without a range is cut where the display stops showing it, so a scene in
//! centimetres renders as the same scene in metres.

mod common;

use common::gltf_fixture::{cube, GltfWriter};
use common::shading::Model;
use glam::{Mat4, Quat, Vec3};
use lightgrid::scene::gltf::{self, LoadOptions};
use lightgrid::scene::Scene;
use lightgrid::{RenderSettings, Renderer};
use serde_json::json;

fn load(bytes: &[u8]) -> lightgrid::Result<gltf::Loaded> {
    gltf::load_bytes(bytes, "fixture.gltf", None, &LoadOptions::default())
}

/// A ground of `half` metres each way at y = 0 (scaled by `unit`), a box on it, a light
/// `light` above and a camera looking at the box from `camera` (its node rotation `q`).
fn stage(unit: f32, light: serde_json::Value, camera: Quat, at: Vec3) -> GltfWriter {
    let mut w = GltfWriter::default();
    let grey = w.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.7, 0.7, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.8}}));
    let red = w.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.2, 0.1, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.5}}));
    let h = 6.0 * unit;
    let ground = w.mesh(
        &[-h, 0.0, -h, h, 0.0, -h, h, 0.0, h, -h, 0.0, h],
        Some(&[0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0]),
        Some(&[0, 2, 1, 0, 3, 2]),
        Some(grey),
        4,
    );
    let (cp, cn, ci) = cube();
    let cp: Vec<f32> = cp.iter().map(|c| c * unit).collect();
    let boxed = w.mesh(&cp, Some(&cn), Some(&ci), Some(red), 4);
    let g = w.node(json!({"mesh": ground}));
    let b = w.node(json!({"mesh": boxed, "translation": [0.0, 0.5 * unit, 0.0]}));
    let l = w.light(light);
    let ln = w.node(json!({"translation": [1.0 * unit, 2.5 * unit, 1.5 * unit],
        "extensions": {"KHR_lights_punctual": {"light": l}}}));
    w.cameras
        .push(json!({"type": "perspective", "perspective": {
        "yfov": 0.9, "znear": 0.05 * unit, "zfar": 100.0 * unit}}));
    let c = w.node(json!({"camera": 0, "rotation": camera.to_array(),
        "translation": (at * unit).to_array()}));
    w.roots = vec![g, b, ln, c];
    w
}

/// The camera of [`stage`]: from (0, 3, 6) looking down at the box, rolled `roll` degrees
/// about its view axis.
fn looking(roll: f32) -> Quat {
    Quat::from_rotation_x(-26f32.to_radians()) * Quat::from_rotation_z(roll.to_radians())
}

const EYE: Vec3 = Vec3::new(0.0, 3.0, 6.0);

fn point(range: Option<f32>, candela: f32) -> serde_json::Value {
    let mut l = json!({"type": "point", "color": [1.0, 0.9, 0.8], "intensity": candela});
    if let Some(r) = range {
        l["range"] = json!(r);
    }
    l
}

fn render(scene: &Scene, pipeline: &str, (w, h): (u32, u32)) -> image::RgbaImage {
    let ctx = common::gpu();
    let mut r = Renderer::new(&ctx, w, h, RenderSettings::default()).unwrap();
    r.render(scene, 0, pipeline).unwrap().image
}

#[test]
fn a_gltf_1_file_is_refused_as_one() {
    // glTF 1.0 keeps its objects in maps by name, where 2.0 has arrays.
    for version in [json!("1.0"), json!("1.0.2"), json!(1)] {
        let doc = json!({
            "asset": {"version": version},
            "accessors": {"accessor_21": {"bufferView": "bv", "count": 36, "type": "SCALAR"}},
            "meshes": {"box": {"primitives": []}},
            "scene": "defaultScene",
        });
        let e = load(&serde_json::to_vec(&doc).unwrap())
            .unwrap_err()
            .to_string();
        let v = match &version {
            serde_json::Value::String(s) => s.clone(),
            other => other.to_string(),
        };
        assert!(
            e.contains(&format!("a glTF {v} file")) && e.contains("only glTF 2.0 is read"),
            "{e}"
        );
    }
    // A malformed 2.0 file still says where.
    let e = load(br#"{"asset": {"version": "2.0"}, "meshes": {"a": 1}}"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("malformed JSON"), "{e}");
}

#[test]
fn every_part_not_applied_is_named_in_one_warning() {
    let mut w = stage(1.0, point(Some(8.0), 20.0), looking(0.0), EYE);
    let tex = w.png(&image::RgbaImage::from_pixel(
        4,
        4,
        image::Rgba([128, 128, 255, 255]),
    ));
    w.materials[0]["normalTexture"] = json!({"index": tex, "texCoord": 2});
    let targets = w.floats(&[0.0; 12], "VEC3");
    w.meshes[0]["primitives"][0]["targets"] = json!([{"POSITION": targets}]);
    w.meshes[0]["weights"] = json!([0.5]);
    let mut doc = w.document(json!({"byteLength": w.bin.len()}));
    doc["skins"] = json!([{"joints": [0]}]);
    doc["samplers"] = json!([{"minFilter": 9984}]);
    doc["extensionsUsed"] = json!(["KHR_lights_punctual", "KHR_materials_sheen"]);
    let loaded = load(&GltfWriter::glb_of(&doc, &w.bin)).unwrap();
    let warned = |needle: &str| {
        let n = loaded
            .warnings
            .iter()
            .filter(|w| w.contains(needle))
            .count();
        assert_eq!(n, 1, "{needle}: {:#?}", loaded.warnings);
    };
    warned("material 0 samples a texture with texture coordinate set 2 or above");
    warned("mesh 0 has morph targets with weights other than 0");
    warned("1 skin(s) are not applied");
    warned("sampler 0 asks for a minification filter without mipmaps");
    warned("extension KHR_materials_sheen is not read");
    // The same stage without them warns of nothing.
    let plain = stage(1.0, point(Some(8.0), 20.0), looking(0.0), EYE);
    assert!(load(&plain.glb()).unwrap().warnings.is_empty());
}

/// An emissive texture black but for a disc in its middle, on a material whose emissive
/// factor is white (the usual export): only the disc glows, in every pipeline.
#[test]
fn an_emissive_texture_glows_only_where_it_is_lit() {
    let size = (160, 120);
    // Strength 20: what glows is white on the display (1 − e^−20).
    let scene_with = |texture: bool, strength: Option<f32>| {
        let mut w = stage(1.0, point(Some(8.0), 2.0), looking(0.0), EYE);
        let disc = image::RgbaImage::from_fn(64, 64, |x, y| {
            let d = (x as f32 - 31.5).hypot(y as f32 - 31.5);
            image::Rgba(if d < 10.0 {
                [255, 255, 255, 255]
            } else {
                [0, 0, 0, 255]
            })
        });
        let t = w.png(&disc);
        w.materials[0]["emissiveFactor"] = json!([1.0, 1.0, 1.0]);
        if texture {
            w.materials[0]["emissiveTexture"] = json!({"index": t});
        }
        if let Some(s) = strength {
            w.materials[0]["extensions"] =
                json!({"KHR_materials_emissive_strength": {"emissiveStrength": s}});
        }
        // The ground's UVs: the texture once over it.
        let uv = w.floats(&[0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0], "VEC2");
        w.meshes[0]["primitives"][0]["attributes"]["TEXCOORD_0"] = json!(uv);
        let loaded = load(&w.glb()).unwrap();
        assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
        loaded.scene
    };
    let textured = scene_with(true, Some(20.0));
    let m = &textured.materials[0];
    assert!(m.emissive_texture.is_some() && m.emissive == Vec3::splat(20.0));
    let glow = render(&textured, "forward", size);
    let flat = render(&scene_with(false, Some(20.0)), "forward", size);
    let white =
        |img: &image::RgbaImage| img.pixels().filter(|p| p.0[..3] == [255, 255, 255]).count();
    // Without the texture the whole ground glows white; with it, only the disc.
    let (all, disc) = (white(&flat), white(&glow));
    assert!(
        all > 3 * disc && disc > 100,
        "white pixels: {all} flat, {disc} textured"
    );
    if std::env::var_os("LIGHTGRID_KEEP_IMAGES").is_some() {
        glow.save(common::output_dir().join("emissive-disc.png"))
            .unwrap();
    }
    // The disc is the texture's middle: the ground's centre, under the box; the ground's
    // corners, black in the texture, show the lit grey, not white.
    let corner = glow.get_pixel(2, size.1 - 3).0;
    assert!(corner[..3].iter().all(|&c| c < 250), "{corner:?}");
    // Every pipeline reads the emissive texture as forward does.
    for info in lightgrid::pipelines::PIPELINES {
        if info.id == "forward" {
            continue;
        }
        let other = render(&textured, info.id, size);
        let over = common::pixels_over(&glow, &other, 8);
        assert!(
            over <= u64::from(size.0 * size.1) / 100,
            "{}: {over} pixels over 8 levels from forward",
            info.id
        );
    }
    // Without KHR_materials_emissive_strength the factor alone.
    assert_eq!(scene_with(true, None).materials[0].emissive, Vec3::ONE);
}

/// The view matrix a file's camera node gives: the inverse of its world matrix.
fn node_view(q: Quat, at: Vec3) -> Mat4 {
    Mat4::from_rotation_translation(q, at).inverse()
}

#[test]
fn the_camera_keeps_its_roll_and_may_look_straight_down() {
    for (q, what) in [
        (looking(30.0), "rolled 30°"),
        (looking(-90.0), "rolled -90°"),
        (Quat::from_rotation_x(-90f32.to_radians()), "straight down"),
        (
            Quat::from_rotation_y(40f32.to_radians()) * Quat::from_rotation_x(90f32.to_radians()),
            "straight up, turned",
        ),
    ] {
        let at = if what.starts_with("straight down") {
            Vec3::new(0.0, 8.0, 0.0)
        } else {
            EYE
        };
        let loaded = load(&stage(1.0, point(Some(8.0), 20.0), q, at).glb()).unwrap();
        assert!(loaded.warnings.is_empty(), "{what}: {:?}", loaded.warnings);
        let cam = loaded.scene.camera_path.at(0);
        let (got, want) = (cam.view(), node_view(q, at));
        assert!(
            got.abs_diff_eq(want, 1e-4),
            "{what}: view\n{got}\nnot the node's\n{want}"
        );
        // The image is the CPU reference's, whose rays leave through that camera (looking
        // up, it sees only sky).
        if what.starts_with("straight up") {
            continue;
        }
        let size = (96, 64);
        let image = render(&loaded.scene, "forward", size);
        let mut checked = common::shading::Checked::default();
        let frame = common::shading::Frame::new(&loaded.scene, 0, size);
        common::shading::compare(&frame, &image, Model::Full, 1, &mut checked);
        assert!(
            checked.pixels > 1000,
            "{what}: {} pixels checked",
            checked.pixels
        );
    }
    // Rolled half a turn, the image is the unrolled one turned half a turn: pixel (x, y)
    // shows what (w-1-x, h-1-y) did.
    let (w, h) = (96, 64);
    let upright = load(&stage(1.0, point(Some(8.0), 20.0), looking(0.0), EYE).glb()).unwrap();
    let turned = load(&stage(1.0, point(Some(8.0), 20.0), looking(180.0), EYE).glb()).unwrap();
    let a = render(&upright.scene, "forward", (w, h));
    let b = render(&turned.scene, "forward", (w, h));
    let rotated = image::imageops::rotate180(&a);
    let over = common::pixels_over(&rotated, &b, 2);
    assert!(
        over <= u64::from(w * h) / 200,
        "{over} pixels differ from the upright image turned half a turn"
    );
    assert!(
        common::pixels_over(&a, &b, 2) > 500,
        "the roll changes the image"
    );
}

/// Mean brightness of an image (0-255).
fn mean(img: &image::RgbaImage) -> f64 {
    img.pixels()
        .map(|p| p.0[..3].iter().map(|&c| f64::from(c)).sum::<f64>() / 3.0)
        .sum::<f64>()
        / (img.width() * img.height()) as f64
}

#[test]
fn a_light_without_a_range_lights_a_centimetre_scene_as_a_metre_one() {
    let size = (128, 96);
    let scene = |unit: f32, candela: f32| {
        let loaded = load(&stage(unit, point(None, candela), looking(0.0), EYE).glb()).unwrap();
        let ranged: Vec<&String> = (loaded.warnings.iter())
            .filter(|w| w.contains("no range"))
            .collect();
        assert_eq!(ranged.len(), 1, "{:?}", loaded.warnings);
        loaded.scene
    };
    // A Blender-style 54 cd light, in a scene in metres and the same scene in centimetres.
    let metres = scene(1.0, 54.0);
    let centimetres = scene(100.0, 54.0);
    let (rm, rc) = (metres.derived_ranges[0].1, centimetres.derived_ranges[0].1);
    assert!(
        (rc / rm - 100.0).abs() < 0.5,
        "the range scales with the scene's units: {rm} m, {rc} cm"
    );
    assert_eq!(metres.lights[0].light.range, rm);
    let a = render(&metres, "forward", size);
    let b = render(&centimetres, "forward", size);
    let over = common::pixels_over(&a, &b, 2);
    assert!(over <= 20, "{over} pixels differ by more than 2 levels");
    // Lit: far brighter than ambient alone, and a dim light lights it as well (the
    // exposure follows it).
    let mut dark = metres.clone();
    dark.lights.clear();
    let ambient = render(&dark, "forward", size);
    assert!(
        mean(&a) > mean(&ambient) + 20.0,
        "{} vs ambient {}",
        mean(&a),
        mean(&ambient)
    );
    let dim = render(&scene(1.0, 0.05), "forward", size);
    assert!(
        common::pixels_over(&a, &dim, 2) <= 20,
        "a 0.05 cd light shows as a 54 cd one"
    );
    // So bright against the exposure that the scene's bounds cap it: it reaches the farthest
    // corner of the ground, and no farther.
    let corner = Vec3::new(-6.0, 0.0, -6.0).distance(Vec3::new(1.0, 2.5, 1.5));
    assert!(
        rm >= corner && rm <= corner * 1.02,
        "range {rm}, corner {corner}"
    );
}

/// [`stage`] with its light node (2) moving in x from `from` to `to` over two seconds
/// (linear), the box (node 1) turning a quarter turn at one second (step), and the camera
/// (node 3) rising 1 m over two seconds (cubic spline, zero tangents).
fn animated(from: f32, to: f32) -> (Vec<u8>, GltfWriter) {
    let mut w = stage(1.0, point(Some(6.0), 8.0), looking(0.0), EYE);
    let times = w.floats(&[0.0, 2.0], "SCALAR");
    let slide = w.floats(&[from, 2.5, 1.5, to, 2.5, 1.5], "VEC3");
    let step_times = w.floats(&[0.0, 1.0], "SCALAR");
    let q = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2).to_array();
    let turn = w.floats(&[0.0, 0.0, 0.0, 1.0, q[0], q[1], q[2], q[3]], "VEC4");
    let (z, e) = ([0.0f32; 3], EYE.to_array());
    let rise: Vec<f32> = [z, e, z, z, [e[0], e[1] + 1.0, e[2]], z].concat();
    let rise = w.floats(&rise, "VEC3");
    let mut doc = w.document(json!({"byteLength": w.bin.len()}));
    doc["animations"] = json!([{
        "channels": [
            {"sampler": 0, "target": {"node": 2, "path": "translation"}},
            {"sampler": 1, "target": {"node": 1, "path": "rotation"}},
            {"sampler": 2, "target": {"node": 3, "path": "translation"}},
        ],
        "samplers": [
            {"input": times, "output": slide},
            {"input": step_times, "output": turn, "interpolation": "STEP"},
            {"input": times, "output": rise, "interpolation": "CUBICSPLINE"},
        ],
    }]);
    (GltfWriter::glb_of(&doc, &w.bin), w)
}

#[test]
fn a_files_animation_moves_its_nodes_lights_and_camera() {
    let (bytes, _) = animated(-2.0, 2.0);
    let loaded = load(&bytes).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let s = &loaded.scene;
    // Two seconds at 30 frames per second: frames 0 to 60, no orbit added.
    assert_eq!(gltf::ANIMATION_FPS, 30.0);
    assert_eq!(s.frame_count(), 61);
    for (frame, x) in [(0, -2.0), (15, -1.0), (30, 0.0), (60, 2.0), (90, 2.0)] {
        let p = s.frame(frame).lights[0].position;
        assert!(
            p.abs_diff_eq(Vec3::new(x, 2.5, 1.5), 1e-5),
            "frame {frame}: the light at {p}, not x = {x}"
        );
    }
    // The box turns at one second (step), not before.
    let box_at = |f: u32| s.frame(f).transforms[1];
    let quarter = Mat4::from_rotation_translation(
        Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
        Vec3::new(0.0, 0.5, 0.0),
    );
    assert!(box_at(29).abs_diff_eq(Mat4::from_translation(Vec3::new(0.0, 0.5, 0.0)), 1e-5));
    assert!(box_at(30).abs_diff_eq(quarter, 1e-5), "{}", box_at(30));
    // The camera rises 1 m on a cubic spline with zero tangents: a smoothstep.
    let eye = |f: u32| s.camera_path.at(f).eye;
    assert!(eye(0).abs_diff_eq(EYE, 1e-5) && eye(60).abs_diff_eq(EYE + Vec3::Y, 1e-5));
    assert!((eye(15).y - (EYE.y + 0.15625)).abs() < 1e-4, "{}", eye(15));
    // The pool of light at the last frame is the one a light placed there lights.
    let size = (128, 96);
    let end = render_at(s, "forward", size, 60);
    let (placed, _) = animated(2.0, 2.0);
    let placed = load(&placed).unwrap().scene;
    let still = render_at(&placed, "forward", size, 60);
    assert!(
        common::pixels_over(&end, &still, 2) <= 10,
        "the moved light lights as a placed one"
    );
    let start = render_at(s, "forward", size, 0);
    assert!(
        common::pixels_over(&start, &end, 8) > 1000,
        "the pool moves"
    );
    // Every pipeline culls the light where it is at frame 30.
    let mid = render_at(s, "forward", size, 30);
    for info in lightgrid::pipelines::PIPELINES {
        let other = render_at(s, info.id, size, 30);
        let over = common::pixels_over(&mid, &other, 8);
        assert!(
            over <= u64::from(size.0 * size.1) / 100,
            "{}: {over} pixels over 8 levels from forward at frame 30",
            info.id
        );
    }
}

#[test]
fn malformed_animations_are_refused_and_extra_ones_named() {
    let (bytes, w) = animated(-2.0, 2.0);
    let doc = |edit: &dyn Fn(&mut serde_json::Value)| {
        let loaded = load(&bytes).unwrap();
        drop(loaded);
        let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        let mut d: serde_json::Value = serde_json::from_slice(&bytes[20..20 + len]).unwrap();
        edit(&mut d);
        GltfWriter::glb_of(&d, &w.bin)
    };
    for (edit, needle) in [
        (
            &(|d: &mut serde_json::Value| {
                d["animations"][0]["channels"][0]["target"]["node"] = json!(99)
            }) as &dyn Fn(&mut serde_json::Value),
            "node 99 does not exist",
        ),
        (
            &|d: &mut serde_json::Value| {
                d["animations"][0]["samplers"][0]["interpolation"] = json!("BOUNCE")
            },
            "interpolation 'BOUNCE'",
        ),
        (
            &|d: &mut serde_json::Value| {
                d["animations"][0]["samplers"][0]["output"] =
                    d["animations"][0]["samplers"][0]["input"].clone()
            },
            "where 3 components are needed",
        ),
        (
            &|d: &mut serde_json::Value| {
                d["animations"][0]["samplers"][1]["input"] =
                    d["animations"][0]["samplers"][0]["input"].clone()
            },
            "",
        ),
    ] {
        let r = load(&doc(edit));
        if needle.is_empty() {
            // Times from another sampler: still increasing, read as given.
            assert!(r.is_ok(), "{:?}", r.err());
        } else {
            let e = r.unwrap_err().to_string();
            assert!(e.contains(needle), "{e}");
        }
    }
    let two = doc(&|d| {
        let first = d["animations"][0].clone();
        d["animations"].as_array_mut().unwrap().push(first);
    });
    let loaded = load(&two).unwrap();
    assert!(
        loaded
            .warnings
            .iter()
            .any(|w| w.contains("animation 0 is played; the file's other 1")),
        "{:?}",
        loaded.warnings
    );
}

fn render_at(scene: &Scene, pipeline: &str, (w, h): (u32, u32), frame: u32) -> image::RgbaImage {
    let ctx = common::gpu();
    let mut r = Renderer::new(&ctx, w, h, RenderSettings::default()).unwrap();
    r.render(scene, frame, pipeline).unwrap().image
}

// ------------------------------------------------------------- every core material input

/// A unit quad facing the camera (z = 0, from (-1, -1) to (1, 1)), seen square-on from
/// (0, 0, 3) by a camera of 45°, lit by a white point light `light` in front; `material`
/// its material, with UVs `uv` (set 0) and `uv1` (set 1) at the corners (-1,-1), (1,-1),
/// (1,1), (-1,1).
fn card(
    material: serde_json::Value,
    uv: [f32; 8],
    uv1: Option<[f32; 8]>,
    light: Vec3,
) -> GltfWriter {
    let mut w = GltfWriter::default();
    let m = w.material(material);
    let q = w.mesh(
        &[
            -1.0, -1.0, 0.0, 1.0, -1.0, 0.0, 1.0, 1.0, 0.0, -1.0, 1.0, 0.0,
        ],
        Some(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0]),
        Some(&[0, 1, 2, 0, 2, 3]),
        Some(m),
        4,
    );
    let a = w.floats(&uv, "VEC2");
    w.meshes[q]["primitives"][0]["attributes"]["TEXCOORD_0"] = json!(a);
    if let Some(uv1) = uv1 {
        let b = w.floats(&uv1, "VEC2");
        w.meshes[q]["primitives"][0]["attributes"]["TEXCOORD_1"] = json!(b);
    }
    let n = w.node(json!({"mesh": q}));
    let l = w
        .light(json!({"type": "point", "color": [1.0, 1.0, 1.0], "intensity": 3.0, "range": 20.0}));
    let ln = w.node(json!({"translation": light.to_array(), "extensions": {"KHR_lights_punctual": {"light": l}}}));
    w.cameras.push(json!({"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.1, "zfar": 20.0, "aspectRatio": 1.0}}));
    let c = w.node(json!({"camera": 0, "translation": [0.0, 0.0, 2.3]}));
    w.roots = vec![n, ln, c];
    w
}

const UNIT_UV: [f32; 8] = [0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0];
const CARD: (u32, u32) = (96, 96);

/// The scene of a card; no warning expected.
fn card_scene(w: &GltfWriter) -> Scene {
    let loaded = load(&w.glb()).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    loaded.scene
}

/// `forward` and its mono references equal the CPU reference, which reads the textures and
/// vertex colours at each sample itself (within one level, a fifth of the image at least,
/// away from triangle and texture edges); every pipeline renders `scene` as its reference
/// does (`forward`, or `forward_mono` for the mono variants, whose one-value specular is
/// their documented compromise), within 8 levels at all but 1% of the pixels; forward's
/// image.
fn every_pipeline_as_forward(scene: &Scene, what: &str) -> image::RgbaImage {
    let ctx = common::gpu();
    let mut r = Renderer::new(&ctx, CARD.0, CARD.1, RenderSettings::default()).unwrap();
    let mut references = std::collections::HashMap::new();
    for info in lightgrid::pipelines::PIPELINES {
        let image = r.render(scene, 0, info.id).unwrap().image;
        references.insert(info.id, image);
    }
    let frame = common::shading::Frame::new(scene, 0, CARD);
    let mut checked = common::shading::Checked::default();
    for model in [Model::Full, Model::Mono, Model::MonoAlbedo] {
        let image = &references[model.pipeline()];
        common::shading::compare(&frame, image, model, 1, &mut checked);
    }
    assert!(
        checked.pixels * 5 >= (CARD.0 * CARD.1) as usize,
        "{what}: the reference checked only {} pixels",
        checked.pixels
    );
    for info in lightgrid::pipelines::PIPELINES {
        let reference = &references[info.reference];
        let over = common::pixels_over(reference, &references[info.id], 8);
        assert!(
            over <= u64::from(CARD.0 * CARD.1) / 100,
            "{what}: {}: {over} pixels over 8 levels from {}",
            info.id,
            info.reference
        );
    }
    references.remove(lightgrid::pipelines::REFERENCE).unwrap()
}

/// Mean colour (0-255) of the pixels in the rectangle `x0..x1` × `y0..y1`.
fn region(img: &image::RgbaImage, (x0, x1): (u32, u32), (y0, y1): (u32, u32)) -> Vec3 {
    let mut sum = Vec3::ZERO;
    for y in y0..y1 {
        for x in x0..x1 {
            let p = img.get_pixel(x, y).0;
            sum += Vec3::new(f32::from(p[0]), f32::from(p[1]), f32::from(p[2]));
        }
    }
    sum / ((x1 - x0) * (y1 - y0)) as f32
}

/// A texture of `n`×`n` whose left half is `a` and right half `b`.
fn halves(n: u32, a: [u8; 4], b: [u8; 4]) -> image::RgbaImage {
    image::RgbaImage::from_fn(n, n, |x, _| image::Rgba(if x < n / 2 { a } else { b }))
}

// The card's left and right thirds on screen, away from the seam and the edges.
const LEFT: (u32, u32) = (24, 40);
const RIGHT: (u32, u32) = (56, 72);
const MIDDLE_ROWS: (u32, u32) = (30, 66);

#[test]
fn a_metallic_roughness_texture_makes_half_the_card_dielectric() {
    // Metallic factor 1 (the default), the texture's left half B = 0: dielectric there.
    let mut w = card(json!({}), UNIT_UV, None, Vec3::new(0.0, 0.0, 1.5));
    // Roughness 0.3 (G full): the metal's highlight stays near the card's middle, so off
    // it the metal is dark where the dielectric shows its diffuse colour.
    let t = w.png(&halves(32, [0, 255, 0, 255], [0, 255, 255, 255]));
    w.materials[0] = json!({"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.5, 0.2, 1.0],
        "metallicFactor": 1.0, "roughnessFactor": 0.3, "metallicRoughnessTexture": {"index": t}}});
    let img = every_pipeline_as_forward(&card_scene(&w), "metallic-roughness");
    if std::env::var_os("LIGHTGRID_KEEP_IMAGES").is_some() {
        img.save(common::output_dir().join("metallic-roughness-card.png"))
            .unwrap();
    }
    // The top corners, away from the metal's highlight: the dielectric half shows its
    // orange diffuse, the metal only its ambient.
    let (top, left, right) = ((8, 24), (10, 22), (74, 86));
    let (dielectric, metal) = (region(&img, left, top), region(&img, right, top));
    assert!(
        dielectric.x > metal.x * 1.5,
        "dielectric {dielectric}, metal {metal}"
    );
    // Without the texture both halves are the metal (the card is symmetric).
    w.materials[0]["pbrMetallicRoughness"]
        .as_object_mut()
        .unwrap()
        .remove("metallicRoughnessTexture");
    let plain = render(&card_scene(&w), "forward", CARD);
    let untextured = region(&plain, left, top);
    assert!(
        (untextured - metal).abs().max_element() < 3.0,
        "untextured {untextured}, metal {metal}"
    );
}

#[test]
fn a_normal_texture_tilts_where_it_says() {
    // The light straight ahead: an untilted card is lit evenly; the texture's right half
    // tilts the normal 45° sideways (tangent space x), so that half turns from the light.
    let light = Vec3::new(0.0, 0.0, 2.0);
    let mut w = card(json!({}), UNIT_UV, None, light);
    let tilt = (0.5f32.sqrt() * 0.5 + 0.5) * 255.0;
    let t = w.png(&halves(
        32,
        [128, 128, 255, 255],
        [tilt as u8, 128, tilt as u8, 255],
    ));
    w.materials[0] = json!({"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1.0],
        "metallicFactor": 0.0, "roughnessFactor": 1.0}, "normalTexture": {"index": t}});
    let scene = card_scene(&w);
    // No TANGENT: MikkTSpace's, along +u (+x on the card).
    let mesh = &scene.meshes[0];
    let along_u = |t: &glam::Vec4| t.truncate().abs_diff_eq(Vec3::X, 1e-4) && t.w.abs() == 1.0;
    assert!(mesh.tangents.iter().all(along_u), "{:?}", mesh.tangents);
    let img = every_pipeline_as_forward(&scene, "normal texture");
    let (flat, tilted) = (
        region(&img, LEFT, MIDDLE_ROWS),
        region(&img, RIGHT, MIDDLE_ROWS),
    );
    assert!(flat.x > tilted.x + 15.0, "flat {flat}, tilted {tilted}");
    // Scale 0 flattens it: the halves alike.
    w.materials[0]["normalTexture"]["scale"] = json!(0.0);
    let flattened = render(&card_scene(&w), "forward", CARD);
    let (a, b) = (
        region(&flattened, LEFT, MIDDLE_ROWS),
        region(&flattened, RIGHT, MIDDLE_ROWS),
    );
    assert!((a - b).abs().max_element() < 8.0, "scale 0: {a} vs {b}");
}

#[test]
fn occlusion_darkens_the_ambient_term_by_its_strength() {
    // The light behind the card: only ambient light shows on its face.
    let mut w = card(json!({}), UNIT_UV, None, Vec3::new(0.0, 0.0, -3.0));
    let t = w.png(&halves(32, [255, 255, 255, 255], [0, 0, 0, 255]));
    w.materials[0] = json!({"pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0],
        "metallicFactor": 0.0}, "occlusionTexture": {"index": t, "strength": 0.5}});
    let img = every_pipeline_as_forward(&card_scene(&w), "occlusion");
    let (open, occluded) = (
        region(&img, LEFT, MIDDLE_ROWS),
        region(&img, RIGHT, MIDDLE_ROWS),
    );
    assert!(open.x > 5.0, "ambient shows: {open}");
    assert!(
        occluded.x < open.x * 0.85 && occluded.x > open.x * 0.3,
        "open {open}, occluded {occluded}"
    );
}

#[test]
fn vertex_colours_multiply_the_base_colour() {
    let mut w = card(
        json!({"pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0],
        "metallicFactor": 0.0, "roughnessFactor": 1.0}}),
        UNIT_UV,
        None,
        Vec3::new(0.0, 0.0, 1.5),
    );
    let red = w.floats(
        &[
            1.0, 0.1, 0.1, 1.0, 0.1, 1.0, 0.1, 1.0, 1.0, 0.1, 0.1, 1.0, 1.0, 0.1, 0.1, 1.0,
        ],
        "VEC4",
    );
    w.meshes[0]["primitives"][0]["attributes"]["COLOR_0"] = json!(red);
    let scene = card_scene(&w);
    let img = every_pipeline_as_forward(&scene, "vertex colours");
    let left = region(&img, (8, 16), MIDDLE_ROWS);
    let right_bottom = region(&img, (80, 88), (80, 88));
    assert!(left.x > left.y + 40.0, "red on the left: {left}");
    assert!(
        right_bottom.y > right_bottom.x + 40.0,
        "green at the lower right: {right_bottom}"
    );
    // On a metal the colours are its F0, per sample in every pipeline.
    w.materials[0]["pbrMetallicRoughness"]["metallicFactor"] = json!(1.0);
    every_pipeline_as_forward(&card_scene(&w), "vertex colours on a metal");
}

/// An emissive card (strength 50, so a texel shows as itself) whose emissive texture is red
/// on its left half and blue on its right, read with `uv` on set 0, `uv1` on set 1, the
/// texture on `set` with sampler wrapping `wrap`.
fn emissive_card(uv: [f32; 8], uv1: Option<[f32; 8]>, set: u32, wrap: u32) -> image::RgbaImage {
    emissive_card_with(uv, uv1, set, json!({"wrapS": wrap, "wrapT": wrap}), 32)
}

/// [`emissive_card`] with any sampler, the texture `n` texels wide.
fn emissive_card_with(
    uv: [f32; 8],
    uv1: Option<[f32; 8]>,
    set: u32,
    sampler: serde_json::Value,
    n: u32,
) -> image::RgbaImage {
    emissive_card_full(uv, uv1, json!({"texCoord": set}), sampler, n)
}

/// [`emissive_card_with`] with the texture reference's fields (`texCoord`, `extensions`)
/// given whole.
fn emissive_card_full(
    uv: [f32; 8],
    uv1: Option<[f32; 8]>,
    reference: serde_json::Value,
    sampler: serde_json::Value,
    n: u32,
) -> image::RgbaImage {
    let mut w = card(json!({}), uv, uv1, Vec3::new(0.0, 0.0, -3.0));
    let t = w.png(&halves(n, [255, 0, 0, 255], [0, 0, 255, 255]));
    let mut reference = reference;
    reference["index"] = json!(t);
    w.materials[0] = json!({"emissiveFactor": [1.0, 1.0, 1.0],
        "emissiveTexture": reference,
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 50.0}},
        "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0]}});
    let mut doc = w.document(json!({"byteLength": w.bin.len()}));
    doc["samplers"] = json!([sampler]);
    doc["extensionsUsed"] = json!([
        "KHR_lights_punctual",
        "KHR_materials_emissive_strength",
        "KHR_texture_transform"
    ]);
    let loaded = load(&GltfWriter::glb_of(&doc, &w.bin)).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    every_pipeline_as_forward(&loaded.scene, "emissive card")
}

/// Which colour each quarter of the card's width shows: 'r', 'b' or '?'.
fn quarters(img: &image::RgbaImage) -> String {
    // The card spans about pixels 11..85 across at this view; the quarters' middles.
    [20, 39, 57, 76]
        .iter()
        .map(|&x| {
            let p = img.get_pixel(x, 48).0;
            match (p[0] > 200 && p[2] < 60, p[2] > 200 && p[0] < 60) {
                (true, false) => 'r',
                (false, true) => 'b',
                _ => '?',
            }
        })
        .collect()
}

#[test]
fn texture_coordinate_sets_and_wrapping_are_read() {
    const REPEAT: u32 = 10497;
    const CLAMP: u32 = 33071;
    const MIRROR: u32 = 33648;
    // u from 0 to 2 across the card: the texture twice, folded back, or its edge.
    let twice = [0.0, 1.0, 2.0, 1.0, 2.0, 0.0, 0.0, 0.0];
    assert_eq!(quarters(&emissive_card(UNIT_UV, None, 0, REPEAT)), "rrbb");
    assert_eq!(quarters(&emissive_card(twice, None, 0, REPEAT)), "rbrb");
    assert_eq!(quarters(&emissive_card(twice, None, 0, MIRROR)), "rbbr");
    assert_eq!(quarters(&emissive_card(twice, None, 0, CLAMP)), "rbbb");
    // Set 1 holds the doubled coordinates; set 0 the plain ones.
    assert_eq!(
        quarters(&emissive_card(UNIT_UV, Some(twice), 1, REPEAT)),
        "rbrb"
    );
    assert_eq!(
        quarters(&emissive_card(UNIT_UV, Some(twice), 0, REPEAT)),
        "rrbb"
    );
}

#[test]
fn a_nearest_magnification_keeps_texels_sharp() {
    // Two texels across the card: magnified linearly their colours blend across the middle,
    // nearest-texel they meet at one edge.
    let blended = |img: &image::RgbaImage| {
        (11..85)
            .filter(|&x| {
                let p = img.get_pixel(x, 48).0;
                p[0] > 40 && p[2] > 40
            })
            .count()
    };
    let linear = emissive_card_with(UNIT_UV, None, 0, json!({"magFilter": 9729}), 2);
    let nearest = emissive_card_with(UNIT_UV, None, 0, json!({"magFilter": 9728}), 2);
    assert!(
        blended(&linear) > 10,
        "linear: {} blended pixels",
        blended(&linear)
    );
    assert!(
        blended(&nearest) <= 2,
        "nearest: {} blended pixels",
        blended(&nearest)
    );
}

#[test]
fn a_texture_transform_moves_turns_and_scales_the_coordinates() {
    let with = |transform: serde_json::Value, uv1: Option<[f32; 8]>| {
        let reference = json!({"texCoord": 0, "extensions": {"KHR_texture_transform": transform}});
        quarters(&emissive_card_full(UNIT_UV, uv1, reference, json!({}), 32))
    };
    assert_eq!(with(json!({}), None), "rrbb");
    assert_eq!(with(json!({"offset": [0.5, 0.0]}), None), "bbrr");
    assert_eq!(with(json!({"scale": [2.0, 1.0]}), None), "rbrb");
    // Half a turn: u' = −u (repeating).
    assert_eq!(
        with(json!({"rotation": std::f32::consts::PI}), None),
        "bbrr"
    );
    // Its texCoord overrides the reference's: set 1 holds doubled coordinates.
    let twice = [0.0, 1.0, 2.0, 1.0, 2.0, 0.0, 0.0, 0.0];
    assert_eq!(with(json!({"texCoord": 1}), Some(twice)), "rbrb");
}
