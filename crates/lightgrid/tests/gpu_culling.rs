//! GPU light assignment never misses a light: randomized scenes (catalog geometry and camera,
//! a few hundred lights placed where assignment goes wrong: containing the camera, crossing
//! the near plane, behind the camera reaching forward, just outside a screen edge), at least
//! 50 per strategy (`cpu`, `gather`, `scatter`, `bvh`, `bvh-gpu`), on every grid pipeline,
//! mostly small odd sizes and a few at 1280x720 with 8-pixel tiles (where `scatter` once
//! missed lights). Each downloaded grid contains every light the brute-force oracle finds
//! reaching a sample of the cell, lies between its CPU twin's with ranges 0.1% smaller and
//! larger, and its cell bounds equal their twin's.

mod common;

use lightgrid::culling::ViewSetup;
use lightgrid::frame::{Assign, CellBox, DepthMask};
use lightgrid::scene::catalog::{self, SceneParams};
use lightgrid::scene::{LightAnchor, Rng, Scene, SceneLight};
use lightgrid::{RenderSettings, Renderer};
use std::time::Instant;

// The strategies and grid pipelines come from the registries (`common::strategies`,
// `common::grid_pipelines`); `tiled_forward` assigns against `[near, far]`, the others
// against the depth bounds of their pre-pass or G-buffer.

const TILES: [u32; 9] = [4, 5, 7, 8, 13, 16, 31, 32, 64];

/// One frame size and grid, rendered by one renderer per strategy for `scenes` scenes.
struct Config {
    size: (u32, u32),
    tile: u32,
    slices: u32,
    pipeline: &'static str,
    scenes: usize,
    lights: usize,
    /// 2.5D culling (`--depth-mask`).
    depth_mask: DepthMask,
    /// Tight cells (`--cell-box`).
    cell_box: CellBox,
}

/// What the scenes of a run measured, for the bounds at the end.
#[derive(Default)]
struct Totals {
    scenes: Vec<usize>,
    coverage: common::Coverage,
    hits: u64,
    at_slice_boundary: u64,
    disagreements: usize,
    /// Opaque cells whose 2.5D mask left bins out (`--depth-mask on`).
    masked_cells: usize,
    /// Opaque cells with a tight box (`--cell-box on`).
    boxed_cells: usize,
    /// Seconds spent rendering (and downloading), per strategy, and checking on the CPU.
    render_s: Vec<f64>,
    check_s: f64,
}

impl Totals {
    /// The scenes exercised at least half of the `measured` hits of every kind, and a miss
    /// excused by a slice boundary stayed rare (measured: none).
    fn check(&self, measured: &common::Coverage, what: &str) {
        self.coverage.at_least(&measured.halved(), what);
        assert!(
            self.at_slice_boundary * 1000 <= self.hits,
            "{what}: {} of {} oracle hits only in the neighbouring slice",
            self.at_slice_boundary,
            self.hits
        );
    }
}

/// Catalog scenes whose geometry and camera paths the random lights are placed in, built
/// with `params`: with the glass, their grids have transparent lists too, whose cells span
/// near..opaque max (the 1280x720 run keeps them opaque: two layers of 921,600 cells there
/// more than double its time).
fn backdrops(params: &SceneParams) -> Vec<Scene> {
    ["random-fps", "robots-many", "random-top", "robots-few"]
        .iter()
        .map(|n| catalog::build(n, params).unwrap())
        .collect()
}

