//! The light BVH built on the GPU (`bvh_build.wgsl`): centre bounding box, Morton codes, the
//! radix sort shared with scatter, then leaf and per-level node boxes. Produces the same
//! layout as the CPU build ([`crate::culling::strategies::bvh::build_bvh`], its twin) and binds as the traversal's
//! group 2 (`bvh_order` is the sorted value array itself).

use crate::consts::ASSIGN_THREADS;
use crate::culling::frame::CullFrame;
use crate::culling::strategies::bvh::{bvh_levels, BvhBuffers, BvhNode};
use crate::culling::strategies::gpu_assign::{bvh_shader, CellKernels};
use crate::culling::strategies::radix_sort::RadixSort;
use crate::culling::strategies::scan::ScanPass;
use crate::culling::strategies::{AssignFrame, AssignStrategy, StrategyContext, StrategyRun};
use crate::error::Result;
use crate::frame::FrameEncoder;
use crate::gpu::CounterValues;
use crate::gpu::{
    bind_resources, buffer_layout, groups_1d, grow_storage, storage_buffer, UniformSlots,
    STORAGE_RW, UNIFORM,
};
use crate::gpu_types::LevelParams;
use crate::shader::{compose, compute_pipeline, parts, src, ComposedShader};

pub(crate) fn shader() -> ComposedShader {
    compose(
        "bvh build",
        &parts![
            src::TYPES,
            src::GRID_PARAMS,
            src::SCENE_BINDINGS,
            crate::culling::strategies::LIGHT_RECORDS_WGSL,
            crate::culling::strategies::TILE_FRUSTUM_WGSL,
            include_str!("bvh_build.wgsl"),
        ],
    )
}

/// Most BVH levels (2^20 lights make 5).
const MAX_LEVELS: u64 = 8;

pub struct GpuBvhBuild {
    layout: wgpu::BindGroupLayout,
    box_pass: wgpu::ComputePipeline,
    morton: wgpu::ComputePipeline,
    leaves: wgpu::ComputePipeline,
    inner: wgpu::ComputePipeline,
    params: UniformSlots,
    nodes: wgpu::Buffer,
    /// The nodes the last `encode` built (0 without lights).
    node_count: usize,
    centre_box: wgpu::Buffer,
    sort: RadixSort,
}

impl GpuBvhBuild {
    pub fn new(device: &wgpu::Device, cull_layout: &wgpu::BindGroupLayout) -> Self {
        let layout = buffer_layout(
            device,
            "bvh build (group 1)",
            &[UNIFORM, STORAGE_RW, STORAGE_RW, STORAGE_RW, STORAGE_RW],
        );
        let s = shader();
        let layouts = [Some(cull_layout), Some(&layout)];
        let pipeline = |entry: &str| {
            compute_pipeline(device, &format!("bvh build {entry}"), &s, entry, &layouts)
        };
        GpuBvhBuild {
            box_pass: pipeline("box_main"),
            morton: pipeline("morton_main"),
            leaves: pipeline("leaves_main"),
            inner: pipeline("inner_main"),
            layout,
            params: UniformSlots::new::<LevelParams>(device, "bvh build levels", MAX_LEVELS),
            nodes: storage_buffer(device, "bvh nodes (gpu build)", 1 << 12),
            node_count: 0,
            centre_box: storage_buffer(device, "bvh centre box", 32),
            sort: RadixSort::new(device),
        }
    }

