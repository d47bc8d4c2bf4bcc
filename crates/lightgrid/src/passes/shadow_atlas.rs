//! The shadow atlas (`--shadows maps`, `crate::shadows::maps`): its depth texture, the
//! comparison sampler the light function filters it with (group 0 bindings 9-10), and the pass
//! that renders every shadowed light's faces into it before a frame is shaded. Without shadow
//! maps it is a 1x1 texture that nothing reads.

use crate::frame::FrameInputs;
use crate::gpu::PassTimer;
use crate::shader::ComposedShader;
use crate::shadows::maps::AtlasLayout;

pub const ATLAS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The shader drawing the faces.
pub fn shader() -> ComposedShader {
    crate::shader::compose(
        "shadow map",
        &[crate::shader::src::TYPES, include_str!("shadow_map.wgsl")],
    )
}

pub(crate) struct ShadowAtlas {
    pub side: u32,
    pub view: wgpu::TextureView,
    pub sampler: wgpu::Sampler,
    /// With shadow maps: the pipeline drawing the faces and its group 0's layout.
    pipeline: Option<(wgpu::RenderPipeline, wgpu::BindGroupLayout)>,
    bind_group: Option<wgpu::BindGroup>,
}

impl ShadowAtlas {
    /// An atlas of `side` texels; `maps`: with the pipeline that draws into it.
    pub fn new(device: &wgpu::Device, side: u32, maps: bool) -> ShadowAtlas {
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow atlas"),
            size: wgpu::Extent3d {
                width: side,
                height: side,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: ATLAS_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        // Bilinear comparison: 2x2 PCF. Reversed depth: a sample is lit where it is at
        // least as near the light as the nearest occluder.
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("shadow comparison"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            compare: Some(wgpu::CompareFunction::GreaterEqual),
            ..Default::default()
        });
        let pipeline = maps.then(|| Self::pipeline(device));
        ShadowAtlas {
            side,
            view,
            sampler,
            pipeline,
            bind_group: None,
        }
    }

    fn pipeline(device: &wgpu::Device) -> (wgpu::RenderPipeline, wgpu::BindGroupLayout) {
        let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::VERTEX,
            ty: wgpu::BindingType::Buffer {
                ty,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow map (group 0)"),
            entries: &[
                entry(0, wgpu::BufferBindingType::Uniform),
                entry(1, wgpu::BufferBindingType::Storage { read_only: true }),
            ],
        });
        let module = crate::shader::create_module(device, &shader());
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow map"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        const ATTRS: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![0 => Float32x3];
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("shadow map"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_shadow"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: std::mem::size_of::<crate::gpu_types::GpuVertex>() as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &ATTRS,
                })],
            },
            // Both sides of a triangle cast.
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: ATLAS_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: None,
            multiview_mask: None,
            cache: None,
        });
        (pipeline, layout)
    }

    /// Bind the frame uniforms and the shadow buffer (again after either was replaced).
    pub fn bind(&mut self, device: &wgpu::Device, uniforms: &wgpu::Buffer, data: &wgpu::Buffer) {
        if let Some((_, layout)) = &self.pipeline {
            self.bind_group = Some(crate::gpu::bind_resources(
                device,
                "shadow map (group 0)",
                layout,
                &[uniforms.as_entire_binding(), data.as_entire_binding()],
            ));
        }
    }

    /// Render the frame's faces: every opaque run that is not alpha tested, once per tile.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut PassTimer,
        f: &FrameInputs,
        layout: &AtlasLayout,
    ) {
        let (Some((pipeline, _)), Some(bind_group)) = (&self.pipeline, &self.bind_group) else {
            return;
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("shadow maps"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: timer.render_pass("shadow maps"),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.set_vertex_buffer(0, f.vertices.slice(..));
        pass.set_index_buffer(f.indices.slice(..), wgpu::IndexFormat::Uint32);
        let t = layout.tile as f32;
        for tile in 0..layout.tiles {
            let (x, y) = layout.origin(tile);
            pass.set_viewport(x as f32, y as f32, t, t, 0.0, 1.0);
            pass.set_scissor_rect(x, y, layout.tile, layout.tile);
            for d in f.opaque.iter().filter(|d| !d.alpha_test) {
                pass.draw_indexed(d.first..d.first + d.count, 0, tile..tile + 1);
            }
        }
    }
}
