//! The machinery the GPU assignment strategies share (group 1 of their kernels,
//! `assign_bindings.wgsl`) and the two per-cell strategies built on it:
//! - **gather** (forward-plus §4): one workgroup per cell tests every light;
//! - **BVH** (tiled-forward-shading §4.4): one workgroup per cell walks the light hierarchy.
//!
//! Both run the count → prefix sum → write scheme: the count pass stores each cell's number of
//! lights, [`ScanPass`] turns counts into offsets and a total, the CPU reads the total and grows
//! the index buffer to fit, and the write pass fills the lists. A hit that does not fit its
//! counted list is counted in `overflow` and turned into an error, never dropped silently.
//! Only cells with samples get lights: the kernels run one workgroup per occupied cell
//! (indirect dispatch from the list the cell-bounds pass builds).

use super::cell_bounds::CellBoundsPass;
use super::scan::ScanPass;
use super::{GridBuffers, GridDims, LightGrid};
use crate::error::{Error, Result};
use crate::gpu::{
    bind_resources, buffer_layout, download, grow_storage, storage_buffer, STORAGE_READ,
    STORAGE_RW, UNIFORM,
};
use crate::shader::{compose, compute_pipeline, src, ComposedShader};

const ASSIGN_BINDINGS_WGSL: &str = include_str!("assign_bindings.wgsl");

fn cell_shader(name: &str, body: &'static str) -> ComposedShader {
    compose(
        name,
        &[
            src::TYPES,
            src::SCENE_BINDINGS,
            super::TILE_FRUSTUM_WGSL,
            ASSIGN_BINDINGS_WGSL,
            body,
        ],
    )
}

pub(crate) fn gather_shader() -> ComposedShader {
    cell_shader("gather", include_str!("gather.wgsl"))
}

pub(crate) fn bvh_shader() -> ComposedShader {
    cell_shader("bvh traversal", include_str!("bvh.wgsl"))
}

/// Group 1 layout and the per-cell count/offset buffers.
pub struct AssignCommon {
    pub layout: wgpu::BindGroupLayout,
    pub scan: ScanPass,
    overflow: wgpu::Buffer,
    cell_counts: wgpu::Buffer,
    cell_offsets: wgpu::Buffer,
    total: wgpu::Buffer,
}

impl AssignCommon {
    pub fn new(device: &wgpu::Device) -> Self {
        let layout = buffer_layout(
            device,
            "light assignment (group 1)",
            &[
                UNIFORM,
                STORAGE_READ,
                STORAGE_RW,
                STORAGE_RW,
                STORAGE_RW,
                STORAGE_RW,
                STORAGE_RW,
                STORAGE_READ,
                STORAGE_READ,
            ],
        );
        AssignCommon {
            layout,
            scan: ScanPass::new(device),
            overflow: storage_buffer(device, "assign overflow", 16),
            cell_counts: storage_buffer(device, "cell counts", 1 << 14),
            cell_offsets: storage_buffer(device, "cell offsets", 1 << 14),
            total: storage_buffer(device, "assign total", 16),
        }
    }

    /// Group 1 for a frame: grow the per-cell arrays, bind the grid and the cell bounds.
    pub fn bind(
        &mut self,
        device: &wgpu::Device,
        grid: &GridBuffers,
        bounds: &CellBoundsPass,
        dims: &GridDims,
    ) -> wgpu::BindGroup {
        let bytes = (dims.cell_count() * 4) as u64;
        grow_storage(device, &mut self.cell_counts, "cell counts", bytes);
        grow_storage(device, &mut self.cell_offsets, "cell offsets", bytes);
        bind_resources(
            device,
            "light assignment",
            &self.layout,
            &[
                grid.params_buffer().as_entire_binding(),
                bounds.buffer().as_entire_binding(),
                grid.cells_buffer().as_entire_binding(),
                grid.indices_buffer().as_entire_binding(),
                self.overflow.as_entire_binding(),
                self.cell_counts.as_entire_binding(),
                self.cell_offsets.as_entire_binding(),
                bounds.occupied_buffer().as_entire_binding(),
                bounds.occupancy_buffer().as_entire_binding(),
            ],
        )
    }

    /// Zero the overflow counter (record before the frame's write pass).
    pub fn clear_overflow(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.clear_buffer(&self.overflow, 0, None);
    }

    /// Read the overflow counter and fail if anything did not fit.
    pub fn check_overflow(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        stage: &str,
    ) -> Result<()> {
        let bytes = download(device, queue, &self.overflow, 4)?;
        let n = u32::from_le_bytes(bytes[..4].try_into().expect("4 bytes"));
        if n > 0 {
            return Err(Error::Gpu {
                stage: stage.into(),
                message: format!(
                    "{n} light indices did not fit the counted lists (count and write passes disagree)"
                ),
            });
        }
        Ok(())
    }

