//! The CPU walk over a depth buffer's samples into the cells they lie in, which the CPU twins
//! of the depth masks (`depth_mask.rs`) and the tight boxes (`cell_box.rs`) share.

use crate::consts::ASSIGN_DEPTH_SLACK;
use crate::culling::grid::GridDims;
use crate::scene::ViewSetup;

/// Every sample of `planes` (per-sample depth planes, as `cell_bounds_cpu_samples` reads
/// them) off the background, with its pixel, its view distance and each cell its distance
/// lies in within the slack `ASSIGN_DEPTH_SLACK` (as the kernel's `include_depth`; the same
/// cell twice when it lies in one): the walk the masks' and boxes' CPU twins share.
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub(crate) fn for_each_sample_cell(
    setup: &ViewSetup,
    dims: &GridDims,
    planes: &[&[f32]],
    mut f: impl FnMut((u32, u32), f32, usize),
) {
    for (y, x) in (0..dims.height).flat_map(|y| (0..dims.width).map(move |x| (y, x))) {
        for plane in planes {
            let d = plane[(y * dims.width + x) as usize];
            if crate::depth::is_background(d) {
                continue;
            }
            let w = setup.view_distance(d);
            let tile = dims.tile_of(x, y);
            let k0 = dims.slice_of(w * (1.0 - ASSIGN_DEPTH_SLACK));
            let k1 = dims.slice_of(w * (1.0 + ASSIGN_DEPTH_SLACK));
            for k in [k0, k1] {
                f((x, y), w, k as usize * dims.tile_count() + tile);
            }
        }
    }
}
