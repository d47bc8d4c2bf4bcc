//! glTF files against the CPU reference that reads them itself (`common::file_reference`:
//! its own reader and the specification's definitions, in f64): the reference against values
//! worked out by hand, then `forward` against the reference on the test room and on metals
//! rough and smooth under a spot and a light below a scaled parent. Importing α = roughness
//! (not roughness²), a spot's cone other than `t²`, candela in other units or a node's
//! transform dropped makes these fail.

mod common;

use common::file_reference::{self, FileReference};
use common::gltf_fixture::{cube, room, GltfWriter};
use glam::{DVec3, Quat};
use lightgrid::scene::source::{self, FileContents, SceneRequest};
use lightgrid::scene::Scene;
use lightgrid::{RenderSettings, Renderer};
use serde_json::json;

/// The file as lightgrid opens it, with the exposure `exposure` (so the automatic
/// exposure's rule stays out of the comparison).
fn open(glb: &[u8], exposure: f32) -> Scene {
    let req = SceneRequest {
        exposure: Some(exposure),
        contents: Some(FileContents(std::sync::Arc::from(glb))),
        ..SceneRequest::new("file.glb")
    };
    source::open(&req).unwrap().scene
}

fn forward(scene: &Scene, (w, h): (u32, u32)) -> image::RgbaImage {
    let ctx = common::gpu();
    let mut r = Renderer::new(&ctx, w, h, RenderSettings::default()).unwrap();
    r.render(scene, 0, "forward").unwrap().image
}

/// A 20 m ground of `ground` (a material index; its diagonal off the origin, which the camera
/// looks at), seen straight down from 5 m, the light `light` pointing down 1 m above the
/// origin in a parent scaled `lift` (so `lift` m up), and the boxes `boxes` (material,
/// position) on the ground.
fn stage(
    w: &mut GltfWriter,
    ground: usize,
    light: serde_json::Value,
    lift: f32,
    boxes: &[(usize, [f32; 3])],
) {
    let g = w.mesh(
        &[
            -10.0, 0.0, -9.0, 10.0, 0.0, -9.0, 10.0, 0.0, 11.0, -10.0, 0.0, 11.0,
        ],
        Some(&[0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0]),
        Some(&[0, 2, 1, 0, 3, 2]),
        Some(ground),
        4,
    );
    let mut roots = vec![w.node(json!({"mesh": g}))];
    let (cp, cn, ci) = cube();
    for &(m, at) in boxes {
        let mesh = w.mesh(&cp, Some(&cn), Some(&ci), Some(m), 4);
        roots.push(w.node(json!({"mesh": mesh, "translation": at, "scale": [0.8, 0.8, 0.8]})));
    }
    let l = w.light(light);
    let down = Quat::from_rotation_x(-90f32.to_radians()).to_array();
    let light = w.node(json!({"translation": [0.0, 1.0, 0.0], "rotation": down,
        "extensions": {"KHR_lights_punctual": {"light": l}}}));
    roots.push(w.node(json!({"scale": [lift, lift, lift], "children": [light]})));
    w.cameras.push(
        json!({"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "zfar": 50.0}}),
    );
    roots.push(w.node(json!({"camera": 0, "translation": [0.0, 5.0, 0.0], "rotation": down})));
    w.roots = roots;
}

/// A point light of `candela`, range 8.
fn point(candela: f32) -> serde_json::Value {
    json!({"type": "point", "color": [1.0, 1.0, 1.0], "intensity": candela, "range": 8.0})
}

#[test]
fn the_files_reference_gives_the_values_worked_out_by_hand() {
    // Straight below the light and the camera, n = v = l = h: D = 1/(πα²), V = 1/4 and
    // F = F0, so glTF's BRDF is (1 − F0) c_diff/π + F0/(4πα²); the light `lift` m up (1 m
    // under a parent scaled `lift`) gives I/lift² windowed by (1 − (lift/8)⁴)².
    let (candela, exposure) = (10.0, 0.5);
    let pi = std::f64::consts::PI;
    let base = DVec3::new(0.9, 0.6, 0.3);
    for (metallic, roughness, lift) in [
        (1.0, 0.5, 2.0),
        (1.0, 1.0, 2.0),
        (0.0, 1.0, 2.0),
        (0.0, 0.4, 3.0),
        (1.0, 0.3, 4.5),
    ] {
        let d = f64::from(lift);
        let window = (1.0 - (d / 8.0).powi(4)).powi(2);
        let e = f64::from(candela) / (d * d) * window;
        let mut w = GltfWriter::default();
        let m = w.material(
            json!({"pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.6, 0.3, 1.0],
            "metallicFactor": metallic, "roughnessFactor": roughness}}),
        );
        stage(&mut w, m, point(candela), lift, &[]);
        let glb = w.glb();
        let alpha = roughness * roughness;
        let f0 = DVec3::splat(0.04).lerp(base, metallic);
        let brdf =
            (DVec3::ONE - f0) * base * (1.0 - metallic) / pi + f0 / (4.0 * pi * alpha * alpha);
        let by_hand = brdf * e * f64::from(exposure) + base * 0.04;
        let size = (65, 65);
        let reference = FileReference::new(&glb, size, f64::from(exposure));
        let got = reference
            .radiance(32, 32)
            .expect("the centre is unambiguous");
        assert!(
            (got - by_hand).abs().max_element() < 1e-6 * by_hand.max_element(),
            "metallic {metallic}, roughness {roughness}: the reference {got}, by hand {by_hand}"
        );
        let image = forward(&open(&glb, exposure), size);
        let want = file_reference::display(by_hand);
        let px = image.get_pixel(32, 32).0;
        assert!(
            (0..3).all(|c| px[c].abs_diff(want[c]) <= 1),
            "metallic {metallic}, roughness {roughness}: forward {:?}, by hand {want:?}",
            &px[..3]
        );
    }
}

/// A spot is its point light inside the inner cone and dark outside the outer one: the
/// reference's radiance with a spot (inner 0.3 rad, outer 0.5) equals the point light's at
/// every ground pixel more than 0.02 rad inside the inner cone, and the ambient term alone
/// more than 0.02 rad outside the outer one; `forward` equals the reference there too.
#[test]
fn the_files_reference_lights_a_spot_as_its_cones_say() {
    let (size, exposure) = ((65, 65), 0.5);
    let base = DVec3::new(0.9, 0.6, 0.3);
    let scene = |light: serde_json::Value| {
        let mut w = GltfWriter::default();
        let m = w.material(
            json!({"pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.6, 0.3, 1.0],
            "metallicFactor": 0.0, "roughnessFactor": 0.7}}),
        );
        stage(&mut w, m, light, 2.0, &[]);
        w.glb()
    };
    let mut spot = point(10.0);
    spot["type"] = json!("spot");
    spot["spot"] = json!({"innerConeAngle": 0.3, "outerConeAngle": 0.5});
    let spot = scene(spot);
    let (with_spot, with_point) = (
        FileReference::new(&spot, size, exposure),
        FileReference::new(&scene(point(10.0)), size, exposure),
    );
    let (mut inside, mut outside) = (0, 0);
    for py in 0..size.1 {
        for px in 0..size.0 {
            let (Some(s), Some(p)) = (with_spot.radiance(px, py), with_point.radiance(px, py))
            else {
                continue;
            };
            // The ground point's angle from the spot's axis, 2 m above the origin.
            let d = with_spot.ray(f64::from(px) + 0.5, f64::from(py) + 0.5);
            let ground = DVec3::new(0.0, 5.0, 0.0) + d * (5.0 / -d.y);
            let theta = (ground.x.hypot(ground.z) / 2.0).atan();
            if theta < 0.28 {
                assert!(
                    (s - p).abs().max_element() < 1e-12,
                    "({px}, {py}): {s} against {p}"
                );
                inside += 1;
            } else if theta > 0.52 {
                assert!(
                    (s - base * 0.04).abs().max_element() < 1e-12,
                    "({px}, {py}): {s}"
                );
                outside += 1;
            }
        }
    }
    assert!(
        inside > 200 && outside > 200,
        "{inside} inside, {outside} outside"
    );
    let image = forward(&open(&spot, exposure as f32), size);
    assert!(file_reference::compare(&with_spot, &image, 1, 1) > 3000);
}

