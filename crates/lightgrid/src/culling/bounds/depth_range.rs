//! The depth range a clustered grid's slices are spread over: the view-distance range of the
//! frame's samples (within near..far), found on the GPU before the cell bounds, so the slices
//! follow the content whatever the camera's planes (a glTF camera's znear 10⁻⁶ / zfar 10⁶
//! spread them over twelve decades, nearly all empty).
//!
//! Inputs: the frame's depth target (every sample with MSAA), the grid's parameters as the
//! CPU wrote them. Outputs: `range` (the slicing range `[lo, hi]`, read back by analysis and
//! by the CPU strategy) and the parameters with the slices spread over it, copied over every
//! uniform copy of the grid's parameters in the frame's encoder (the cell-bounds kernel's and
//! the lists'), so every later stage of the frame reads them.
//! Steps (`depth_range.wgsl`): 1. `reduce`, 2. `finish`. CPU twins: [`depth_range_cpu`] and
//! [`slicing_range`].

use crate::consts::SLICING_MIN_RATIO;
use crate::culling::frame::CullFrame;
use crate::culling::grid::GridDims;
use crate::error::Result;
use crate::frame::FrameEncoder;
use crate::gpu::{bind_resources, download, storage_buffer};
use crate::gpu_types::GridParams;
use crate::scene::ViewSetup;
use crate::shader::{compute_pipeline, src, SampleStage, SamplesKey, ShaderKey};

/// The depth-range kernel of a depth target of `samples` samples per pixel.
pub(crate) type DepthRangeKey = SamplesKey<DepthRangeStage>;

pub(crate) enum DepthRangeStage {}

impl SampleStage for DepthRangeStage {
    const STAGE: &'static str = "depth_range";

    fn parts(_samples: u32) -> Vec<&'static str> {
        vec![
            src::TYPES,
            src::GRID_PARAMS,
            src::SCENE_BINDINGS,
            src::MSAA,
            include_str!("depth_range.wgsl"),
        ]
    }
}

/// The view-distance `[min, max]` of every sample that holds geometry (`planes[s]`: sample
/// `s` of every pixel); `[+inf, 0]` when none does. Twin of `reduce`.
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub fn depth_range_cpu(setup: &ViewSetup, planes: &[&[f32]]) -> [f32; 2] {
    planes
        .iter()
        .flat_map(|p| p.iter())
        .map(|&d| setup.view_distance(d))
        .filter(|w| w.is_finite())
        .fold([f32::INFINITY, 0.0], |[lo, hi], w| [lo.min(w), hi.max(w)])
}

/// The slicing range for samples spanning `samples` (`[+inf, 0]`: none): clamped to
/// near..far, near..far without samples, and at least `SLICING_MIN_RATIO` wide. Twin of
/// `finish`.
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub fn slicing_range(samples: [f32; 2], near: f32, far: f32) -> [f32; 2] {
    let [lo, hi] = if samples[0] > samples[1] {
        [near, far]
    } else {
        samples
    };
    let lo = lo.clamp(near, far);
    [lo, hi.clamp(near, far).max(lo * SLICING_MIN_RATIO)]
}

pub(crate) struct DepthRangePass {
    reduce: wgpu::ComputePipeline,
    finish: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    range: wgpu::Buffer,
    params_out: wgpu::Buffer,
}

