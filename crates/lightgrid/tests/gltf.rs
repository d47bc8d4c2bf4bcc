//! glTF scenes in and out: the fixture room (hierarchy, mirrored instance, strips, computed
//! normals, materials, point and spot lights, a camera) loads into the scene it describes;
//! `.gltf` and `.glb` load alike; every catalog scene survives export → load (geometry, lights,
//! camera, materials) and renders the same; `--add-lights` fills any scene; a corpus of
//! malformed files each fails with a clear error naming the problem; and a bounded fuzz run
//! over mutated files never panics or hangs.

mod common;

use common::gltf_fixture::{room, textured, GltfWriter};
use glam::{Mat4, Quat, Vec3};
use lightgrid::scene::catalog::{SceneParams, SCENES};
use lightgrid::scene::gltf::{self, LoadOptions};
use lightgrid::scene::source::{self, AddLights, SceneRequest};
use lightgrid::scene::{Light, Scene};
use lightgrid::Error;
use serde_json::{json, Value};
use std::time::{Duration, Instant};

fn load(bytes: &[u8]) -> lightgrid::Result<gltf::Loaded> {
    gltf::load_bytes(bytes, "fixture.gltf", None, &LoadOptions::default())
}

fn world_vertices(scene: &Scene) -> Vec<Vec3> {
    let state = scene.frame(0);
    scene
        .geometry(&state)
        .vertices
        .iter()
        .map(|v| Vec3::from(v.position))
        .collect()
}

#[test]
fn the_fixture_room_loads_as_described() {
    let w = room();
    let loaded = load(&w.gltf()).unwrap();
    let s = &loaded.scene;
    // Ground, red cube, grandchild, mirrored cube, glass, wall, triangle; the MASK cube under
    // its cutoff is not drawn.
    assert_eq!(s.objects.len(), 7, "{:?}", loaded.warnings);
    assert_eq!(s.lights.len(), 6);
    assert!(s.has_transparency());
    // The grandchild cube: parent (translate, 45° about y) × child (translate, scale) ×
    // grandchild (translate, scale 0.6).
    let parent = Mat4::from_rotation_translation(
        Quat::from_rotation_y(std::f32::consts::FRAC_PI_4),
        Vec3::new(-2.0, 0.0, 1.0),
    );
    let child = Mat4::from_scale_rotation_translation(
        Vec3::new(1.5, 2.0, 1.5),
        Quat::IDENTITY,
        Vec3::new(0.0, 1.0, 0.0),
    );
    let grand =
        Mat4::from_scale_rotation_translation(Vec3::splat(0.6), Quat::IDENTITY, Vec3::Y * 1.5);
    let expected = (parent * child * grand).transform_point3(Vec3::splat(0.5));
    let verts = world_vertices(s);
    assert!(
        verts.iter().any(|v| v.distance(expected) < 1e-4),
        "the grandchild's corner {expected} is not where the hierarchy puts it"
    );
    // Every triangle's winding agrees with its normals (the mirrored instance was flipped
    // back; computed normals follow the winding), so two-sided lighting lights front faces.
    let state = s.frame(0);
    let g = s.geometry(&state);
    for t in g.indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| g.vertices[i as usize]);
        let face = (Vec3::from(b.position) - Vec3::from(a.position))
            .cross(Vec3::from(c.position) - Vec3::from(a.position));
        let n = Vec3::from(a.normal) + Vec3::from(b.normal) + Vec3::from(c.normal);
        assert!(face.dot(n) > 0.0, "a triangle faces away from its normals");
    }
    // Materials by the documented rule: dielectric red keeps its colour as diffuse, metal has
    // no diffuse and its colour as specular; the untextured default material is metallic.
    let red = s.materials[1];
    assert!((red.diffuse - Vec3::new(0.8, 0.1, 0.1)).length() < 1e-6);
    assert!((red.specular - Vec3::splat(0.04)).length() < 1e-6);
    let metal = s.materials[2];
    assert_eq!(metal.diffuse, Vec3::ZERO);
    assert!((metal.specular - Vec3::new(0.9, 0.8, 0.3)).length() < 1e-6);
    assert!(s.materials[3].transparent && (s.materials[3].alpha - 0.4).abs() < 1e-6);
    // Lights: positions, ranges (given, or from the cutoff), spot directions from rotations.
    let lights: Vec<Light> = s.lights.iter().map(|l| l.light).collect();
    assert_eq!(lights[0].position, Vec3::new(-4.0, 2.0, 3.0));
    assert_eq!(lights[0].range, 7.0);
    // The rangeless one: cut where it stops showing at the scene's exposure, at most the
    // farthest corner of the scene's bounds (gltf_exported.rs checks the rule itself).
    assert_eq!(s.derived_ranges, vec![(2, lights[2].range)]);
    let (lo, hi) = source::bounds(s).unwrap();
    let p = lights[2].position;
    let corner = (p - lo).abs().max((p - hi).abs()).length();
    assert!(
        lights[2].range > 1.0 && lights[2].range <= corner * 1.011,
        "{}",
        lights[2].range
    );
    let down = lights[4].spot.expect("a spot");
    assert!(
        down.direction.distance(Vec3::NEG_Y) < 1e-5,
        "{}",
        down.direction
    );
    assert!((down.cos_outer - 0.5f32.cos()).abs() < 1e-6);
    let side = lights[5];
    assert!(side.position.distance(Vec3::new(7.0, 1.5, 0.0)) < 1e-5);
    let expected = Quat::from_rotation_y(std::f32::consts::FRAC_PI_3) * Vec3::NEG_Z;
    assert!(side.spot.unwrap().direction.distance(expected) < 1e-5);
    // The camera: frame 0 is the file's camera; the animation orbits from there.
    let cam = s.camera_path.at(0);
    assert_eq!(cam.eye, Vec3::new(4.0, 7.0, 13.0));
    assert!((cam.fov_y - 0.9).abs() < 1e-6 && cam.near == 0.1 && cam.far == 60.0);
    assert_eq!(s.default_size, (640, 400));
    assert_eq!(s.frame_count(), gltf::ORBIT_FRAMES);
    let half = s.camera_path.at(gltf::ORBIT_FRAMES / 2);
    assert!(half.eye.distance(cam.eye) > 5.0, "the camera orbits");
    // The warnings say what was skipped or derived, nothing else.
    assert_eq!(loaded.warnings.len(), 1, "{:?}", loaded.warnings);
    assert!(loaded.warnings[0].contains("1 light(s) have no range"));
}

