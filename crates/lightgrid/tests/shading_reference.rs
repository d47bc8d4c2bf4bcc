//! `forward`, the reference every pipeline is compared with, checked against a shading
//! reference it did not produce: a CPU ray caster and the light function written here from
//! the papers' formulas and the shaders' documented contract (Blinn-Phong from a point or spot
//! light with a finite range, tiled-shading §1.1: the window (1 - (d/r)²)², a smoothstep
//! between a spot's outer and inner cones; the material shaders' grazing terms; the ambient
//! and emissive base; glass blended back to front over the opaque colour; the tone curve
//! 1 - e^(-x·exposure); sRGB encoding), not generated from the WGSL.
//!
//! At sampled pixels whose surface is unambiguous (the rays a third of a pixel around the
//! centre meet the same triangles, no second surface within 0.1 % of the depth, not a
//! texture), every channel of `forward`, `forward_mono` and `forward_mono_albedo` must be
//! within one level of the reference, on every catalog scene (with spots and headlights, every
//! material shader and the glass), on the test glTF room and on a catalog scene exported to
//! GLB and loaded back. A plane under one light, worked out by hand, checks the reference
//! itself.

mod common;

use common::shading::{check, display, Frame, Model};
use glam::Vec3;
use lightgrid::consts::SCENE_AMBIENT;
use lightgrid::scene::catalog::{self, SceneParams};
use lightgrid::scene::{CameraPath, Light, Material, Mesh, Object, Scene, SceneLight};
use lightgrid::{RenderSettings, Renderer};

#[test]
fn forward_equals_the_reference_on_every_catalog_scene() {
    let ctx = common::gpu();
    let (mut glass, mut shaders) = (0, [0; 3]);
    for info in catalog::SCENES {
        let name = info.name;
        let params = SceneParams {
            spot_fraction: 0.3,
            headlights: info.robots,
            lights: info.variable_lights.then_some(300),
            ..Default::default()
        };
        let scene = catalog::build(name, &params).unwrap();
        let frame = scene.frame_count() / 3;
        let c = check(&ctx, &scene, frame, (160, 96), 5);
        eprintln!("{name} frame {frame}: {c:?}");
        assert!(c.pixels >= 150, "{name}: too few clean pixels: {c:?}");
        assert!(c.lit * 4 >= c.pixels, "{name}: too few lit pixels: {c:?}");
        glass += c.glass;
        for (all, n) in shaders.iter_mut().zip(c.shaders) {
            *all += n;
        }
    }
    // Every material shader and the glass were among the pixels checked.
    assert!(
        glass > 0 && shaders.iter().all(|&n| n > 0),
        "glass {glass}, shaders {shaders:?}"
    );
}

#[test]
fn forward_equals_the_reference_on_a_gltf_room() {
    let ctx = common::gpu();
    let bytes = common::gltf_fixture::room().glb();
    let opts = lightgrid::scene::gltf::LoadOptions::default();
    let scene = lightgrid::scene::gltf::load_bytes(&bytes, "room.glb", None, &opts)
        .unwrap()
        .scene;
    for frame in [0, scene.frame_count() / 2] {
        let c = check(&ctx, &scene, frame, (160, 96), 4);
        eprintln!("room frame {frame}: {c:?}");
        assert!(c.pixels >= 150 && c.lit * 4 >= c.pixels, "{c:?}");
        assert!(c.glass > 0, "no pixel behind the room's glass: {c:?}");
    }
}

/// The second glTF file: a catalog scene with spots and headlights written as GLB by
/// `gltf::export` and read back, so the importer's path (nodes, materials from `extras`,
/// KHR_lights_punctual spots, the exported camera) feeds the frame the reference checks.
#[test]
fn forward_equals_the_reference_on_an_exported_and_loaded_scene() {
    let ctx = common::gpu();
    let params = SceneParams {
        spot_fraction: 0.3,
        headlights: true,
        ..Default::default()
    };
    let original = catalog::build("robots-few", &params).unwrap();
    let bytes = lightgrid::scene::gltf::export(&original, 120, (160, 96)).unwrap();
    let opts = lightgrid::scene::gltf::LoadOptions::default();
    let scene = lightgrid::scene::gltf::load_bytes(&bytes, "robots-few.glb", None, &opts)
        .unwrap()
        .scene;
    let c = check(&ctx, &scene, 0, (160, 96), 4);
    eprintln!("exported robots-few: {c:?}");
    assert!(c.pixels >= 150 && c.lit * 4 >= c.pixels, "{c:?}");
}