#[test]
fn forward_equals_the_files_reference_on_metals_rough_and_smooth() {
    let mut w = GltfWriter::default();
    let ground = w.material(
        json!({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.0],
        "metallicFactor": 0.0, "roughnessFactor": 0.6}}),
    );
    let metal = |w: &mut GltfWriter, roughness: f32| {
        w.material(
            json!({"pbrMetallicRoughness": {"baseColorFactor": [0.95, 0.7, 0.35, 1.0],
            "metallicFactor": 1.0, "roughnessFactor": roughness}}),
        )
    };
    let (smooth, middle, rough) = (metal(&mut w, 0.25), metal(&mut w, 0.5), metal(&mut w, 0.9));
    stage(
        &mut w,
        ground,
        point(12.0),
        2.0,
        &[
            (smooth, [-1.3, 0.4, 0.3]),
            (middle, [0.0, 0.4, -1.2]),
            (rough, [1.3, 0.4, 0.4]),
        ],
    );
    // A spot aimed down past the boxes (a rotation of -90° about x turns -z into -y).
    let s = w.light(
        json!({"type": "spot", "color": [0.6, 0.8, 1.0], "intensity": 25.0, "range": 7.0,
        "spot": {"innerConeAngle": 0.25, "outerConeAngle": 0.55}}),
    );
    let down = Quat::from_rotation_x(-90f32.to_radians()).to_array();
    let spot = w.node(json!({"translation": [0.6, 3.0, 1.2], "rotation": down,
        "extensions": {"KHR_lights_punctual": {"light": s}}}));
    w.roots.push(spot);
    let glb = w.glb();
    let (size, exposure) = ((128, 96), 0.8);
    let image = forward(&open(&glb, exposure), size);
    if std::env::var_os("LIGHTGRID_KEEP_IMAGES").is_some() {
        image
            .save(common::output_dir().join("file-reference-metals.png"))
            .unwrap();
    }
    let reference = FileReference::new(&glb, size, f64::from(exposure));
    let checked = file_reference::compare(&reference, &image, 1, 1);
    assert!(checked > 8000, "{checked} pixels checked");
}

#[test]
fn forward_equals_the_files_reference_on_the_room() {
    // The room's glass is left out of the comparison (pixels behind it are skipped), its
    // alpha-tested cube is drawn by neither (its alpha is under the cutoff).
    let glb = room().glb();
    let (size, exposure) = ((160, 100), 1.5);
    let image = forward(&open(&glb, exposure), size);
    let reference = FileReference::new(&glb, size, f64::from(exposure));
    let checked = file_reference::compare(&reference, &image, 1, 1);
    assert!(checked > 8000, "{checked} pixels checked");
}
