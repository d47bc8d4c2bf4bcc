//! Per-tile depth bounds (tiled-shading §6.3): the GPU kernel and its CPU twin.
//!
//! Inputs: the depth buffer (pre-Z or G-buffer depth), the grid shape. Output: per tile the
//! `[min, max]` depth-buffer value of its samples; `min > max` for a tile without samples.
//! Bindings: 0 depth texture, 1 `GridParams`, 2 bounds (storage, read-write).
//! Dispatch: one workgroup of TILE_THREADS² per tile.

use super::{GridDims, ViewSetup};
use crate::gpu::{read_buffer, PassTimer};
use crate::shader::{compose, compute_pipeline, src, ComposedShader};
use crate::Result;

pub(crate) const TILE_DEPTH_WGSL: &str = include_str!("tile_depth.wgsl");

pub(crate) fn shader() -> ComposedShader {
    compose(
        "depth_bounds",
        &[
            src::TYPES,
            TILE_DEPTH_WGSL,
            include_str!("depth_bounds.wgsl"),
        ],
    )
}

/// CPU twin of the kernel: same inputs (depth values, row-major), same output.
pub fn depth_bounds_cpu(depth: &[f32], dims: &GridDims) -> Vec<[f32; 2]> {
    (0..dims.tile_count())
        .map(|t| {
            let (x0, y0, x1, y1) = dims.tile_rect(t);
            let mut b = [1.0f32, 0.0];
            for y in y0..y1 {
                for x in x0..x1 {
                    let d = depth[(y * dims.width + x) as usize];
                    if d < 1.0 {
                        b[0] = b[0].min(d);
                        b[1] = b[1].max(d);
                    }
                }
            }
            b
        })
        .collect()
}

/// Depth-buffer bounds to view-distance bounds (monotonic, so empty tiles stay empty).
pub fn to_view_bounds(setup: &ViewSetup, ndc: &[[f32; 2]]) -> Vec<[f32; 2]> {
    ndc.iter()
        .map(|[lo, hi]| [setup.view_distance(*lo), setup.view_distance(*hi)])
        .collect()
}

/// The GPU kernel with its output and readback buffers.
pub struct DepthBoundsPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    bounds: wgpu::Buffer,
    readback: wgpu::Buffer,
    dims: GridDims,
}

impl DepthBoundsPass {
    pub fn new(device: &wgpu::Device, dims: GridDims) -> Self {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("depth bounds"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: false },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let pipeline =
            compute_pipeline(device, "depth bounds", &shader(), "main", &[Some(&layout)]);
        let size = (dims.tile_count() * 8) as u64;
        let buffer = |label, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        use wgpu::BufferUsages as U;
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("depth bounds params"),
            size: std::mem::size_of::<crate::gpu_types::GridParams>() as u64,
            usage: U::UNIFORM | U::COPY_DST,
            mapped_at_creation: false,
        });
        DepthBoundsPass {
            pipeline,
            layout,
            params,
            bounds: buffer("depth bounds", U::STORAGE | U::COPY_SRC),
            readback: buffer("depth bounds readback", U::MAP_READ | U::COPY_DST),
            dims,
        }
    }

    /// Record the reduction of `depth` and the copy to the readback buffer.
    pub fn encode(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut PassTimer,
        depth: &wgpu::TextureView,
    ) {
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&self.dims.params()));
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("depth bounds"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(depth),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: self.params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: self.bounds.as_entire_binding(),
                },
            ],
        });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("depth bounds"),
                timestamp_writes: timer.compute_pass("depth bounds"),
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups(self.dims.tiles_x, self.dims.tiles_y, 1);
        }
        encoder.copy_buffer_to_buffer(&self.bounds, 0, &self.readback, 0, self.bounds.size());
    }

    /// The per-tile bounds on the GPU (written by `encode`).
    pub fn bounds_buffer(&self) -> &wgpu::Buffer {
        &self.bounds
    }

    /// Read the bounds written by the last submitted `encode` (waits for the GPU).
    pub fn read(&self, device: &wgpu::Device) -> Result<Vec<[f32; 2]>> {
        let bytes = read_buffer(device, &self.readback)?;
        Ok(bytemuck::cast_slice::<u8, [f32; 2]>(&bytes).to_vec())
    }
}
