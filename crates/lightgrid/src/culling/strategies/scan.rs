//! Exclusive prefix sum on the GPU (`scan.wgsl`), used to turn counts into offsets: cell
//! counts into index-list offsets (gather, BVH), per-light pair counts into pair offsets
//! (scatter) and digit histograms into radix-sort offsets. One workgroup; the length is the
//! bound range of the source, so one pass object serves any number of calls per frame.

use crate::gpu::{bind_resources, buffer_layout, PassTimer, STORAGE_READ, STORAGE_RW};
use crate::shader::{compose, compute_pipeline, src, ComposedShader};
use std::num::NonZeroU64;

pub(crate) fn shader() -> ComposedShader {
    compose("scan", &[src::TYPES, include_str!("scan.wgsl")])
}

pub struct ScanPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

fn range(buffer: &wgpu::Buffer, offset: u64, bytes: u64) -> wgpu::BindingResource<'_> {
    wgpu::BindingResource::Buffer(wgpu::BufferBinding {
        buffer,
        offset,
        size: NonZeroU64::new(bytes),
    })
}

impl ScanPass {
    pub fn new(device: &wgpu::Device) -> Self {
        let layout = buffer_layout(device, "scan", &[STORAGE_READ, STORAGE_RW, STORAGE_RW]);
        let pipeline = compute_pipeline(device, "scan", &shader(), "main", &[Some(&layout)]);
        ScanPass { pipeline, layout }
    }

    /// Record `dst[i] = src[0] + .. + src[i - 1]` for the first `n` u32s of `src`, and the sum
    /// into the u32 at byte `total_offset` of `total`. With `n == 0` only the total (0) is
    /// written.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut PassTimer,
        label: &str,
        src: &wgpu::Buffer,
        dst: &wgpu::Buffer,
        n: u64,
        total: (&wgpu::Buffer, u64),
    ) {
        if n == 0 {
            encoder.clear_buffer(total.0, total.1, Some(4));
            return;
        }
        let group = bind_resources(
            device,
            label,
            &self.layout,
            &[
                range(src, 0, n * 4),
                range(dst, 0, n * 4),
                range(total.0, total.1, 4),
            ],
        );
        let mut pass = timer.begin_compute(encoder, label);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(1, 1, 1);
    }
}
