//! Tonemap: reads the HDR target, writes the sRGB display target (and resolves MSAA).
//! Bindings: group 0 binding 0 = HDR texture (textureLoad, no sampler).

use super::LDR_FORMAT;
use crate::gpu::PassTimer;
use crate::shader::{compose, ComposedShader};

pub(crate) fn shader(samples: u32) -> ComposedShader {
    compose(
        "tonemap",
        &[
            super::FULLSCREEN_WGSL,
            &crate::shader::msaa_wgsl(samples),
            crate::shader::src::TONE,
            include_str!("tonemap.wgsl"),
        ],
    )
}

pub struct Tonemap {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

impl Tonemap {
    /// The tonemap of a frame with `samples` samples per pixel (above one, it resolves).
    pub fn new(device: &wgpu::Device, samples: u32) -> Self {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("tonemap"),
            entries: &[super::sampled_texture_entry(
                0,
                wgpu::TextureSampleType::Float { filterable: false },
                samples,
            )],
        });
        let pipeline = super::fullscreen_pipeline(
            device,
            &super::FullscreenDesc {
                label: "tonemap",
                shader: &shader(samples),
                fragment_entry: "fs_tonemap",
                layout: &layout,
                target: LDR_FORMAT,
                samples: 1,
                constants: &[],
            },
        );
        Tonemap { pipeline, layout }
    }

    pub fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut PassTimer,
        hdr: &wgpu::TextureView,
        out: &wgpu::TextureView,
    ) {
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("tonemap"),
            layout: &self.layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(hdr),
            }],
        });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("tonemap"),
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
            timestamp_writes: timer.render_pass("tonemap"),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.draw(0..3, 0..1);
    }
}