fn run(
    ctx: &lightgrid::gpu::GpuContext,
    configs: &[Config],
    (seed, params): (u64, &SceneParams),
    totals: &mut Totals,
) {
    let backdrops = backdrops(params);
    let mut rng = Rng::new(seed);
    for (ci, config) in configs.iter().enumerate() {
        let start = Instant::now();
        let (w, h) = config.size;
        // z-binning keeps no per-cell lists for masks or boxes to cut (it is refused with
        // them); it is the registry's last row, so the others keep their indices.
        let strategies: Vec<Assign> = common::strategies()
            .into_iter()
            .filter(|&a| {
                a != Assign::ZBin
                    || (config.depth_mask == DepthMask::Off && config.cell_box == CellBox::Off)
            })
            .collect();
        let n = strategies.len().max(totals.scenes.len());
        totals.scenes.resize(n, 0);
        totals.render_s.resize(n, 0.0);
        let mut renderers: Vec<Renderer> = strategies
            .iter()
            .map(|&assign| {
                let settings = RenderSettings {
                    grid: lightgrid::CullConfig {
                        tile_size: config.tile,
                        slices: config.slices,
                        strategy: assign,
                        depth_mask: config.depth_mask,
                        cell_box: config.cell_box,
                        ..lightgrid::CullConfig::default()
                    },
                    ..Default::default()
                };
                Renderer::new(ctx, w, h, settings).unwrap()
            })
            .collect();
        for k in 0..config.scenes {
            let mut scene = backdrops[(ci + k) % backdrops.len()].clone();
            let frame = rng.below(scene.frame_count());
            let camera = scene.frame(frame).camera;
            let setup = ViewSetup::new(&camera, w, h);
            scene.lights = common::edge_case_lights(&mut rng, &camera, &setup, config.lights)
                .into_iter()
                .map(|light| SceneLight {
                    light,
                    anchor: LightAnchor::World,
                })
                .collect();
            scene.validate().unwrap();
            let lights = scene.frame(frame).lights;
            let mut oracle: Option<common::FrameOracle> = None;
            for (si, (assign, r)) in strategies.iter().zip(&mut renderers).enumerate() {
                let what = format!(
                    "scene {k} of config {ci} ({} f{frame}, {} --assign {} {w}x{h} tile {} \
                     slices {} mask {} box {})",
                    scene.name,
                    config.pipeline,
                    assign.name(),
                    config.tile,
                    config.slices,
                    config.depth_mask.name(),
                    config.cell_box.name()
                );
                let t = Instant::now();
                let out = r.render(&scene, frame, config.pipeline).unwrap();
                totals.render_s[si] += t.elapsed().as_secs_f64();
                let t = Instant::now();
                assert_eq!(out.stats.assign.as_deref(), Some(assign.name()), "{what}");
                assert_eq!(out.stats.truncated_loops, 0, "{what}");
                let bounds = out
                    .cell_bounds
                    .as_deref()
                    .expect("a grid pipeline reports its cell bounds");
                let grid = &out.grid;
                let near_far = config.pipeline == "tiled_forward";
                if !near_far {
                    common::check_cell_bounds(&what, &setup, &grid.dims, bounds, &out.depth, 2);
                }
                let culls = out
                    .cell_culls
                    .as_deref()
                    .expect("a grid pipeline reports its culling records");
                let planes: Vec<&[f32]> = out.depth_samples.iter().map(|p| &p[..]).collect();
                let seen = common::check_cell_culls(
                    &what,
                    &setup,
                    &grid.dims,
                    culls,
                    bounds,
                    &planes,
                    (
                        config.depth_mask == DepthMask::On,
                        config.cell_box == CellBox::On,
                    ),
                    !near_far,
                );
                totals.masked_cells += seen.partial_masks;
                totals.boxed_cells += seen.boxes;
                totals.disagreements += common::check_grid_against_twin(
                    &what,
                    *assign,
                    &setup,
                    grid,
                    &lights,
                    (bounds, Some(culls)),
                    near_far,
                    4,
                );
                // Same geometry, camera and pipeline: every strategy's frame has the same depth.
                let oracle = oracle.get_or_insert_with(|| {
                    let o = common::FrameOracle::new(&setup, &grid.dims, &lights, &out.depth);
                    totals.coverage.add(&setup, &grid.dims, &lights, &o.cells);
                    o
                });
                let found = oracle.check(&what, &setup, grid);
                totals.hits += found.hits;
                totals.at_slice_boundary += found.at_slice_boundary;
                totals.scenes[si] += 1;
                totals.check_s += t.elapsed().as_secs_f64();
            }
        }
        eprintln!(
            "config {ci}: {w}x{h} tile {} slices {} {}: {} scenes x {} strategies in {:.1} s \
             (so far {:.1} s rendering {:?}, {:.1} s checking)",
            config.tile,
            config.slices,
            config.pipeline,
            config.scenes,
            strategies.len(),
            start.elapsed().as_secs_f64(),
            totals.render_s.iter().sum::<f64>(),
            totals
                .render_s
                .iter()
                .map(|t| (t * 10.0).round() / 10.0)
                .collect::<Vec<_>>(),
            totals.check_s,
        );
    }
}

