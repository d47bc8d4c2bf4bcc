//! GPU: every registry pipeline's image equals the `forward` reference within its stated
//! tolerance, on two catalog scenes, two tile sizes and a resolution that is not a multiple
//! of the tile size; lighting-computation counts are never below the ideal; every light
//! assignment strategy (CPU, GPU gather, scatter, BVH) builds, on every grid pipeline, the grid
//! its CPU twin builds from the same cell bounds, and the GPU cell bounds equal their twin's.

mod common;

use lightgrid::culling::{
    assign_cpu, assign_gather_cpu, cell_bounds_cpu, DepthRange, LightGrid, ViewSetup,
};
use lightgrid::image_io::{diff, save_png};
use lightgrid::passes::GBufferFormat;
use lightgrid::pipelines::Assign;
use lightgrid::pipelines::{PipelineInfo, PIPELINES, REFERENCE};
use lightgrid::scene::catalog::{self, SceneParams};
use lightgrid::scene::{PointLight, Scene};
use lightgrid::{RenderSettings, Renderer};

/// Per-pipeline tolerance against `forward`, in 8-bit sRGB levels: (id, max mean, max p99,
/// why). Every registry row must have one.
const TOLERANCES: &[(&str, f64, f64, &str)] = &[
    (
        "tiled_forward",
        0.01,
        1.0,
        "same fragments and light order as forward; unlisted lights contribute exactly zero, so \
         lavapipe is bit-identical; one level allows other drivers' reassociation",
    ),
    (
        "tiled_forward_prez",
        0.01,
        1.0,
        "as tiled_forward (the pre-pass uses the same invariant vertex stage), except single \
         pixels on an edge shared by two faces at exactly equal depth, where LessEqual keeps the \
         face drawn last and forward's Less the one drawn first (affects max, not p99)",
    ),
    (
        "tiled_deferred",
        0.1,
        2.0,
        "16-bit G-buffer normals and colours, and positions rebuilt from depth instead of interpolated",
    ),
    ("tiled_deferred_single", 0.1, 2.0, "as tiled_deferred"),
    ("clustered_forward", 0.01, 1.0, "as tiled_forward_prez: same fragments, each cluster list holds every light reaching its samples"),
    ("clustered_deferred", 0.1, 2.0, "as tiled_deferred"),
    (
        "deferred",
        0.5,
        2.0,
        "16-bit G-buffer, positions rebuilt from depth, and per-light additive blending into the \
         16-bit HDR target (forward sums in 32-bit registers): where many lights overlap the \
         rounding of each blend shifts many pixels by one level (measured: mean 0.36, max 1)",
    ),
    ("deferred_stencil", 0.5, 2.0, "as deferred"),
    (
        "light_prepass",
        0.5,
        2.0,
        "positions rebuilt from depth, and diffuse and specular irradiance summed by 16-bit \
         blending before the material multiplies them",
    ),
    ("light_prepass_mono", 0.5, 2.0, "as light_prepass, against forward_mono (the same monochrome-specular model)"),
];

fn tolerance(id: &str) -> (f64, f64) {
    let row = TOLERANCES
        .iter()
        .find(|t| t.0 == id)
        .unwrap_or_else(|| panic!("pipeline {id} has no row in TOLERANCES"));
    (row.1, row.2)
}

/// A pipeline that is its own reference (`forward`, `forward_mono`).
fn is_reference(p: &PipelineInfo) -> bool {
    p.reference == p.id
}

fn check_scene(scene: &str, frame: u32, size: (u32, u32), settings: RenderSettings) {
    let s = catalog::build(scene, &SceneParams::default()).unwrap();
    check(&s, frame, size, settings);
}

