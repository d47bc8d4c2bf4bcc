//! Stable GPU radix sort of (u32 key, u32 value) pairs, 4 bits per pass (`radix_sort.wgsl`):
//! per pass a block-local sort with digit histograms, a prefix sum of the histograms
//! ([`ScanPass`]) and a scatter to the global positions. Sorts `keys`/`vals` in place (with
//! `tmp_*` as the other half of each pass). CPU twin: a stable sort by key.

use crate::consts::ASSIGN_THREADS;
use crate::culling::strategies::scan::ScanPass;
use crate::gpu::{bind_resources, buffer_layout, groups_1d, grow_storage, storage_buffer};
use crate::gpu::{PassTimer, UniformSlots, STORAGE_RW, UNIFORM};
use crate::gpu_types::SortParams;
use crate::shader::{compose, compute_pipeline, ComposedShader};

pub(crate) fn shader() -> ComposedShader {
    compose(
        "radix sort",
        &[crate::shader::src::TYPES, include_str!("radix_sort.wgsl")],
    )
}

/// Most 4-bit passes (32-bit keys).
const MAX_PASSES: u32 = 8;

pub struct RadixSort {
    layout: wgpu::BindGroupLayout,
    local: wgpu::ComputePipeline,
    scatter: wgpu::ComputePipeline,
    params: UniformSlots,
    pub keys: wgpu::Buffer,
    pub vals: wgpu::Buffer,
    tmp_keys: wgpu::Buffer,
    tmp_vals: wgpu::Buffer,
    hist: wgpu::Buffer,
    hist_offsets: wgpu::Buffer,
    hist_total: wgpu::Buffer,
}

impl RadixSort {
    pub fn new(device: &wgpu::Device) -> Self {
        let layout = buffer_layout(
            device,
            "radix sort",
            &[
                UNIFORM, STORAGE_RW, STORAGE_RW, STORAGE_RW, STORAGE_RW, STORAGE_RW, STORAGE_RW,
            ],
        );
        let s = shader();
        let pipeline = |entry: &str| {
            compute_pipeline(
                device,
                &format!("radix sort {entry}"),
                &s,
                entry,
                &[Some(&layout)],
            )
        };
        RadixSort {
            local: pipeline("local_main"),
            scatter: pipeline("scatter_main"),
            layout,
            params: UniformSlots::new::<SortParams>(device, "radix sort params", MAX_PASSES.into()),
            keys: storage_buffer(device, "sort keys", 1 << 12),
            vals: storage_buffer(device, "sort values", 1 << 12),
            tmp_keys: storage_buffer(device, "sort keys (tmp)", 1 << 12),
            tmp_vals: storage_buffer(device, "sort values (tmp)", 1 << 12),
            hist: storage_buffer(device, "sort histograms", 1 << 12),
            hist_offsets: storage_buffer(device, "sort histogram offsets", 1 << 12),
            hist_total: storage_buffer(device, "sort total", 16),
        }
    }

    /// Make room for `n` pairs (contents of `keys`/`vals` are lost when they grow).
    pub fn ensure(&mut self, device: &wgpu::Device, n: u64) {
        let bytes = n * 4;
        for (b, label) in [
            (&mut self.keys, "sort keys"),
            (&mut self.vals, "sort values"),
            (&mut self.tmp_keys, "sort keys (tmp)"),
            (&mut self.tmp_vals, "sort values (tmp)"),
        ] {
            grow_storage(device, b, label, bytes);
        }
        let hist = n.div_ceil(u64::from(ASSIGN_THREADS)) * 16 * 4;
        grow_storage(device, &mut self.hist, "sort histograms", hist);
        grow_storage(
            device,
            &mut self.hist_offsets,
            "sort histogram offsets",
            hist,
        );
    }

    /// Record the sort of the first `n` pairs by the low `bits` bits of their keys (call
    /// `ensure(n)` first and fill `keys`/`vals`).
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut PassTimer,
        scan: &ScanPass,
        n: u32,
        bits: u32,
    ) {
        if n <= 1 {
            return;
        }
        let passes = bits.div_ceil(4).clamp(1, MAX_PASSES);
        let blocks = n.div_ceil(ASSIGN_THREADS);
        let records: Vec<SortParams> = (0..passes)
            .map(|p| SortParams {
                n,
                shift: p * 4,
                blocks,
                _pad: 0,
            })
            .collect();
        self.params.write(queue, &records);
        let groups = groups_1d(blocks);
        for p in 0..passes {
            let group = bind_resources(
                device,
                "radix sort",
                &self.layout,
                &[
                    self.params.binding(p as usize),
                    self.keys.as_entire_binding(),
                    self.vals.as_entire_binding(),
                    self.tmp_keys.as_entire_binding(),
                    self.tmp_vals.as_entire_binding(),
                    self.hist.as_entire_binding(),
                    self.hist_offsets.as_entire_binding(),
                ],
            );
            let run = |encoder: &mut wgpu::CommandEncoder,
                       timer: &mut PassTimer,
                       pipeline: &wgpu::ComputePipeline,
                       label: &str| {
                let mut pass = timer.begin_compute(encoder, label);
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &group, &[]);
                pass.dispatch_workgroups(groups.0, groups.1, 1);
            };
            run(encoder, timer, &self.local, "assign: sort blocks");
            scan.encode(
                device,
                encoder,
                timer,
                "assign: sort scan",
                &self.hist,
                &self.hist_offsets,
                u64::from(blocks) * 16,
                (&self.hist_total, 0),
            );
            run(encoder, timer, &self.scatter, "assign: sort scatter");
        }
    }
}
