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
use crate::culling::bounds::cell_bounds::CellBoundsPass;
use crate::culling::frame::CullFrame;
use crate::culling::grid::{GridBuffers, GridDims};
use crate::culling::strategies::gpu_assign::{copy_dispatch_args, ASSIGN_GROUP1};
use crate::culling::strategies::radix_sort::RadixSort;
use crate::culling::strategies::scan::ScanPass;
use crate::culling::strategies::{
    AssignFrame, AssignStrategy, ListCapacity, StrategyContext, StrategyRun,
};
use crate::error::Result;
use crate::frame::FrameEncoder;
use crate::gpu::{
    buffer_entry, groups_1d, grow_storage, indirect_args_buffer, storage_buffer, CounterValues,
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
            crate::culling::strategies::LIGHT_RECORDS_WGSL,
            src::GRID_CELL,
            crate::culling::strategies::TILE_FRUSTUM_WGSL,
            include_str!("assign_bindings.wgsl"),
            include_str!("light_tiles.wgsl"),
            include_str!("scatter.wgsl"),
        ],
    )
}

/// The bindings of groups 1 (`assign_bindings.wgsl`) and 2 (`scatter.wgsl`) one kernel
/// uses: its pipeline layout holds only those, so no kernel binds more than WebGPU's default
/// 8 storage buffers per stage (group 0's 2 and all of these would be 12).
struct KernelUse {
    entry: &'static str,
    group1: &'static [u32],
    group2: &'static [u32],
}

/// Group 2's bindings: light items, item offsets, pair keys, pair values, item total, light
/// rectangles.
const GROUP2: [wgpu::BufferBindingType; 6] = [STORAGE_RW; 6];

/// Steps 1, 3, 4, 5 and 7 of `scatter.wgsl`, in order.
const KERNELS: [KernelUse; 6] = [
    KernelUse {
        entry: "rect_main",
        group1: &[0],
        group2: &[0, 5],
    },
    KernelUse {
        entry: "items_args_main",
        group1: &[],
        group2: &[4],
    },
    KernelUse {
        entry: "emit_main",
        group1: &[0, 1, 5],
        group2: &[1, 2, 3, 5],
    },
    KernelUse {
        entry: "pad_main",
        group1: &[],
        group2: &[2],
    },
    KernelUse {
        entry: "bounds_main",
        group1: &[2],
        group2: &[2],
    },
    KernelUse {
        entry: "counts_main",
        group1: &[0, 2],
        group2: &[],
    },
];
const RECT: usize = 0;
const ITEMS_ARGS: usize = 1;
const EMIT: usize = 2;
const PAD: usize = 3;
const BOUNDS: usize = 4;
const COUNTS: usize = 5;

/// The layout of the bindings `used` of a group whose bindings have `types` (none when
/// nothing is used).
fn subset_layout(
    device: &wgpu::Device,
    label: &str,
    types: &[wgpu::BufferBindingType],
    used: &[u32],
) -> Option<wgpu::BindGroupLayout> {
    let entries: Vec<_> = used
        .iter()
        .map(|&b| buffer_entry(b, types[b as usize]))
        .collect();
    (!used.is_empty()).then(|| {
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(label),
            entries: &entries,
        })
    })
}

/// A scatter kernel: its pipeline and its own layouts of groups 1 and 2.
struct Kernel {
    pipeline: wgpu::ComputePipeline,
    layouts: [Option<wgpu::BindGroupLayout>; 2],
    uses: &'static KernelUse,
}

impl Kernel {
    fn new(ctx: &StrategyContext, shader: &ComposedShader, uses: &'static KernelUse) -> Self {
        let device = ctx.device;
        let label = format!("scatter {}", uses.entry);
        let layouts = [
            subset_layout(device, &label, &ASSIGN_GROUP1, uses.group1),
            subset_layout(device, &label, &GROUP2, uses.group2),
        ];
        let pipeline = compute_pipeline(
            device,
            &label,
            shader,
            uses.entry,
            &[
                Some(ctx.cull_layout),
                layouts[0].as_ref(),
                layouts[1].as_ref(),
            ],
        );
        Kernel {
            pipeline,
            layouts,
            uses,
        }
    }

    /// Its groups 1 and 2 over the frame's buffers (`group1` in `ASSIGN_GROUP1`'s order,
    /// `group2` in `GROUP2`'s).
    fn bind(
        &self,
        device: &wgpu::Device,
        group1: &[&wgpu::Buffer; 6],
        group2: &[&wgpu::Buffer; 6],
    ) -> [Option<wgpu::BindGroup>; 2] {
        let bind =
            |layout: &Option<wgpu::BindGroupLayout>, used: &[u32], all: &[&wgpu::Buffer; 6]| {
                layout.as_ref().map(|layout| {
                    let entries: Vec<_> = used
                        .iter()
                        .map(|&b| wgpu::BindGroupEntry {
                            binding: b,
                            resource: all[b as usize].as_entire_binding(),
                        })
                        .collect();
                    device.create_bind_group(&wgpu::BindGroupDescriptor {
                        label: Some(self.uses.entry),
                        layout,
                        entries: &entries,
                    })
                })
            };
        [
            bind(&self.layouts[0], self.uses.group1, group1),
            bind(&self.layouts[1], self.uses.group2, group2),
        ]
    }
}

/// How a kernel is dispatched.
enum Dispatch<'a> {
    /// One invocation per item of this many.
    Items(u64),
    /// One invocation.
    Once,
    /// Arguments from this buffer.
    Indirect(&'a wgpu::Buffer),
}