fn check(s: &lightgrid::scene::Scene, frame: u32, (w, h): (u32, u32), settings: RenderSettings) {
    let ctx = common::gpu();
    let scene = &s.name;
    let mut r = Renderer::new(&ctx, w, h, settings).unwrap();
    let mut references = std::collections::HashMap::new();
    for p in PIPELINES.iter().filter(|p| is_reference(p)) {
        references.insert(p.id, r.render(s, frame, p.id).unwrap());
    }
    let reference = &references[REFERENCE];
    let ideal = reference.stats.ideal_lighting_computations;
    assert!(
        ideal > 0,
        "{scene}: nothing lit, the comparison would prove nothing"
    );
    let forward_count = reference
        .stats
        .lighting_computations
        .expect("lavapipe counts");
    assert!(forward_count >= ideal);
    let mut counts = std::collections::HashMap::new();
    for p in PIPELINES.iter().filter(|p| !is_reference(p)) {
        let out = r.render(s, frame, p.id).unwrap();
        let (max_mean, max_p99) = tolerance(p.id);
        let expected = &references[p.reference];
        let (d, vis) = diff(&expected.image, &out.image).unwrap();
        let name = format!("{scene}-f{frame}-{w}x{h}-t{}-{}", settings.tile_size, p.id);
        if d.mean > max_mean || d.p99 > max_p99 {
            let dir = common::output_dir();
            save_png(&out.image, &dir.join(format!("actual-{name}.png"))).unwrap();
            save_png(&expected.image, &dir.join(format!("reference-{name}.png"))).unwrap();
            save_png(&vis, &dir.join(format!("diff-{name}.png"))).unwrap();
            panic!(
                "{name}: mean {:.4} p99 {} max {} vs {} (allowed {max_mean}/{max_p99})",
                d.mean, d.p99, d.max, p.reference
            );
        }
        let st = &out.stats;
        assert_eq!(
            st.ideal_lighting_computations, ideal,
            "{name}: the ideal depends on the scene only"
        );
        let n = st.lighting_computations.expect("lavapipe counts");
        assert!(
            n >= ideal,
            "{name}: {n} lighting computations, below the ideal {ideal}"
        );
        assert!(
            n <= forward_count,
            "{name}: culling did more work than brute force"
        );
        if out.grid_is_pipelines {
            assert_eq!(out.grid.dims.tile_size, settings.tile_size);
            assert_eq!(st.lights_per_tile_max, Some(out.grid.max_lights_per_cell()));
        }
        let m = (p.memory)(&settings);
        assert_eq!(st.memory.bytes_per_pixel, m.bytes_per_pixel());
        assert_eq!(
            st.memory.target_bytes,
            u64::from(m.bytes_per_pixel()) * u64::from(w) * u64::from(h)
        );
        counts.insert(p.id, n);
    }
    // Depth bounds can only remove work (tiled-shading Fig. 3).
    assert!(counts["tiled_forward_prez"] <= counts["tiled_forward"]);
    // Pre-Z forward shades each visible sample with the same grid as tiled deferred; only
    // coplanar fragments passing the LessEqual test twice can add to it.
    let (prez, deferred) = (counts["tiled_forward_prez"], counts["tiled_deferred"]);
    assert!(
        prez >= deferred && prez as f64 <= deferred as f64 * 1.01,
        "prez {prez} vs deferred {deferred}"
    );
    // Clusters are tiles cut by depth slices (and clipped to the tiles' depth bounds): never
    // more lights per sample than the depth-bounded tiles.
    assert!(counts["clustered_forward"] <= counts["tiled_forward_prez"]);
    assert!(counts["clustered_deferred"] <= counts["tiled_deferred"]);
    // The stencil test culls per sample: never more work than the plain volumes.
    assert!(counts["deferred_stencil"] <= counts["deferred"]);
    // Deferred lighting runs the light function on the same volume fragments as deferred.
    assert_eq!(counts["light_prepass"], counts["deferred"]);
    assert_eq!(counts["light_prepass_mono"], counts["deferred"]);
}

fn settings(tile_size: u32) -> RenderSettings {
    RenderSettings {
        tile_size,
        ..Default::default()
    }
}

#[test]
fn robots_many_tile_16() {
    check_scene("robots-many", 200, (160, 90), settings(16));
}

#[test]
fn deferred_stencil_culls_more_than_deferred_on_robots_many() {
    let ctx = common::gpu();
    let s = catalog::build("robots-many", &SceneParams::default()).unwrap();
    let mut r = Renderer::new(&ctx, 160, 90, settings(16)).unwrap();
    let plain = r.render(&s, 200, "deferred").unwrap().stats;
    let stencil = r.render(&s, 200, "deferred_stencil").unwrap().stats;
    let (p, st) = (
        plain.lighting_computations.unwrap(),
        stencil.lighting_computations.unwrap(),
    );
    assert!(st < p, "stencil {st} vs plain {p}");
    assert!(st >= stencil.ideal_lighting_computations);
}

