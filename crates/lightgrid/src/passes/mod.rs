//! Passes and resources several pipelines share: the render targets, the scene vertex layout,
//! the scene bind group (group 0) and the tonemap pass.

pub mod base_textures;
pub(crate) mod depth_texels;
mod gbuffer;
pub(crate) mod geometry;
mod light_volumes;
mod readback;
pub(crate) mod shadow_atlas;
mod tonemap;

pub use crate::frame::targets::{cleared, loaded, DEPTH_FORMAT, HDR_FORMAT, LDR_FORMAT};
pub(crate) use crate::frame::targets::{
    cleared_depth, loaded_depth, multisampled_texture, render_texture, Targets, COUNT_FORMAT,
};
pub(crate) use gbuffer::{GBuffer, GBUFFER_READ_WGSL};
pub use gbuffer::{GBufferFormat, GBufferLayout};
pub use light_volumes::{additive, classify_lights, Shading, VolumeClasses, VOLUME_DEPTH_BYTES};
pub(crate) use light_volumes::{
    Fullscreen, FullscreenVolumeDesc, LightVolumes, VolumeDraw, VolumePipelineDesc, VOLUME_WGSL,
};
pub use readback::Readback;
pub(crate) use readback::{BufferReadback, DepthBits, DepthSamples};
pub(crate) use tonemap::Tonemap;

use crate::gpu_types::{FrameUniforms, GpuLight, GpuMaterial, GpuVertex};
use crate::shader::ComposedShader;
use std::num::NonZeroU64;

/// Every shader of the shared passes, for validation.
pub fn shaders() -> Vec<ComposedShader> {
    use crate::shader::ShaderKey;
    let mut out = tonemap::TonemapKey::all_shaders();
    out.extend(readback::DepthSamplesKey::all_shaders());
    out.push(gbuffer::shader());
    out.push(shadow_atlas::shader());
    out.push(depth_texels::shader());
    out
}

/// `fullscreen_position(vertex_index)`: a screen-covering triangle.
pub const FULLSCREEN_WGSL: &str = include_str!("fullscreen.wgsl");

/// What a full-screen pass (`vs_fullscreen` + one fragment entry, no depth) draws with.
pub struct FullscreenDesc<'a> {
    /// Label of the pipeline and its pipeline layout.
    pub label: &'a str,
    /// The shader holding `vs_fullscreen` and the fragment entry point.
    pub shader: &'a ComposedShader,
    /// Name of the fragment entry point in `shader`.
    pub fragment_entry: &'a str,
    /// Layout of group 0, the pipeline's only bind group.
    pub layout: &'a wgpu::BindGroupLayout,
    /// Format of the one colour target.
    pub target: wgpu::TextureFormat,
    /// Samples per pixel of the target.
    pub samples: u32,
    /// Values of the shader's `override` constants.
    pub constants: &'a [(&'a str, f64)],
}

/// A full-screen triangle pipeline (tonemap, the MSAA sample expand, the viewer's blit).
pub fn fullscreen_pipeline(device: &wgpu::Device, d: &FullscreenDesc) -> wgpu::RenderPipeline {
    let module = crate::shader::create_module(device, d.shader);
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(d.label),
        bind_group_layouts: &[Some(d.layout)],
        immediate_size: 0,
    });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(d.label),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_fullscreen"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: Default::default(),
        depth_stencil: None,
        multisample: wgpu::MultisampleState {
            count: d.samples,
            ..Default::default()
        },
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some(d.fragment_entry),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants: d.constants,
                ..Default::default()
            },
            targets: &[Some(d.target.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// Record a full-screen pass of `pipeline` (a [`fullscreen_pipeline`] whose group 0 is one
/// texture, `layout`) reading `source` into `out`, cleared to black first.
#[allow(clippy::too_many_arguments)]
pub fn draw_fullscreen(
    device: &wgpu::Device,
    encoder: &mut wgpu::CommandEncoder,
    label: &str,
    (pipeline, layout): (&wgpu::RenderPipeline, &wgpu::BindGroupLayout),
    source: &wgpu::TextureView,
    out: &wgpu::TextureView,
    timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
) {
    let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: wgpu::BindingResource::TextureView(source),
        }],
    });
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: out,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, &bind, &[]);
    pass.draw(0..3, 0..1);
}

/// WGSL of a deferred compute pass's outputs (group 3).
pub(crate) const COMPUTE_OUTPUTS_WGSL: &str = include_str!("compute_outputs.wgsl");

/// The MSAA edge test (`differs`) over a per-sample G-buffer: the edge-aware deferred kernel
/// and the light volumes' edge marking both compose it, so they shade the same pixels per
/// sample. Needs `GBUFFER_READ_WGSL` and `shader::src::MSAA` with `shader::msaa_defs`.
pub(crate) const MSAA_EDGES_WGSL: &[&str] = &[MSAA_SURFACES_WGSL, include_str!("msaa_edges.wgsl")];

/// The edge test's core (`surfaces_differ`: normals and planes of two samples with geometry),
/// for readers of other per-sample attributes than the G-buffer (the light pre-pass). Needs
/// `shader::src::MSAA` with `shader::msaa_defs`.
pub(crate) const MSAA_SURFACES_WGSL: &str = include_str!("msaa_surfaces.wgsl");

