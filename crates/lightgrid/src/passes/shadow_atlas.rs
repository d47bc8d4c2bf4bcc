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
    /// The texture's size (1x1 without shadow maps).
    pub size: (u32, u32),
    texture: wgpu::Texture,
    pub view: wgpu::TextureView,
    pub sampler: wgpu::Sampler,
    /// With shadow maps: the pipeline drawing the faces and its group 0's layout.
    pipeline: Option<(wgpu::RenderPipeline, wgpu::BindGroupLayout)>,
    bind_group: Option<wgpu::BindGroup>,
}

impl ShadowAtlas {
    /// A 1x1 texture; `maps`: with the pipeline that draws into it ([`Self::fit`] sizes it).
    pub fn new(device: &wgpu::Device, maps: bool) -> ShadowAtlas {
        let pipeline = maps.then(|| Self::pipeline(device));
        let (texture, view) = Self::texture(device, (1, 1));
        ShadowAtlas {
            size: (1, 1),
            texture,
            view,
            sampler: Self::sampler(device),
            pipeline,
            bind_group: None,
        }
    }

    /// Make the texture `size` (what a frame's layout needs). Returns true when it was
    /// replaced (group 0 binds its view).
    pub fn fit(&mut self, device: &wgpu::Device, size: (u32, u32)) -> bool {
        if self.size == size {
            return false;
        }
        (self.texture, self.view) = Self::texture(device, size);
        self.size = size;
        true
    }

    /// The texture as an image (analysis only: blocks): each texel's distance to its light
    /// on a log scale, near white, far dark; black where no geometry was drawn.
    pub fn image(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> crate::error::Result<image::RgbaImage> {
        let (w, h) = self.size;
        let row = (w * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("shadow atlas readback"),
            size: u64::from(row) * u64::from(h),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &self.texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::DepthOnly,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: Some(h),
                },
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        queue.submit([encoder.finish()]);
        let bytes = crate::gpu::read_buffer(device, &buffer)?;
        let depth = |x: u32, y: u32| {
            let at = (y * row + x * 4) as usize;
            f32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"))
        };
        // Reversed depth near / w: its log is the distance's, up to each light's near plane.
        let logs: Vec<f32> = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| depth(x, y))
            .filter(|&d| d > 0.0)
            .map(f32::ln)
            .collect();
        let lo = logs.iter().copied().fold(f32::INFINITY, f32::min);
        let hi = logs.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        Ok(image::RgbaImage::from_fn(w, h, |x, y| {
            let d = depth(x, y);
            let v = if d > 0.0 {
                (40.0 + 215.0 * (d.ln() - lo) / (hi - lo).max(1e-6)) as u8
            } else {
                0
            };
            image::Rgba([v, v, v, 255])
        }))
    }

    fn texture(
        device: &wgpu::Device,
        (width, height): (u32, u32),
    ) -> (wgpu::Texture, wgpu::TextureView) {
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow maps"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: ATLAS_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        (texture, view)
    }

    /// Bilinear comparison: 2x2 PCF. Reversed depth: a sample is lit where it is at least as
    /// near the light as the nearest occluder.
    fn sampler(device: &wgpu::Device) -> wgpu::Sampler {
        device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("shadow comparison"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            compare: Some(wgpu::CompareFunction::GreaterEqual),
            ..Default::default()
        })
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

    /// All in flight: every face of the frame into its own tile of the atlas.
    pub fn encode_all(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut PassTimer,
        f: &FrameInputs,
        layout: &AtlasLayout,
    ) {
        let faces: Vec<(u32, u32)> = (0..layout.tiles).map(|t| (t, t)).collect();
        self.encode(
            encoder,
            timer.render_pass(crate::shadows::maps::PASS_LABEL),
            f,
            layout,
            &faces,
        );
    }

    /// Re-used: one light's faces `first..first + count` into the six tiles, before its volume
    /// (untimed: a frame may shade hundreds of shadowed lights).
    pub fn encode_light(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        f: &FrameInputs,
        layout: &AtlasLayout,
        (first, count): (u32, u32),
    ) {
        let faces: Vec<(u32, u32)> = (0..count).map(|k| (k, first + k)).collect();
        self.encode(encoder, None, f, layout, &faces);
    }

    /// Draw every opaque run that is not alpha tested once per (tile, face).
    fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
        f: &FrameInputs,
        layout: &AtlasLayout,
        faces: &[(u32, u32)],
    ) {
        let (Some((pipeline, _)), Some(bind_group)) = (&self.pipeline, &self.bind_group) else {
            return;
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(crate::shadows::maps::PASS_LABEL),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.set_vertex_buffer(0, f.vertices.slice(..));
        pass.set_index_buffer(f.indices.slice(..), wgpu::IndexFormat::Uint32);
        let t = layout.tile as f32;
        for &(tile, face) in faces {
            let (x, y) = layout.origin(tile);
            pass.set_viewport(x as f32, y as f32, t, t, 0.0, 1.0);
            pass.set_scissor_rect(x, y, layout.tile, layout.tile);
            for d in f.opaque.iter().filter(|d| !d.alpha_test) {
                pass.draw_indexed(d.first..d.first + d.count, 0, face..face + 1);
            }
        }
    }
}

/// A frame's re-used maps (`FrameInputs::reused_shadow_maps`): the texture and the frame's
/// faces.
pub(crate) struct ReusedMaps<'a> {
    pub atlas: &'a ShadowAtlas,
    pub frame: &'a crate::shadows::maps::MapFrame,
}

impl crate::frame::ReusedShadowMaps for ReusedMaps<'_> {
    fn casts(&self, light: usize) -> bool {
        self.frame.faces_of(light).is_some()
    }

    fn encode_light(&self, encoder: &mut wgpu::CommandEncoder, f: &FrameInputs, light: usize) {
        if let Some(faces) = self.frame.faces_of(light) {
            self.atlas
                .encode_light(encoder, f, &self.frame.layout, faces);
        }
    }
}