#[test]
fn light_volumes_crossing_the_near_and_far_planes() {
    // A far plane of 45 puts the range-40 robots-few lights across both clip planes (drawn
    // full screen), across the far plane only (front faces, and no stencil), or containing
    // the camera (back faces).
    let mut s = catalog::build("robots-few", &SceneParams::default()).unwrap();
    s.camera_path.far = 45.0;
    let state = s.frame(200);
    let setup = ViewSetup::new(&state.camera, 160, 90);
    let classes = lightgrid::passes::classify_lights(&setup, &state.lights, false);
    assert!(
        !classes.full.is_empty() || !classes.back.is_empty(),
        "{classes:?}"
    );
    check(&s, 200, (160, 90), settings(16));
}

#[test]
fn robots_many_tile_7_odd_resolution() {
    check_scene("robots-many", 120, (150, 86), settings(7));
}

#[test]
fn robots_few_tile_32_odd_resolution_camera_inside_light_volumes() {
    // Range-40 lights around the walking robots: the street-level camera sits inside several.
    let s = catalog::build("robots-few", &SceneParams::default()).unwrap();
    let state = s.frame(200);
    let inside = state
        .lights
        .iter()
        .filter(|l| l.position.distance(state.camera.eye) < l.range)
        .count();
    assert!(inside >= 2, "camera inside only {inside} light volumes");
    check_scene("robots-few", 200, (170, 100), settings(32));
}

#[test]
fn random_fps_tile_16_with_32_bit_gbuffer() {
    check_scene(
        "random-fps",
        30,
        (160, 96),
        RenderSettings {
            tile_size: 16,
            gbuffer: GBufferFormat::F32,
            slices: 24,
            assign: Default::default(),
        },
    );
}

/// The grid a strategy's CPU twin builds from the given cell bounds.
fn twin(
    assign: Assign,
    setup: &ViewSetup,
    grid: &LightGrid,
    lights: &[PointLight],
    bounds: &[[f32; 2]],
    near_far: bool,
) -> LightGrid {
    let dims = &grid.dims;
    match assign {
        Assign::Cpu | Assign::Scatter if near_far => {
            assign_cpu(setup, dims, lights, DepthRange::NearFar)
        }
        Assign::Cpu | Assign::Scatter => assign_cpu(setup, dims, lights, DepthRange::Cells(bounds)),
        Assign::Gather | Assign::Bvh | Assign::BvhGpu => {
            assign_gather_cpu(setup, dims, lights, bounds)
        }
        Assign::Auto => unreachable!("resolved by the renderer"),
    }
}

fn with_ranges_scaled(lights: &[PointLight], f: f32) -> Vec<PointLight> {
    lights
        .iter()
        .map(|l| PointLight {
            range: l.range * f,
            ..*l
        })
        .collect()
}

