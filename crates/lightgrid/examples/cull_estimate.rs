//! How far finer culling could take the grids, measured on the CPU before any of it is built
//! on the GPU (issue 31's goal: the best grid at <= 1.3x the ideal lighting computations on
//! robots-many). Renders each frame with `tiled_forward_prez` and `clustered_forward` (16-px
//! tiles, 32 slices, no glass), then recounts the same frame's lists per visible sample:
//! - **tight boxes**: each cell's lights kept only where the light's sphere meets the view-space
//!   box of the cell's samples (each sample's pixel footprint at its distance, with the slack):
//!   Persson/Olsson's cluster bounds from the samples, the closest-point test;
//! - **z-bins** (tiles): the tile's lights over near..far (no depth bounds), kept where the
//!   sample's depth bin lies within the bins the light's depth span covers (Drobot 2017), with
//!   N linear bins over the frame's sample range.
//!
//! `cargo run --release -p lightgrid --example cull_estimate -- [scene] [first..last:step]`
//! (default robots-many 0..259:20); prints each frame and the means, as × the ideal.

use glam::Vec3;
use lightgrid::culling::{assign_cpu, DepthRange, GridDims};
use lightgrid::gpu::GpuContext;
use lightgrid::scene::catalog::{self, SceneParams};
use lightgrid::{RenderSettings, Renderer};

const SIZE: (u32, u32) = (640, 360);
const TILE: u32 = 16;
const BINS: [u32; 2] = [64, 1024];

fn sphere_meets_box(c: Vec3, r: f32, lo: Vec3, hi: Vec3) -> bool {
    let d = (lo - c).max(Vec3::ZERO).max(c - hi);
    d.length_squared() <= r * r
}

type Result<T> = std::result::Result<T, Box<dyn std::error::Error>>;

/// Per cell the view-space box of its samples' pixel footprints, and every sample off the
/// background: (cell, view distance, x, y).
#[allow(clippy::type_complexity)]
fn sample_boxes(out: &lightgrid::FrameOutput) -> (Vec<Vec3>, Vec<Vec3>, Vec<(usize, f32, u32, u32)>) {
    let (setup, dims, (w, h)) = (&out.setup, out.grid.dims, SIZE);
    let mut lo = vec![Vec3::INFINITY; dims.cell_count()];
    let mut hi = vec![Vec3::NEG_INFINITY; dims.cell_count()];
    let mut samples = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let d = out.depth[(y * w + x) as usize];
            if lightgrid::depth::is_background(d) {
                continue;
            }
            let wd = setup.view_distance(d);
            let c = dims.cell_of(x, y, wd);
            for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
                for ww in [wd * 0.9999, wd * 1.0001] {
                    let nx = (x as f32 + dx) / w as f32 * 2.0 - 1.0;
                    let ny = 1.0 - (y as f32 + dy) / h as f32 * 2.0;
                    let p = Vec3::new(nx / setup.p00 * ww, ny / setup.p11 * ww, -ww);
                    lo[c] = lo[c].min(p);
                    hi[c] = hi[c].max(p);
                }
            }
            samples.push((c, wd, x, y));
        }
    }
    (lo, hi, samples)
}