/// `--assign scatter`.
struct ScatterStrategy {
    scan: ScanPass,
    kernels: Vec<Kernel>,
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
    let s = shader();
    Box::new(ScatterStrategy {
        scan: ScanPass::new(device),
        kernels: KERNELS.iter().map(|k| Kernel::new(ctx, &s, k)).collect(),
        light_items: storage_buffer(device, "scatter light items", 1 << 12),
        item_offsets: storage_buffer(device, "scatter item offsets", 1 << 12),
        item_total: storage_buffer(device, "scatter item total", 16),
        light_rects: storage_buffer(device, "scatter light rects", 1 << 14),
        item_args: indirect_args_buffer(device, "scatter emit arguments"),
        pairs: ListCapacity::new("scatter", ctx.index_capacity),
        sort: RadixSort::new(device),
    })
}

/// A compute pass running `steps` (kernel, its groups 1 and 2, dispatch) in order.
fn pass(
    encoder: &mut wgpu::CommandEncoder,
    timer: &mut PassTimer,
    label: &str,
    group0: &wgpu::BindGroup,
    steps: &[(&Kernel, &[Option<wgpu::BindGroup>; 2], Dispatch)],
) {
    let mut pass = timer.begin_compute(encoder, label);
    pass.set_bind_group(0, group0, &[]);
    for (kernel, groups, dispatch) in steps {
        pass.set_pipeline(&kernel.pipeline);
        for (i, g) in groups.iter().enumerate() {
            if let Some(g) = g {
                pass.set_bind_group(1 + i as u32, g, &[]);
            }
        }
        match dispatch {
            Dispatch::Items(n) => {
                let (x, y) = groups_1d((n.div_ceil(u64::from(ASSIGN_THREADS)) as u32).max(1));
                pass.dispatch_workgroups(x, y, 1);
            }
            Dispatch::Once => pass.dispatch_workgroups(1, 1, 1),
            Dispatch::Indirect(args) => pass.dispatch_workgroups_indirect(args, 0),
        }
    }
}

impl ScatterStrategy {
    /// Room for the frame's lights and pairs, and each kernel's groups 1 and 2; returns the
    /// pair slots (the whole pair buffer is sorted: its bound length is what the kernels see).
    fn prepare(
        &mut self,
        f: &CullFrame,
        grid: &mut GridBuffers,
        bounds: &CellBoundsPass,
        dims: &GridDims,
    ) -> (u64, Vec<[Option<wgpu::BindGroup>; 2]>) {
        let device = f.device;
        let lights = (f.light_count as u64).max(1);
        for (buffer, label, bytes) in [
            (&mut self.light_items, "scatter light items", 4),
            (&mut self.item_offsets, "scatter item offsets", 4),
            (&mut self.light_rects, "scatter light rects", 16),
        ] {
            grow_storage(device, buffer, label, lights * bytes);
        }
        self.sort.ensure(device, self.pairs.entries);
        let slots = self.sort.keys.size() / 4;
        grid.ensure(device, f.queue, dims, dims.cell_count(), slots as usize);
        let group1 = [
            grid.params_buffer(),
            bounds.buffer(),
            grid.cells_buffer(),
            grid.indices_buffer(),
            bounds.lists_buffer(),
            bounds.cull_buffer(),
        ];
        let group2 = [
            &self.light_items,
            &self.item_offsets,
            &self.sort.keys,
            &self.sort.vals,
            &self.item_total,
            &self.light_rects,
        ];
        let groups = self
            .kernels
            .iter()
            .map(|k| k.bind(device, &group1, &group2))
            .collect();
        (slots, groups)
    }
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
        let (slots, groups) = self.prepare(f, grid, bounds, dims);
        let k = |i: usize| (&self.kernels[i], &groups[i]);
        let step = |i: usize, d| (k(i).0, k(i).1, d);
        let (encoder, timer) = enc.parts();
        // 1. Tile rectangles and items per light; 2. their offsets; 3. dispatch arguments.
        pass(
            encoder,
            timer,
            "assign: scatter rects",
            f.bind_group,
            &[step(RECT, Dispatch::Items(lights))],
        );
        self.scan.encode(
            device,
            encoder,
            timer,
            "assign: scatter scan",
            &self.light_items,
            &self.item_offsets,
            lights,
            (&self.item_total, 0),
        );
        pass(
            encoder,
            timer,
            "assign: scatter args",
            f.bind_group,
            &[step(ITEMS_ARGS, Dispatch::Once)],
        );
        copy_dispatch_args(encoder, f.counters, COUNTER_ITEM_ARGS, &self.item_args);
        // 4. Pairs, one invocation per (light, tile); 5. padding past the pairs.
        pass(
            encoder,
            timer,
            "assign: scatter emit",
            f.bind_group,
            &[
                step(EMIT, Dispatch::Indirect(&self.item_args)),
                step(PAD, Dispatch::Items(slots)),
            ],
        );
        // 6. Sort by cell (keys 0xffffffff past the pairs sort last: enough bits for the
        // cell count itself), 7. cell offsets and counts from the sorted keys.
        let cell_bits = u32::BITS - (dims.cell_count() as u32).leading_zeros();
        self.sort.encode(
            device,
            f.queue,
            encoder,
            timer,
            &self.scan,
            slots as u32,
            cell_bits,
        );
        encoder.clear_buffer(grid.cells_buffer(), 0, Some((dims.cell_count() * 8) as u64));
        pass(
            encoder,
            timer,
            "assign: scatter cell ranges",
            f.bind_group,
            &[
                step(BOUNDS, Dispatch::Items(slots)),
                step(COUNTS, Dispatch::Items(dims.cell_count() as u64)),
            ],
        );
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