impl DepthRangePass {
    /// The passes over a depth target of `samples` samples per pixel.
    pub fn new(device: &wgpu::Device, cull_layout: &wgpu::BindGroupLayout, samples: u32) -> Self {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("depth range (group 1)"),
            entries: &[
                crate::passes::sampled_texture_entry(0, wgpu::TextureSampleType::Depth, samples),
                crate::gpu::buffer_entry(1, crate::gpu::UNIFORM),
                crate::gpu::buffer_entry(2, crate::gpu::STORAGE_RW),
                crate::gpu::buffer_entry(3, crate::gpu::STORAGE_RW),
            ],
        });
        let s = DepthRangeKey::new(samples).shader();
        let layouts = [Some(cull_layout), Some(&layout)];
        DepthRangePass {
            reduce: compute_pipeline(device, "depth range", &s, "reduce", &layouts),
            finish: compute_pipeline(device, "depth range finish", &s, "finish", &layouts),
            layout,
            params: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("depth range params"),
                size: PARAMS_BYTES,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            range: storage_buffer(device, "depth range", 8),
            params_out: storage_buffer(device, "sliced grid params", PARAMS_BYTES),
        }
    }

    /// Record both steps over `f.targets.depth` for a grid of `dims` (as the CPU sliced it),
    /// then copy the sliced parameters over each of `targets` (uniform buffers holding
    /// `dims.params()`, written with `queue.write_buffer` this frame: those writes land
    /// before the frame's commands, so the copies win).
    pub fn encode(
        &self,
        f: &CullFrame,
        enc: &mut FrameEncoder,
        dims: &GridDims,
        targets: &[&wgpu::Buffer],
    ) {
        let queue = f.queue;
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&dims.params()));
        queue.write_buffer(
            &self.range,
            0,
            bytemuck::cast_slice(&[f32::INFINITY.to_bits(), 0u32]),
        );
        let group = bind_resources(
            f.device,
            "depth range",
            &self.layout,
            &[
                wgpu::BindingResource::TextureView(f.depth()),
                self.params.as_entire_binding(),
                self.range.as_entire_binding(),
                self.params_out.as_entire_binding(),
            ],
        );
        let (encoder, timer) = enc.parts();
        {
            let mut pass = timer.begin_compute(encoder, crate::consts::pass_labels::DEPTH_RANGE);
            pass.set_bind_group(0, f.bind_group, &[]);
            pass.set_bind_group(1, &group, &[]);
            pass.set_pipeline(&self.reduce);
            let t = crate::consts::TILE_THREADS;
            pass.dispatch_workgroups(dims.width.div_ceil(t), dims.height.div_ceil(t), 1);
            pass.set_pipeline(&self.finish);
            pass.dispatch_workgroups(1, 1, 1);
        }
        for target in targets {
            encoder.copy_buffer_to_buffer(&self.params_out, 0, target, 0, PARAMS_BYTES);
        }
    }

    /// `dims` sliced as the last recorded frame was (submits nothing itself: call after the
    /// frame's work is submitted).
    pub fn read(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        dims: &GridDims,
    ) -> Result<GridDims> {
        let range = download(device, queue, &self.range, 8)?;
        let params = download(device, queue, &self.params_out, PARAMS_BYTES)?;
        Ok(sliced(dims, &range, &params))
    }

    /// What to read back part-way through the frame for `sliced` (the slicing range, the
    /// sliced parameters): the CPU strategy reads them with the cell bounds, in one wait.
    pub fn readback(&self) -> [(&wgpu::Buffer, u64); 2] {
        [(&self.range, 8), (&self.params_out, PARAMS_BYTES)]
    }
}

const PARAMS_BYTES: u64 = std::mem::size_of::<GridParams>() as u64;

/// `dims` with the GPU's slicing, from the bytes of [`DepthRangePass::readback`]: its range
/// and, bit for bit, its scale and bias.
pub fn sliced(dims: &GridDims, range: &[u8], params: &[u8]) -> GridDims {
    let range: [f32; 2] = bytemuck::pod_read_unaligned(range);
    let p: GridParams = bytemuck::pod_read_unaligned(params);
    dims.with_slicing(range, p.slice_scale, p.slice_bias)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_slicing_range_is_the_samples_within_near_and_far() {
        assert_eq!(slicing_range([2.0, 50.0], 0.1, 100.0), [2.0, 50.0]);
        assert_eq!(slicing_range([0.01, 500.0], 0.1, 100.0), [0.1, 100.0]);
        assert_eq!(
            slicing_range([f32::INFINITY, 0.0], 0.1, 100.0),
            [0.1, 100.0]
        );
        // One view distance: a range of SLICING_MIN_RATIO.
        let [lo, hi] = slicing_range([3.0, 3.0], 0.1, 100.0);
        assert_eq!(lo, 3.0);
        assert!((hi / lo - SLICING_MIN_RATIO).abs() < 1e-6);
    }
}
