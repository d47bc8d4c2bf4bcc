//! GPU scatter (forward-plus §4): one invocation per light emits a (cell, light) pair for
//! every cell it overlaps, a radix sort orders the pairs by cell, and each cell's offset and
//! count are read off the sorted keys (`scatter.wgsl`, `radix_sort.wgsl`). Pairs are sized
//! from counts (count pass → prefix sum → write pass), so nothing is ever dropped; the sort is
//! stable, so every cell's list comes out in light order, exactly as the CPU twin
//! ([`super::assign_cpu`] with the same cell bounds) builds it.

use super::gpu_assign::{check_index_capacity, AssignCommon, AssignFrame};
use super::radix_sort::RadixSort;
use crate::consts::ASSIGN_THREADS;
use crate::error::Result;
use crate::gpu::STORAGE_RW;
use crate::gpu::{
    bind_resources, buffer_layout, download, groups_1d, grow_storage, storage_buffer,
};
use crate::pipelines::FrameEncoder;
use crate::shader::{compose, compute_pipeline, src, ComposedShader};

pub(crate) fn shader() -> ComposedShader {
    compose(
        "scatter",
        &[
            src::TYPES,
            src::SCENE_BINDINGS,
            src::GRID_CELL,
            super::TILE_FRUSTUM_WGSL,
            include_str!("assign_bindings.wgsl"),
            include_str!("scatter.wgsl"),
        ],
    )
}

pub struct ScatterPass {
    layout: wgpu::BindGroupLayout,
    count: wgpu::ComputePipeline,
    write: wgpu::ComputePipeline,
    bounds: wgpu::ComputePipeline,
    counts: wgpu::ComputePipeline,
    light_counts: wgpu::Buffer,
    light_offsets: wgpu::Buffer,
    pair_total: wgpu::Buffer,
    sort: RadixSort,
}

impl ScatterPass {
    pub fn new(
        device: &wgpu::Device,
        scene_layout: &wgpu::BindGroupLayout,
        common: &AssignCommon,
    ) -> Self {
        let layout = buffer_layout(device, "scatter (group 2)", &[STORAGE_RW; 5]);
        let s = shader();
        let layouts = [Some(scene_layout), Some(&common.layout), Some(&layout)];
        let pipeline = |entry: &str| {
            compute_pipeline(device, &format!("scatter {entry}"), &s, entry, &layouts)
        };
        ScatterPass {
            count: pipeline("count_main"),
            write: pipeline("write_main"),
            bounds: pipeline("bounds_main"),
            counts: pipeline("counts_main"),
            layout,
            light_counts: storage_buffer(device, "scatter light counts", 1 << 12),
            light_offsets: storage_buffer(device, "scatter light offsets", 1 << 12),
            pair_total: storage_buffer(device, "scatter pair total", 16),
            sort: RadixSort::new(device),
        }
    }

    fn bind(&self, device: &wgpu::Device) -> wgpu::BindGroup {
        bind_resources(
            device,
            "scatter",
            &self.layout,
            &[
                self.light_counts.as_entire_binding(),
                self.light_offsets.as_entire_binding(),
                self.sort.keys.as_entire_binding(),
                self.sort.vals.as_entire_binding(),
                self.pair_total.as_entire_binding(),
            ],
        )
    }

    /// Build the grid from the cell bounds in `bounds`; leaves it in `grid` (waits for it)
    /// and returns the number of index entries.
    pub fn run(&mut self, a: AssignFrame, enc: &mut FrameEncoder, light_count: u32) -> Result<u32> {
        let AssignFrame {
            device,
            queue,
            scene,
            common,
            grid,
            bounds,
            dims,
        } = a;
        let lights = u64::from(light_count.max(1)) * 4;
        grow_storage(
            device,
            &mut self.light_counts,
            "scatter light counts",
            lights,
        );
        grow_storage(
            device,
            &mut self.light_offsets,
            "scatter light offsets",
            lights,
        );
        grid.ensure(device, queue, dims, dims.cell_count(), 1);
        let common_group = common.bind(device, grid, bounds, dims);
        let dispatch = |enc: &mut FrameEncoder,
                        pipeline: &wgpu::ComputePipeline,
                        groups: [&wgpu::BindGroup; 2],
                        label: &str,
                        items: u32| {
            let (encoder, timer) = enc.parts();
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(label),
                timestamp_writes: timer.compute_pass(label),
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, scene, &[]);
            pass.set_bind_group(1, groups[0], &[]);
            pass.set_bind_group(2, groups[1], &[]);
            let (x, y) = groups_1d(items.div_ceil(ASSIGN_THREADS));
            pass.dispatch_workgroups(x, y, 1);
        };
        // 1. Pairs per light, and their offsets.
        let group = self.bind(device);
        dispatch(
            enc,
            &self.count,
            [&common_group, &group],
            "assign: scatter count",
            light_count,
        );
        {
            let (encoder, timer) = enc.parts();
            common.clear_counters(encoder);
            common.scan.encode(
                device,
                encoder,
                timer,
                "assign: scatter scan",
                &self.light_counts,
                &self.light_offsets,
                u64::from(light_count),
                (&self.pair_total, 0),
            );
        }
        enc.submit_and_wait()?;
        let total = u32::from_le_bytes(
            download(device, queue, &self.pair_total, 4)?[..4]
                .try_into()
                .expect("4 bytes"),
        );
        check_index_capacity(device, u64::from(total), "scatter")?;
        // 2. The pairs (buffers grown to the counted total; bind groups follow them).
        self.sort.ensure(device, u64::from(total));
        grid.ensure(device, queue, dims, dims.cell_count(), total as usize);
        let common_group = common.bind(device, grid, bounds, dims);
        let group = self.bind(device);
        dispatch(
            enc,
            &self.write,
            [&common_group, &group],
            "assign: scatter write",
            light_count,
        );
        // 3. Sort by cell, 4. cell offsets and counts from the sorted keys.
        let cell_bits = u32::BITS - (dims.cell_count().max(2) as u32 - 1).leading_zeros();
        {
            let (encoder, timer) = enc.parts();
            self.sort.encode(
                device,
                queue,
                encoder,
                timer,
                &common.scan,
                total,
                cell_bits,
            );
            encoder.clear_buffer(grid.cells_buffer(), 0, Some((dims.cell_count() * 8) as u64));
        }
        dispatch(
            enc,
            &self.bounds,
            [&common_group, &group],
            "assign: scatter cell ranges",
            total,
        );
        dispatch(
            enc,
            &self.counts,
            [&common_group, &group],
            "assign: scatter cell counts",
            dims.cell_count() as u32,
        );
        if total > 0 {
            let (encoder, _) = enc.parts();
            encoder.copy_buffer_to_buffer(
                &self.sort.vals,
                0,
                grid.indices_buffer(),
                0,
                u64::from(total) * 4,
            );
        }
        enc.submit_and_wait()?;
        AssignCommon::check_write_overflow(&common.read_counters(device, queue)?, "scatter")?;
        Ok(total)
    }
}