/// Render `id` with `settings` and check its grid against the CPU twin of the strategy that
/// built it, fed with the pipeline's own cell bounds: equal for the CPU strategy; for GPU
/// strategies every cell's set lies between the twin's with all light ranges 0.1% smaller and
/// 0.1% larger (f32 round-off of the view transform and frustum planes differs between the GPU
/// and the CPU), and differs from the exact twin in at most a handful of (cell, light) pairs.
/// Also: the GPU cell bounds equal `cell_bounds_cpu` of the frame's depth, the grid is well
/// formed, the image matches the reference and the count is never below the ideal.
fn check_assign(
    r: &mut Renderer,
    s: &Scene,
    frame: u32,
    id: &str,
    reference: &image::RgbaImage,
) -> LightGrid {
    let (w, h) = r.size();
    let out = r.render(s, frame, id).unwrap();
    let state = s.frame(frame);
    let setup = ViewSetup::new(&state.camera, w, h);
    let assign = r.settings().assign;
    assert_ne!(
        assign,
        Assign::Auto,
        "check_assign takes an explicit strategy"
    );
    let what = format!("{} {id} --assign {} {w}x{h}", s.name, assign.name());
    assert_eq!(out.stats.assign.as_deref(), Some(assign.name()), "{what}");
    let bounds = out
        .cell_bounds
        .clone()
        .expect("a grid pipeline reports its cell bounds");
    let grid = &out.grid;
    let dims = grid.dims;
    let near_far = id == "tiled_forward";
    // Cell bounds: the GPU kernel against its twin on the same depth buffer.
    if !near_far {
        let cpu = cell_bounds_cpu(&setup, &dims, &out.depth);
        let mut emptiness = 0;
        for (c, (g, b)) in bounds.iter().zip(&cpu).enumerate() {
            match (g[0] <= g[1], b[0] <= b[1]) {
                (true, true) => assert!(
                    (g[0] - b[0]).abs() <= 1e-5 * b[0] && (g[1] - b[1]).abs() <= 1e-5 * b[1],
                    "{what}: cell {c} bounds {g:?} vs twin {b:?}"
                ),
                (false, false) => {}
                _ => emptiness += 1, // a sample within round-off of a slice boundary
            }
        }
        assert!(
            emptiness <= 2,
            "{what}: {emptiness} cells differ in occupancy"
        );
        assert!(
            bounds.iter().any(|b| b[0] <= b[1]),
            "{what}: no cell holds samples"
        );
        if dims.slices > 1 {
            assert!(
                bounds.iter().any(|b| b[0] > b[1]),
                "{what}: every cluster occupied"
            );
        }
    }
    // Well formed: counts add up, lists inside the index array, no light twice in a cell.
    let total: u64 = grid.cells.iter().map(|c| u64::from(c[1])).sum();
    assert_eq!(total, grid.indices.len() as u64, "{what}");
    let mut sets = Vec::with_capacity(grid.cells.len());
    for c in 0..grid.cells.len() {
        let mut list = grid.cell(c).to_vec();
        list.sort_unstable();
        let n = list.len();
        list.dedup();
        assert_eq!(n, list.len(), "{what}: cell {c} lists a light twice");
        sets.push(list);
    }
    let exact = twin(assign, &setup, grid, &state.lights, &bounds, near_far);
    if assign == Assign::Cpu {
        assert_eq!(grid, &exact, "{what}");
    } else {
        let lo = twin(
            assign,
            &setup,
            grid,
            &with_ranges_scaled(&state.lights, 0.999),
            &bounds,
            near_far,
        );
        let hi = twin(
            assign,
            &setup,
            grid,
            &with_ranges_scaled(&state.lights, 1.001),
            &bounds,
            near_far,
        );
        let mut differing = 0;
        for (c, set) in sets.iter().enumerate() {
            assert!(
                lo.cell(c).iter().all(|l| set.binary_search(l).is_ok()),
                "{what}: cell {c} misses a light"
            );
            assert!(
                set.iter().all(|l| hi.cell(c).contains(l)),
                "{what}: cell {c} lists a light out of reach"
            );
            differing += set.len().abs_diff(exact.cell(c).len());
        }
        assert!(
            differing <= 4,
            "{what}: {differing} round-off disagreements with the twin"
        );
    }
    let (d, _) = diff(reference, &out.image).unwrap();
    let (max_mean, max_p99) = tolerance(id);
    assert!(d.mean <= max_mean && d.p99 <= max_p99, "{what}: {d:?}");
    let n = out.stats.lighting_computations.unwrap();
    assert!(n >= out.stats.ideal_lighting_computations, "{what}");
    out.grid
}

const GRID_PIPELINES: [&str; 5] = [
    "tiled_forward",
    "tiled_forward_prez",
    "tiled_deferred",
    "clustered_forward",
    "clustered_deferred",
];
const STRATEGIES: [Assign; 5] = [
    Assign::Cpu,
    Assign::Gather,
    Assign::Scatter,
    Assign::Bvh,
    Assign::BvhGpu,
];

fn check_strategies(
    scene: &Scene,
    frame: u32,
    (w, h): (u32, u32),
    tile: u32,
    slices: u32,
    ids: &[&str],
) {
    let ctx = common::gpu();
    let reference = Renderer::new(&ctx, w, h, settings(tile))
        .unwrap()
        .render(scene, frame, REFERENCE)
        .unwrap()
        .image;
    for assign in STRATEGIES {
        let settings = RenderSettings {
            tile_size: tile,
            slices,
            assign,
            ..Default::default()
        };
        let mut r = Renderer::new(&ctx, w, h, settings).unwrap();
        for id in ids {
            check_assign(&mut r, scene, frame, id, &reference);
        }
    }
}

#[test]
fn every_strategy_matches_its_twin_on_every_grid_pipeline() {
    let s = catalog::build("robots-many", &SceneParams::default()).unwrap();
    check_strategies(&s, 200, (160, 90), 16, 32, &GRID_PIPELINES);
}

