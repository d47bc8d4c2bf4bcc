//! Tight cells (`--cell-box on`; Olsson, Billeter and Assarsson 2012 bound each cluster by its
//! own samples, and what later engines call tight clusters): a cell's frustum piece is the
//! space its samples *may* occupy, a box of the space they *do* occupy is much smaller
//! wherever a cell holds a slanted surface or a silhouette. Each occupied cell keeps the
//! view-space box of its samples' pixel footprints (every sample's pixel at its view distance
//! widened by the slack `ASSIGN_DEPTH_SLACK`, so every MSAA sample position of the pixel lies
//! inside), and a light is listed only where its sphere reaches the box: the exact
//! closest-point test, `|max(lo - c, 0, c - hi)| <= r`. A spot's sector box (and a BVH node's
//! box) must overlap it too, and a spot's cone is tested against the box's bounding sphere
//! ([`cone_sphere`]) instead of the frustum piece's.
//!
//! What is not a sample widens the box by its whole tile frustum over its depth range: an MSAA
//! forward fragment's range and, with one shared list, the range transparent fragments may
//! lie in; the transparent layer of separate lists has no box (its fragments may lie
//! anywhere in front of the opaque samples).
//!
//! The box travels with the 2.5D depth mask in one per-cell record, [`CellCull`] (48 bytes:
//! the mask, then the box's corners; `lo.w` is 1 when the cell has a box), so a grid with
//! both needs no second binding. The kernel reduces the footprints with u32 atomics over
//! order-preserving bit patterns of the signed coordinates (`cell_box.wgsl`); its CPU twin is
//! [`cell_boxes_cpu`], and every strategy's twin applies [`sphere_box_gap`] and
//! [`box_overlap`] as the WGSL does.

use crate::culling::bounds::depth_mask::{CellMask, NO_MASK};
use crate::culling::grid::{GridDims, GridLists};
use crate::scene::ViewSetup;
use glam::Vec3;

/// One cell's culling record beyond its depth bounds: its 2.5D depth mask (`depth_mask.rs`)
/// and its tight view-space box (`lo.w` = 1 when it has one). WGSL: `CellCull`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CellCull {
    /// The 2.5D depth mask: which of 32 bins of the cell's bounds hold samples.
    pub mask: CellMask,
    /// The box's view-space minimum corner; `w` = 1 when the cell has a box.
    pub lo: [f32; 4],
    /// The box's view-space maximum corner.
    pub hi: [f32; 4],
}

/// No mask and no box (cells of a grid without `--depth-mask on` or `--cell-box on`).
pub(crate) const NO_CULL: CellCull = CellCull {
    mask: NO_MASK,
    lo: [0.0; 4],
    hi: [0.0; 4],
};

impl CellCull {
    /// The cell's view-space box, when it has one.
    pub fn view_box(&self) -> Option<(Vec3, Vec3)> {
        (self.lo[3] != 0.0).then(|| (Vec3::from_slice(&self.lo), Vec3::from_slice(&self.hi)))
    }

    /// A record with this mask and no box.
    pub fn with_mask(mask: CellMask) -> CellCull {
        CellCull { mask, ..NO_CULL }
    }
}

/// The range of `n / scale * w` over `n` in `{n0, n1}` and `w` in `{w0, w1}`: one view-space
/// axis of a screen rectangle's frustum piece (`view_extent` in WGSL, the same operations).
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub(crate) fn view_extent(n0: f32, n1: f32, scale: f32, w0: f32, w1: f32) -> [f32; 2] {
    let (a, b) = (n0 / scale, n1 / scale);
    let v = [a * w0, a * w1, b * w0, b * w1];
    [
        v[0].min(v[1]).min(v[2].min(v[3])),
        v[0].max(v[1]).max(v[2].max(v[3])),
    ]
}

