//! The texture grid (`--grid-storage textures`, `culling/texture_grid.rs`): tiled forward
//! without compute shaders, its grid assigned on the CPU and read with `textureLoad`
//! (tiled-forward-shading §4.2). Its images equal `forward`'s, its grids contain the
//! brute-force oracle, a frame beyond the textures' capacity is refused on both sides of the
//! boundary, and wgpu's GL backend (llvmpipe's OpenGL) renders it as Vulkan renders `forward`
//! while refusing what it cannot run.

mod common;
use common::{ImageTolerance, MissingLight};
use lightgrid::culling::ViewSetup;
use lightgrid::frame::GridStorage;
use lightgrid::gpu::{DeviceLimits, GpuContext};
use lightgrid::pipelines::Assign;
use lightgrid::scene::catalog::{self, SceneParams};
use lightgrid::scene::{LightAnchor, Rng, Scene, SceneLight};
use lightgrid::{RenderSettings, Renderer};

const TEXTURE_GRID: [&str; 2] = ["tiled_forward", "tiled_forward_prez"];

/// Measured: the texture grid's images equal `forward`'s exactly on lavapipe (max 0), as the
/// buffer grid's do; one level of room for round-off elsewhere. A missing light changes at
/// least tens of pixels by more than 2 levels (`assert_missing_light_fails`).
const TOLERANCE: ImageTolerance = ImageTolerance {
    max_mean: 0.05,
    max_p99: 1.0,
    level: 2,
    max_over: 2,
    fine: None,
};

/// The error of a render that must be refused.
fn refusal<T>(r: lightgrid::error::Result<T>) -> String {
    match r {
        Ok(_) => panic!("rendered what must be refused"),
        Err(e) => e.to_string(),
    }
}

fn settings(tile: u32, storage: GridStorage) -> RenderSettings {
    let mut s = RenderSettings::default();
    s.grid.tile_size = tile;
    s.grid_storage = storage;
    s
}

/// Render `id` and `forward` on `r`; the texture grid's image must equal forward's, its grid
/// must be the one the textures held and contain the oracle on the frame's depth.
fn check_against_forward(r: &mut Renderer, s: &Scene, frame: u32, id: &str, what: &str) {
    let (w, h) = r.size();
    let reference = r.render(s, frame, "forward").unwrap();
    let out = r.render(s, frame, id).unwrap();
    let cmp = common::compare_images(&reference.image, &out.image, TOLERANCE);
    assert!(cmp.passes(), "{what}: {}", cmp.describe());
    assert!(
        out.grid_is_pipelines,
        "{what}: analysis reports the texture grid"
    );
    assert_eq!(out.grid.dims.slices, 1, "{what}: the texture grid is tiled");
    let state = s.frame(frame);
    let setup = ViewSetup::new(&state.camera, w, h);
    common::check_grid_contains_oracle(what, &setup, &out.grid, &state.lights, &out.depth);
    let n = out.stats.lighting_computations.expect("lavapipe counts");
    assert!(
        n >= out.stats.ideal_lighting_computations,
        "{what}: below the ideal"
    );
}

#[test]
fn the_texture_grid_renders_as_forward_and_contains_the_oracle() {
    let ctx = common::gpu();
    let cases = [
        ("robots-many", 0, (128, 96), 16),
        ("random-fps", 7, (173, 97), 7),
        ("scattered", 40, (97, 130), 13),
    ];
    for (name, frame, (w, h), tile) in cases {
        let s = catalog::build(name, &SceneParams::default()).unwrap();
        let mut r = Renderer::new(&ctx, w, h, settings(tile, GridStorage::Textures)).unwrap();
        for id in TEXTURE_GRID {
            let what = format!("{name} f{frame} {w}x{h} tile {tile} {id} --grid-storage textures");
            check_against_forward(&mut r, &s, frame, id, &what);
        }
    }
}

/// Lights behind the camera, across the near plane, at the screen's edges, at odd sizes:
/// the CPU assignment the texture grid shares with `--assign cpu` holds there too.
#[test]
fn the_texture_grid_holds_randomized_edge_case_lights() {
    let ctx = common::gpu();
    let mut rng = Rng::new(51);
    for (name, (w, h), tile) in [("random-fps", (97, 61), 13), ("robots-many", (130, 77), 8)] {
        let mut s = catalog::build(name, &SceneParams::default()).unwrap();
        let frame = rng.below(s.frame_count());
        let camera = s.frame(frame).camera;
        let setup = ViewSetup::new(&camera, w, h);
        s.lights = common::edge_case_lights(&mut rng, &camera, &setup, 240)
            .into_iter()
            .map(|light| SceneLight {
                light,
                anchor: LightAnchor::World,
            })
            .collect();
        s.validate().unwrap();
        let mut r = Renderer::new(&ctx, w, h, settings(tile, GridStorage::Textures)).unwrap();
        for id in TEXTURE_GRID {
            let what = format!("{name} f{frame} {w}x{h} tile {tile} {id}, edge-case lights");
            check_against_forward(&mut r, &s, frame, id, &what);
        }
    }
}

