//! The machinery the GPU assignment strategies share (group 1 of their kernels,
//! `assign_bindings.wgsl`) and the two per-cell strategies built on it:
//! - **gather** (forward-plus §4): one workgroup per occupied cell tests every light;
//! - **BVH walk** (tiled-forward-shading §4.4): one workgroup per occupied cell walks the light
//!   hierarchy.
//!
//! Both run in one pass (indirect dispatch over the occupied cells the cell-bounds pass
//! listed): a workgroup appends its cell's lights to a workgroup-memory list, reserves the
//! cell's range of the global index list with an atomic cursor and copies the list there.
//! Cells whose list overflowed (more than CELL_LIST_CAPACITY lights) keep their range and are
//! finished by a spill pass that writes straight to global memory. The index buffer is sized
//! from the previous frame's total; ranges that do not fit are counted, and the CPU, which
//! reads the counters back once per frame, grows the buffer to the needed total and reruns the
//! pass (reported as `assign_reruns` in the stats): the grid is never missing a light.

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

/// What a GPU strategy works on in one frame: the device, the scene (group 0), the shared
/// group-1 state, the grid it fills and the cell bounds it reads.
pub struct AssignFrame<'a> {
    pub device: &'a wgpu::Device,
    pub queue: &'a wgpu::Queue,
    pub scene: &'a wgpu::BindGroup,
    pub common: &'a mut AssignCommon,
    pub grid: &'a mut GridBuffers,
    pub bounds: &'a CellBoundsPass,
    pub dims: &'a GridDims,
}

/// Counter slots of `assign_bindings.wgsl`.
const CURSOR: usize = 0;
const OUT_OF_ROOM: usize = 1;
const WRITE_OVERFLOW: usize = 3;
/// Byte offset of the spill pass's indirect arguments in the counters buffer.
const SPILL_ARGS: u64 = 16;