/// Z-binning's lighting computations per ideal, one per bin count of `BINS`: the tiles'
/// near..far lists, a light kept where its depth bins meet the sample's.
fn zbin_columns(
    setup: &lightgrid::scene::ViewSetup,
    lights: &[lightgrid::scene::Light],
    views: &[lightgrid::scene::ViewLight],
    samples: &[(usize, f32, u32, u32)],
    ideal: f64,
) -> Result<Vec<f64>> {
    let (w, h) = SIZE;
    let mut row = Vec::new();
    let tiles = GridDims::new(w, h, TILE)?;
    let flat = assign_cpu(setup, &tiles, lights, DepthRange::NearFar);
    let (wmin, wmax) = samples.iter().fold((f32::INFINITY, 0f32), |a, s| (a.0.min(s.1), a.1.max(s.1)));
    for bins in BINS {
        let bin =
            |x: f32| ((x - wmin) / (wmax - wmin) * bins as f32).floor().clamp(0.0, (bins - 1) as f32) as u32;
        let mut count = 0u64;
        for &(_, wd, x, y) in samples {
            let b = bin(wd);
            for &l in flat.cell(tiles.tile_of(x, y)) {
                let v = &views[l as usize];
                let wc = -v.center.z;
                if bin(wc - v.radius) <= b && b <= bin(wc + v.radius) {
                    count += 1;
                }
            }
        }
        row.push(count as f64 / ideal);
    }
    Ok(row)
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scene_name = args.first().map_or("robots-many", String::as_str);
    let frames = args.get(1).map_or("0..259:20", String::as_str);
    let (range, step) = frames.split_once(':').unwrap_or((frames, "1"));
    let (first, last) =
        range.split_once("..").ok_or_else(|| format!("frames: first..last:step, not {frames}"))?;
    let (first, last, step): (u32, u32, u32) = (first.parse()?, last.parse()?, step.parse()?);
    if step == 0 || first > last {
        return Err("frames: first..last:step, with step > 0".into());
    }
    let ctx = GpuContext::new(None)?;
    let params = SceneParams { transparency: false, ..Default::default() };
    let s = catalog::build(scene_name, &params).or_else(|_| {
        catalog::build(scene_name, &SceneParams::default()) // scenes without glass refuse the flag
    })?;
    let (w, h) = SIZE;
    let mut tiled = Renderer::new(
        &ctx,
        w,
        h,
        RenderSettings {
            grid: lightgrid::CullConfig { tile_size: TILE, slices: 32, ..lightgrid::CullConfig::default() },
            ..Default::default()
        },
    )?;
    let mut clustered = Renderer::new(
        &ctx,
        w,
        h,
        RenderSettings {
            grid: lightgrid::CullConfig { tile_size: TILE, slices: 32, ..lightgrid::CullConfig::default() },
            ..Default::default()
        },
    )?;
    // Per column: tiles, tiles with tight boxes, z-bins per BINS, clusters, clusters with boxes.
    let mut sums = vec![0.0f64; 4 + BINS.len()];
    let mut n = 0;
    for frame in (first..=last.min(s.frame_count() - 1)).step_by(step as usize) {
        let lights = s.frame(frame).lights;
        let mut row = Vec::new();
        for (r, id) in [(&mut tiled, "tiled_forward_prez"), (&mut clustered, "clustered_forward")] {
            let out = r.render(&s, frame, id)?;
            let (setup, grid) = (&out.setup, &out.grid);
            let dims = grid.dims;
            let ideal = out.stats.ideal_lighting_computations as f64;
            if ideal == 0.0 {
                break;
            }
            let views: Vec<_> = lights.iter().map(|l| setup.to_view(l)).collect();
            let (lo, hi, samples) = sample_boxes(&out);
            let kept: Vec<u64> = (0..dims.cell_count())
                .map(|c| {
                    let in_box = |l: &&u32| {
                        let v = &views[**l as usize];
                        sphere_meets_box(v.center, v.radius * 1.0001, lo[c], hi[c])
                    };
                    grid.cell(c).iter().filter(in_box).count() as u64
                })
                .collect();
            let listed: u64 = samples.iter().map(|s| grid.cell(s.0).len() as u64).sum();
            let boxed: u64 = samples.iter().map(|s| kept[s.0]).sum();
            row.push(listed as f64 / ideal);
            row.push(boxed as f64 / ideal);
            if id == "tiled_forward_prez" {
                row.extend(zbin_columns(setup, &lights, &views, &samples, ideal)?);
            }
        }
        if row.len() < sums.len() {
            println!("{scene_name} f{frame}: no light reaches a visible sample");
            continue;
        }
        println!(
            "{scene_name} f{frame}: tiles {:.2}, tight tile boxes {:.2}, z-bins {}, clusters {:.2}, tight cluster boxes {:.2}",
            row[0],
            row[1],
            BINS.iter().zip(&row[2..]).map(|(b, v)| format!("{b}: {v:.2}")).collect::<Vec<_>>().join(", "),
            row[2 + BINS.len()],
            row[3 + BINS.len()]
        );
        for (s, v) in sums.iter_mut().zip(&row) {
            *s += v;
        }
        n += 1;
    }
    let m: Vec<String> = sums.iter().map(|s| format!("{:.2}", s / n as f64)).collect();
    println!(
        "mean over {n} frames (x ideal): tiles {}, tight tile boxes {}, z-bins {} ({}), clusters {}, tight cluster boxes {}",
        m[0], m[1], BINS.map(|b| b.to_string()).join("/"), m[2..2 + BINS.len()].join("/"), m[2 + BINS.len()], m[3 + BINS.len()]
    );
    Ok(())
}
