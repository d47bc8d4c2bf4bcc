//! Passes and resources several pipelines share: the render targets, the scene vertex layout,
//! the scene bind group (group 0) and the tonemap pass.

mod tonemap;

pub use tonemap::Tonemap;

use crate::gpu_types::{FrameUniforms, GpuLight, GpuMaterial, GpuVertex};
use crate::shader::ComposedShader;
use std::num::NonZeroU64;

/// HDR colour target every pipeline accumulates light into.
pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Scene depth buffer.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Display target: the tonemap pass writes linear values and the format encodes sRGB.
pub const LDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// Every shader of the shared passes, for validation.
pub fn shaders() -> Vec<ComposedShader> {
    vec![tonemap::shader()]
}

/// The vertex buffer layout matching `passes/geometry.wgsl`'s `VertexIn`.
pub fn vertex_layout() -> wgpu::VertexBufferLayout<'static> {
    const ATTRS: [wgpu::VertexAttribute; 4] =
        wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Uint32];
    wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<GpuVertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &ATTRS,
    }
}

/// Layout of group 0 (`shading/scene_bindings.wgsl`): frame uniforms, lights, materials.
pub fn scene_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let storage = |binding, size: usize| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT | wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: NonZeroU64::new(size as u64),
        },
        count: None,
    };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("scene (group 0)"),
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT | wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: NonZeroU64::new(std::mem::size_of::<FrameUniforms>() as u64),
                },
                count: None,
            },
            storage(1, std::mem::size_of::<GpuLight>()),
            storage(2, std::mem::size_of::<GpuMaterial>()),
        ],
    })
}

/// The frame's render targets.
pub struct Targets {
    pub width: u32,
    pub height: u32,
    pub hdr: wgpu::TextureView,
    pub depth: wgpu::TextureView,
    pub ldr_texture: wgpu::Texture,
    pub ldr: wgpu::TextureView,
}

impl Targets {
    pub fn new(device: &wgpu::Device, width: u32, height: u32) -> Self {
        let make = |label, format, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        use wgpu::TextureUsages as U;
        let hdr = make("hdr", HDR_FORMAT, U::RENDER_ATTACHMENT | U::TEXTURE_BINDING);
        let depth = make(
            "depth",
            DEPTH_FORMAT,
            U::RENDER_ATTACHMENT | U::TEXTURE_BINDING,
        );
        let ldr_texture = make("ldr", LDR_FORMAT, U::RENDER_ATTACHMENT | U::COPY_SRC);
        Targets {
            width,
            height,
            hdr: hdr.create_view(&Default::default()),
            depth: depth.create_view(&Default::default()),
            ldr: ldr_texture.create_view(&Default::default()),
            ldr_texture,
        }
    }

    /// Bytes per pixel of the targets every pipeline has (HDR + depth + display).
    pub fn base_bytes_per_pixel() -> u32 {
        8 + 4 + 4
    }
}