/// Group 1 layout, the counters and the spill list.
pub struct AssignCommon {
    pub layout: wgpu::BindGroupLayout,
    pub scan: ScanPass,
    counters: wgpu::Buffer,
    /// The spill pass's arguments, copied out of `counters` (a buffer bound for storage
    /// cannot also feed an indirect dispatch).
    spill_args: wgpu::Buffer,
    spill_cells: wgpu::Buffer,
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
                STORAGE_READ,
                STORAGE_READ,
            ],
        );
        AssignCommon {
            layout,
            scan: ScanPass::new(device),
            counters: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("assign counters"),
                size: 32,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            spill_args: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("spill pass arguments"),
                size: 16,
                usage: wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            spill_cells: storage_buffer(device, "spill cells", 1 << 12),
        }
    }

    /// Group 1 for a frame: grow the spill list, bind the grid and the cell bounds.
    pub fn bind(
        &mut self,
        device: &wgpu::Device,
        grid: &GridBuffers,
        bounds: &CellBoundsPass,
        dims: &GridDims,
    ) -> wgpu::BindGroup {
        let bytes = (dims.cell_count() * 4) as u64;
        grow_storage(device, &mut self.spill_cells, "spill cells", bytes);
        bind_resources(
            device,
            "light assignment",
            &self.layout,
            &[
                grid.params_buffer().as_entire_binding(),
                bounds.buffer().as_entire_binding(),
                grid.cells_buffer().as_entire_binding(),
                grid.indices_buffer().as_entire_binding(),
                self.counters.as_entire_binding(),
                self.spill_cells.as_entire_binding(),
                bounds.occupied_buffer().as_entire_binding(),
                bounds.occupancy_buffer().as_entire_binding(),
            ],
        )
    }

    /// Zero the counters (record before the frame's assignment passes).
    pub fn clear_counters(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.clear_buffer(&self.counters, 0, None);
    }

    /// The counters after the submitted passes.
    pub fn read_counters(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<[u32; 4]> {
        let bytes = download(device, queue, &self.counters, 16)?;
        Ok(bytemuck::pod_read_unaligned(&bytes[..16]))
    }

    /// Fail if a write went past a counted length (the passes disagree: a bug, never silent).
    pub fn check_write_overflow(counters: &[u32; 4], stage: &str) -> Result<()> {
        let n = counters[WRITE_OVERFLOW];
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

/// A per-cell strategy's kernels (first pass, spill arguments, spill pass).
pub struct CellKernels {
    main: wgpu::ComputePipeline,
    spill_args: wgpu::ComputePipeline,
    spill: wgpu::ComputePipeline,
    name: &'static str,
}

/// What a per-cell strategy's run produced.
pub struct CellRun {
    /// Index entries of the grid.
    pub total: u32,
    /// Times the pass ran again because the index buffer (sized from earlier frames) was too
    /// small.
    pub reruns: u32,
}

impl CellKernels {
    pub fn new(
        device: &wgpu::Device,
        name: &'static str,
        shader: &ComposedShader,
        layouts: &[Option<&wgpu::BindGroupLayout>],
    ) -> Self {
        let pipeline = |entry: &str| {
            compute_pipeline(device, &format!("{name} {entry}"), shader, entry, layouts)
        };
        CellKernels {
            main: pipeline("main"),
            spill_args: pipeline("spill_args_main"),
            spill: pipeline("spill_main"),
            name,
        }
    }

    /// Build the grid into `a.grid` (waits for it). Groups: 0 the scene, 1 `a.common`'s,
    /// 2.. `extra`.
    pub fn run(
        &self,
        a: AssignFrame,
        enc: &mut crate::pipelines::FrameEncoder,
        extra: &[&wgpu::BindGroup],
    ) -> Result<CellRun> {
        let AssignFrame {
            device,
            queue,
            scene,
            common,
            grid,
            bounds,
            dims,
        } = a;
        let name = self.name;
        let mut reruns = 0;
        grid.ensure(device, queue, dims, dims.cell_count(), 1);
        loop {
            let group = common.bind(device, grid, bounds, dims);
            let (encoder, timer) = enc.parts();
            common.clear_counters(encoder);
            // Cells without samples are never visited: their entries stay (0, 0).
            encoder.clear_buffer(grid.cells_buffer(), 0, Some((dims.cell_count() * 8) as u64));
            let pass = |encoder: &mut wgpu::CommandEncoder,
                        timer: &mut crate::gpu::PassTimer,
                        label: &str,
                        run: &dyn Fn(&mut wgpu::ComputePass)| {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(label),
                    timestamp_writes: timer.compute_pass(label),
                });
                pass.set_bind_group(0, scene, &[]);
                pass.set_bind_group(1, &group, &[]);
                for (i, g) in extra.iter().enumerate() {
                    pass.set_bind_group(2 + i as u32, *g, &[]);
                }
                run(&mut pass);
            };
            pass(encoder, timer, &format!("assign: {name}"), &|p| {
                p.set_pipeline(&self.main);
                p.dispatch_workgroups_indirect(bounds.occupancy_buffer(), 4);
                p.set_pipeline(&self.spill_args);
                p.dispatch_workgroups(1, 1, 1);
            });
            encoder.copy_buffer_to_buffer(&common.counters, SPILL_ARGS, &common.spill_args, 0, 12);
            pass(encoder, timer, &format!("assign: {name} spill"), &|p| {
                p.set_pipeline(&self.spill);
                p.dispatch_workgroups_indirect(&common.spill_args, 0);
            });
            enc.submit_and_wait()?;
            let counters = common.read_counters(device, queue)?;
            AssignCommon::check_write_overflow(&counters, name)?;
            let total = counters[CURSOR];
            if counters[OUT_OF_ROOM] == 0 {
                return Ok(CellRun { total, reruns });
            }
            // The cursor counted every reservation: grow to it and run again.
            check_index_capacity(device, u64::from(total), name)?;
            grid.ensure(device, queue, dims, dims.cell_count(), total as usize);
            reruns += 1;
            if reruns > 2 {
                return Err(Error::Gpu {
                    stage: name.into(),
                    message: format!(
                        "the index list still did not fit after growing it to {total} entries"
                    ),
                });
            }
        }
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