/// The view-space box of the pixel rectangle `[x0, x1] × [y0, y1]` (pixel edges) over view
/// distances `[w0, w1]` (`rect_box` in WGSL).
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub(crate) fn rect_box(
    setup: &ViewSetup,
    x: [f32; 2],
    y: [f32; 2],
    w0: f32,
    w1: f32,
) -> (Vec3, Vec3) {
    let (sx, sy) = (setup.width as f32, setup.height as f32);
    let ex = view_extent(
        x[0] / sx * 2.0 - 1.0 + setup.p20,
        x[1] / sx * 2.0 - 1.0 + setup.p20,
        setup.p00,
        w0,
        w1,
    );
    let ey = view_extent(
        1.0 - y[0] / sy * 2.0 + setup.p21,
        1.0 - y[1] / sy * 2.0 + setup.p21,
        setup.p11,
        w0,
        w1,
    );
    (Vec3::new(ex[0], ey[0], -w1), Vec3::new(ex[1], ey[1], -w0))
}

/// How far the sphere `(c, r)` is from the box (`> 0`: it misses; `sphere_meets_cell_box` in
/// WGSL decides `|d|² <= r²` on the same `d`).
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub(crate) fn sphere_box_gap(lo: Vec3, hi: Vec3, c: Vec3, r: f32) -> f32 {
    let d = (lo - c).max(Vec3::ZERO).max(c - hi);
    d.length() - r
}

/// How far two boxes overlap on their least overlapping axis (`< 0`: they are apart;
/// `box_meets_box` in WGSL decides `a.lo <= b.hi && a.hi >= b.lo` on every axis).
pub(crate) fn box_overlap(a: (Vec3, Vec3), b: (Vec3, Vec3)) -> f32 {
    (b.1 - a.0).min(a.1 - b.0).min_element()
}

/// The sphere a spot's cone is tested against (`cone_sphere` in WGSL): the bounding sphere
/// of the cell's tight box where the cell has one and it is the smaller, else `frustum`, the
/// frustum piece's. Either holds every point the cell shades, so the cone test stays
/// conservative; the box's is smaller wherever the box is (a cell's samples on one surface).
pub(crate) fn cone_sphere(frustum: (Vec3, f32), cell_box: Option<(Vec3, Vec3)>) -> (Vec3, f32) {
    match cell_box {
        Some((lo, hi)) => {
            let r = (hi - lo).length() * 0.5;
            if r < frustum.1 {
                ((lo + hi) * 0.5, r)
            } else {
                frustum
            }
        }
        None => frustum,
    }
}

#[cfg_attr(not(feature = "testing"), allow(dead_code))]
fn union(a: Option<(Vec3, Vec3)>, b: (Vec3, Vec3)) -> Option<(Vec3, Vec3)> {
    Some(a.map_or(b, |a| (a.0.min(b.0), a.1.max(b.1))))
}