#[test]
fn strategies_at_odd_sizes_and_tiles() {
    let few = catalog::build("robots-few", &SceneParams::default()).unwrap();
    check_strategies(
        &few,
        200,
        (150, 86),
        7,
        16,
        &["tiled_deferred", "clustered_deferred"],
    );
    let many = catalog::build("robots-many", &SceneParams::default()).unwrap();
    check_strategies(
        &many,
        0,
        (170, 100),
        32,
        8,
        &["tiled_forward_prez", "clustered_forward"],
    );
}

/// Enough lights for a BVH with inner levels, a sort over several blocks and cells with
/// hundreds of lights.
#[test]
fn strategies_with_twenty_thousand_lights() {
    let params = SceneParams {
        lights: Some(20_000),
        ..Default::default()
    };
    let s = catalog::build("stress", &params).unwrap();
    check_strategies(
        &s,
        0,
        (128, 72),
        16,
        32,
        &["clustered_deferred", "tiled_deferred"],
    );
}

#[test]
fn strategies_agree_with_each_other_and_pipelines_without_a_grid_ignore_them() {
    let ctx = common::gpu();
    let s = catalog::build("robots-few", &SceneParams::default()).unwrap();
    let mut lists = Vec::new();
    for assign in STRATEGIES {
        let settings = RenderSettings {
            assign,
            ..Default::default()
        };
        let mut r = Renderer::new(&ctx, 96, 64, settings).unwrap();
        let out = r.render(&s, 100, "clustered_deferred").unwrap();
        lists.push(out.stats.grid_indices.unwrap());
        for id in ["deferred", "tiled_deferred_single", "forward"] {
            let out = r.render(&s, 100, id).unwrap();
            assert_eq!(out.stats.assign, None, "{id} builds no grid");
            assert!(out.cell_bounds.is_none());
        }
    }
    // `auto` resolves by adapter and light count, and says what it chose.
    let mut r = Renderer::new(&ctx, 96, 64, RenderSettings::default()).unwrap();
    let out = r.render(&s, 100, "tiled_deferred").unwrap();
    let chosen = Assign::Auto.resolve(s.frame(100).lights.len(), ctx.is_software());
    assert_eq!(out.stats.assign.as_deref(), Some(chosen.name()));
    // CPU and scatter run the same test; gather and both BVHs the same (plane-based) test.
    assert_eq!(lists[0], lists[2], "cpu vs scatter");
    assert_eq!(lists[1], lists[3], "gather vs bvh");
    assert_eq!(lists[1], lists[4], "gather vs bvh-gpu");
}

#[test]
fn bad_tile_sizes_are_rejected() {
    let ctx = common::gpu();
    assert!(Renderer::new(&ctx, 64, 64, settings(0)).is_err());
    assert!(Renderer::new(&ctx, 64, 64, settings(3)).is_err());
    assert!(Renderer::new(&ctx, 64, 64, settings(65)).is_err());
}

/// A grid longer than the device can bind is refused with a message, never truncated.
#[test]
fn index_lists_beyond_the_device_limit_are_refused() {
    let ctx = common::gpu();
    let limits = ctx.device.limits();
    let max = limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size)
        / 4;
    assert!(lightgrid::culling::check_index_capacity(&ctx.device, max, "test").is_ok());
    let err = lightgrid::culling::check_index_capacity(&ctx.device, max + 1, "scatter")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("scatter") && err.contains("more than"),
        "{err}"
    );
}

