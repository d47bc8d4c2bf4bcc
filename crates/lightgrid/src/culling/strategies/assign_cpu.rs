//! CPU light assignment (tiled-shading §6.1, §6.3):
//! 1. project each light's sphere to a tight screen rectangle, correct when the sphere
//!    crosses the near plane, lies behind the camera or contains it (per axis, the extremes of
//!    u/w over the sphere clipped to w >= near: tangent points from the eye where they are in
//!    front of the near plane, else the sphere's intersection with the near plane);
//! 2. bucket lights by tile row, then, in parallel over rows, insert each light into the cells
//!    of the tiles its rectangle covers whose sample depth bounds its view-depth interval
//!    overlaps.
//!
//! GPU scatter (`scatter.wgsl`) runs exactly this test, so this is also its CPU twin.
//!
//! The brute-force oracle in `oracle.rs` checks that nothing is ever missed.

use crate::consts::ASSIGN_DEPTH_SLACK as DEPTH_SLACK;
use crate::culling::bounds::cell_box::{box_overlap, cone_sphere, CellCull};
use crate::culling::bounds::depth_mask::depth_mask_meets;
use crate::culling::frame::{check_index_capacity, CellSource};
use crate::culling::grid::{GridDims, LightGrid};
use crate::culling::strategies::{AssignFrame, AssignStrategy, StrategyContext, StrategyRun};
use crate::error::Result;
use crate::frame::FrameEncoder;
use crate::scene::Light;
use crate::scene::{ViewLight, ViewSetup};
use glam::Vec3;
use rayon::prelude::*;
use web_time::Instant;

/// Pixels covered by a projected light: inclusive pixel index ranges, clipped to the frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelRect {
    /// First covered column.
    pub x0: u32,
    /// Last covered column (inclusive).
    pub x1: u32,
    /// First covered row (from the top).
    pub y0: u32,
    /// Last covered row (inclusive).
    pub y1: u32,
}

/// Depth ranges the light must overlap to be inserted into a cell.
#[derive(Clone, Copy, Debug)]
pub enum DepthRange<'a> {
    /// No depth bounds: every tile spans near..far (tiled-shading §3, `tiled_forward`).
    NearFar,
    /// Per cell, the view-distance `[min, max]` of its samples (`cell_bounds.rs`; min > max
    /// marks a cell without samples, which gets no lights). For a tiled grid these are the
    /// tile depth bounds (§6.3); for a clustered grid (tiled-forward-shading §4.8) a light
    /// goes into the clusters of its rectangle whose slices its view-depth interval spans and
    /// whose samples' bounds it overlaps.
    Cells(&'a [[f32; 2]]),
    /// As `Cells`, with each cell's culling record (`cell_box.rs`): with `--depth-mask on` a
    /// light must also meet a bin of the cell holding samples (`depth_mask.rs`), with
    /// `--cell-box on` its sphere must reach the cell's box.
    Culled(&'a [[f32; 2]], &'a [CellCull]),
}

impl<'a> DepthRange<'a> {
    /// The cell bounds, unless every cell spans near..far.
    fn bounds(&self) -> Option<&'a [[f32; 2]]> {
        match *self {
            DepthRange::NearFar => None,
            DepthRange::Cells(b) | DepthRange::Culled(b, _) => Some(b),
        }
    }
}

/// Range of s = u / w over the disc (centre (cu, cw), radius r) clipped to w >= near, where u
/// is view x or y and w the view distance. None when nothing is in front of the near plane.
fn axis_range(cu: f32, cw: f32, r: f32, near: f32) -> Option<(f32, f32)> {
    if cw + r < near {
        return None;
    }
    let mut lo = f32::INFINITY;
    let mut hi = f32::NEG_INFINITY;
    let mut take = |s: f32| {
        lo = lo.min(s);
        hi = hi.max(s);
    };
    let d2 = cu * cu + cw * cw;
    let r2 = r * r;
    if d2 > r2 {
        // Tangent points from the eye: (t² c ± t r c⊥) / d², t² = d² - r², c⊥ = (-cw, cu).
        let t2 = d2 - r2;
        let t = t2.sqrt();
        for sign in [-1.0f32, 1.0] {
            let u = (t2 * cu + sign * t * r * -cw) / d2;
            let w = (t2 * cw + sign * t * r * cu) / d2;
            if w >= near {
                take(u / w);
            }
        }
    }
    let dn = cw - near;
    if dn.abs() <= r {
        let k = (r2 - dn * dn).max(0.0).sqrt();
        take((cu - k) / near);
        take((cu + k) / near);
    }
    if lo > hi {
        // Only reachable through round-off at a grazing configuration: be conservative.
        return Some((f32::NEG_INFINITY, f32::INFINITY));
    }
    Some((lo, hi))
}

