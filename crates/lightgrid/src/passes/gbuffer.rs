//! The G-buffer pass and the group-2 bindings deferred compute passes read it through
//! (`gbuffer_read.wgsl`). Four colour targets of four channels, 16-bit float by default or
//! 32-bit (`--gbuffer 32`), as tiled-shading §8 measures both; depth is the shared target.

use super::geometry::{draw_scene, geometry_pipeline, GeometryPipelineDesc};
use super::Targets;
use crate::frame::FrameInputs;
use crate::gpu::PassTimer;
use crate::shader::{compose, create_module, ComposedShader, SCENE_PARTS};

pub use crate::frame::GBufferFormat;

pub(crate) fn shader() -> ComposedShader {
    let mut parts = SCENE_PARTS.to_vec();
    parts.push(include_str!("gbuffer.wgsl"));
    compose("gbuffer", &parts)
}

/// WGSL a deferred compute shader includes to read the G-buffer.
pub const GBUFFER_READ_WGSL: &str = include_str!("gbuffer_read.wgsl");

const TARGET_NAMES: [&str; 4] = [
    "gbuffer normal",
    "gbuffer diffuse",
    "gbuffer specular",
    "gbuffer base",
];

pub struct GBuffer {
    pub format: GBufferFormat,
    views: Vec<wgpu::TextureView>,
    pipeline: wgpu::RenderPipeline,
    pub read_layout: wgpu::BindGroupLayout,
}

impl GBuffer {
    pub fn new(
        device: &wgpu::Device,
        scene_layout: &wgpu::BindGroupLayout,
        format: GBufferFormat,
        size: (u32, u32),
        samples: u32,
    ) -> Self {
        let tf = format.texture_format();
        let views = TARGET_NAMES
            .iter()
            .map(|name| {
                super::multisampled_texture(
                    device,
                    name,
                    tf,
                    size,
                    samples,
                    wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
                )
                .create_view(&Default::default())
            })
            .collect();
        let module = create_module(device, &shader());
        let targets: Vec<Option<wgpu::ColorTargetState>> =
            (0..4).map(|_| Some(tf.into())).collect();
        let pipeline = geometry_pipeline(
            device,
            &GeometryPipelineDesc {
                label: "gbuffer",
                module: &module,
                fragment_entry: Some("fs_gbuffer"),
                layouts: &[Some(scene_layout)],
                color_targets: &targets,
                depth_write: true,
                depth_compare: wgpu::CompareFunction::Less,
                samples,
            },
        );
        GBuffer {
            format,
            views,
            pipeline,
            read_layout: Self::read_layout(device, samples),
        }
    }

    fn read_layout(device: &wgpu::Device, samples: u32) -> wgpu::BindGroupLayout {
        let tex =
            |binding, sample_type| super::sampled_texture_entry(binding, sample_type, samples);
        let float = wgpu::TextureSampleType::Float { filterable: false };
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("gbuffer read (group 2)"),
            entries: &[
                tex(0, float),
                tex(1, float),
                tex(2, float),
                tex(3, float),
                tex(4, wgpu::TextureSampleType::Depth),
            ],
        })
    }

    /// Group 2 of a deferred pass: the G-buffer and the depth it was rendered with.
    pub fn read_bind_group(&self, device: &wgpu::Device, targets: &Targets) -> wgpu::BindGroup {
        let view = |binding, v| wgpu::BindGroupEntry {
            binding,
            resource: wgpu::BindingResource::TextureView(v),
        };
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gbuffer read"),
            layout: &self.read_layout,
            entries: &[
                view(0, &self.views[0]),
                view(1, &self.views[1]),
                view(2, &self.views[2]),
                view(3, &self.views[3]),
                view(4, &targets.depth),
            ],
        })
    }

    /// Rasterize the scene into the G-buffer and the depth target.
    pub fn encode(
        &self,
        f: &FrameInputs,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut PassTimer,
    ) {
        let attachments: Vec<Option<wgpu::RenderPassColorAttachment>> = self
            .views
            .iter()
            .map(|v| {
                Some(wgpu::RenderPassColorAttachment {
                    view: v,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })
            })
            .collect();
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("gbuffer"),
            color_attachments: &attachments,
            depth_stencil_attachment: Some(crate::passes::cleared_depth(&f.targets.depth)),
            timestamp_writes: timer.render_pass("gbuffer"),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        draw_scene(&mut pass, f, &[]);
    }
}
