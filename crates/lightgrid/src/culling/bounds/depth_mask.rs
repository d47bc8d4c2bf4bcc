//! 2.5D culling (`--depth-mask on`; Harada, McKee and Yang 2012, "A 2.5D culling for
//! Forward+"): a tile's depth bounds say only that its samples lie somewhere between its
//! nearest and farthest one, so a tile that holds a robot's edge and the street behind it
//! lists every light floating in the empty space between them. The paper cuts the tile's
//! depth range into 32 bins, keeps a 32-bit mask of the bins holding samples, and lists a
//! light only where the bins its view-depth span covers meet the mask.
//!
//! lightgrid keeps the mask per cell, so it works for clustered grids too (each cluster's
//! own bounds cut into 32 bins). A cell's mask is `[bits, lo, inv, 0]` (`lo` and `inv` as f32
//! bits): the bin of view distance `w` is `floor((w - lo) * inv)` clamped to `0..=31`, where
//! `lo` is the cell's nearest sample and `inv = 32 / (max - min)` (0 for a cell of one depth).
//! The kernel (`cell_bounds.wgsl`, after the bounds, a second sweep over the tile) sets the
//! bins of every sample's distance inflated by the slack `ASSIGN_DEPTH_SLACK`, as the bounds
//! themselves are, plus every bin of what is not a sample: an MSAA forward fragment's range
//! and, with one shared list, the range transparent fragments may lie in. The transparent
//! layer of separate lists has no mask: its fragments may lie anywhere in front of the opaque
//! samples, which is what its bounds already say.
//!
//! Every strategy applies the same test (`depth_mask_meets` in `depth_mask.wgsl`: the
//! gather/BVH frustum test and scatter's slice walk); the CPU twins call
//! [`depth_mask_meets`]. Binning needs only a subtraction and a multiplication, both
//! correctly rounded in WGSL, so from the same `(lo, inv)` the CPU bins a distance exactly as
//! the GPU does.

use crate::consts::{DEPTH_MASK_ALL, DEPTH_MASK_BINS};
use crate::culling::grid::{GridDims, GridLists};
use crate::scene::ViewSetup;

/// One cell's mask: `[bits, lo, inv, 0]` (`lo`, `inv`: f32 bits).
pub type CellMask = [u32; 4];

/// No mask: every bin (the cells of a grid without `--depth-mask on`).
pub const NO_MASK: CellMask = [DEPTH_MASK_ALL, 0, 0, 0];

fn bin(w: f32, m: &CellMask) -> u32 {
    let b = ((w - f32::from_bits(m[1])) * f32::from_bits(m[2])).floor();
    b.clamp(0.0, (DEPTH_MASK_BINS - 1) as f32) as u32
}

/// The bits of the bins `[w0, w1]` covers (none when `w0 > w1`); `depth_mask_span` in WGSL.
pub(crate) fn depth_mask_span(w0: f32, w1: f32, m: &CellMask) -> u32 {
    let (b0, b1) = (bin(w0, m), bin(w1, m));
    (u32::MAX >> (31 - b1)) & (u32::MAX << b0)
}

/// Does the view-depth span `[w0, w1]` meet a bin of `m` that holds samples?
pub(crate) fn depth_mask_meets(m: &CellMask, w0: f32, w1: f32) -> bool {
    m[0] == DEPTH_MASK_ALL || depth_mask_span(w0, w1, m) & m[0] != 0
}

/// A mask's bins over the bounds `[lo, hi]`, with no bit set yet (what the kernel computes
/// from the cell's bounds; the division may round differently there, so tests take the
/// GPU's scales).
#[cfg(test)]
pub(crate) fn mask_scale(b: [f32; 2]) -> CellMask {
    let inv = if b[1] > b[0] {
        DEPTH_MASK_BINS as f32 / (b[1] - b[0])
    } else {
        0.0
    };
    [0, b[0].to_bits(), inv.to_bits(), 0]
}

/// The bins of `[lo, hi]` inflated by `slack` on both sides (none for an empty range).
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
fn inflated_span(lo: f32, hi: f32, slack: f32, m: &CellMask) -> u32 {
    if lo > hi {
        return 0;
    }
    depth_mask_span(lo * (1.0 - slack), hi * (1.0 + slack), m)
}

