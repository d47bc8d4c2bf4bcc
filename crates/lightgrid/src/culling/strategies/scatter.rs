//! GPU scatter (forward-plus §4): every light emits a (cell, light) pair for every cell it
//! overlaps, a radix sort orders the pairs by cell, and each cell's offset and count are read
//! off the sorted keys (`scatter.wgsl`, `radix_sort.wgsl`; its steps are numbered there). A
//! light's cells are spread over one invocation per tile of its rectangle, so no invocation
//! loops over a whole screen of cells (llvmpipe ends loops after 65,536 iterations). Pairs
//! are appended at an atomic cursor into a buffer sized from earlier frames' frame counters;
//! pairs that do not fit are counted and the frame reported, never passed off as right. The
//! lists hold what the CPU twin ([`crate::culling::strategies::assign_cpu`] with the same cell bounds) builds, in
//! the cursor's order (the tests compare them as sets).

use crate::consts::{ASSIGN_THREADS, COUNTER_ITEM_ARGS};
use crate::culling::strategies::gpu_assign::{
    copy_dispatch_args, indirect_args_buffer, AssignCommon,
};
use crate::culling::strategies::radix_sort::RadixSort;
use crate::culling::strategies::{
    AssignFrame, AssignStrategy, ListCapacity, StrategyContext, StrategyRun,
};
use crate::error::Result;
use crate::frame::FrameEncoder;
use crate::gpu::{
    bind_resources, buffer_layout, groups_1d, grow_storage, storage_buffer, CounterValues,
    PassTimer, STORAGE_RW,
};
use crate::shader::{compose, compute_pipeline, parts, src, ComposedShader};

pub(crate) fn shader() -> ComposedShader {
    compose(
        "scatter",
        &parts![
            src::TYPES,
            src::GRID_PARAMS,
            src::SCENE_BINDINGS,
            src::GRID_CELL,
            crate::culling::strategies::TILE_FRUSTUM_WGSL,
            include_str!("assign_bindings.wgsl"),
            include_str!("light_tiles.wgsl"),
            include_str!("scatter.wgsl"),
        ],
    )
}

/// `--assign scatter`.
struct ScatterStrategy {
    common: AssignCommon,
    layout: wgpu::BindGroupLayout,
    rect: wgpu::ComputePipeline,
    items_args: wgpu::ComputePipeline,
    emit: wgpu::ComputePipeline,
    pad: wgpu::ComputePipeline,
    bounds: wgpu::ComputePipeline,
    counts: wgpu::ComputePipeline,
    light_items: wgpu::Buffer,
    item_offsets: wgpu::Buffer,
    item_total: wgpu::Buffer,
    light_rects: wgpu::Buffer,
    /// The emit pass's indirect arguments, copied out of the frame counters.
    item_args: wgpu::Buffer,
    /// (cell, light) pairs the pair buffer holds, sized from earlier frames.
    pairs: ListCapacity,
    sort: RadixSort,
}

pub(super) fn create_strategy(ctx: &StrategyContext) -> Box<dyn AssignStrategy> {
    let device = ctx.device;
    let common = AssignCommon::new(device);
    let layout = buffer_layout(device, "scatter (group 2)", &[STORAGE_RW; 6]);
    let s = shader();
    let layouts = [Some(ctx.cull_layout), Some(&common.layout), Some(&layout)];
    let pipeline =
        |entry: &str| compute_pipeline(device, &format!("scatter {entry}"), &s, entry, &layouts);
    Box::new(ScatterStrategy {
        rect: pipeline("rect_main"),
        items_args: pipeline("items_args_main"),
        emit: pipeline("emit_main"),
        pad: pipeline("pad_main"),
        bounds: pipeline("bounds_main"),
        counts: pipeline("counts_main"),
        layout,
        common,
        light_items: storage_buffer(device, "scatter light items", 1 << 12),
        item_offsets: storage_buffer(device, "scatter item offsets", 1 << 12),
        item_total: storage_buffer(device, "scatter item total", 16),
        light_rects: storage_buffer(device, "scatter light rects", 1 << 14),
        item_args: indirect_args_buffer(device, "scatter emit arguments"),
        pairs: ListCapacity::new("scatter", ctx.index_capacity),
        sort: RadixSort::new(device),
    })
}

impl ScatterStrategy {
    fn bind(&self, device: &wgpu::Device) -> wgpu::BindGroup {
        bind_resources(
            device,
            "scatter",
            &self.layout,
            &[
                self.light_items.as_entire_binding(),
                self.item_offsets.as_entire_binding(),
                self.sort.keys.as_entire_binding(),
                self.sort.vals.as_entire_binding(),
                self.item_total.as_entire_binding(),
                self.light_rects.as_entire_binding(),
            ],
        )
    }
}

