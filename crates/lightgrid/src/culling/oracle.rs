//! Brute force: which lights reach which samples. Used by the culling tests (the CPU and GPU
//! grids must contain every light the oracle finds) and for the ideal lighting-computation
//! count: for every visible sample, the lights whose range reaches it.

use crate::culling::grid::{GridDims, LightGrid};
use crate::scene::{Fragment, Light};
use crate::scene::{ViewLight, ViewSetup};
use glam::Vec3;
use rayon::prelude::*;

/// The lights (indices, in order) reaching at least one of `samples` (view space).
fn lights_reaching_any(view_lights: &[ViewLight], samples: &[Vec3]) -> Vec<u32> {
    if samples.is_empty() {
        return Vec::new();
    }
    view_lights
        .iter()
        .enumerate()
        .filter(|(_, l)| samples.iter().any(|&p| l.reaches(p)))
        .map(|(i, _)| i as u32)
        .collect()
}

/// For every cell (tile, or tile × slice), the lights that reach at least one of the cell's
/// samples (inside the range and, for a spot, the outer cone). `view_distance[y * width + x]` is the sample's view distance; non-finite
/// means no sample.
pub fn oracle_tile_lights(
    setup: &ViewSetup,
    dims: &GridDims,
    lights: &[Light],
    view_distance: &[f32],
) -> Vec<Vec<u32>> {
    let view_lights: Vec<_> = lights.iter().map(|l| setup.to_view(l)).collect();
    let per_tile: Vec<Vec<Vec<u32>>> = (0..dims.tile_count())
        .into_par_iter()
        .map(|t| {
            let (x0, y0, x1, y1) = dims.tile_rect(t);
            let mut samples = vec![Vec::new(); dims.slices as usize];
            for y in y0..y1 {
                for x in x0..x1 {
                    let w = view_distance[(y * dims.width + x) as usize];
                    if w.is_finite() {
                        samples[dims.slice_of(w) as usize].push(setup.sample_position(x, y, w));
                    }
                }
            }
            samples
                .iter()
                .map(|s| lights_reaching_any(&view_lights, s))
                .collect()
        })
        .collect();
    // Reorder tile-major results into cell order (slice-major).
    let mut cells = vec![Vec::new(); dims.cell_count()];
    for (t, slices) in per_tile.into_iter().enumerate() {
        for (k, list) in slices.into_iter().enumerate() {
            cells[k * dims.tile_count() + t] = list;
        }
    }
    cells
}

/// The ideal count: for every sample with a finite view distance, the number of lights that
/// reach it (range and cone). `grid` must contain every such light for the sample's tile (the CPU
/// assignment does; the culling tests prove it), so only its lists are searched.
pub fn ideal_lighting_computations(
    setup: &ViewSetup,
    grid: &LightGrid,
    lights: &[Light],
    view_distance: &[f32],
) -> u64 {
    ideal_pixel_counts(setup, grid, lights, view_distance)
        .iter()
        .map(|&n| u64::from(n))
        .sum()
}

/// [`ideal_lighting_computations`] per pixel (row-major; 0 where there is no sample): the
/// viewer's wasted-work view subtracts it from the pipeline's counts.
pub(crate) fn ideal_pixel_counts(
    setup: &ViewSetup,
    grid: &LightGrid,
    lights: &[Light],
    view_distance: &[f32],
) -> Vec<u32> {
    let view_lights: Vec<_> = lights.iter().map(|l| setup.to_view(l)).collect();
    let dims = grid.dims;
    let mut out = vec![0u32; (dims.width * dims.height) as usize];
    out.par_chunks_mut(dims.width as usize)
        .enumerate()
        .for_each(|(y, row)| {
            let y = y as u32;
            for (x, n) in (0..dims.width).zip(row.iter_mut()) {
                let w = view_distance[(y * dims.width + x) as usize];
                if !w.is_finite() {
                    continue;
                }
                let p = setup.sample_position(x, y, w);
                *n = grid
                    .cell(dims.cell_of(x, y, w))
                    .iter()
                    .filter(|&&l| view_lights[l as usize].reaches(p))
                    .count() as u32;
            }
        });
    out
}

/// For every cell, the lights reaching at least one of the transparent fragments that read it
/// (`GridDims::transparent_cell_of`); cells no fragment reads stay empty. Brute force over
/// every light (tests only).
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub fn oracle_fragment_lights(
    setup: &ViewSetup,
    dims: &GridDims,
    lights: &[Light],
    fragments: &[Fragment],
) -> Vec<Vec<u32>> {
    let view_lights: Vec<_> = lights.iter().map(|l| setup.to_view(l)).collect();
    let mut per_cell: Vec<Vec<Vec3>> = vec![Vec::new(); dims.cell_count()];
    for f in fragments {
        per_cell[dims.transparent_cell_of(f.x, f.y, f.w)]
            .push(setup.sample_position(f.x, f.y, f.w));
    }
    per_cell
        .par_iter()
        .map(|samples| lights_reaching_any(&view_lights, samples))
        .collect()
}

/// [`ideal_fragment_computations`] per fragment, in the order of `fragments`.
pub(crate) fn ideal_fragment_counts(
    setup: &ViewSetup,
    grid: &LightGrid,
    lights: &[Light],
    fragments: &[Fragment],
) -> Vec<u32> {
    let view_lights: Vec<_> = lights.iter().map(|l| setup.to_view(l)).collect();
    let dims = grid.dims;
    fragments
        .par_iter()
        .map(|f| {
            let p = setup.sample_position(f.x, f.y, f.w);
            grid.cell(dims.transparent_cell_of(f.x, f.y, f.w))
                .iter()
                .filter(|&&l| view_lights[l as usize].reaches(p))
                .count() as u32
        })
        .collect()
}