/// The comparison's bound catches one missing light (so the equality above proves a grid
/// that lists every light).
#[test]
fn a_missing_light_fails_the_texture_grid_comparison() {
    let ctx = common::gpu();
    let s = catalog::build("robots-many", &SceneParams::default()).unwrap();
    let (size, frame) = ((192, 108), 200);
    let mut r = Renderer::new(&ctx, size.0, size.1, settings(16, GridStorage::Textures)).unwrap();
    for case in MissingLight::ALL {
        let with = common::with_missing_light(&s, frame, size, case);
        let reference = r.render(&with, frame, "forward").unwrap().image;
        let lit = r.render(&with, frame, "tiled_forward_prez").unwrap().image;
        let unlit = r.render(&s, frame, "tiled_forward_prez").unwrap().image;
        common::assert_missing_light_fails(
            "tiled_forward_prez --grid-storage textures",
            case,
            TOLERANCE,
            [&reference, &lit, &unlit],
            None,
        );
    }
}

/// A scene whose every light covers the whole 128x96 frame: each of its 48 tiles lists all
/// `n` lights, `48 n` index entries.
fn covering_lights(n: u32) -> Scene {
    let mut s = catalog::build("robots-many", &SceneParams::default()).unwrap();
    let eye = s.frame(0).camera.eye;
    let keep: Vec<SceneLight> = s.lights.iter().take(1).copied().collect();
    s.lights = (0..n)
        .map(|i| {
            let mut l = keep[0];
            l.light.position = eye + glam::Vec3::new(0.01 * i as f32, 0.0, 0.0);
            l.light.range = 1000.0;
            l.light.intensity *= 0.001;
            l.anchor = LightAnchor::World;
            l
        })
        .collect();
    s.validate().unwrap();
    s
}

/// On a device whose 2D textures are at most 128 texels wide the index texture holds 128² =
/// 16,384 entries: 340 covering lights (16,320 entries) render as `forward`, 342 (16,416)
/// are refused naming the capacity and the limit, never truncated.
#[test]
fn a_frame_beyond_the_textures_capacity_is_refused_on_both_sides_of_the_boundary() {
    let ctx = common::gpu_with(DeviceLimits::WebGpuTextureEdge(128));
    assert_eq!(ctx.max_texture_edge(), 128);
    let mut r = Renderer::new(&ctx, 128, 96, settings(16, GridStorage::Textures)).unwrap();
    let fits = covering_lights(340);
    let out = r.render(&fits, 0, "tiled_forward").unwrap();
    assert_eq!(
        out.grid.indices.len(),
        48 * 340,
        "every tile lists every light"
    );
    check_against_forward(&mut r, &fits, 0, "tiled_forward", "340 covering lights");
    let over = covering_lights(342);
    let e = refusal(r.render(&over, 0, "tiled_forward"));
    for needle in ["16384", "16416", "max_texture_dimension_2d", "grid-storage"] {
        assert!(e.contains(needle), "the refusal names {needle}: {e}");
    }
    // The same frame with the buffer grid renders: the limit is the textures'.
    let mut b = Renderer::new(&ctx, 128, 96, settings(16, GridStorage::Buffers)).unwrap();
    b.render(&over, 0, "tiled_forward").unwrap();
}