/// CPU twin of the kernel's masks for a grid whose bounds were computed with both sides
/// (`--depth-bounds both`) and no MSAA forward fragments: every opaque cell's bins holding
/// the samples of `planes` (as `cell_bounds_cpu_samples` reads them), each sample's distance
/// inflated by `slack` (the kernel's `ASSIGN_DEPTH_SLACK`; tests bracket round-off with a
/// smaller and a larger one), with the bins over `scales` (per cell `[_, lo, inv, _]`, from
/// `mask_scale` or the GPU's own masks). With a shared list, `transparent[cell]` is the
/// range the cell's transparent fragments may lie in (every bin of it is set); the
/// transparent layer of separate lists gets [`NO_MASK`].
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub fn cell_masks_cpu(
    setup: &ViewSetup,
    dims: &GridDims,
    planes: &[&[f32]],
    scales: &[CellMask],
    transparent: Option<&[[f32; 2]]>,
    slack: f32,
) -> Vec<CellMask> {
    let mut masks: Vec<CellMask> = scales.iter().map(|s| [0, s[1], s[2], 0]).collect();
    crate::culling::bounds::samples::for_each_sample_cell(setup, dims, planes, |_, w, cell| {
        let m = masks[cell];
        masks[cell][0] |= inflated_span(w, w, slack, &m);
    });
    let layer = dims.layer_cells();
    match (dims.lists, transparent) {
        (GridLists::Shared, Some(t)) => {
            for cell in 0..layer {
                let m = masks[cell];
                masks[cell][0] |= inflated_span(t[cell][0], t[cell][1], slack, &m);
            }
        }
        (GridLists::Separate, _) => {
            for m in &mut masks[layer..] {
                *m = NO_MASK;
            }
        }
        _ => {}
    }
    masks
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cell over [10, 42]: 32 bins of 1.
    fn cell(bits: u32) -> CellMask {
        let mut m = mask_scale([10.0, 42.0]);
        m[0] = bits;
        m
    }

    #[test]
    fn bins_are_equal_slices_of_the_bounds() {
        let m = cell(0);
        assert_eq!(f32::from_bits(m[2]), 1.0);
        assert_eq!(depth_mask_span(10.0, 10.5, &m), 1);
        assert_eq!(depth_mask_span(11.0, 11.0, &m), 2);
        assert_eq!(depth_mask_span(12.5, 14.5, &m), 0b11100);
        assert_eq!(depth_mask_span(41.9, 41.95, &m), 1 << 31);
        // Beyond the bounds clamps to the end bins.
        assert_eq!(depth_mask_span(0.0, 100.0, &m), u32::MAX);
        assert_eq!(depth_mask_span(50.0, 60.0, &m), 1 << 31);
        assert_eq!(depth_mask_span(1.0, 2.0, &m), 1);
        // An empty span covers nothing.
        assert_eq!(depth_mask_span(20.0, 19.0, &m), 0);
    }

    #[test]
    fn a_light_between_two_surfaces_misses_and_one_on_them_meets() {
        // Samples at 10-11 (a robot) and 40-42 (the street behind it).
        let m = cell(0b11 | (0b111 << 29));
        assert!(!depth_mask_meets(&m, 15.0, 25.0), "the gap between them");
        assert!(depth_mask_meets(&m, 5.0, 10.5), "reaches the robot");
        assert!(depth_mask_meets(&m, 39.5, 45.0), "reaches the street");
        assert!(depth_mask_meets(&m, 0.0, 100.0), "spans both");
        assert!(depth_mask_meets(&NO_MASK, 15.0, 25.0), "no mask lists it");
    }

    #[test]
    fn a_cell_of_one_depth_puts_everything_in_bin_zero() {
        let mut m = mask_scale([7.0, 7.0]);
        assert_eq!(f32::from_bits(m[2]), 0.0);
        m[0] = 1;
        assert!(depth_mask_meets(&m, 6.0, 8.0));
        assert_eq!(depth_mask_span(1e30, 1e30, &m), 1);
    }
}