/// A compute pass of one pipeline with groups 0..=2.
fn pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    timer: &mut PassTimer,
    label: &str,
    pipeline: &wgpu::ComputePipeline,
    groups: [&wgpu::BindGroup; 3],
) -> wgpu::ComputePass<'e> {
    let mut pass = timer.begin_compute(encoder, label);
    pass.set_pipeline(pipeline);
    for (i, g) in groups.iter().enumerate() {
        pass.set_bind_group(i as u32, *g, &[]);
    }
    pass
}

/// Dispatch one invocation per item of `items`.
fn dispatch_items(pass: &mut wgpu::ComputePass, items: u64) {
    let (x, y) = groups_1d((items.div_ceil(u64::from(ASSIGN_THREADS)) as u32).max(1));
    pass.dispatch_workgroups(x, y, 1);
}

impl AssignStrategy for ScatterStrategy {
    fn encode(&mut self, a: AssignFrame, enc: &mut FrameEncoder) -> Result<StrategyRun> {
        let AssignFrame {
            f,
            grid,
            bounds,
            dims,
            ..
        } = a;
        let device = f.device;
        let lights = f.light_count as u64;
        grow_storage(
            device,
            &mut self.light_items,
            "scatter light items",
            lights.max(1) * 4,
        );
        grow_storage(
            device,
            &mut self.item_offsets,
            "scatter item offsets",
            lights.max(1) * 4,
        );
        grow_storage(
            device,
            &mut self.light_rects,
            "scatter light rects",
            lights.max(1) * 16,
        );
        self.sort.ensure(device, self.pairs.entries);
        // The whole pair buffer is sorted: its bound length is what the kernels see.
        let slots = self.sort.keys.size() / 4;
        grid.ensure(device, f.queue, dims, dims.cell_count(), slots as usize);
        let common = self.common.bind(device, grid, bounds);
        let own = self.bind(device);
        let groups = [f.bind_group, &common, &own];
        let (encoder, timer) = enc.parts();
        // 1. Tile rectangles and items per light; 2. their offsets; 3. dispatch arguments.
        {
            let mut p = pass(encoder, timer, "assign: scatter rects", &self.rect, groups);
            dispatch_items(&mut p, lights);
        }
        self.common.scan.encode(
            device,
            encoder,
            timer,
            "assign: scatter scan",
            &self.light_items,
            &self.item_offsets,
            lights,
            (&self.item_total, 0),
        );
        {
            let mut p = pass(
                encoder,
                timer,
                "assign: scatter args",
                &self.items_args,
                groups,
            );
            p.dispatch_workgroups(1, 1, 1);
        }
        copy_dispatch_args(encoder, f.counters, COUNTER_ITEM_ARGS, &self.item_args);
        // 4. Pairs, one invocation per (light, tile); 5. padding past the pairs.
        {
            let mut p = pass(encoder, timer, "assign: scatter emit", &self.emit, groups);
            p.dispatch_workgroups_indirect(&self.item_args, 0);
            p.set_pipeline(&self.pad);
            dispatch_items(&mut p, slots);
        }
        // 6. Sort by cell (keys 0xffffffff past the pairs sort last: enough bits for the
        // cell count itself), 7. cell offsets and counts from the sorted keys.
        let cell_bits = u32::BITS - (dims.cell_count() as u32).leading_zeros();
        self.sort.encode(
            device,
            f.queue,
            encoder,
            timer,
            &self.common.scan,
            slots as u32,
            cell_bits,
        );
        encoder.clear_buffer(grid.cells_buffer(), 0, Some((dims.cell_count() * 8) as u64));
        {
            let mut p = pass(
                encoder,
                timer,
                "assign: scatter cell ranges",
                &self.bounds,
                groups,
            );
            dispatch_items(&mut p, slots);
            p.set_pipeline(&self.counts);
            dispatch_items(&mut p, dims.cell_count() as u64);
        }
        encoder.copy_buffer_to_buffer(&self.sort.vals, 0, grid.indices_buffer(), 0, slots * 4);
        Ok(StrategyRun::default())
    }

    fn observe(&mut self, device: &wgpu::Device, values: &CounterValues) -> Result<()> {
        self.pairs.observe(device, u64::from(values.pairs_needed()))
    }

    fn grid_entries(&self, values: &CounterValues) -> u32 {
        values.pairs_needed()
    }
}