/// Layout of group 3 of deferred compute passes (`compute_outputs.wgsl`).
pub(crate) fn compute_outputs_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let storage = |binding, format| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format,
            view_dimension: wgpu::TextureViewDimension::D2,
        },
        count: None,
    };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("compute outputs (group 3)"),
        entries: &[storage(0, HDR_FORMAT), storage(1, COUNT_FORMAT)],
    })
}

/// Group 3 for a deferred compute pass: the HDR and count targets as storage textures.
pub(crate) fn compute_outputs(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    targets: &Targets,
) -> wgpu::BindGroup {
    compute_outputs_to(device, layout, &targets.hdr, &targets.counts)
}

/// Group 3 with another RGBA16F target in the colour's place (the tiled light pre-pass's
/// irradiance).
pub(crate) fn compute_outputs_to(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    color: &wgpu::TextureView,
    counts: &wgpu::TextureView,
) -> wgpu::BindGroup {
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("compute outputs"),
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(color),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(counts),
            },
        ],
    })
}

/// The count target of a fragment pipeline: additive blending where the adapter can blend
/// R32Float, otherwise no target (the count is then not reported).
pub(crate) fn count_target(count_blend: bool) -> Option<wgpu::ColorTargetState> {
    count_blend.then_some(wgpu::ColorTargetState {
        format: COUNT_FORMAT,
        blend: Some(wgpu::BlendState {
            color: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::One,
                dst_factor: wgpu::BlendFactor::One,
                operation: wgpu::BlendOperation::Add,
            },
            alpha: wgpu::BlendComponent::REPLACE,
        }),
        write_mask: wgpu::ColorWrites::RED,
    })
}

/// The vertex buffer layout matching `passes/geometry.wgsl`'s `VertexIn`.
pub fn vertex_layout() -> wgpu::VertexBufferLayout<'static> {
    const ATTRS: [wgpu::VertexAttribute; 7] = wgpu::vertex_attr_array![
        0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Uint32,
        4 => Snorm16x4, 5 => Unorm8x4, 6 => Float32x2
    ];
    wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<GpuVertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &ATTRS,
    }
}

/// Which stages see group 0's light bounds (`scene_layout_with`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SceneBounds {
    /// The light volumes' vertex stage only: every shading pass, whose grid (3 storage
    /// buffers) then fits WebGPU's default 8 per stage beside group 0's 4 (5 with MSAA's
    /// sample outputs in compute).
    Vertex,
    /// Also compute: the single-kernel tiled deferred pass, which culls in the kernel.
    Compute,
}

/// Layout of group 0 (`shading/scene_bindings.wgsl`): frame uniforms, lights, materials,
/// and (`passes/geometry.wgsl`) the base-colour textures; the light bounds visible to the
/// vertex stage only (every pipeline's passes but the single-kernel tiled deferred one's).
pub fn scene_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    scene_layout_with(device, SceneBounds::Vertex)
}

/// [`scene_layout`] with the light bounds visible to `bounds`' stages.
pub(crate) fn scene_layout_with(
    device: &wgpu::Device,
    bounds: SceneBounds,
) -> wgpu::BindGroupLayout {
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
            // Per light its bounding sphere [centre, radius]: placing the light volumes
            // (vertex) and, with `SceneBounds::Compute`, culling in the single-kernel tiled
            // deferred pass. Not visible to fragment stages, nor to the other compute passes
            // (each a storage buffer fewer per stage: see `SceneBounds`).
            wgpu::BindGroupLayoutEntry {
                visibility: match bounds {
                    SceneBounds::Vertex => wgpu::ShaderStages::VERTEX,
                    SceneBounds::Compute => {
                        wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::COMPUTE
                    }
                },
                ..storage(4, 16)
            },
            // The frame counters (`gpu/counters.rs`), with MSAA the per-pixel lighting counts
            // after them: written by fragment and compute stages (a vertex stage may not
            // write storage).
            wgpu::BindGroupLayoutEntry {
                binding: 3,
                visibility: wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: false },
                    has_dynamic_offset: false,
                    min_binding_size: NonZeroU64::new(crate::gpu::COUNTER_BYTES),
                },
                count: None,
            },
            // The base-colour texture array and its sampler (`base_textures.rs`).
            base_textures::layout_entries()[0],
            base_textures::layout_entries()[1],
            // The shadow rays' hierarchies and casters (`shading/shadows.wgsl`): a header of
            // two vec4s at least.
            storage(7, 32),
            // The shadow atlas and its comparison sampler (`shadow_atlas.rs`).
            wgpu::BindGroupLayoutEntry {
                binding: 8,
                visibility: wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Depth,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 9,
                visibility: wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
                count: None,
            },
            // The textures' nearest sampler (glTF's magFilter NEAREST) and the array again.
            base_textures::nearest_layout_entries()[0],
            base_textures::nearest_layout_entries()[1],
        ],
    })
}

/// A texture binding visible to fragment and compute stages.
pub fn texture_entry(
    binding: u32,
    sample_type: wgpu::TextureSampleType,
) -> wgpu::BindGroupLayoutEntry {
    sampled_texture_entry(binding, sample_type, 1)
}

/// As [`texture_entry`], multisampled when `samples` > 1 (`shader::src::MSAA`'s types).
pub(crate) fn sampled_texture_entry(
    binding: u32,
    sample_type: wgpu::TextureSampleType,
    samples: u32,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: samples > 1,
        },
        count: None,
    }
}