#[test]
fn gltf_and_glb_load_the_same_scene() {
    let w = room();
    let a = load(&w.gltf()).unwrap().scene;
    let b = load(&w.glb()).unwrap().scene;
    assert_eq!(world_vertices(&a), world_vertices(&b));
    assert_eq!(a.lights.len(), b.lights.len());
    for (x, y) in a.lights.iter().zip(&b.lights) {
        assert_eq!(x.light, y.light);
    }
    assert_eq!(a.materials, b.materials);
}

#[test]
fn a_file_on_disk_resolves_its_buffer_beside_it() {
    let dir = common::output_dir().join("gltf-external");
    std::fs::create_dir_all(&dir).unwrap();
    let w = room();
    let mut doc = w.document(json!({"byteLength": w.bin.len(), "uri": "room%20data.bin"}));
    doc["asset"]["generator"] = json!("external buffer");
    std::fs::write(dir.join("room data.bin"), &w.bin).unwrap();
    let path = dir.join("room.gltf");
    std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
    let s = gltf::load(&path, &LoadOptions::default()).unwrap().scene;
    assert_eq!(s.name, "room");
    assert_eq!(s.objects.len(), 7);
    // The same document as bytes without a folder cannot resolve the file.
    let e = load(&serde_json::to_vec(&doc).unwrap()).unwrap_err();
    assert!(e.to_string().contains("separate file"), "{e}");
}

/// Export → load gives back every catalog scene's frame: the same world-space triangles, the
/// same lights (exactly: the file carries lightgrid's numbers), materials and camera.
#[test]
fn every_catalog_scene_survives_export_and_load() {
    for info in SCENES {
        let params = SceneParams {
            lights: info.variable_lights.then_some(500),
            spot_fraction: 0.3,
            ..SceneParams::default()
        };
        let scene = lightgrid::scene::catalog::build(info.name, &params).unwrap();
        let frame = scene.frame_count() / 3;
        let bytes = gltf::export(&scene, frame, (320, 180)).unwrap();
        let back = load(&bytes).unwrap();
        assert!(
            back.warnings.is_empty(),
            "{}: {:?}",
            info.name,
            back.warnings
        );
        let back = back.scene;
        let state = scene.frame(frame);
        let want = scene.geometry(&state);
        let got = back.geometry(&back.frame(0));
        assert_eq!(want.indices.len(), got.indices.len(), "{}", info.name);
        assert_eq!(want.opaque_indices, got.opaque_indices, "{}", info.name);
        let mut a: Vec<[i64; 3]> = want
            .vertices
            .iter()
            .map(|v| v.position.map(|c| (c * 1e3).round() as i64))
            .collect();
        let mut b: Vec<[i64; 3]> = got
            .vertices
            .iter()
            .map(|v| v.position.map(|c| (c * 1e3).round() as i64))
            .collect();
        a.sort();
        b.sort();
        assert_eq!(a, b, "{}: world-space vertices differ", info.name);
        assert_eq!(scene.materials, back.materials, "{}", info.name);
        let lights = back.frame(0).lights;
        assert_eq!(state.lights.len(), lights.len());
        for (x, y) in state.lights.iter().zip(&lights) {
            assert!(x.position.distance(y.position) < 1e-4, "{}", info.name);
            assert_eq!(
                (x.color, x.intensity, x.range),
                (y.color, y.intensity, y.range)
            );
            match (x.spot, y.spot) {
                (None, None) => {}
                (Some(p), Some(q)) => {
                    assert!(p.direction.distance(q.direction) < 1e-5);
                    assert_eq!((p.cos_inner, p.cos_outer), (q.cos_inner, q.cos_outer));
                }
                _ => panic!("{}: a spot became a point light or back", info.name),
            }
        }
        let (c, d) = (state.camera, back.camera_path.at(0));
        assert!(c.eye.distance(d.eye) < 1e-3, "{}", info.name);
        let dir = |cam: lightgrid::scene::Camera| (cam.target - cam.eye).normalize();
        assert!(dir(c).distance(dir(d)) < 1e-5, "{}", info.name);
        assert_eq!((c.fov_y, c.near, c.far), (d.fov_y, d.near, d.far));
    }
}

#[test]
fn added_lights_fill_the_bounds_of_any_scene() {
    let dir = common::output_dir().join("gltf-added");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("room.glb");
    std::fs::write(&path, room().glb()).unwrap();
    let mut req = SceneRequest::new(path.to_str().unwrap());
    req.add_lights = Some(AddLights {
        count: 300,
        range: None,
    });
    let opened = source::open(&req).unwrap();
    let s = &opened.scene;
    assert_eq!(s.lights.len(), 306);
    let (lo, hi) = source::bounds(s).unwrap();
    let pad = (hi - lo) * 0.1 + Vec3::splat(1e-3);
    for l in &s.lights[6..] {
        let p = l.light.position;
        assert!(
            p.cmpge(lo - pad).all() && p.cmple(hi + pad).all(),
            "{p} outside the bounds"
        );
        assert_eq!(l.light.range, s.lights[6].light.range);
    }
    let range = s.lights[6].light.range;
    assert!(range > 0.5 && range < (hi - lo).length(), "{range}");
    // Seeded: the same request gives the same lights, another seed others.
    let again = source::open(&req).unwrap().scene;
    assert_eq!(again.lights[100].light, s.lights[100].light);
    req.params.seed = 9;
    let other = source::open(&req).unwrap().scene;
    assert_ne!(
        other.lights[100].light.position,
        s.lights[100].light.position
    );
    // A catalog scene takes them too, with --spot-fraction making spots of all its lights.
    let mut street = SceneRequest::new("robots-few");
    street.add_lights = Some(AddLights {
        count: 50,
        range: Some(3.0),
    });
    street.params.spot_fraction = 1.0;
    let s = source::open(&street).unwrap().scene;
    assert_eq!(s.lights.len(), 11 + 50);
    assert!(s.lights.iter().all(|l| l.light.spot.is_some()));
    assert_eq!(s.lights[20].light.range, 3.0);
    // Refused: zero, too many, a bad range, --camera for a catalog scene.
    for (count, range) in [
        (0, None),
        (2_000_000, None),
        (5, Some(-1.0)),
        (5, Some(f32::NAN)),
    ] {
        street.add_lights = Some(AddLights { count, range });
        assert!(source::open(&street).is_err(), "{count} {range:?}");
    }
    street.add_lights = None;
    street.camera = Some(0);
    assert!(source::open(&street).is_err());
}