/// What the texture grid cannot take is refused naming the setting, and `auto` keeps the
/// buffer grid on an adapter that runs compute (lavapipe).
#[test]
fn the_texture_grid_refuses_what_it_cannot_build_and_auto_keeps_buffers_on_vulkan() {
    let ctx = common::gpu();
    assert!(Renderer::runs_compute(&ctx));
    let s = catalog::build("robots-few", &SceneParams::default()).unwrap();
    let mut auto = Renderer::new(&ctx, 64, 48, settings(16, GridStorage::Auto)).unwrap();
    let labels = |r: &mut Renderer| -> Vec<String> {
        let out = r.render(&s, 0, "tiled_forward_prez").unwrap();
        out.stats.passes.iter().map(|p| p.label.clone()).collect()
    };
    let drawn = "assign: tile depth (fragment)";
    let auto_passes = labels(&mut auto);
    assert!(
        auto_passes.iter().any(|l| l == "assign: cell bounds")
            && !auto_passes.iter().any(|l| l == drawn),
        "auto on Vulkan builds the buffer grid: {auto_passes:?}"
    );
    let mut textures = Renderer::new(&ctx, 64, 48, settings(16, GridStorage::Textures)).unwrap();
    let texture_passes = labels(&mut textures);
    assert!(
        texture_passes.iter().any(|l| l == drawn)
            && !texture_passes.iter().any(|l| l == "assign: cell bounds"),
        "the texture grid draws its tile bounds, no compute: {texture_passes:?}"
    );
    for (what, change) in [
        (
            "--assign other than cpu",
            (|s: &mut RenderSettings| s.grid.strategy = Assign::Gather) as fn(&mut RenderSettings),
        ),
        ("--msaa above 1", |s: &mut RenderSettings| {
            s.grid.samples = 4
        }),
        ("--depth-mask on", |s: &mut RenderSettings| {
            s.grid.depth_mask = lightgrid::frame::DepthMask::On
        }),
    ] {
        let mut set = settings(16, GridStorage::Textures);
        change(&mut set);
        let e = match Renderer::new(&ctx, 64, 48, set) {
            Ok(mut r) => refusal(r.render(&s, 0, "tiled_forward_prez")),
            Err(e) => e.to_string(),
        };
        assert!(
            e.contains("grid-storage") && e.contains(what),
            "{what}: {e}"
        );
    }
}

/// llvmpipe's OpenGL through wgpu's GL backend (`--adapter gl`): `forward` and the texture
/// grid's pipelines (`auto` picks it there) render as Vulkan renders `forward`; what needs
/// compute or MSAA is refused with the reason. Under CI a missing GL adapter fails.
#[test]
fn gl_renders_forward_and_the_texture_grid_as_vulkan_and_refuses_the_rest() {
    let gl = match GpuContext::with_limits(Some("gl"), DeviceLimits::Adapter) {
        Ok(ctx) => ctx,
        Err(e) => panic!("no GL adapter (llvmpipe's OpenGL through EGL): {e}"),
    };
    assert_eq!(gl.info.backend, wgpu::Backend::Gl);
    assert!(!Renderer::runs_compute(&gl));
    let vk = common::gpu();
    let s = catalog::build("robots-many", &SceneParams::default()).unwrap();
    let (w, h) = (128, 96);
    let set = settings(16, GridStorage::Auto);
    let reference = Renderer::new(&vk, w, h, set)
        .unwrap()
        .render(&s, 0, "forward")
        .unwrap();
    let mut r = Renderer::new(&gl, w, h, set).unwrap();
    let gl_forward = r.render(&s, 0, "forward").unwrap();
    for id in ["forward", "tiled_forward", "tiled_forward_prez"] {
        let out = r.render(&s, 0, id).unwrap();
        // Measured at 128x96: GL and Vulkan rasterize a few edge pixels differently
        // (forward against forward: max 5, p99 0); within GL the texture grid equals
        // forward exactly.
        let cmp = common::compare_images(
            &reference.image,
            &out.image,
            ImageTolerance {
                max_p99: 1.0,
                level: 4,
                max_over: 4,
                ..TOLERANCE
            },
        );
        assert!(
            cmp.passes(),
            "GL {id} vs Vulkan forward: {}",
            cmp.describe()
        );
        let same = common::compare_images(&gl_forward.image, &out.image, TOLERANCE);
        assert!(same.passes(), "GL {id} vs GL forward: {}", same.describe());
        if id != "forward" {
            assert!(out.grid_is_pipelines, "GL {id} built the texture grid");
        }
    }
    for (id, msaa, needle) in [
        ("tiled_deferred", 1, "compute"),
        ("clustered_forward", 1, "compute"),
        ("deferred", 1, "depth"),
        ("forward", 4, "MSAA"),
    ] {
        let mut set = settings(16, GridStorage::Auto);
        set.grid.samples = msaa;
        let e = match Renderer::new(&gl, w, h, set) {
            Ok(mut r) => refusal(r.render(&s, 0, id)),
            Err(e) => e.to_string(),
        };
        assert!(
            e.contains(needle) && e.contains("gl"),
            "GL {id} msaa {msaa}: {e}"
        );
    }
    let mut buffers = Renderer::new(&gl, w, h, settings(16, GridStorage::Buffers)).unwrap();
    let e = refusal(buffers.render(&s, 0, "tiled_forward_prez"));
    assert!(e.contains("--grid-storage buffers"), "{e}");
}
