//! `forward`: one geometry pass; the fragment shader loops over every light.
//! Inputs: group 0 only. Outputs: HDR colour, depth, counts. Never reads a light grid: it is
//! the independent reference every other pipeline is compared with.

use super::{
    begin_lighting_pass, draw_scene, geometry_pipeline, lighting_targets, FrameEncoder, FrameInputs,
};
use super::{GeometryPipelineDesc, PipelineContext, Technique};
use crate::culling::LightGrid;
use crate::shader::{compose, create_module, ComposedShader, SCENE_PARTS};
use crate::Result;

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
            fragment_entry: Some("fs_main"),
            layouts: &[Some(ctx.scene_layout)],
            color_targets: &lighting_targets(ctx.count_blend),
            depth_write: true,
            depth_compare: wgpu::CompareFunction::Less,
        },
    );
    Box::new(Forward { pipeline })
}

impl Technique for Forward {
    fn render(&mut self, f: &FrameInputs, enc: &mut FrameEncoder) -> Result<Option<LightGrid>> {
        let (encoder, timer) = enc.parts();
        let mut pass = begin_lighting_pass(encoder, timer, f, "forward shading", true);
        pass.set_pipeline(&self.pipeline);
        draw_scene(&mut pass, f, &[]);
        Ok(None)
    }
}