#[test]
fn a_file_without_lights_asks_for_added_ones() {
    let mut w = room();
    w.lights.clear();
    w.roots.truncate(8);
    let dir = common::output_dir().join("gltf-dark");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("dark.gltf");
    std::fs::write(&path, w.gltf()).unwrap();
    let e = source::open(&SceneRequest::new(path.to_str().unwrap())).unwrap_err();
    assert!(e.to_string().contains("--add-lights"), "{e}");
}

// ------------------------------------------------------------------ the malformed corpus

/// A document edit and the words its error must contain.
type Case = (&'static str, fn(&mut Value, &mut Vec<u8>), &'static str);

fn corpus() -> Vec<Case> {
    vec![
        (
            "normalized floats",
            |d, _| d["accessors"][0]["normalized"] = json!(true),
            "normalized is only",
        ),
        (
            "no asset",
            |d, _| {
                d.as_object_mut().unwrap().remove("asset");
            },
            "asset",
        ),
        (
            "glTF 1.0",
            |d, _| d["asset"]["version"] = json!("1.0"),
            "only glTF 2.0",
        ),
        (
            "buffer shorter than declared",
            |d, b| d["buffers"][0]["byteLength"] = json!(b.len() + 100),
            "declares",
        ),
        (
            "missing external buffer",
            |d, _| d["buffers"][0]["uri"] = json!("nowhere.bin"),
            "separate file",
        ),
        (
            "remote buffer",
            |d, _| d["buffers"][0]["uri"] = json!("https://example.com/a.bin"),
            "remote",
        ),
        (
            "absolute buffer path",
            |d, _| d["buffers"][0]["uri"] = json!("/etc/passwd"),
            "absolute",
        ),
        (
            "data URI not base64",
            |d, _| d["buffers"][0]["uri"] = json!("data:application/octet-stream,abc"),
            "base64",
        ),
        (
            "corrupt base64",
            |d, _| d["buffers"][0]["uri"] = json!("data:application/octet-stream;base64,AB$C"),
            "not base64",
        ),
        (
            "accessor index out of range",
            |d, _| d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(9999),
            "accessor 9999 does not exist",
        ),
        (
            "index past the vertices",
            |d, b| {
                // The ground's indices are the accessor after its positions and normals.
                let view = d["accessors"][2]["bufferView"].as_u64().unwrap() as usize;
                let at = d["bufferViews"][view]["byteOffset"].as_u64().unwrap() as usize;
                b[at..at + 2].copy_from_slice(&500u16.to_le_bytes());
            },
            "out of range for 4 vertices",
        ),
        (
            "accessor overruns its view",
            |d, _| d["accessors"][0]["count"] = json!(5),
            "overrun buffer view",
        ),
        (
            "view overruns its buffer",
            |d, _| d["bufferViews"][0]["byteLength"] = json!(1 << 30),
            "overruns buffer",
        ),
        (
            "view names a missing buffer",
            |d, _| d["bufferViews"][0]["buffer"] = json!(7),
            "buffer 7, which does not exist",
        ),
        (
            "absurd count",
            |d, _| d["accessors"][0]["count"] = json!(4_000_000_000_000u64),
            "4194304",
        ),
        (
            "huge offset",
            |d, _| d["accessors"][0]["byteOffset"] = json!(u64::MAX),
            "overrun",
        ),
        (
            "stride below the element",
            |d, _| d["bufferViews"][0]["byteStride"] = json!(4),
            "byteStride",
        ),
        (
            "NaN position",
            |d, b| {
                let view = d["accessors"][0]["bufferView"].as_u64().unwrap() as usize;
                let at = d["bufferViews"][view]["byteOffset"].as_u64().unwrap() as usize;
                b[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
            },
            "NaN or infinite",
        ),
        (
            "infinite position",
            |d, b| {
                let view = d["accessors"][0]["bufferView"].as_u64().unwrap() as usize;
                let at = d["bufferViews"][view]["byteOffset"].as_u64().unwrap() as usize + 4;
                b[at..at + 4].copy_from_slice(&f32::INFINITY.to_le_bytes());
            },
            "NaN or infinite",
        ),
        (
            "cyclic nodes",
            |d, _| {
                let n = d["nodes"].as_array().unwrap().len();
                let root = d["scenes"][0]["nodes"][1].as_u64().unwrap() as usize;
                d["nodes"]
                    .as_array_mut()
                    .unwrap()
                    .push(json!({"children": [root]}));
                let leaf = d["nodes"][root]["children"][0].as_u64().unwrap() as usize;
                d["nodes"][leaf]["children"] = json!([n]);
            },
            "reached twice",
        ),
        (
            "node with two parents",
            |d, _| {
                let (a, b) = (&d["scenes"][0]["nodes"][0], &d["scenes"][0]["nodes"][2]);
                let (a, b) = (a.as_u64().unwrap() as usize, b.as_u64().unwrap());
                d["nodes"][a]["children"] = json!([b]);
            },
            "reached twice",
        ),
        (
            "missing node",
            |d, _| d["scenes"][0]["nodes"] = json!([4242]),
            "node 4242 does not exist",
        ),
        (
            "missing default scene",
            |d, _| d["scene"] = json!(3),
            "default scene 3",
        ),
        (
            "missing mesh",
            |d, _| d["nodes"][0]["mesh"] = json!(99),
            "mesh 99 does not exist",
        ),
        (
            "missing material",
            |d, _| d["meshes"][0]["primitives"][0]["material"] = json!(99),
            "material 99 does not exist",
        ),
        (
            "bad primitive mode",
            |d, _| d["meshes"][0]["primitives"][0]["mode"] = json!(9),
            "mode 9",
        ),
        (
            "NaN in a matrix",
            |d, _| {
                d["nodes"][0]["matrix"] = json!([1e39, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1])
            },
            "number out of range",
        ),
        (
            "zero quaternion",
            |d, _| d["nodes"][0]["rotation"] = json!([0, 0, 0, 0]),
            "not a quaternion",
        ),
        (
            "overflowing hierarchy",
            |d, _| {
                let root = d["scenes"][0]["nodes"][1].as_u64().unwrap() as usize;
                d["nodes"][root]["scale"] = json!([1e30, 1e30, 1e30]);
                let child = d["nodes"][root]["children"][0].as_u64().unwrap() as usize;
                d["nodes"][child]["scale"] = json!([1e30, 1e30, 1e30]);
            },
            "overflows",
        ),
        (
            "unsupported required extension",
            |d, _| d["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]),
            "requires extension KHR_draco_mesh_compression",
        ),
        (
            "missing light",
            |d, _| {
                let l = d["scenes"][0]["nodes"]
                    .as_array()
                    .unwrap()
                    .last()
                    .unwrap()
                    .as_u64()
                    .unwrap() as usize;
                let child = d["nodes"][l]["children"][0].as_u64().unwrap() as usize;
                d["nodes"][child]["extensions"]["KHR_lights_punctual"]["light"] = json!(77);
            },
            "light 77, which does not exist",
        ),
        (
            "light range far too small",
            |d, _| d["extensions"]["KHR_lights_punctual"]["lights"][0]["range"] = json!(1e-30),
            "light 0: range 1e-30 is too small",
        ),
        (
            "light colour × intensity past f32",
            |d, _| {
                let l = &mut d["extensions"]["KHR_lights_punctual"]["lights"][0];
                l["color"] = json!([1e30, 1e30, 1e30]);
                l["intensity"] = json!(1e10);
                l["range"] = json!(5.0);
            },
            "light 0: radiance (colour [1e30, 1e30, 1e30] × intensity",
        ),
        (
            "light colour × intensity past f32, no range",
            |d, _| {
                let l = &mut d["extensions"]["KHR_lights_punctual"]["lights"][0];
                l.as_object_mut().unwrap().remove("range");
                l["color"] = json!([1e30, 1e30, 1e30]);
                l["intensity"] = json!(1e10);
            },
            "of 1e40 exceeds 1e12",
        ),
        (
            "light intensity past the radiance limit",
            |d, _| {
                let l = &mut d["extensions"]["KHR_lights_punctual"]["lights"][0];
                l["intensity"] = json!(1e30);
                l["range"] = json!(1e-5);
            },
            "from the intensity 1e30 cd",
        ),
        (
            "light beyond the coordinate bound",
            |d, _| {
                let l = d["nodes"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .position(|n| n["extensions"]["KHR_lights_punctual"].is_object())
                    .unwrap();
                d["nodes"][l]["translation"] = json!([1e20, 0.0, 0.0]);
                d["nodes"][l].as_object_mut().unwrap().remove("matrix");
            },
            "beyond ±1e12",
        ),
        (
            "negative light range",
            |d, _| d["extensions"]["KHR_lights_punctual"]["lights"][0]["range"] = json!(-3.0),
            "not a positive number",
        ),
        (
            "spot cone wider than 90°",
            |d, _| {
                d["extensions"]["KHR_lights_punctual"]["lights"][4]["spot"]["outerConeAngle"] =
                    json!(2.0)
            },
            "cone angles",
        ),
        (
            "unknown light type",
            |d, _| d["extensions"]["KHR_lights_punctual"]["lights"][0]["type"] = json!("area"),
            "'area'",
        ),
        (
            "negative material factor",
            |d, _| {
                d["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = json!([-1, 0, 0, 1])
            },
            "non-negative",
        ),
        (
            "unknown alpha mode",
            |d, _| d["materials"][0]["alphaMode"] = json!("DITHER"),
            "alphaMode",
        ),
        (
            "camera with zero fov",
            |d, _| d["cameras"][0]["perspective"]["yfov"] = json!(0.0),
            "yfov",
        ),
        (
            "far before near",
            |d, _| d["cameras"][0]["perspective"]["zfar"] = json!(0.01),
            "zfar",
        ),
        (
            "wrong JSON type",
            |d, _| d["nodes"] = json!("many"),
            "malformed JSON",
        ),
        (
            "negative index",
            |d, _| d["nodes"][0]["mesh"] = json!(-1),
            "malformed JSON",
        ),
        (
            "no triangles",
            |d, _| {
                d["scenes"][0]["nodes"] = json!([]);
            },
            "no triangles",
        ),
        (
            "normals of the wrong type",
            |d, _| {
                d["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = json!(2);
            },
            "SCALAR where 3 components",
        ),
    ]
}

fn fixture_parts() -> (Value, Vec<u8>) {
    let w = room();
    (
        w.document(json!({"byteLength": w.bin.len()})),
        w.bin.clone(),
    )
}

#[test]
fn every_malformed_file_fails_with_a_clear_error() {
    for (what, edit, words) in corpus() {
        let (mut doc, mut bin) = fixture_parts();
        edit(&mut doc, &mut bin);
        let bytes = GltfWriter::glb_of(&doc, &bin);
        match load(&bytes) {
            Ok(_) => panic!("{what}: loaded"),
            Err(Error::Gltf { path, reason }) => {
                assert_eq!(path, "fixture.gltf", "{what}");
                assert!(
                    reason.contains(words),
                    "{what}: '{reason}' does not say '{words}'"
                );
            }
            Err(e) => panic!("{what}: not a glTF error: {e}"),
        }
    }
}

#[test]
fn malformed_containers_fail_clearly() {
    let glb = room().glb();
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("empty file", Vec::new(), "malformed JSON"),
        ("not JSON", b"{\"asset\": ".to_vec(), "malformed JSON"),
        ("GLB header only", glb[..10].to_vec(), "shorter"),
        (
            "GLB version 1",
            {
                let mut g = glb.clone();
                g[4] = 1;
                g
            },
            "version 1",
        ),
        (
            "GLB length past the file",
            {
                let mut g = glb.clone();
                g[8..12].copy_from_slice(&(glb.len() as u32 + 10).to_le_bytes());
                g
            },
            "declares",
        ),
        (
            "GLB chunk past the end",
            {
                let mut g = glb.clone();
                g[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
                g
            },
            "runs past the end",
        ),
        (
            "GLB truncated in its binary chunk",
            {
                let mut g = glb[..glb.len() - 64].to_vec();
                let n = g.len() as u32;
                g[8..12].copy_from_slice(&n.to_le_bytes());
                g
            },
            "runs past the end",
        ),
        (
            "GLB without a JSON chunk",
            {
                let mut g = glb.clone();
                g[16..20].copy_from_slice(b"BIN\0");
                g
            },
            "not JSON",
        ),
        (
            "deeply nested JSON",
            {
                let mut s = String::from("{\"asset\":{\"version\":\"2.0\"},\"extras\":");
                s.push_str(&"[".repeat(100_000));
                s.into_bytes()
            },
            "malformed JSON",
        ),
    ];
    for (what, bytes, words) in cases {
        let e = load(&bytes).unwrap_err().to_string();
        assert!(e.contains(words), "{what}: '{e}' does not say '{words}'");
    }
}

#[test]
fn unsupported_optional_parts_are_skipped_with_warnings() {
    let (mut doc, bin) = fixture_parts();
    doc["extensionsUsed"] = json!(["KHR_lights_punctual", "KHR_materials_clearcoat"]);
    doc["extensions"]["KHR_lights_punctual"]["lights"][1] = json!({"type": "directional"});
    doc["meshes"][0]["primitives"][0]["mode"] = json!(1);
    doc["cameras"][0] = json!({"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}});
    let loaded = load(&GltfWriter::glb_of(&doc, &bin)).unwrap();
    let w = loaded.warnings.join("\n");
    for words in [
        "KHR_materials_clearcoat",
        "directional",
        "lines",
        "orthographic",
    ] {
        assert!(w.contains(words), "no warning about {words}: {w}");
    }
    assert_eq!(loaded.scene.lights.len(), 5);
    assert_eq!(
        loaded.scene.objects.len(),
        6,
        "the ground (now lines) is skipped"
    );
}

#[test]
fn camera_choice() {
    let (mut doc, bin) = fixture_parts();
    doc["cameras"]
        .as_array_mut()
        .unwrap()
        .push(json!({"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.5}}));
    let n = doc["nodes"].as_array().unwrap().len();
    doc["nodes"]
        .as_array_mut()
        .unwrap()
        .push(json!({"camera": 1, "translation": [0, 2, 20]}));
    doc["scenes"][0]["nodes"]
        .as_array_mut()
        .unwrap()
        .push(json!(n));
    let bytes = GltfWriter::glb_of(&doc, &bin);
    let with = |camera| gltf::load_bytes(&bytes, "f.glb", None, &LoadOptions { camera });
    assert_eq!(with(None).unwrap().scene.camera_path.at(0).fov_y, 0.9);
    let second = with(Some(1)).unwrap().scene.camera_path.at(0);
    assert_eq!((second.fov_y, second.eye), (0.5, Vec3::new(0.0, 2.0, 20.0)));
    assert!(second.far > 20.0, "no zfar: the far plane covers the scene");
    assert!(with(Some(2)).unwrap_err().to_string().contains("2 camera"));
    // Without any camera one is fitted: the whole scene in view.
    doc["cameras"] = json!([]);
    for node in doc["nodes"].as_array_mut().unwrap() {
        node.as_object_mut().unwrap().remove("camera");
    }
    let fitted = load(&GltfWriter::glb_of(&doc, &bin)).unwrap().scene;
    let cam = fitted.camera_path.at(0);
    let view_proj = cam.proj(16.0 / 9.0) * cam.view();
    for v in world_vertices(&fitted) {
        let c = view_proj * v.extend(1.0);
        let ndc = c.truncate() / c.w;
        assert!(
            c.w > 0.0 && ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0 && (0.0..=1.0).contains(&ndc.z),
            "{v} out of the fitted view"
        );
    }
}

// ---------------------------------------------------------------------------- the fuzz run

/// Seconds the fuzz run takes (`LIGHTGRID_FUZZ_SECONDS`, default 10).
fn fuzz_budget() -> Duration {
    let secs = std::env::var("LIGHTGRID_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .unwrap_or(10.0);
    Duration::from_secs_f64(secs)
}

/// Mutate valid `.glb` and `.gltf` files (bit flips, byte overwrites with boundary values,
/// truncation, splices of digits into the JSON) for a bounded time: loading must return,
/// never panic, and no single load may take more than a second.
#[test]
fn fuzzed_files_never_panic_or_hang() {
    let w = room();
    let seeds = [w.glb(), w.gltf(), textured().glb()];
    let mut rng = lightgrid::scene::Rng::new(0xf022);
    let start = Instant::now();
    let (mut runs, mut loaded) = (0u64, 0u64);
    while start.elapsed() < fuzz_budget() {
        let mut bytes = seeds[rng.below(seeds.len() as u32) as usize].clone();
        for _ in 0..1 + rng.below(8) {
            let at = rng.below(bytes.len() as u32) as usize;
            match rng.below(5) {
                0 => bytes[at] ^= 1 << rng.below(8),
                1 => {
                    bytes[at] = [0, 0xff, 0x7f, 0x80, b'9', b'-', b'"', b'['][rng.below(8) as usize]
                }
                2 => bytes.truncate(at.max(1)),
                3 => {
                    let digits = [
                        "1e39",
                        "-1",
                        "4294967295",
                        "18446744073709551616",
                        "0",
                        "NaN",
                    ];
                    let d = digits[rng.below(digits.len() as u32) as usize];
                    bytes.splice(at..at, d.bytes());
                }
                _ => {
                    let span = rng.below(64) as usize;
                    let end = (at + span).min(bytes.len());
                    bytes.drain(at..end);
                }
            }
            if bytes.is_empty() {
                break;
            }
        }
        let t = Instant::now();
        let result = std::panic::catch_unwind(|| load(&bytes).is_ok());
        let took = t.elapsed();
        if result.is_err() || took > Duration::from_secs(1) {
            let path = common::output_dir().join(format!("fuzz-failure-{runs}.bin"));
            std::fs::write(&path, &bytes).unwrap();
            panic!(
                "input {runs} {} (written to {})",
                if result.is_err() {
                    "panicked"
                } else {
                    "took over a second"
                },
                path.display()
            );
        }
        loaded += u64::from(result.unwrap());
        runs += 1;
    }
    println!(
        "fuzz: {runs} mutated files in {:?}, {loaded} still loaded",
        start.elapsed()
    );
    assert!(runs > 100, "the fuzz run tried only {runs} inputs");
}

// ------------------------------------------------------------------------------ rendering

/// Export → load → render equals the catalog render, for every catalog scene (GPU).
#[test]
fn exported_catalog_scenes_render_the_same() {
    let ctx = common::gpu();
    let (w, h) = (112, 63);
    let mut r = lightgrid::Renderer::new(&ctx, w, h, lightgrid::RenderSettings::default()).unwrap();
    for info in SCENES {
        let params = SceneParams {
            lights: info.variable_lights.then_some(2000),
            ..SceneParams::default()
        };
        let scene = lightgrid::scene::catalog::build(info.name, &params).unwrap();
        let frame = scene.frame_count() / 2;
        let back = load(&gltf::export(&scene, frame, (w, h)).unwrap())
            .unwrap()
            .scene;
        for pipeline in ["forward", "clustered_deferred"] {
            let a = r.render(&scene, frame, pipeline).unwrap();
            let b = r.render(&back, 0, pipeline).unwrap();
            // The camera goes through a matrix inverse (its node), so an edge pixel whose
            // centre lies on a silhouette may show the other surface (scattered frame 60:
            // one pixel of 7,056); everything else is within a level (the grids see a camera
            // a rounding away, so lists may sum in another order: stress with
            // clustered_deferred has 1-level differences in 6% of its pixels).
            let (d, _) = lightgrid::image_io::diff(&a.image, &b.image).unwrap();
            let over = common::pixels_over(&a.image, &b.image, 2);
            assert!(
                over <= u64::from(w * h) / 1000 && d.mean < 0.1,
                "{} via glTF with {pipeline}: mean {} max {}, {over} pixels over 2 levels",
                info.name,
                d.mean,
                d.max
            );
            let (x, y) = (
                a.stats.ideal_lighting_computations as f64,
                b.stats.ideal_lighting_computations as f64,
            );
            assert!(
                x > 0.0 && (x - y).abs() <= x * 1e-3,
                "{}: the same samples reached by the same lights ({x} vs {y})",
                info.name
            );
        }
    }
}

#[test]
fn textures_load_with_their_materials_and_survive_export() {
    let loaded = load(&textured().glb()).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let s = loaded.scene;
    assert_eq!(s.textures.len(), 3);
    assert_eq!((s.textures[0].width, s.textures[0].height), (64, 64));
    assert_eq!(&s.textures[0].rgba[..4], &[230, 220, 200, 255]);
    let (ground, cage, pane) = (s.materials[0], s.materials[1], s.materials[2]);
    assert_eq!(ground.texture, Some(0));
    assert_eq!(ground.alpha_cutoff, None);
    assert_eq!((cage.texture, cage.alpha_cutoff), (Some(1), Some(0.5)));
    assert!(!cage.transparent);
    assert!(pane.transparent && pane.texture == Some(2) && (pane.alpha - 0.9).abs() < 1e-6);
    assert!(s.meshes[0].uvs.iter().any(|uv| uv.x == 4.0));
    // Export carries the textures (PNG, lossless) and the alpha test.
    let back = load(&gltf::export(&s, 0, (320, 200)).unwrap())
        .unwrap()
        .scene;
    assert_eq!(back.textures, s.textures);
    assert_eq!(back.materials, s.materials);
}

#[test]
fn broken_textures_fail_clearly() {
    let w = textured();
    let parts = || {
        (
            w.document(json!({"byteLength": w.bin.len()})),
            w.bin.clone(),
        )
    };
    let cases: Vec<Case> = vec![
        (
            "missing texture",
            |d, _| {
                d["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["index"] = json!(9)
            },
            "texture 9 does not exist",
        ),
        (
            "missing image",
            |d, _| d["textures"][0]["source"] = json!(5),
            "image 5 does not exist",
        ),
        (
            "corrupt image",
            |d, b| {
                let view = d["images"][0]["bufferView"].as_u64().unwrap() as usize;
                let at = d["bufferViews"][view]["byteOffset"].as_u64().unwrap() as usize;
                b[at + 20..at + 40].fill(0xee);
            },
            "image 0",
        ),
        (
            "image declaring a huge size",
            |d, b| {
                // The PNG header's width (IHDR, bytes 16..20) says 100,000 pixels.
                let view = d["images"][0]["bufferView"].as_u64().unwrap() as usize;
                let at = d["bufferViews"][view]["byteOffset"].as_u64().unwrap() as usize;
                b[at + 16..at + 20].copy_from_slice(&100_000u32.to_be_bytes());
            },
            "image 0",
        ),
        (
            "image without data",
            |d, _| {
                d["images"][0].as_object_mut().unwrap().remove("bufferView");
            },
            "neither a uri nor a bufferView",
        ),
        (
            "negative cutoff",
            |d, _| d["materials"][1]["alphaCutoff"] = json!(-1.0),
            "alphaCutoff",
        ),
    ];
    for (what, edit, words) in cases {
        let (mut doc, mut bin) = parts();
        edit(&mut doc, &mut bin);
        let e = load(&GltfWriter::glb_of(&doc, &bin))
            .unwrap_err()
            .to_string();
        assert!(e.contains(words), "{what}: '{e}' does not say '{words}'");
    }
    // Clamped wrapping is applied (the material records it); a wrap mode glTF does not have
    // is an error naming the sampler.
    let (mut doc, bin) = parts();
    doc["samplers"] = json!([{"wrapS": 33071}]);
    let loaded = load(&GltfWriter::glb_of(&doc, &bin)).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    assert_eq!(
        loaded.scene.materials[0].wraps,
        lightgrid::consts::WRAP_CLAMP
    );
    doc["samplers"] = json!([{"wrapS": 1234}]);
    let e = load(&GltfWriter::glb_of(&doc, &bin))
        .unwrap_err()
        .to_string();
    assert!(e.contains("sampler 0: wrap mode 1234"), "{e}");
}

/// Sparse accessors (glTF §3.6.2.3): substitutions over a base view, and over zeros without
/// one.
#[test]
fn sparse_accessors_substitute_their_elements() {
    let (mut doc, mut bin) = fixture_parts();
    // The ground's positions (accessor 0): vertex 2 moves up to y = 5.
    let at = bin.len();
    bin.extend_from_slice(&2u16.to_le_bytes());
    bin.extend_from_slice(&[0, 0]);
    for v in [10.0f32, 5.0, 10.0] {
        bin.extend_from_slice(&v.to_le_bytes());
    }
    doc["buffers"][0]["byteLength"] = json!(bin.len());
    let views = doc["bufferViews"].as_array_mut().unwrap();
    views.push(json!({"buffer": 0, "byteOffset": at, "byteLength": 2}));
    views.push(json!({"buffer": 0, "byteOffset": at + 4, "byteLength": 12}));
    let n = views.len();
    doc["accessors"][0]["sparse"] = json!({
        "count": 1,
        "indices": {"bufferView": n - 2, "componentType": 5123},
        "values": {"bufferView": n - 1},
    });
    let s = load(&GltfWriter::glb_of(&doc, &bin)).unwrap().scene;
    let ground = &s.meshes[s.objects[0].mesh];
    assert_eq!(ground.positions[2], Vec3::new(10.0, 5.0, 10.0));
    assert_eq!(ground.positions[1], Vec3::new(10.0, 0.0, -10.0));
    // Without a base view the other elements are zeros.
    doc["accessors"][0]
        .as_object_mut()
        .unwrap()
        .remove("bufferView");
    let s = load(&GltfWriter::glb_of(&doc, &bin)).unwrap().scene;
    let ground = &s.meshes[s.objects[0].mesh];
    assert_eq!(ground.positions[2], Vec3::new(10.0, 5.0, 10.0));
    assert_eq!(ground.positions[0], Vec3::ZERO);
    // A substitution past the elements is refused.
    doc["accessors"][0]["sparse"]["count"] = json!(9);
    let e = load(&GltfWriter::glb_of(&doc, &bin))
        .unwrap_err()
        .to_string();
    assert!(e.contains("sparse"), "{e}");
}

/// What the review of the loader found, each pinned: normals computed flat (§3.7.2.1) and from
/// the file's winding (a mirrored instance without normals is lit from the front); a loaded
/// file with a mirrored and a sheared instance survives export and load; a repeated child is
/// refused before it can fill the stack; very narrow spots load and 90° spots export; a
/// camera without zfar gets a far plane past its near one; many buffers naming one file read
/// it once.
#[test]
fn loader_review_cases() {
    let w = room();
    let s = load(&w.glb()).unwrap().scene;
    // The strip wall (4 vertices, 2 triangles, no normals) is flat: a vertex per corner.
    let wall = s
        .meshes
        .iter()
        .find(|m| m.positions.iter().any(|p| p.z == -6.5))
        .unwrap();
    assert_eq!((wall.positions.len(), wall.indices.len()), (6, 6));
    for t in wall.indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| wall.positions[i as usize]);
        let face = (b - a).cross(c - a).normalize();
        for &i in t {
            assert!(wall.normals[i as usize].distance(face) < 1e-5);
        }
    }
    // A mirrored instance of a mesh without normals: every triangle faces its normals.
    let (mut doc, bin) = fixture_parts();
    let tri_mesh = doc["meshes"].as_array().unwrap().len() - 1;
    let n = doc["nodes"].as_array().unwrap().len();
    doc["nodes"]
        .as_array_mut()
        .unwrap()
        .push(json!({"mesh": tri_mesh, "scale": [-1.0, 1.0, 1.0]}));
    // And a sheared one: a rotated child of a non-uniformly scaled parent.
    doc["nodes"]
        .as_array_mut()
        .unwrap()
        .push(json!({"mesh": 1, "rotation": [0.0, 0.38268343, 0.0, 0.9238795]}));
    doc["nodes"].as_array_mut().unwrap().push(
        json!({"scale": [3.0, 1.0, 1.0], "translation": [0.0, 0.0, 6.0], "children": [n + 1]}),
    );
    doc["scenes"][0]["nodes"]
        .as_array_mut()
        .unwrap()
        .extend([json!(n), json!(n + 2)]);
    let s = load(&GltfWriter::glb_of(&doc, &bin)).unwrap().scene;
    let faces_its_normals = |s: &Scene| {
        let g = s.geometry(&s.frame(0));
        g.indices.chunks_exact(3).all(|t| {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| g.vertices[i as usize]);
            let face = (Vec3::from(b.position) - Vec3::from(a.position))
                .cross(Vec3::from(c.position) - Vec3::from(a.position));
            face.dot(Vec3::from(a.normal) + Vec3::from(b.normal) + Vec3::from(c.normal)) > 0.0
        })
    };
    assert!(faces_its_normals(&s));
    let back = load(&gltf::export(&s, 0, (320, 200)).unwrap())
        .unwrap()
        .scene;
    assert!(
        faces_its_normals(&back),
        "export turned a mirrored mesh's winding"
    );
    let key = |s: &Scene| {
        let mut v: Vec<[i64; 3]> = world_vertices(s)
            .iter()
            .map(|p| p.to_array().map(|c| (c * 1e3).round() as i64))
            .collect();
        v.sort();
        v
    };
    assert_eq!(
        key(&s),
        key(&back),
        "the sheared and mirrored instances moved"
    );
    // A repeated child.
    let (mut doc, bin) = fixture_parts();
    doc["nodes"][1]["children"] = json!(vec![0; 100_000]);
    let e = load(&GltfWriter::glb_of(&doc, &bin))
        .unwrap_err()
        .to_string();
    assert!(e.contains("reached twice"), "{e}");
    // A very narrow spot loads; a 90° one exports.
    let (mut doc, bin) = fixture_parts();
    doc["extensions"]["KHR_lights_punctual"]["lights"][4]["spot"] =
        json!({"innerConeAngle": 0.0, "outerConeAngle": 0.001});
    let s = load(&GltfWriter::glb_of(&doc, &bin)).unwrap().scene;
    s.validate().unwrap();
    doc["extensions"]["KHR_lights_punctual"]["lights"][4]["spot"] =
        json!({"outerConeAngle": std::f64::consts::FRAC_PI_2});
    let s = load(&GltfWriter::glb_of(&doc, &bin)).unwrap().scene;
    gltf::export(&s, 0, (64, 36)).unwrap();
    // A far-away near plane without zfar.
    let (mut doc, bin) = fixture_parts();
    doc["cameras"][0]["perspective"] = json!({"yfov": 0.9, "znear": 500.0});
    let cam = load(&GltfWriter::glb_of(&doc, &bin))
        .unwrap()
        .scene
        .camera_path
        .at(0);
    assert!(cam.far > cam.near, "{} {}", cam.near, cam.far);
    // 1,000 buffers naming one 4 MiB file beside the document: it is read once.
    let dir = common::output_dir().join("gltf-shared-buffer");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("big.bin"), vec![7u8; 4 << 20]).unwrap();
    let (mut doc, bin) = fixture_parts();
    for _ in 0..1000 {
        doc["buffers"]
            .as_array_mut()
            .unwrap()
            .push(json!({"byteLength": 1024, "uri": "big.bin"}));
    }
    let path = dir.join("shared.glb");
    std::fs::write(&path, GltfWriter::glb_of(&doc, &bin)).unwrap();
    let t = Instant::now();
    gltf::load(&path, &LoadOptions::default()).unwrap();
    assert!(t.elapsed() < Duration::from_secs(2), "{:?}", t.elapsed());
}

/// A file made for another engine keeps its photometric lights through lightgrid: loaded as
/// candela with GGX and an automatic exposure, exported, and loaded back with the same
/// lighting and the same intensities (the root's `extras.lightgrid.lighting`); a catalog
/// scene's export keeps the papers' units and Blinn-Phong.
#[test]
fn photometric_lights_and_the_scenes_lighting_survive_export() {
    use lightgrid::scene::{Brdf, LightUnits};
    let scene = load(&common::gltf_fixture::engine_street(16).glb())
        .unwrap()
        .scene;
    assert_eq!(scene.lighting.units, LightUnits::Photometric);
    assert_eq!(scene.lighting.brdf, Brdf::Ggx);
    assert!(scene.lighting.exposure > 0.0 && scene.lighting.exposure < 1.0);
    assert!(scene.lights.iter().all(|l| l.light.intensity == 4000.0));
    let bytes = gltf::export(&scene, 0, (160, 90)).unwrap();
    let back = load(&bytes).unwrap().scene;
    assert_eq!(back.lighting, scene.lighting);
    let cd = |s: &Scene| -> Vec<f32> { s.lights.iter().map(|l| l.light.intensity).collect() };
    assert_eq!(cd(&back), cd(&scene));
    // A catalog scene's export keeps the papers' units and Blinn-Phong.
    let robots = lightgrid::scene::catalog::build("robots-few", &SceneParams::default()).unwrap();
    let glb = gltf::export(&robots, 0, (160, 90)).unwrap();
    let back = load(&glb).unwrap().scene;
    assert_eq!(back.lighting, robots.lighting);
    assert_eq!(back.lighting.brdf, Brdf::Phong);
    // An earlier lightgrid's export (no lighting record, lightgrid's own intensities) is
    // still read in the papers' units, with a warning; with the intensities gone too, its
    // candela are photometric.
    let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let mut doc: Value = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
    let bin = glb[20 + json_len + 8..].to_vec();
    doc.as_object_mut().unwrap().remove("extras");
    let loaded = load(&GltfWriter::glb_of(&doc, &bin)).unwrap();
    assert_eq!(loaded.scene.lighting, robots.lighting);
    assert!(
        loaded
            .warnings
            .iter()
            .any(|w| w.contains("earlier lightgrid")),
        "{:?}",
        loaded.warnings
    );
    for l in doc["extensions"]["KHR_lights_punctual"]["lights"]
        .as_array_mut()
        .unwrap()
    {
        l.as_object_mut().unwrap().remove("extras");
    }
    let loaded = load(&GltfWriter::glb_of(&doc, &bin)).unwrap();
    assert_eq!(loaded.scene.lighting.units, LightUnits::Photometric);
}
