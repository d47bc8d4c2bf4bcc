//! CPU twin of the GPU gather and BVH traversal (`gather.wgsl`, `bvh.wgsl`, driven by
//! `gpu_assign.rs`): per cell, the lights whose bounding sphere reaches into the cell's
//! frustum (its tile's four side planes and its samples' view-distance bounds) and, for spots,
//! whose cone may reach the frustum's bounding sphere, computed as `tile_frustum` /
//! `light_in_tile` in `tile_frustum.wgsl`, in the same f32 arithmetic.

use crate::consts::ASSIGN_DEPTH_SLACK;
use crate::culling::bounds::cell_box::{box_overlap, cone_sphere, sphere_box_gap, CellCull};
use crate::culling::bounds::depth_mask::{depth_mask_meets, CellMask, NO_MASK};
use crate::culling::grid::{GridDims, LightGrid};
use crate::culling::strategies::gpu_assign::{gather_shader, CellKernels};
use crate::culling::strategies::{AssignFrame, AssignStrategy, StrategyContext, StrategyRun};
use crate::error::Result;
use crate::frame::FrameEncoder;
use crate::gpu::CounterValues;
use crate::scene::Light;
use crate::scene::{ViewLight, ViewSetup};
use glam::Vec3;
use rayon::prelude::*;

/// A tile's frustum on the CPU, computed exactly as `tile_frustum` in WGSL.
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub(super) struct CpuFrustum {
    pub planes: [Vec3; 4],
    pub w_min: f32,
    pub w_max: f32,
    /// Bounding sphere of the frustum piece (`ViewSetup::cell_sphere` over the slack-widened
    /// bounds), for spot cones.
    pub sphere: (Vec3, f32),
    /// The cell's 2.5D depth mask (`depth_mask.rs`; [`NO_MASK`] unless the caller sets it).
    pub mask: CellMask,
    /// The cell's tight view-space box (`cell_box.rs`; none unless the caller sets it).
    pub cell_box: Option<(Vec3, Vec3)>,
}

#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub(super) fn cpu_frustum(
    setup: &ViewSetup,
    dims: &GridDims,
    t: usize,
    w_bounds: [f32; 2],
) -> CpuFrustum {
    let (x0, y0, _, _) = dims.tile_rect(t);
    let size = (setup.width as f32, setup.height as f32);
    let ts = dims.tile_size as f32;
    let lo = (x0 as f32, y0 as f32);
    let hi = ((lo.0 + ts).min(size.0), (lo.1 + ts).min(size.1));
    // Shifted by an off-centre projection (`ViewSetup::p20`), as `tile_frustum.wgsl`.
    let ndc_lo = (
        lo.0 / size.0 * 2.0 - 1.0 + setup.p20,
        1.0 - lo.1 / size.1 * 2.0 + setup.p21,
    );
    let ndc_hi = (
        hi.0 / size.0 * 2.0 - 1.0 + setup.p20,
        1.0 - hi.1 / size.1 * 2.0 + setup.p21,
    );
    CpuFrustum {
        planes: [
            Vec3::new(1.0, 0.0, ndc_lo.0 / setup.p00).normalize(),
            Vec3::new(-1.0, 0.0, -ndc_hi.0 / setup.p00).normalize(),
            Vec3::new(0.0, 1.0, ndc_hi.1 / setup.p11).normalize(),
            Vec3::new(0.0, -1.0, -ndc_lo.1 / setup.p11).normalize(),
        ],
        w_min: w_bounds[0],
        w_max: w_bounds[1],
        sphere: setup.cell_sphere(
            dims.tile_rect(t),
            w_bounds[0] * (1.0 - ASSIGN_DEPTH_SLACK),
            w_bounds[1] * (1.0 + ASSIGN_DEPTH_SLACK),
        ),
        mask: NO_MASK,
        cell_box: None,
    }
}

/// The frustum of cell `c` (`cell_frustum` in assign_bindings.wgsl): its tile's planes, its
/// bounds and, when given, its depth mask and box.
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub(super) fn cell_frustum(
    setup: &ViewSetup,
    dims: &GridDims,
    c: usize,
    cell_bounds: &[[f32; 2]],
    culls: Option<&[CellCull]>,
) -> CpuFrustum {
    let mut f = cpu_frustum(setup, dims, c % dims.tile_count(), cell_bounds[c]);
    if let Some(m) = culls {
        f.mask = m[c].mask;
        f.cell_box = m[c].view_box();
        f.sphere = cone_sphere(f.sphere, f.cell_box);
    }
    f
}

/// How far inside the cell's frustum the light is (≥ 0: inside, as `sphere_in_tile` decides);
/// `-inf` for a cell without samples. Tests use its size to recognise round-off cases.
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub(super) fn margin(f: &CpuFrustum, center: Vec3, r: f32) -> f32 {
    if f.w_min > f.w_max {
        return f32::NEG_INFINITY;
    }
    let w = -center.z;
    let mut m = (w + r - f.w_min * (1.0 - ASSIGN_DEPTH_SLACK))
        .min(f.w_max * (1.0 + ASSIGN_DEPTH_SLACK) - (w - r));
    for p in &f.planes {
        m = m.min(p.dot(center) + r);
    }
    if m >= 0.0 && !depth_mask_meets(&f.mask, w - r, w + r) {
        // Outside every bin holding samples: as far out as the nearest such bin is (a
        // size for the tests' round-off reading, not a distance the GPU computes).
        return -mask_gap(&f.mask, w - r, w + r);
    }
    match f.cell_box {
        Some((lo, hi)) if m >= 0.0 => m.min(-sphere_box_gap(lo, hi, center, r)),
        _ => m,
    }
}