    /// Record the build for the frame's lights. The hierarchy is ready for the passes
    /// recorded after it; [`GpuBvhBuild::buffers`] binds it.
    pub fn encode(&mut self, f: &CullFrame, enc: &mut FrameEncoder, scan: &ScanPass) {
        let device = f.device;
        let n = f.light_count as u32;
        self.node_count = 0;
        if n == 0 {
            return;
        }
        let levels = bvh_levels(n as usize);
        let node_count: u32 = levels.iter().map(|l| l.1).sum();
        self.node_count = node_count as usize;
        grow_storage(
            device,
            &mut self.nodes,
            "bvh nodes (gpu build)",
            u64::from(node_count) * std::mem::size_of::<BvhNode>() as u64,
        );
        self.sort.ensure(device, u64::from(n));
        let records: Vec<LevelParams> = levels
            .iter()
            .enumerate()
            .map(|(i, &(first, count))| {
                let (child_first, child_count) = if i > 0 { levels[i - 1] } else { (0, n) };
                LevelParams {
                    first,
                    count,
                    child_first,
                    child_count,
                }
            })
            .collect();
        self.params.write(f.queue, &records);
        let group = |slot: usize| {
            bind_resources(
                device,
                "bvh build",
                &self.layout,
                &[
                    self.params.binding(slot),
                    self.sort.keys.as_entire_binding(),
                    self.sort.vals.as_entire_binding(),
                    self.nodes.as_entire_binding(),
                    self.centre_box.as_entire_binding(),
                ],
            )
        };
        let (encoder, timer) = enc.parts();
        encoder.clear_buffer(&self.centre_box, 0, None);
        let run = |encoder: &mut wgpu::CommandEncoder,
                   timer: &mut crate::gpu::PassTimer,
                   pipeline: &wgpu::ComputePipeline,
                   group: &wgpu::BindGroup,
                   label: &str,
                   items: u32| {
            let mut pass = timer.begin_compute(encoder, label);
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, f.bind_group, &[]);
            pass.set_bind_group(1, group, &[]);
            let (x, y) = groups_1d(items.div_ceil(ASSIGN_THREADS));
            pass.dispatch_workgroups(x, y, 1);
        };
        let g0 = group(0);
        run(
            encoder,
            timer,
            &self.box_pass,
            &g0,
            "assign: bvh build box",
            n,
        );
        run(
            encoder,
            timer,
            &self.morton,
            &g0,
            "assign: bvh build morton",
            n,
        );
        self.sort
            .encode(device, f.queue, encoder, timer, scan, n, 30);
        run(
            encoder,
            timer,
            &self.leaves,
            &g0,
            "assign: bvh build leaves",
            levels[0].1,
        );
        for (i, level) in levels.iter().enumerate().skip(1) {
            let g = group(i);
            run(
                encoder,
                timer,
                &self.inner,
                &g,
                "assign: bvh build levels",
                level.1,
            );
        }
    }

    /// The nodes the last `encode` built (and their number) and the order, for the
    /// traversal's group 2.
    pub fn buffers(&self) -> ((&wgpu::Buffer, usize), &wgpu::Buffer) {
        ((&self.nodes, self.node_count), &self.sort.vals)
    }
}

/// `--assign bvh-gpu`: the hierarchy built on the GPU ([`GpuBvhBuild`]) and walked like
/// `bvh`'s, all in the frame's one submission.
struct GpuBvhStrategy {
    kernels: CellKernels,
    buffers: BvhBuffers,
    build: GpuBvhBuild,
}

pub(super) fn create_strategy(ctx: &StrategyContext) -> Box<dyn AssignStrategy> {
    let buffers = BvhBuffers::new(ctx.device);
    Box::new(GpuBvhStrategy {
        kernels: CellKernels::new(ctx, "bvh", &bvh_shader(), &[&buffers.layout]),
        build: GpuBvhBuild::new(ctx.device, ctx.cull_layout),
        buffers,
    })
}

impl AssignStrategy for GpuBvhStrategy {
    fn encode(&mut self, a: AssignFrame, enc: &mut FrameEncoder) -> Result<StrategyRun> {
        self.build.encode(a.f, enc, self.kernels.scan());
        let lights = a.f.light_count;
        let (nodes, order) = self.build.buffers();
        let group = self
            .buffers
            .copy(a.f.device, enc.parts().0, lights, nodes, order);
        self.kernels.encode(a, enc, &[&group]);
        Ok(StrategyRun::default())
    }

    fn observe(&mut self, device: &wgpu::Device, values: &CounterValues) -> Result<()> {
        self.kernels.observe(device, values)
    }

    fn grid_entries(&self, values: &CounterValues) -> u32 {
        values.index_needed()
    }
}