/// The pixels whose centres the light's projected sphere may cover, or None if it is
/// entirely off screen, behind the near plane or beyond the far plane.
pub fn project_sphere(setup: &ViewSetup, light: &ViewLight) -> Option<PixelRect> {
    let c = light.center;
    let r = light.radius;
    let cw = -c.z;
    if cw - r > setup.far {
        return None;
    }
    let (sx0, sx1) = axis_range(c.x, cw, r, setup.near)?;
    let (sy0, sy1) = axis_range(c.y, cw, r, setup.near)?;
    let (w, h) = (setup.width as f32, setup.height as f32);
    // NDC -> pixels (y down). A small widening absorbs round-off.
    let px = |s: f32| ((setup.p00 * s - setup.p20) * 0.5 + 0.5) * w;
    let py = |s: f32| (0.5 - (setup.p11 * s - setup.p21) * 0.5) * h;
    let (x_lo, x_hi) = (px(sx0) - 0.01, px(sx1) + 0.01);
    let (y_lo, y_hi) = (py(sy1) - 0.01, py(sy0) + 0.01);
    if x_hi < 0.0 || y_hi < 0.0 || x_lo > w || y_lo > h {
        return None;
    }
    let clamp = |v: f32, max: u32| (v.floor().max(0.0) as u32).min(max - 1);
    Some(PixelRect {
        x0: clamp(x_lo, setup.width),
        x1: clamp(x_hi, setup.width),
        y0: clamp(y_lo, setup.height),
        y1: clamp(y_hi, setup.height),
    })
}

/// Per cell, the sphere spot cones are tested against: the bounding sphere of its frustum
/// piece (`ViewSetup::cell_sphere`) over the depth range its samples span (near..far without
/// bounds; nothing for an empty cell), or its tight box's where smaller ([`cone_sphere`]);
/// None when no light is culled by a cone (no spots, or `SpotCull::Sphere`).
pub fn cell_spheres(
    setup: &ViewSetup,
    dims: &GridDims,
    depth: &DepthRange,
    lights: &[Light],
) -> Option<Vec<(Vec3, f32)>> {
    let cones = setup.spot_cull == crate::scene::SpotCull::Cone;
    if !cones || lights.iter().all(|l| l.spot.is_none()) {
        return None;
    }
    let tiles = dims.tile_count();
    let spheres = match depth {
        // The GPU strategies' bounds are [near, far] here, widened by the slack as below.
        DepthRange::NearFar => (0..tiles)
            .map(|t| {
                let (lo, hi) = (
                    setup.near * (1.0 - DEPTH_SLACK),
                    setup.far * (1.0 + DEPTH_SLACK),
                );
                setup.cell_sphere(dims.tile_rect(t), lo, hi)
            })
            .collect(),
        DepthRange::Cells(bounds) | DepthRange::Culled(bounds, _) => bounds
            .iter()
            .enumerate()
            .map(|(cell, &[lo, hi])| {
                if lo > hi {
                    return (Vec3::ZERO, 0.0);
                }
                let lo = lo * (1.0 - DEPTH_SLACK);
                let hi = hi * (1.0 + DEPTH_SLACK);
                let sphere = setup.cell_sphere(dims.tile_rect(cell % tiles), lo, hi);
                match depth {
                    DepthRange::Culled(_, culls) => cone_sphere(sphere, culls[cell].view_box()),
                    _ => sphere,
                }
            })
            .collect(),
    };
    Some(spheres)
}

/// A light placed on the screen: the tiles its projected sphere covers, its view-distance
/// extent, and the light in view space.
struct Placed {
    tx0: u32,
    tx1: u32,
    ty0: u32,
    ty1: u32,
    w_min: f32,
    w_max: f32,
    view: ViewLight,
    /// A spot's sector box (`ViewLight::reach_box`), tested against cells' tight boxes.
    sector: Option<(Vec3, Vec3)>,
}

