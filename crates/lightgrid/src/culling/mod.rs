//! Light assignment: the light grid contract (tiled-shading §6.2), the cell bounds every
//! strategy reads, the strategies (CPU; GPU gather, scatter, BVH and z-binning) with their CPU twins,
//! [`LightCuller`] (over `builder.rs`'s `GridBuilder`) which runs the one `--assign` names, for lightgrid's renderer and for any other wgpu renderer, and the brute-force oracle that proves
//! nothing is ever missed.

mod assign_cpu;
mod builder;
mod bvh;
mod bvh_gpu;
mod cell_bounds;
mod cell_box;
mod culler;
mod depth_mask;
mod depth_range;
mod fragment_bounds;
mod gather;
mod gpu_assign;
mod grid;
mod oracle;
mod radix_sort;
mod registry;
mod scan;
mod scatter;
mod spot_ray;
mod strategy;
mod zbin;

pub use crate::frame::{Assign, AUTO_GATHER_MAX_LIGHTS};
pub use crate::scene::{ViewLight, ViewSetup};
pub use assign_cpu::{assign_cpu, project_sphere, DepthRange, PixelRect};
pub use builder::BuiltGrid;
pub(crate) use builder::{CellSource, GridSetup};
pub use bvh::{build_bvh, bvh_levels, morton_code, traverse_bvh_cpu, BvhNode, LightBvh};
pub use cell_bounds::{
    cell_bounds_cpu, cell_bounds_cpu_samples, open_bounds, CellBoundsPass, EMPTY_CELL,
};
pub use cell_box::{
    box_overlap, cell_boxes_cpu, cone_sphere, rect_box, sphere_box_gap, view_extent, CellCull,
    NO_CULL,
};
pub use culler::{
    CullConfig, CullError, CullGrid, CullInput, CullInputs, CullLight, CullReport, CullStrategy,
    LightCuller,
};
pub use depth_mask::{
    cell_masks_cpu, depth_mask_meets, depth_mask_span, mask_scale, CellMask, NO_MASK,
};
pub use depth_range::{depth_range_cpu, slicing_range, DepthRangePass};
pub use gather::{assign_gather_cpu, assign_gather_cpu_masked, gather_margins};
pub use gpu_assign::check_index_capacity;
pub use grid::{GridBuffers, GridDims, GridLists, LightGrid};
pub use oracle::{
    ideal_fragment_computations, ideal_fragment_counts, ideal_lighting_computations,
    ideal_pixel_counts, oracle_fragment_lights, oracle_tile_lights,
};
pub use registry::{find_strategy, StrategyInfo, ASSIGN_VALUES, STRATEGIES};
pub use spot_ray::{ray_test_count, RayTestCount};
pub use strategy::AssignStrategy;
pub(crate) use strategy::{bind_cull_group, cull_layout, CullFrame};
pub use zbin::{ordered_bits, zbins_cpu, ZBins};

pub use crate::consts::pass_labels as labels;

/// Per-tile depth min/max inside a workgroup (the single-kernel tiled deferred pipeline).
pub(crate) const TILE_DEPTH_WGSL: &str = include_str!("tile_depth.wgsl");
/// `tile_frustum` / `light_in_tile` (needs the scene bindings), with the 2.5D depth mask and
/// tight-cell box tests.
pub(crate) const TILE_FRUSTUM_WGSL: &str = concat!(
    include_str!("depth_mask.wgsl"),
    include_str!("cell_box.wgsl"),
    include_str!("tile_frustum.wgsl")
);
/// The 2.5D depth mask's bins (`depth_mask.rs`) and the tight cells' record (`cell_box.rs`).
pub(crate) const CELL_CULL_WGSL: &str = concat!(
    include_str!("depth_mask.wgsl"),
    include_str!("cell_box.wgsl")
);

/// Every assignment shader, for the validation test: every value of the keyed stages.
pub(crate) fn shaders() -> Vec<crate::shader::ComposedShader> {
    use crate::shader::ShaderKey;
    let mut out = cell_bounds::CellBoundsKey::all_shaders();
    out.extend(depth_range::DepthRangeKey::all_shaders());
    out.extend([
        fragment_bounds::shader(),
        scan::shader(),
        radix_sort::shader(),
        gpu_assign::gather_shader(),
        gpu_assign::bvh_shader(),
        bvh_gpu::shader(),
        scatter::shader(),
        culler::prep_shader(),
        zbin::shader(),
    ]);
    out.extend(culler::embed_shaders());
    out
}
