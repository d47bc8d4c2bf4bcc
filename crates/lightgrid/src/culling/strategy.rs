//! Light-assignment strategies behind one trait, one file and one registry row each (like the
//! pipelines): `registry.rs` maps every `--assign` value to the type that records it.
//!
//! A strategy reads the cell bounds (`cell_bounds.rs`), the lights and the camera, and leaves
//! the frame's grid in [`GridBuffers`] (the paper's three arrays, group 1 of the shading pass).
//! GPU strategies record everything into the frame's one submission; their buffers are sized
//! from the frame counters of earlier frames ([`AssignStrategy::observe`]), and a frame whose
//! lists did not fit is reported by those counters, never passed off as right.

use super::cell_bounds::CellBoundsPass;
use super::depth_range::DepthRangePass;
use super::{GridBuffers, GridDims, LightGrid};
use crate::error::{Error, Result};
use crate::frame::{FrameEncoder, FrameInputs};
use crate::gpu::CounterValues;
use crate::scene::{Light, ViewSetup};

/// What every culling stage reads in one frame: group 0 of its kernels ([`cull_layout`]: the
/// camera uniforms, the lights and their bounding spheres in camera-relative space, the frame
/// counters), the depth buffer, and the camera on the CPU. The renderer fills it from its
/// frame ([`CullFrame::of`]); [`super::LightCuller`] from a caller's inputs.
pub struct CullFrame<'a> {
    pub device: &'a wgpu::Device,
    pub queue: &'a wgpu::Queue,
    /// Group 0 of the culling kernels ([`cull_layout`]).
    pub bind_group: &'a wgpu::BindGroup,
    /// The counters bound at group 0 binding 3 (indirect dispatch arguments are copied out).
    pub counters: &'a wgpu::Buffer,
    /// The frame's depth (as recorded so far); `None` only for `CellSource::NearFar`.
    pub depth: Option<&'a wgpu::TextureView>,
    pub setup: ViewSetup,
    pub light_count: usize,
    /// The lights on the CPU (world space), for the strategies that work there (`cpu`,
    /// `bvh`); empty where only the GPU has them ([`super::LightCuller`]).
    pub lights: &'a [Light],
    /// The frame draws transparent geometry (the grid's transparent lists are built).
    pub transparency: bool,
    /// The renderer's frame: with MSAA its forward fragments' distances widen the cell bounds
    /// (`fragment_bounds.rs` draws its geometry). `None` for a caller's depth buffer.
    pub scene: Option<&'a FrameInputs<'a>>,
}

impl<'a> CullFrame<'a> {
    /// The renderer's frame as the culling stages see it.
    pub fn of(f: &'a FrameInputs<'a>) -> Self {
        CullFrame {
            device: f.device,
            queue: f.queue,
            bind_group: f.cull_bind_group,
            counters: f.counters,
            depth: Some(&f.targets.depth),
            setup: f.setup,
            light_count: f.lights.len(),
            lights: f.lights,
            transparency: f.has_transparency(),
            scene: Some(f),
        }
    }

    /// The depth view (a `CellSource::Depth` grid always has one).
    pub fn depth(&self) -> &wgpu::TextureView {
        self.depth
            .expect("a grid over the depth buffer is given the depth")
    }
}

/// Group 0 of every culling kernel: `shading/scene_bindings.wgsl`'s bindings 0 (the frame
/// uniforms), 1 (lights), 3 (frame counters) and 4 (bounding spheres); the materials, MSAA
/// pixel counts and textures of the renderer's group 0 are not part of it.
pub fn cull_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    use crate::gpu::{STORAGE_READ, STORAGE_RW, UNIFORM};
    let entry = |binding, ty| crate::gpu::buffer_entry(binding, ty);
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("culling (group 0)"),
        entries: &[
            entry(0, UNIFORM),
            entry(1, STORAGE_READ),
            entry(3, STORAGE_RW),
            entry(4, STORAGE_READ),
        ],
    })
}

/// A group 0 for [`cull_layout`] over `[uniforms, lights, counters, bounds]`.
pub fn bind_cull_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    [uniforms, lights, counters, bounds]: [&wgpu::Buffer; 4],
) -> wgpu::BindGroup {
    fn entry(binding: u32, b: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
        wgpu::BindGroupEntry {
            binding,
            resource: b.as_entire_binding(),
        }
    }
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("culling (group 0)"),
        layout,
        entries: &[
            entry(0, uniforms),
            entry(1, lights),
            entry(3, counters),
            entry(4, bounds),
        ],
    })
}

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
    /// Where the bounds came from (`NearFar`: every cell spans near..far).
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
    pub cell_culls: Option<Vec<super::CellCull>>,
}

/// One light-assignment strategy.
pub trait AssignStrategy {
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
        super::gpu_assign::read_grid(device, queue, buffers, dims, self.grid_entries(values))
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

/// Where the cell bounds come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CellSource {
    /// No depth information: every cell spans near..far (`tiled_forward`).
    NearFar,
    /// The frame's depth buffer (`targets.depth`), reduced on the GPU.
    Depth,
}

/// Most u32 entries one storage binding of this device holds.
pub fn max_index_entries(device: &wgpu::Device) -> u64 {
    let limits = device.limits();
    limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size)
        / 4
}

/// Index lists longer than the device can bind are an error, never a truncated list.
pub fn check_index_capacity(device: &wgpu::Device, entries: u64, stage: &str) -> Result<()> {
    let max = max_index_entries(device);
    if entries > max {
        return Err(Error::invalid(
            "--assign",
            format!(
                "{stage}: the light grid needs {entries} index entries, more than the {max} this device can bind; use fewer lights, a larger --tile or fewer --slices"
            ),
        ));
    }
    Ok(())
}