/// Small frames: odd sizes between 64x48 and 200x150 (most not a multiple of the tile), every
/// tile size and pipeline, slices from 2 to 64, 240 lights each; 11 configurations of 5
/// scenes, so 55 scenes per strategy. About 65 s in release on lavapipe with two cores.
#[test]
fn gpu_strategies_contain_the_oracle_in_small_randomized_scenes() {
    let ctx = common::gpu();
    let mut rng = Rng::new(11);
    let configs: Vec<Config> = (0..11)
        .map(|i| Config {
            size: (64 + 2 * rng.below(68) + 1, 48 + 2 * rng.below(51) + 1),
            tile: TILES[i % TILES.len()],
            slices: [2, 8, 16, 32, 64][i % 5],
            pipeline: common::grid_pipelines()[i % common::grid_pipelines().len()],
            scenes: 5,
            lights: 240,
            depth_mask: DepthMask::Off,
            cell_box: CellBox::Off,
        })
        .collect();
    let mut totals = Totals::default();
    run(&ctx, &configs, (808, &SceneParams::default()), &mut totals);
    eprintln!(
        "small: scenes per strategy {:?}, {} oracle hits checked ({} across a slice boundary), \
         {} twin disagreements, {:?}",
        totals.scenes, totals.hits, totals.at_slice_boundary, totals.disagreements, totals.coverage
    );
    assert!(
        totals.scenes.iter().all(|&n| n >= 50),
        "{:?}",
        totals.scenes
    );
    // At least half of what the scenes measured (oracle (cell, light) pairs of each scene's
    // frame, counted once per scene; the kinds are disjoint, see `common::Coverage`).
    let measured = common::Coverage {
        cases: 55,
        odd_cases: 50,
        // Measured with 40% of the lights spots (common::random_spot), which light fewer
        // samples than the point lights before them (295,170 hits).
        hits: 137_246,
        containing: 96_465,
        behind: 304,
        crossing_near: 21_141,
        off_screen: 4016,
        partial_tiles: 14_275,
    };
    totals.check(&measured, "small scenes");
    for config in &configs {
        let (w, h) = config.size;
        assert!(w % 2 == 1 && h % 2 == 1 && (64..=200).contains(&w) && (48..=150).contains(&h));
    }
}

/// 1280x720 with 8-pixel tiles: 14,400 tiles, 460,800 clusters with 32 slices, so a light
/// containing the camera covers more cells than a shader loop may run on llvmpipe. Four scenes
/// per strategy; about 60 s in release on lavapipe with two cores.
#[test]
fn gpu_strategies_contain_the_oracle_at_1280x720_with_8_pixel_tiles() {
    let ctx = common::gpu();
    let configs = [
        Config {
            size: (1280, 720),
            tile: 8,
            slices: 32,
            pipeline: "clustered_deferred",
            scenes: 2,
            lights: 240,
            depth_mask: DepthMask::Off,
            cell_box: CellBox::Off,
        },
        Config {
            size: (1280, 720),
            tile: 8,
            slices: 16,
            pipeline: "clustered_forward",
            scenes: 1,
            lights: 240,
            depth_mask: DepthMask::Off,
            cell_box: CellBox::Off,
        },
        Config {
            size: (1280, 720),
            tile: 8,
            slices: 1,
            pipeline: "tiled_deferred",
            scenes: 1,
            lights: 240,
            depth_mask: DepthMask::Off,
            cell_box: CellBox::Off,
        },
    ];
    let mut totals = Totals::default();
    let opaque = SceneParams {
        transparency: false,
        ..Default::default()
    };
    run(&ctx, &configs, (1280, &opaque), &mut totals);
    eprintln!(
        "1280x720: {} oracle hits checked ({} across a slice boundary), {} twin \
         disagreements, {:?}",
        totals.hits, totals.at_slice_boundary, totals.disagreements, totals.coverage
    );
    assert!(totals.scenes.iter().all(|&n| n == 4), "{:?}", totals.scenes);
    // At least half of what the scenes measured; the frame is a multiple of the tile and
    // these cameras had no light behind them that reached a sample.
    let measured = common::Coverage {
        cases: 4,
        odd_cases: 0,
        // Measured with 40% of the lights spots (367,268 hits with point lights only).
        hits: 208_029,
        containing: 145_599,
        behind: 1303,
        crossing_near: 35_717,
        off_screen: 3330,
        partial_tiles: 0,
    };
    totals.check(&measured, "1280x720");
}