/// CPU twin of the kernel's boxes for a grid whose bounds were computed with both sides
/// (`--depth-bounds both`): per opaque cell the box of its samples' pixel footprints in
/// `planes` (as `cell_bounds_cpu_samples` reads them, each distance widened by `slack`; tests
/// bracket round-off with a smaller and a larger one), its depth from `bounds` (the GPU's,
/// widened by `slack`), and, where `extra[cell]` is a range (MSAA forward fragments, a shared
/// list's transparent range), the cell's tile over that range. The transparent layer of
/// separate lists has none.
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub fn cell_boxes_cpu(
    setup: &ViewSetup,
    dims: &GridDims,
    planes: &[&[f32]],
    bounds: &[[f32; 2]],
    extra: Option<&[[f32; 2]]>,
    slack: f32,
) -> Vec<Option<(Vec3, Vec3)>> {
    let mut boxes: Vec<Option<(Vec3, Vec3)>> = vec![None; dims.cell_count()];
    crate::culling::bounds::samples::for_each_sample_cell(
        setup,
        dims,
        planes,
        |(x, y), w, cell| {
            let (px, py) = (x as f32, y as f32);
            let b = rect_box(
                setup,
                [px, px + 1.0],
                [py, py + 1.0],
                w * (1.0 - slack),
                w * (1.0 + slack),
            );
            boxes[cell] = union(boxes[cell], b);
        },
    );
    let layer = dims.layer_cells();
    for (cell, b) in boxes.iter_mut().enumerate().take(layer) {
        if let Some(r) = extra.map(|e| e[cell]).filter(|r| r[0] <= r[1]) {
            let (x0, y0, x1, y1) = dims.tile_rect(cell % dims.tile_count());
            let t = rect_box(
                setup,
                [x0 as f32, x1 as f32],
                [y0 as f32, y1 as f32],
                r[0] * (1.0 - slack),
                r[1] * (1.0 + slack),
            );
            *b = union(*b, t);
        }
        let [w0, w1] = bounds[cell];
        if let Some(bx) = b {
            if w0 <= w1 {
                bx.0.z = -w1 * (1.0 + slack);
                bx.1.z = -w0 * (1.0 - slack);
            }
        }
    }
    if dims.lists == GridLists::Separate {
        for b in &mut boxes[layer..] {
            *b = None;
        }
    }
    boxes
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_closest_point_test_is_exact_at_a_corner() {
        let (lo, hi) = (Vec3::ZERO, Vec3::ONE);
        // A sphere off the corner (2, 2, 2): distance sqrt(3) to the corner (1, 1, 1).
        let c = Vec3::splat(2.0);
        assert!(sphere_box_gap(lo, hi, c, 1.7) > 0.0);
        assert!(sphere_box_gap(lo, hi, c, 1.75) < 0.0);
        // Inside: the gap is -r.
        assert_eq!(sphere_box_gap(lo, hi, Vec3::splat(0.5), 0.25), -0.25);
        // Beside a face, only that axis counts.
        assert!((sphere_box_gap(lo, hi, Vec3::new(0.5, 3.0, 0.5), 1.0) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn boxes_overlap_on_every_axis_or_not_at_all() {
        let a = (Vec3::ZERO, Vec3::ONE);
        assert!(box_overlap(a, (Vec3::splat(0.5), Vec3::splat(2.0))) > 0.0);
        assert!(box_overlap(a, (Vec3::new(0.5, 1.5, 0.5), Vec3::splat(2.0))) < 0.0);
        assert_eq!(
            box_overlap(a, (Vec3::ONE, Vec3::splat(2.0))),
            0.0,
            "touching"
        );
    }

    #[test]
    fn a_view_extent_takes_the_signs_into_account() {
        // Left of centre (negative n) the far distance gives the minimum.
        assert_eq!(view_extent(-0.5, 0.5, 1.0, 2.0, 4.0), [-2.0, 2.0]);
        assert_eq!(view_extent(0.25, 0.5, 0.5, 2.0, 4.0), [1.0, 4.0]);
        assert_eq!(view_extent(-0.5, -0.25, 0.5, 2.0, 4.0), [-4.0, -1.0]);
    }

    #[test]
    fn the_cone_sphere_is_the_boxs_where_smaller_and_holds_its_corners() {
        let frustum = (Vec3::new(0.0, 0.0, -10.0), 5.0);
        assert_eq!(cone_sphere(frustum, None), frustum);
        let (lo, hi) = (Vec3::new(-1.0, 2.0, -12.0), Vec3::new(1.0, 3.0, -9.0));
        let (c, r) = cone_sphere(frustum, Some((lo, hi)));
        assert_eq!(c, Vec3::new(0.0, 2.5, -10.5));
        for i in 0..8 {
            let corner = Vec3::select(glam::BVec3::new(i & 1 != 0, i & 2 != 0, i & 4 != 0), hi, lo);
            assert!(
                corner.distance(c) <= r * (1.0 + 1e-6),
                "corner {corner} outside"
            );
        }
        // A box larger than the frustum piece's sphere leaves that sphere.
        let big = (Vec3::splat(-10.0), Vec3::splat(10.0));
        assert_eq!(cone_sphere(frustum, Some(big)), frustum);
    }

    #[test]
    fn no_cull_has_no_box_and_no_mask() {
        assert_eq!(NO_CULL.view_box(), None);
        assert_eq!(NO_CULL.mask, NO_MASK);
        assert_eq!(std::mem::size_of::<CellCull>(), 48);
    }
}