/// Randomized edge cases on the GPU: a catalog frame's geometry and camera with lights placed
/// relative to that camera (behind it, containing it, crossing the near plane, centred just
/// outside a screen edge, and scattered in front), at resolutions that are not multiples of the
/// tile size; every strategy on every grid pipeline against its CPU twin.
#[test]
fn strategies_on_randomized_edge_case_lights() {
    use glam::Vec3;
    use lightgrid::scene::{LightAnchor, Rng, SceneLight};
    let mut rng = Rng::new(77);
    let cases = [
        ("random-fps", (97, 61), 13, 32),
        ("robots-many", (130, 77), 8, 16),
        ("random-top", (151, 83), 31, 8),
    ];
    for (name, (w, h), tile, slices) in cases {
        let mut scene = catalog::build(name, &SceneParams::default()).unwrap();
        let frame = rng.below(scene.frame_count());
        let camera = scene.frame(frame).camera;
        let setup = ViewSetup::new(&camera, w, h);
        let world = setup.view.inverse();
        let mut lights = Vec::new();
        for k in 0..240 {
            let r = rng.range(0.3, 10.0);
            let v = match k % 6 {
                0 => Vec3::new(rng.range(-r, r), rng.range(-r, r), rng.range(-r, r)) * 0.5,
                1 => Vec3::new(
                    rng.range(-r, r),
                    rng.range(-r, r),
                    -camera.near + rng.range(-r, r),
                ),
                2 => Vec3::new(
                    rng.range(-3.0, 3.0),
                    rng.range(-3.0, 3.0),
                    rng.range(0.0, r),
                ),
                3 => {
                    let depth = rng.range(1.0, 60.0);
                    let edge = if rng.unit() < 0.5 { -1.0 } else { 1.0 } * rng.range(0.95, 1.15);
                    let other = rng.range(-1.1, 1.1);
                    let (sx, sy) = if k % 12 < 6 {
                        (edge, other)
                    } else {
                        (other, edge)
                    };
                    Vec3::new(sx / setup.p00 * depth, sy / setup.p11 * depth, -depth)
                }
                _ => {
                    let depth = rng.range(0.5, 80.0);
                    Vec3::new(
                        rng.range(-1.0, 1.0) / setup.p00 * depth,
                        rng.range(-1.0, 1.0) / setup.p11 * depth,
                        -depth,
                    )
                }
            };
            lights.push(SceneLight {
                light: PointLight {
                    position: world.transform_point3(v),
                    color: Vec3::new(rng.unit(), rng.unit(), rng.unit()),
                    intensity: rng.range(0.5, 3.0),
                    range: r,
                },
                anchor: LightAnchor::World,
            });
        }
        scene.lights = lights;
        scene.validate().unwrap();
        check_strategies(&scene, frame, (w, h), tile, slices, &GRID_PIPELINES);
    }
}

/// On llvmpipe a shader invocation's loops end silently after SOFTWARE_LOOP_BUDGET iterations:
/// below it `forward` is exact (equal to a grid pipeline), above it every pipeline whose
/// per-sample light loop would run longer is refused with a message instead of rendering an
/// image with lights missing, while one with short enough lists still renders.
#[test]
fn light_loops_beyond_the_adapters_budget_are_refused() {
    let ctx = common::gpu();
    let settings = RenderSettings {
        tile_size: 64,
        assign: Assign::Cpu,
        ..Default::default()
    };
    let scene = |n| {
        let params = SceneParams {
            lights: Some(n),
            ..Default::default()
        };
        catalog::build("stress", &params).unwrap()
    };
    let mut r = Renderer::new(&ctx, 32, 18, settings).unwrap();
    let below = scene(65_000);
    let forward = r.render(&below, 0, "forward").unwrap();
    let tiled = r.render(&below, 0, "tiled_forward").unwrap();
    let (d, _) = diff(&forward.image, &tiled.image).unwrap();
    assert!(
        d.max <= 1.0,
        "forward below the budget must be exact: {d:?}"
    );
    let above = scene(100_000);
    match ctx.loop_budget() {
        Some(budget) => {
            for id in [
                "forward",
                "forward_mono",
                "tiled_forward",
                "tiled_deferred_single",
            ] {
                let err = r.render(&above, 0, id).err().unwrap_or_else(|| {
                    panic!("{id} with 100,000 lights in one 64px tile must be refused")
                });
                // Counted on the GPU (check_loop after every data-dependent loop), not
                // estimated on the CPU: the frame is refused, never passed off as right.
                assert!(
                    matches!(&err, lightgrid::Error::TruncatedLoops { pipeline, count }
                        if pipeline == id && *count > 0),
                    "{id}: {err}"
                );
            }
            let clustered = r.render(&above, 0, "clustered_deferred").unwrap();
            assert!(u64::from(clustered.grid.max_lights_per_cell()) <= budget);
        }
        None => {
            for id in ["forward", "tiled_forward", "clustered_deferred"] {
                r.render(&above, 0, id).unwrap();
            }
        }
    }
    if std::env::var("CI").is_ok() {
        assert!(
            ctx.loop_budget().is_some(),
            "CI runs on lavapipe, which has the budget"
        );
    }
}
