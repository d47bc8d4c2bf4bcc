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
//! from earlier frames' totals (the frame counters, read back without waiting); ranges that
//! do not fit are counted, the frame is reported as one whose lists did not fit, and the
//! buffer grows to the needed total for the next frame (an analysis run reruns the frame at
//! once: `assign_reruns` in the stats). A frame missing a light is never passed off as right.

use crate::consts::COUNTER_SPILL_ARGS;
use crate::culling::bounds::cell_bounds::CellBoundsPass;
use crate::culling::grid::GridBuffers;
use crate::culling::strategies::scan::ScanPass;
use crate::culling::strategies::{AssignFrame, ListCapacity, StrategyContext};
use crate::error::Result;
use crate::frame::FrameEncoder;
use crate::gpu::{
    bind_resources, buffer_layout, indirect_args_buffer, CounterValues, PassTimer, STORAGE_READ,
    STORAGE_RW, UNIFORM,
};
use crate::shader::{compose, compute_pipeline, parts, src, ComposedShader};

const ASSIGN_BINDINGS_WGSL: &str = include_str!("assign_bindings.wgsl");

fn cell_shader(name: &str, body: &'static str) -> ComposedShader {
    compose(
        name,
        &parts![
            src::TYPES,
            src::GRID_PARAMS,
            src::SCENE_BINDINGS,
            crate::culling::strategies::LIGHT_RECORDS_WGSL,
            crate::culling::strategies::TILE_FRUSTUM_WGSL,
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

/// Group 1's bindings (`assign_bindings.wgsl`): the grid's parameters, the cell bounds, the
/// cells, the index list, the cell lists, the cells' culling records.
pub(crate) const ASSIGN_GROUP1: [wgpu::BufferBindingType; 6] = [
    UNIFORM,
    STORAGE_READ,
    STORAGE_RW,
    STORAGE_RW,
    STORAGE_RW,
    STORAGE_READ,
];

/// Group 1 layout (`assign_bindings.wgsl`) and the spill pass's arguments (the spill list
/// is the second half of the cell lists: `CellBoundsPass::lists_buffer`).
pub struct AssignCommon {
    pub layout: wgpu::BindGroupLayout,
    pub scan: ScanPass,
    /// The spill pass's arguments, copied out of the frame counters (a buffer bound for
    /// storage cannot also feed an indirect dispatch).
    spill_args: wgpu::Buffer,
}

impl AssignCommon {
    pub fn new(device: &wgpu::Device) -> Self {
        let layout = buffer_layout(device, "light assignment (group 1)", &ASSIGN_GROUP1);
        AssignCommon {
            layout,
            scan: ScanPass::new(device),
            spill_args: indirect_args_buffer(device, "spill pass arguments"),
        }
    }

    /// Group 1 for a frame: bind the grid, the cell bounds and lists, and the masks.
    pub fn bind(
        &self,
        device: &wgpu::Device,
        grid: &GridBuffers,
        bounds: &CellBoundsPass,
    ) -> wgpu::BindGroup {
        bind_resources(
            device,
            "light assignment",
            &self.layout,
            &[
                grid.params_buffer().as_entire_binding(),
                bounds.buffer().as_entire_binding(),
                grid.cells_buffer().as_entire_binding(),
                grid.indices_buffer().as_entire_binding(),
                bounds.lists_buffer().as_entire_binding(),
                bounds.cull_buffer().as_entire_binding(),
            ],
        )
    }
}

/// Record the copy of three dispatch arguments from frame-counter slot `slot` on.
pub fn copy_dispatch_args(
    encoder: &mut wgpu::CommandEncoder,
    counters: &wgpu::Buffer,
    slot: u32,
    dst: &wgpu::Buffer,
) {
    encoder.copy_buffer_to_buffer(counters, u64::from(slot) * 4, dst, 0, 12);
}

/// A per-cell strategy's kernels (first pass, spill arguments, spill pass) and the index
/// capacity it sizes from earlier frames.
pub struct CellKernels {
    main: wgpu::ComputePipeline,
    spill_args: wgpu::ComputePipeline,
    spill: wgpu::ComputePipeline,
    name: &'static str,
    common: AssignCommon,
    capacity: ListCapacity,
}

impl CellKernels {
    /// `extra`: the layouts of groups 2.. (the BVH).
    pub fn new(
        ctx: &StrategyContext,
        name: &'static str,
        shader: &ComposedShader,
        extra: &[&wgpu::BindGroupLayout],
    ) -> Self {
        let device = ctx.device;
        let common = AssignCommon::new(device);
        let mut layouts = vec![Some(ctx.cull_layout), Some(&common.layout)];
        layouts.extend(extra.iter().map(|l| Some(*l)));
        let pipeline = |entry: &str| {
            compute_pipeline(device, &format!("{name} {entry}"), shader, entry, &layouts)
        };
        CellKernels {
            main: pipeline("main"),
            spill_args: pipeline("spill_args_main"),
            spill: pipeline("spill_main"),
            name,
            capacity: ListCapacity::new(name, ctx.index_capacity),
            common,
        }
    }

    /// The scan pass (shared with a GPU BVH build's sort).
    pub fn scan(&self) -> &ScanPass {
        &self.common.scan
    }

    /// Record the grid's construction into `a.grid`: no wait, no readback. Index ranges that
    /// do not fit the capacity (sized from earlier frames) are counted in the frame counters
    /// (`COUNTER_INDEX_OUT_OF_ROOM`). Groups: 0 the scene, 1 the common group, 2.. `extra`.
    pub fn encode(&mut self, a: AssignFrame, enc: &mut FrameEncoder, extra: &[&wgpu::BindGroup]) {
        let AssignFrame {
            f,
            grid,
            bounds,
            dims,
            ..
        } = a;
        let device = f.device;
        let name = self.name;
        grid.ensure(
            device,
            f.queue,
            dims,
            dims.cell_count(),
            self.capacity.entries as usize,
        );
        let group = self.common.bind(device, grid, bounds);
        let (encoder, timer) = enc.parts();
        // Cells without samples are never visited: their entries stay (0, 0).
        encoder.clear_buffer(grid.cells_buffer(), 0, Some((dims.cell_count() * 8) as u64));
        let pass = |encoder: &mut wgpu::CommandEncoder,
                    timer: &mut PassTimer,
                    label: &str,
                    run: &dyn Fn(&mut wgpu::ComputePass)| {
            let mut pass = timer.begin_compute(encoder, label);
            pass.set_bind_group(0, f.bind_group, &[]);
            pass.set_bind_group(1, &group, &[]);
            for (i, g) in extra.iter().enumerate() {
                pass.set_bind_group(2 + i as u32, *g, &[]);
            }
            run(&mut pass);
        };
        pass(encoder, timer, &format!("assign: {name}"), &|p| {
            p.set_pipeline(&self.main);
            p.dispatch_workgroups_indirect(bounds.dispatch_args(), 0);
            p.set_pipeline(&self.spill_args);
            p.dispatch_workgroups(1, 1, 1);
        });
        copy_dispatch_args(
            encoder,
            f.counters,
            COUNTER_SPILL_ARGS,
            &self.common.spill_args,
        );
        pass(encoder, timer, &format!("assign: {name} spill"), &|p| {
            p.set_pipeline(&self.spill);
            p.dispatch_workgroups_indirect(&self.common.spill_args, 0);
        });
    }

    /// Grow the index capacity to what a finished frame reserved.
    pub fn observe(&mut self, device: &wgpu::Device, values: &CounterValues) -> Result<()> {
        self.capacity
            .observe(device, u64::from(values.index_needed()))
    }
}
