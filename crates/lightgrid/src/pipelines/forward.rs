//! `forward`: one geometry pass; the fragment shader loops over every light.
//! Inputs: group 0 only. Output: HDR colour and depth. Never reads a light grid: it is the
//! independent reference every other pipeline is compared with.

use super::{geometry_pipeline, FrameInputs, GeometryPipelineDesc, PipelineContext, Technique};
use crate::gpu::PassTimer;
use crate::passes::HDR_FORMAT;
use crate::shader::{compose, create_module, ComposedShader, SCENE_PARTS};

pub(super) fn shaders() -> Vec<ComposedShader> {
    let mut parts = SCENE_PARTS.to_vec();
    parts.push(include_str!("forward.wgsl"));
    vec![compose("forward", &parts)]
}

struct Forward {
    pipeline: wgpu::RenderPipeline,
}

pub(super) fn create(ctx: &PipelineContext) -> Box<dyn Technique> {
    let module = create_module(ctx.device, &shaders()[0]);
    let pipeline = geometry_pipeline(
        ctx.device,
        &GeometryPipelineDesc {
            label: "forward",
            module: &module,
            fragment_entry: "fs_main",
            layouts: &[Some(ctx.scene_layout)],
            color_targets: &[Some(HDR_FORMAT.into())],
            depth_write: true,
            depth_compare: wgpu::CompareFunction::Less,
        },
    );
    Box::new(Forward { pipeline })
}

impl Technique for Forward {
    fn encode(&self, f: &FrameInputs, encoder: &mut wgpu::CommandEncoder, timer: &mut PassTimer) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("forward shading"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &f.targets.hdr,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &f.targets.depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: timer.render_pass("forward shading"),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, f.scene_bind_group, &[]);
        pass.set_vertex_buffer(0, f.vertices.slice(..));
        pass.set_index_buffer(f.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..f.index_count, 0, 0..1);
    }
}
