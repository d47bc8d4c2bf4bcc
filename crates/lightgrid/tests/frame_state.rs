//! A frame is data: the renderer takes a scene once (`Renderer::set_scene`, an `Arc` it
//! shares, never copies) and then frames as `FrameState`s. A state with another camera renders
//! what that camera sees (the viewer's fly camera and its analysis worker), a scene whose
//! contents change is uploaded again, and a state the scene cannot render is refused with the
//! reason, leaving the renderer usable.

mod common;

use lightgrid::image_io::diff;
use lightgrid::scene::catalog::{self, SceneParams};
use lightgrid::scene::{CameraPath, Scene};
use lightgrid::{RenderSettings, Renderer};
use std::sync::Arc;

fn scene() -> Scene {
    catalog::build("robots-many", &SceneParams::default()).unwrap()
}

fn max_difference(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    diff(a, b).unwrap().0.max
}

fn mean_difference(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    diff(a, b).unwrap().0.mean
}

#[test]
fn a_state_with_another_camera_renders_what_that_camera_sees() {
    let ctx = common::gpu();
    let scene = Arc::new(scene());
    let mut r = Renderer::new(&ctx, 96, 64, RenderSettings::default()).unwrap();
    r.set_scene(scene.clone()).unwrap();
    assert!(Arc::ptr_eq(r.scene().unwrap(), &scene), "held, not copied");
    let mut state = scene.frame(30);
    let camera = &mut state.camera;
    (camera.eye, camera.target) = (camera.eye + glam::Vec3::new(3.0, 1.0, -2.0), camera.eye);
    let moved = state.camera;
    // The same view as a scene whose camera path holds that camera, rendered afresh.
    let mut held = (*scene).clone();
    held.camera_path = CameraPath {
        keys: vec![
            (0, moved.eye, moved.target),
            (scene.frame_count() - 1, moved.eye, moved.target),
        ],
        ..scene.camera_path.clone()
    };
    let mut fresh = Renderer::new(&ctx, 96, 64, RenderSettings::default()).unwrap();
    for pipeline in ["forward", "tiled_forward_prez", "clustered_deferred"] {
        let a = r.render_state(&state, pipeline).unwrap();
        let b = fresh.render(&held, 30, pipeline).unwrap();
        assert_eq!(max_difference(&a.image, &b.image), 0.0, "{pipeline}");
        assert_eq!(a.stats.lighting_computations, b.stats.lighting_computations);
        // The path's own camera sees something else: the state's camera was used.
        let c = fresh.render(&scene, 30, pipeline).unwrap();
        assert!(mean_difference(&a.image, &c.image) > 1.0, "{pipeline}");
    }
    assert!(Arc::ptr_eq(r.scene().unwrap(), &scene));
}

#[test]
fn a_frame_without_a_scene_is_refused() {
    let ctx = common::gpu();
    let scene = scene();
    let mut r = Renderer::new(&ctx, 32, 32, RenderSettings::default()).unwrap();
    let e = r
        .render_state(&scene.frame(0), "forward")
        .map(|_| ())
        .unwrap_err();
    assert!(e.to_string().contains("set_scene"), "{e}");
    let e = r
        .render_frame(&scene.frame(0), "forward")
        .map(|_| ())
        .unwrap_err();
    assert!(e.to_string().contains("set_scene"), "{e}");
}

#[test]
fn a_state_the_scene_cannot_render_is_refused_and_the_renderer_goes_on() {
    let ctx = common::gpu();
    let scene = Arc::new(scene());
    let mut r = Renderer::new(&ctx, 48, 32, RenderSettings::default()).unwrap();
    r.set_scene(scene.clone()).unwrap();
    let good = scene.frame(10);
    type Change = fn(&mut lightgrid::scene::FrameState);
    let cases: [(Change, &str); 7] = [
        (|s| s.transforms.truncate(1), "object transforms for the"),
        (
            |s| s.transforms.push(glam::Mat4::IDENTITY),
            "object transforms for the",
        ),
        (
            |s| s.transforms[3].w_axis.y = f32::NAN,
            "object 3's transform is not finite",
        ),
        (|s| s.camera.eye.x = f32::NAN, "camera"),
        (|s| s.camera.target = s.camera.eye, "no view direction"),
        (|s| s.camera.near = -1.0, "0 < near < far"),
        (|s| s.lights[2].range = f32::NAN, "light 2"),
    ];
    for (change, want) in cases {
        let mut state = good.clone();
        change(&mut state);
        for e in [
            r.render_state(&state, "tiled_forward")
                .map(|_| ())
                .unwrap_err(),
            r.render_frame(&state, "tiled_forward")
                .map(|_| ())
                .unwrap_err(),
        ] {
            assert!(e.to_string().contains(want), "{want}: {e}");
        }
    }
    let after = r.render_state(&good, "tiled_forward").unwrap();
    let mut fresh = Renderer::new(&ctx, 48, 32, RenderSettings::default()).unwrap();
    let before = fresh.render(&scene, 10, "tiled_forward").unwrap();
    assert_eq!(max_difference(&after.image, &before.image), 0.0);
}

#[test]
fn a_scene_whose_contents_change_is_uploaded_again() {
    let ctx = common::gpu();
    let first = scene();
    let mut r = Renderer::new(&ctx, 96, 64, RenderSettings::default()).unwrap();
    let a = r.render(&first, 5, "tiled_forward").unwrap();
    // Every material brighter and one static object moved: static geometry and materials.
    let mut second = first.clone();
    for m in &mut second.materials {
        m.diffuse *= 0.3;
    }
    let i = second.objects.iter().position(|o| o.is_static()).unwrap();
    second.objects[i].local.w_axis.y += 0.5;
    let b = r.render(&second, 5, "tiled_forward").unwrap();
    let mut fresh = Renderer::new(&ctx, 96, 64, RenderSettings::default()).unwrap();
    let want = fresh.render(&second, 5, "tiled_forward").unwrap();
    assert_eq!(max_difference(&b.image, &want.image), 0.0);
    assert!(mean_difference(&a.image, &b.image) > 1.0);
    // And back: the first scene again, as a fresh renderer draws it.
    let again = r.render(&first, 5, "tiled_forward").unwrap();
    assert_eq!(max_difference(&again.image, &a.image), 0.0);
}

/// A scene given from Rust whose indices do not hold is refused by `set_scene` with the
/// reason (never a panic while baking it), and the renderer then renders nothing until a
/// good scene comes.
#[test]
fn a_scene_whose_indices_do_not_hold_is_refused() {
    let ctx = common::gpu();
    let good = scene();
    let mut r = Renderer::new(&ctx, 32, 32, RenderSettings::default()).unwrap();
    type Break = fn(&mut Scene);
    let cases: [(Break, &str); 4] = [
        (|s| s.objects[0].material = 10_000, "missing material"),
        (|s| s.objects[0].mesh = 10_000, "missing mesh"),
        (|s| s.meshes[0].indices[0] = u32::MAX, "index out of range"),
        (|s| s.meshes[0].normals.truncate(1), "normals"),
    ];
    for (damage, want) in cases {
        let mut bad = good.clone();
        damage(&mut bad);
        let e = r.set_scene(Arc::new(bad.clone())).unwrap_err();
        assert!(e.to_string().contains(want), "{want}: {e}");
        assert!(r.scene().is_none());
        let e = r.render(&bad, 0, "forward").map(|_| ()).unwrap_err();
        assert!(e.to_string().contains(want), "{want}: {e}");
    }
    r.set_scene(Arc::new(good.clone())).unwrap();
    r.render_state(&good.frame(0), "forward").unwrap();
}
