//! Light-assignment strategies behind one trait, one file and one registry row each (like the
//! pipelines): `registry.rs` maps every `--assign` value to the type that records it.
//!
//! A strategy reads the cell bounds (`cell_bounds.rs`), the lights and the camera, and leaves
//! the frame's grid in [`GridBuffers`] (the paper's three arrays, group 1 of the shading pass).
//! GPU strategies record everything into the frame's one submission; their buffers are sized
//! from the frame counters of earlier frames ([`AssignStrategy::observe`]), and a frame whose
//! lists did not fit is reported by those counters, never passed off as right.

pub(crate) mod assign_cpu;
pub(crate) mod bvh;
pub(crate) mod bvh_gpu;
pub(crate) mod gather;
pub(crate) mod gpu_assign;
pub(crate) mod radix_sort;
pub(crate) mod registry;
pub(crate) mod scan;
pub(crate) mod scatter;
pub(crate) mod zbin;

/// `light_cull(l)` in LightCuller's kernels: group 0's light records (after the scene
/// bindings).
pub(crate) const LIGHT_RECORDS_WGSL: &str = include_str!("../embed/light_records.wgsl");
/// `light_cull(l)` from the renderer's group 0, its lights and their bounds (the
/// single-kernel tiled deferred pass).
pub(crate) const LIGHT_CULL_SCENE_WGSL: &str = include_str!("../embed/light_cull_scene.wgsl");

/// `tile_frustum` / `light_in_tile` (needs the scene bindings and a `light_cull`), with the 2.5D depth mask and
/// tight-cell box tests.
pub(crate) const TILE_FRUSTUM_WGSL: &[&str] = &[
    crate::culling::bounds::DEPTH_MASK_WGSL,
    crate::culling::bounds::CELL_BOX_WGSL,
    include_str!("tile_frustum.wgsl"),
];

use crate::culling::bounds::cell_bounds::CellBoundsPass;
use crate::culling::bounds::depth_range::DepthRangePass;
use crate::culling::frame::{check_index_capacity, max_index_entries, CellSource, CullFrame};
use crate::culling::grid::{GridBuffers, GridDims, LightGrid};
use crate::error::Result;
use crate::frame::FrameEncoder;
use crate::gpu::CounterValues;

/// What a strategy works on in one frame.
pub struct AssignFrame<'a, 'f> {
    pub f: &'a CullFrame<'f>,
    /// The grid it fills.
    pub grid: &'a mut GridBuffers,
    /// The cell bounds it reads (recorded before it in the same encoder).
    pub bounds: &'a CellBoundsPass,
    /// For a clustered grid over the depth buffer, where the frame's slicing range is (the
    /// GPU spreads the slices: `dims` holds near..far until it is read back).
    pub range: Option<&'a DepthRangePass>,
    pub dims: &'a GridDims,
    /// Where the bounds came from (`NearFar`: every cell spans its slice of near..far).
    pub source: CellSource,
}

/// What a strategy produced on the CPU side of a frame.
#[derive(Default)]
pub struct StrategyRun {
    /// CPU time of the assignment itself (`assign_cpu`, the BVH build).
    pub cpu_ms: f64,
    /// The grid, when the CPU built it (analysis reads it instead of downloading it).
    pub cpu_grid: Option<LightGrid>,
    /// The cell bounds, when the strategy read them back.
    pub cell_bounds: Option<Vec<[f32; 2]>>,
    /// The cells' depth masks, read back with the bounds.
    pub cell_culls: Option<Vec<crate::culling::bounds::cell_box::CellCull>>,
}

/// One light-assignment strategy.
pub(crate) trait AssignStrategy {
    /// Record this frame's assignment into `enc` (after the cell bounds).
    fn encode(&mut self, a: AssignFrame, enc: &mut FrameEncoder) -> Result<StrategyRun>;
    /// Size buffers from a finished frame's counters (an earlier frame's, read back without
    /// waiting, or in analysis the frame's own). Errors when the grid cannot fit the device.
    fn observe(&mut self, _device: &wgpu::Device, _values: &CounterValues) -> Result<()> {
        Ok(())
    }
    /// Index entries of the grid a finished frame built (its counters).
    fn grid_entries(&self, _values: &CounterValues) -> u32 {
        0
    }
    /// The grid's shape for a frame with `lights` lights (a z-binned grid records the light
    /// count its masks have bits for), before anything is recorded.
    fn shape(&self, dims: GridDims, _lights: usize) -> GridDims {
        dims
    }
    /// The grid the last frame built, read back (analysis): per-cell lists by default.
    fn read_grid(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        buffers: &GridBuffers,
        dims: &GridDims,
        values: &CounterValues,
    ) -> Result<LightGrid> {
        buffers.read_lists(device, queue, dims, self.grid_entries(values))
    }
}

/// What a strategy needs to create its GPU objects.
pub struct StrategyContext<'a> {
    pub device: &'a wgpu::Device,
    /// Group 0 of the culling kernels ([`cull_layout`]).
    pub cull_layout: &'a wgpu::BindGroupLayout,
    /// Index entries (or scatter's pairs) the lists start with; they grow from the counters.
    pub index_capacity: u64,
}

/// Capacity of a list sized from earlier frames: grows to 5/4 of what a frame needed, never
/// shrinks, and refuses sizes the device cannot bind.
pub struct ListCapacity {
    pub entries: u64,
    stage: &'static str,
}

impl ListCapacity {
    pub fn new(stage: &'static str, initial: u64) -> Self {
        ListCapacity {
            entries: initial,
            stage,
        }
    }

    /// A frame needed `needed` entries: grow to fit it with headroom.
    pub fn observe(&mut self, device: &wgpu::Device, needed: u64) -> Result<()> {
        check_index_capacity(device, needed, self.stage)?;
        if needed > self.entries {
            let limit = max_index_entries(device);
            self.entries = (needed + needed / 4).min(limit);
        }
        Ok(())
    }
}