/// Every light's [`Placed`], or None for a light in no tile.
fn place(setup: &ViewSetup, dims: &GridDims, lights: &[Light]) -> Vec<Option<Placed>> {
    lights
        .par_iter()
        .map(|l| {
            let v = setup.to_view(l);
            let rect = project_sphere(setup, &v)?;
            let t = dims.tile_size;
            Some(Placed {
                tx0: rect.x0 / t,
                tx1: rect.x1 / t,
                ty0: rect.y0 / t,
                ty1: rect.y1 / t,
                w_min: -v.center.z - v.radius,
                w_max: -v.center.z + v.radius,
                sector: v.reach_box(),
                view: v,
            })
        })
        .collect()
}

/// The grid of (cell, light) pairs: per cell its offset and count, the lists in the order
/// the pairs come.
fn grid_from_pairs(dims: &GridDims, pairs: &[Vec<(u32, u32)>]) -> LightGrid {
    let mut counts = vec![0u32; dims.cell_count()];
    for &(c, _) in pairs.iter().flatten() {
        counts[c as usize] += 1;
    }
    let mut cells = Vec::with_capacity(counts.len());
    let mut offset = 0u32;
    for &n in &counts {
        cells.push([offset, n]);
        offset += n;
    }
    let mut indices = vec![0u32; offset as usize];
    let mut cursor: Vec<u32> = cells.iter().map(|c| c[0]).collect();
    for &(c, l) in pairs.iter().flatten() {
        indices[cursor[c as usize] as usize] = l;
        cursor[c as usize] += 1;
    }
    LightGrid {
        dims: *dims,
        cells,
        indices,
        zbins: None,
    }
}

/// Build the tile grid on the CPU.
pub fn assign_cpu(
    setup: &ViewSetup,
    dims: &GridDims,
    lights: &[Light],
    depth: DepthRange,
) -> LightGrid {
    let placed = place(setup, dims, lights);
    let mut rows: Vec<Vec<u32>> = vec![Vec::new(); dims.tiles_y as usize];
    for (i, p) in placed.iter().enumerate() {
        if let Some(p) = p {
            for ty in p.ty0..=p.ty1 {
                rows[ty as usize].push(i as u32);
            }
        }
    }
    let tiles = dims.tile_count();
    let overlaps = |p: &Placed, lo: f32, hi: f32| {
        lo <= hi && p.w_max >= lo * (1.0 - DEPTH_SLACK) && p.w_min <= hi * (1.0 + DEPTH_SLACK)
    };
    // `sphere_meets_box` in WGSL: the same `d`, compared squared; a spot's sector box must
    // overlap the cell's box too (`box_meets_box`).
    let in_cull = |p: &Placed, cell: usize| match depth {
        DepthRange::Culled(_, culls) => {
            let m = &culls[cell];
            depth_mask_meets(&m.mask, p.w_min, p.w_max)
                && m.view_box().is_none_or(|(lo, hi)| {
                    let (c, r) = (p.view.center, p.view.radius);
                    let d = (lo - c).max(Vec3::ZERO).max(c - hi);
                    d.dot(d) <= r * r && p.sector.is_none_or(|s| box_overlap(s, (lo, hi)) >= 0.0)
                })
        }
        _ => true,
    };
    // Spots culled by their cone test it against each cell's bounding sphere.
    let spheres = cell_spheres(setup, dims, &depth, lights);
    let cone_reaches = |p: &Placed, cell: usize| {
        spheres
            .as_ref()
            .is_none_or(|s| p.view.may_reach_sphere(s[cell].0, s[cell].1))
    };
    // (cell, light) pairs per row; a cell belongs to one row and lights are visited in index
    // order, so each cell's list comes out sorted.
    let pairs: Vec<Vec<(u32, u32)>> = rows
        .par_iter()
        .enumerate()
        .map(|(ty, row)| {
            let mut out = Vec::new();
            for &l in row {
                let p = placed[l as usize]
                    .as_ref()
                    .expect("bucketed lights are placed");
                for tx in p.tx0..=p.tx1 {
                    let tile = ty * dims.tiles_x as usize + tx as usize;
                    match depth.bounds() {
                        None => {
                            if cone_reaches(p, tile) {
                                out.push((tile as u32, l));
                            }
                        }
                        Some(bounds) => {
                            let k0 = dims.slice_of(p.w_min * (1.0 - DEPTH_SLACK));
                            let k1 = dims.slice_of(p.w_max * (1.0 + DEPTH_SLACK));
                            for layer in 0..dims.lists.layers() as usize {
                                for k in k0..=k1 {
                                    let cell =
                                        layer * dims.layer_cells() + k as usize * tiles + tile;
                                    let [lo, hi] = bounds[cell];
                                    if overlaps(p, lo, hi)
                                        && in_cull(p, cell)
                                        && cone_reaches(p, cell)
                                    {
                                        out.push((cell as u32, l));
                                    }
                                }
                            }
                        }
                    }
                }
            }
            out
        })
        .collect();
    grid_from_pairs(dims, &pairs)
}