/// 2.5D culling (`--depth-mask on`): the same randomized lights (behind, around and in front
/// of the camera, crossing the near plane, spots from narrow to 180 degrees, at screen edges)
/// on the pipelines whose grids come from the depth buffer, odd sizes and every tile size,
/// tiled and clustered, with the glass's transparent lists: every strategy's grid holds every
/// light the oracle finds reaching a sample, equals its twin fed with the GPU's masks, and the
/// masks hold every sample's bin (`common::check_cell_culls`). The catalog's backdrops put
/// robots in front of the street, so tiles straddle depth discontinuities: the masks must
/// leave bins out in many cells, or the test would not exercise them.
#[test]
fn gpu_strategies_with_depth_masks_contain_the_oracle() {
    let totals = per_sample_culling_run((25, 1), |_| (DepthMask::On, CellBox::Off));
    eprintln!(
        "depth masks: scenes per strategy {:?}, {} oracle hits checked, {} twin \
         disagreements, {} cells with a partial mask, {:?}",
        totals.scenes, totals.hits, totals.disagreements, totals.masked_cells, totals.coverage
    );
    assert!(
        totals.masked_cells >= 1000,
        "masks left bins out in only {} cells",
        totals.masked_cells
    );
}

/// Tight cells (`--cell-box on`), alone and with 2.5D masks: over randomized lights at odd
/// sizes, tiled and clustered, with the glass's transparent lists, every strategy's grid
/// holds every light the oracle finds reaching a sample, equals its twin fed with the GPU's
/// boxes, and every occupied opaque cell's box holds its samples' footprints and no more
/// (`common::check_cell_culls`).
#[test]
fn gpu_strategies_with_cell_boxes_contain_the_oracle() {
    let totals = per_sample_culling_run((31, 2), |i| {
        ([DepthMask::Off, DepthMask::On][(i / 2) % 2], CellBox::On)
    });
    eprintln!(
        "cell boxes: scenes per strategy {:?}, {} oracle hits checked, {} twin \
         disagreements, {} cells with a box, {:?}",
        totals.scenes, totals.hits, totals.disagreements, totals.boxed_cells, totals.coverage
    );
    assert!(
        totals.boxed_cells >= 1000,
        "only {} cells had a box",
        totals.boxed_cells
    );
    let c = &totals.coverage;
    assert!(
        c.behind > 0 && c.crossing_near > 0 && c.off_screen > 0 && c.partial_tiles > 0,
        "the lights missed a case: {c:?}"
    );
}

/// Eight configurations of three scenes each over the depth-bounded grid pipelines, odd sizes,
/// tiles from `TILES` (every third from `offset`), tiled and clustered, with the masks and
/// boxes `culling(i)` gives configuration i, randomized by `seed`: every strategy ran every
/// scene and the oracle found enough hits.
fn per_sample_culling_run(
    (seed, offset): (u64, usize),
    culling: fn(usize) -> (DepthMask, CellBox),
) -> Totals {
    let ctx = common::gpu();
    let mut rng = Rng::new(seed);
    let depth_pipelines: Vec<&str> = common::grid_pipelines()
        .into_iter()
        .filter(|id| *id != "tiled_forward")
        .collect();
    let configs: Vec<Config> = (0..8)
        .map(|i| Config {
            size: (64 + 2 * rng.below(68) + 1, 48 + 2 * rng.below(51) + 1),
            tile: TILES[(3 * i + offset) % TILES.len()],
            slices: [1, 8, 1, 32][i % 4],
            pipeline: depth_pipelines[(i + offset - 1) % depth_pipelines.len()],
            scenes: 3,
            lights: 240,
            depth_mask: culling(i).0,
            cell_box: culling(i).1,
        })
        .collect();
    let mut totals = Totals::default();
    run(&ctx, &configs, (2525, &SceneParams::default()), &mut totals);
    assert!(
        totals.scenes.iter().all(|&n| n == 24),
        "{:?}",
        totals.scenes
    );
    assert!(totals.hits >= 10_000, "{} oracle hits", totals.hits);
    totals
}
