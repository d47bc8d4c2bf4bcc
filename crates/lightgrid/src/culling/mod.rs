//! Light assignment: the light grid contract (tiled-shading §6.2), the cell bounds every
//! strategy reads, the strategies (CPU; GPU gather, scatter, BVH and z-binning) with their CPU twins,
//! [`LightCuller`] (over `builder.rs`'s `GridBuilder`) which runs the one `--assign` names, for lightgrid's renderer and for any other wgpu renderer, and the brute-force oracle that proves
//! nothing is ever missed.

mod bounds;
mod builder;
mod embed;
mod frame;
mod grid;
mod oracle;
mod spot_ray;
mod strategies;
pub(crate) mod texture_grid;

pub use crate::frame::{Assign, CullConfig, AUTO_GATHER_MAX_LIGHTS};
pub use crate::scene::{ViewLight, ViewSetup};
pub(crate) use bounds::cell_bounds::cell_bounds_cpu_samples;
pub use bounds::cell_box::CellCull;
pub use embed::culler::{
    CullError, CullExtras, CullInput, CullInputs, CullLight, CullReport, LightCuller, LightLayout,
};
pub(crate) use grid::GridBuffers;
pub use grid::{GridDims, GridLists, LightGrid, ZBins};
pub use oracle::ideal_lighting_computations;
pub(crate) use oracle::{ideal_fragment_counts, ideal_pixel_counts};
pub use spot_ray::{ray_test_count, RayTestCount};
pub use strategies::assign_cpu::{assign_cpu, DepthRange};
pub(crate) use strategies::registry::ASSIGN_VALUES;

/// The CPU twin of every culling stage, the brute-force oracle and the strategies' registry,
/// for lightgrid's own tests: public as `lightgrid::testing` with the `testing` feature only.
#[cfg(feature = "testing")]
pub(crate) mod testing {
    pub use super::bounds::cell_bounds::{
        cell_bounds_cpu, cell_bounds_cpu_samples, open_bounds, EMPTY_CELL,
    };
    pub use super::bounds::cell_box::{cell_boxes_cpu, CellCull};
    pub use super::bounds::depth_mask::{cell_masks_cpu, CellMask, NO_MASK};
    pub use super::bounds::depth_range::{depth_range_cpu, slicing_range};
    pub use super::frame::check_index_capacity;
    pub use super::grid::GridBuffers;
    pub use super::oracle::{oracle_fragment_lights, oracle_tile_lights};
    pub use super::strategies::assign_cpu::{project_sphere, PixelRect};
    pub use super::strategies::bvh::{build_bvh, morton_code, traverse_bvh_cpu, BvhNode, LightBvh};
    pub use super::strategies::gather::{assign_gather_cpu, assign_gather_cpu_masked};
    pub use super::strategies::registry::{StrategyInfo, STRATEGIES};
    pub use super::strategies::zbin::zbins_cpu;
}

pub use crate::consts::pass_labels as labels;

/// The key of [`LightCuller::fragment_bounds_wgsl`] (lightgrid's renderer composes its
/// fragment-bounds shader from its parts).
pub(crate) fn fragment_bounds_key(group: u32) -> embed::culler::CallerFragmentsKey {
    embed::culler::CallerFragmentsKey { group }
}

pub(crate) use bounds::TILE_DEPTH_WGSL;
pub(crate) use strategies::{LIGHT_CULL_SCENE_WGSL, TILE_FRUSTUM_WGSL};

/// Every assignment shader, for the validation test: every value of the keyed stages.
pub(crate) fn shaders() -> Vec<crate::shader::ComposedShader> {
    use crate::shader::ShaderKey;
    let mut out = bounds::cell_bounds::CellBoundsKey::all_shaders();
    out.extend(bounds::depth_range::DepthRangeKey::all_shaders());
    out.extend([
        strategies::scan::shader(),
        strategies::radix_sort::shader(),
        strategies::gpu_assign::gather_shader(),
        strategies::gpu_assign::bvh_shader(),
        strategies::bvh_gpu::shader(),
        strategies::scatter::shader(),
        embed::culler::prep_shader(),
        strategies::zbin::shader(),
    ]);
    out.extend(embed::culler::embed_shaders());
    out
}