/// `--assign cpu`: the papers' CPU pipeline (tiled-shading §6.3: a CPU-built grid "cannot be
/// completely pipelined"). With depth bounds the frame is submitted part-way and the bounds
/// are read back (the one wait a real-time frame makes); without them (`tiled_forward`) the
/// grid needs nothing from the GPU. The grid is uploaded before the rest of the frame.
struct CpuStrategy;

pub(super) fn create_strategy(_: &StrategyContext) -> Box<dyn AssignStrategy> {
    Box::new(CpuStrategy)
}

impl AssignStrategy for CpuStrategy {
    fn encode(&mut self, a: AssignFrame, enc: &mut FrameEncoder) -> Result<StrategyRun> {
        // The cell bounds and, for clusters, the slices the GPU spread over the frame's depth
        // range, read back in one wait (the papers' CPU pipeline waits for the depth anyway).
        let depth = a.source == CellSource::Depth;
        let mut parts = Vec::new();
        if depth {
            parts.push((a.bounds.buffer(), (a.dims.cell_count() * 8) as u64));
        }
        // The masks and boxes only where the kernel computes them (`--depth-mask on`,
        // `--cell-box on`).
        let culled = depth && a.bounds.culled();
        if culled {
            let bytes = a.dims.cell_count() * std::mem::size_of::<CellCull>();
            parts.push((a.bounds.cull_buffer(), bytes as u64));
        }
        if let Some(range) = a.range {
            parts.extend(range.readback());
        }
        let bytes = enc.download_all(&parts)?;
        let cell_bounds: Option<Vec<[f32; 2]>> =
            depth.then(|| bytemuck::pod_collect_to_vec(&bytes[0]));
        let culls: Option<Vec<CellCull>> = culled.then(|| bytemuck::pod_collect_to_vec(&bytes[1]));
        let dims = &match a.range {
            Some(_) => crate::culling::bounds::depth_range::sliced(
                a.dims,
                &bytes[parts.len() - 2],
                &bytes[parts.len() - 1],
            ),
            None => *a.dims,
        };
        // Clusters without depth (a caller's froxels): each cell spans its slice of
        // near..far, as the GPU strategies' bounds do (`slice_bounds`).
        let slices = (!depth && dims.slices > 1).then(|| {
            crate::culling::bounds::cell_bounds::slice_bounds(dims, [a.f.setup.near, a.f.setup.far])
        });
        let start = Instant::now();
        let range = match (&cell_bounds, &culls, &slices) {
            (Some(b), Some(m), _) => DepthRange::Culled(b, m),
            (Some(b), None, _) | (None, _, Some(b)) => DepthRange::Cells(b),
            _ => DepthRange::NearFar,
        };
        let grid = assign_cpu(&a.f.setup, dims, a.f.lights, range);
        let cpu_ms = start.elapsed().as_secs_f64() * 1e3;
        check_index_capacity(a.f.device, grid.indices.len() as u64, "cpu")?;
        a.grid.upload(a.f.device, a.f.queue, &grid);
        Ok(StrategyRun {
            cpu_ms,
            cpu_grid: Some(grid),
            cell_bounds,
            cell_culls: culls,
        })
    }
}