    /// Read the total written by the last scan.
    pub fn read_total(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<u32> {
        let bytes = download(device, queue, &self.total, 4)?;
        Ok(u32::from_le_bytes(bytes[..4].try_into().expect("4 bytes")))
    }
}

/// The grid as built on the GPU, read back (for statistics, heatmaps and the tests).
pub fn read_grid(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    grid: &GridBuffers,
    dims: &GridDims,
    total: u32,
) -> Result<LightGrid> {
    let cells = download(
        device,
        queue,
        grid.cells_buffer(),
        (dims.cell_count() * 8) as u64,
    )?;
    let indices = download(device, queue, grid.indices_buffer(), u64::from(total) * 4)?;
    Ok(LightGrid {
        dims: *dims,
        cells: bytemuck::pod_collect_to_vec(&cells),
        indices: bytemuck::pod_collect_to_vec(&indices),
    })
}

/// A per-cell strategy's two kernels (count, write), with their extra bind group layout.
pub struct CellKernels {
    count: wgpu::ComputePipeline,
    write: wgpu::ComputePipeline,
    name: &'static str,
}

impl CellKernels {
    pub fn new(
        device: &wgpu::Device,
        name: &'static str,
        shader: &ComposedShader,
        layouts: &[Option<&wgpu::BindGroupLayout>],
    ) -> Self {
        CellKernels {
            count: compute_pipeline(
                device,
                &format!("{name} count"),
                shader,
                "count_main",
                layouts,
            ),
            write: compute_pipeline(
                device,
                &format!("{name} write"),
                shader,
                "write_main",
                layouts,
            ),
            name,
        }
    }

    /// Count, prefix sum, grow, write: leaves the grid in `grid` (waits for it) and returns
    /// the number of index entries.
    /// Groups: 0 the scene, 1 `common`'s, 2.. `extra`.
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        enc: &mut crate::pipelines::FrameEncoder,
        scene: &wgpu::BindGroup,
        common: &mut AssignCommon,
        grid: &mut GridBuffers,
        bounds: &CellBoundsPass,
        dims: &GridDims,
        extra: &[&wgpu::BindGroup],
    ) -> Result<u32> {
        grid.ensure(device, queue, dims, dims.cell_count(), 1);
        let group = common.bind(device, grid, bounds, dims);
        let cell_bytes = (dims.cell_count() * 4) as u64;
        // Cells without samples are never visited: their counts (and later grid entries)
        // stay zero.
        enc.parts()
            .0
            .clear_buffer(&common.cell_counts, 0, Some(cell_bytes));
        let dispatch = |enc: &mut crate::pipelines::FrameEncoder,
                        pipeline: &wgpu::ComputePipeline,
                        group: &wgpu::BindGroup,
                        label: &str| {
            let (encoder, timer) = enc.parts();
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(label),
                timestamp_writes: timer.compute_pass(label),
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, scene, &[]);
            pass.set_bind_group(1, group, &[]);
            for (i, g) in extra.iter().enumerate() {
                pass.set_bind_group(2 + i as u32, *g, &[]);
            }
            pass.dispatch_workgroups_indirect(bounds.occupancy_buffer(), 4);
        };
        let name = self.name;
        dispatch(enc, &self.count, &group, &format!("assign: {name} count"));
        {
            let (encoder, timer) = enc.parts();
            common.clear_overflow(encoder);
            common.scan.encode(
                device,
                encoder,
                timer,
                &format!("assign: {name} scan"),
                &common.cell_counts,
                &common.cell_offsets,
                dims.cell_count() as u64,
                (&common.total, 0),
            );
        }
        enc.submit_and_wait()?;
        let total = common.read_total(device, queue)?;
        check_index_capacity(device, total as u64, name)?;
        // Grow the index list to the counted total; the bind group follows the buffers.
        grid.ensure(device, queue, dims, dims.cell_count(), total as usize);
        let group = common.bind(device, grid, bounds, dims);
        enc.parts()
            .0
            .clear_buffer(grid.cells_buffer(), 0, Some(cell_bytes * 2));
        dispatch(enc, &self.write, &group, &format!("assign: {name} write"));
        enc.submit_and_wait()?;
        common.check_overflow(device, queue, name)?;
        Ok(total)
    }
}

/// Index lists longer than the device can bind are an error, never a truncated list.
pub fn check_index_capacity(device: &wgpu::Device, entries: u64, stage: &str) -> Result<()> {
    let limits = device.limits();
    let max = limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size)
        / 4;
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