/// How far the span `[w0, w1]` is from the nearest bin of `m` holding samples, in view
/// distance (positive when they do not meet).
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
fn mask_gap(m: &CellMask, w0: f32, w1: f32) -> f32 {
    let (lo, inv) = (f32::from_bits(m[1]), f32::from_bits(m[2]));
    if inv <= 0.0 || m[0] == 0 {
        return f32::INFINITY;
    }
    let width = 1.0 / inv;
    (0..32)
        .filter(|b| m[0] & (1 << b) != 0)
        .map(|b| {
            let (b0, b1) = (lo + b as f32 * width, lo + (b + 1) as f32 * width);
            (b0 - w1).max(w0 - b1).max(0.0)
        })
        .fold(f32::INFINITY, f32::min)
        .max(f32::MIN_POSITIVE)
}

/// `light_in_tile` in WGSL: the light's bounding sphere against the frustum, and a spot's
/// cone against the frustum's bounding sphere; the smaller margin.
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub(super) fn light_margin(f: &CpuFrustum, v: &ViewLight) -> f32 {
    let m = margin(f, v.center, v.radius);
    if m < 0.0 || v.cone.is_none() {
        return m;
    }
    let m = m.min(v.cone_margin(f.sphere.0, f.sphere.1));
    match v.reach_box() {
        Some((lo, hi)) if m >= 0.0 => m.min(box_margin(f, lo, hi)),
        _ => m,
    }
}

/// `box_in_cell` of tile_frustum.wgsl as a margin: how far the view-space box reaches into
/// the frustum (≥ 0: it does).
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub(super) fn box_margin(f: &CpuFrustum, lo: Vec3, hi: Vec3) -> f32 {
    if f.w_min > f.w_max {
        return f32::NEG_INFINITY;
    }
    let (w_lo, w_hi) = (-hi.z, -lo.z);
    let mut m = (w_hi - f.w_min * (1.0 - ASSIGN_DEPTH_SLACK))
        .min(f.w_max * (1.0 + ASSIGN_DEPTH_SLACK) - w_lo);
    for p in &f.planes {
        m = m.min(p.dot(Vec3::select(p.cmpgt(Vec3::ZERO), hi, lo)));
    }
    if m >= 0.0 && !depth_mask_meets(&f.mask, w_lo, w_hi) {
        return -mask_gap(&f.mask, w_lo, w_hi);
    }
    match f.cell_box {
        Some(b) if m >= 0.0 => m.min(box_overlap((lo, hi), b)),
        _ => m,
    }
}

/// Per cell and light, the gather test's margin (cells in grid order, lights in order).
/// `cell_bounds`: per cell the view-distance `[min, max]` (`cell_bounds.rs`); `culls`: per
/// cell its 2.5D depth mask and tight box, for a grid built with `--depth-mask on` or `--cell-box on`.
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub(crate) fn gather_margins(
    setup: &ViewSetup,
    dims: &GridDims,
    lights: &[Light],
    cell_bounds: &[[f32; 2]],
    culls: Option<&[CellCull]>,
) -> Vec<Vec<f32>> {
    let view: Vec<ViewLight> = lights.iter().map(|l| setup.to_view(l)).collect();
    (0..dims.cell_count())
        .into_par_iter()
        .map(|c| {
            let f = cell_frustum(setup, dims, c, cell_bounds, culls);
            view.iter().map(|v| light_margin(&f, v)).collect()
        })
        .collect()
}

/// CPU twin of the GPU gather (and of the BVH traversal, which applies the same final test):
/// the same inputs and the same grid (lists in light order; the GPU's order varies).
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub fn assign_gather_cpu(
    setup: &ViewSetup,
    dims: &GridDims,
    lights: &[Light],
    cell_bounds: &[[f32; 2]],
) -> LightGrid {
    assign_gather_cpu_masked(setup, dims, lights, cell_bounds, None)
}

/// [`assign_gather_cpu`] of a grid built with `--depth-mask on` or `--cell-box on`: its
/// cells' culling records.
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub fn assign_gather_cpu_masked(
    setup: &ViewSetup,
    dims: &GridDims,
    lights: &[Light],
    cell_bounds: &[[f32; 2]],
    culls: Option<&[CellCull]>,
) -> LightGrid {
    let lists: Vec<Vec<u32>> = gather_margins(setup, dims, lights, cell_bounds, culls)
        .into_iter()
        .map(|m| {
            m.iter()
                .enumerate()
                .filter(|(_, &x)| x >= 0.0)
                .map(|(i, _)| i as u32)
                .collect()
        })
        .collect();
    LightGrid::from_lists(*dims, &lists)
}

/// `--assign gather` (forward-plus §4): one workgroup per occupied cell tests every light
/// (`gather.wgsl` on `assign_bindings.wgsl`, run by [`CellKernels`]).
struct GatherStrategy {
    kernels: CellKernels,
}

pub(super) fn create_strategy(ctx: &StrategyContext) -> Box<dyn AssignStrategy> {
    Box::new(GatherStrategy {
        kernels: CellKernels::new(ctx, "gather", &gather_shader(), &[]),
    })
}

impl AssignStrategy for GatherStrategy {
    fn encode(&mut self, a: AssignFrame, enc: &mut FrameEncoder) -> Result<StrategyRun> {
        self.kernels.encode(a, enc, &[]);
        Ok(StrategyRun::default())
    }

    fn observe(&mut self, device: &wgpu::Device, values: &CounterValues) -> Result<()> {
        self.kernels.observe(device, values)
    }

    fn grid_entries(&self, values: &CounterValues) -> u32 {
        values.index_needed()
    }
}