/// A plane under one light, worked out by hand: the reference (and `forward`) at three
/// points against the formulas written out.
#[test]
fn a_plane_under_one_light_has_the_radiance_worked_out_by_hand() {
    let ctx = common::gpu();
    const EYE: Vec3 = Vec3::new(0.0, 10.0, 4.0);
    let (height, range, intensity) = (2.0f32, 5.0f32, 3.0f32);
    let material = Material::plain(Vec3::new(0.8, 0.5, 0.2), 0.25, 16.0);
    let light = Light::point(Vec3::new(0.0, height, 0.0), Vec3::ONE, intensity, range);
    let scene = Scene {
        name: "plane".into(),
        meshes: vec![Mesh::ground(-20.0, -20.0, 20.0, 20.0, 0.0)],
        materials: vec![material],
        objects: vec![Object {
            mesh: 0,
            material: 0,
            local: glam::Mat4::IDENTITY,
            motion: lightgrid::scene::Motion::Static,
        }],
        paths: vec![],
        lights: vec![SceneLight {
            light,
            anchor: lightgrid::scene::LightAnchor::World,
        }],
        textures: vec![],
        // Looking down at the point under the light from above and to the side.
        camera_path: CameraPath::fixed(EYE, Vec3::ZERO, 40.0, 0.1, 100.0),
        default_size: (64, 64),
    };
    let f = Frame::new(&scene, 0, (64, 64));
    let mut r = Renderer::new(&ctx, 64, 64, RenderSettings::default()).unwrap();
    let image = r.render(&scene, 0, "forward").unwrap().image;
    // At the ground point p under pixel (px, py): the light at distance d, the eye at e.
    let clean: Vec<(u32, u32)> = [
        (20u32, 40u32),
        (40, 24),
        (50, 12),
        (28, 30),
        (36, 44),
        (12, 20),
    ]
    .into_iter()
    .filter(|&(x, y)| f.reference(x, y, Model::Full).is_some())
    .collect();
    assert!(clean.len() >= 3, "{clean:?}");
    for (px, py) in clean {
        let d = f.ray(f64::from(px) + 0.5, f64::from(py) + 0.5);
        let eye = EYE;
        let t = f64::from(eye.y) / -d.y;
        let p = eye + (d * t).as_vec3();
        let to_light = Vec3::new(0.0, height, 0.0) - p;
        let dist = to_light.length();
        let l = to_light / dist;
        let v = (eye - p).normalize();
        let n_dot_l = l.y;
        let window = (1.0 - (dist / range).powi(2)).powi(2);
        let h = (l + v).normalize();
        let radiance = intensity * window;
        let by_hand = material.ambient * SCENE_AMBIENT
            + material.diffuse * radiance * n_dot_l
            + material.specular * radiance * h.y.powf(material.shininess) * n_dot_l;
        let (reference, _) = f.reference(px, py, Model::Full).unwrap();
        assert!(
            (reference - by_hand).abs().max_element() < 1e-4 * by_hand.max_element().max(1.0),
            "({px}, {py}): reference {reference}, by hand {by_hand}"
        );
        let want = display(by_hand);
        let got = image.get_pixel(px, py).0;
        for c in 0..3 {
            assert!(
                got[c].abs_diff(want[c]) <= 1,
                "({px}, {py}): forward {:?}, by hand {want:?}",
                &got[..3]
            );
        }
    }
    // The point under the light is lit brightly; the window is zero beyond the range.
    assert!(display(Vec3::splat(intensity))[0] > 200);
}
