//! `forward`: one geometry pass; the fragment shader loops over every light.
//! Inputs: group 0 only. Outputs: HDR colour, depth, counts. Never reads a light grid: it is
//! the independent reference every other pipeline is compared with.

use super::{
    begin_lighting_pass, draw_scene_materials, lighting_targets, FrameEncoder, FrameInputs,
    MaterialPipelines,
};
use super::{GeometryPipelineDesc, PipelineContext, Technique};
use super::{RenderSettings, TransparentLights};
use crate::error::Result;
use crate::memory::{MemoryModel, Traffic, DEPTH_BYTES, HDR_BYTES, LIGHT_BYTES};
use crate::shader::{compose, create_module, ComposedShader, SCENE_PARTS};

pub(super) fn shaders() -> Vec<ComposedShader> {
    let mut parts = SCENE_PARTS.to_vec();
    parts.push(include_str!("forward.wgsl"));
    vec![compose("forward", &parts)]
}

struct Forward {
    pipelines: MaterialPipelines,
}

pub(super) fn create(ctx: &PipelineContext) -> Result<Box<dyn Technique>> {
    create_with(ctx, "fs_main")
}

/// `forward_mono`: the same, with the light pre-pass's monochrome specular model.
pub(super) fn create_mono(ctx: &PipelineContext) -> Result<Box<dyn Technique>> {
    create_with(ctx, "fs_mono")
}

/// `forward_mono_albedo`: the same, with `deferred_mono`'s one-value specular albedo.
pub(super) fn create_mono_albedo(ctx: &PipelineContext) -> Result<Box<dyn Technique>> {
    create_with(ctx, "fs_mono_albedo")
}

fn create_with(ctx: &PipelineContext, fragment_entry: &str) -> Result<Box<dyn Technique>> {
    let module = create_module(ctx.device, &shaders()[0].specialized(ctx.shading));
    let pipelines = MaterialPipelines::new(
        ctx.device,
        &GeometryPipelineDesc {
            label: "forward",
            module: &module,
            fragment_entry: Some(fragment_entry),
            layouts: &[Some(ctx.scene_layout)],
            color_targets: &lighting_targets(ctx.count_blend, ctx.settings.grid.samples),
            depth_write: true,
            depth_compare: crate::depth::SURFACE,
            samples: ctx.settings.grid.samples,
        },
        ctx.settings.material_draws,
    );
    Ok(Box::new(Forward { pipelines }))
}

impl Technique for Forward {
    fn encode(&mut self, f: &FrameInputs, enc: &mut FrameEncoder) -> Result<()> {
        let (encoder, timer) = enc.parts();
        let mut pass = begin_lighting_pass(encoder, timer, f, "forward shading", true);
        draw_scene_materials(&mut pass, f, &[], &self.pipelines);
        Ok(())
    }

    fn transparent_lights(&self) -> TransparentLights<'_> {
        TransparentLights::All
    }
}

/// HDR + depth; every fragment writes both and reads each light once.
pub(super) fn memory(_: &RenderSettings) -> MemoryModel {
    MemoryModel::new(
        &[("hdr", HDR_BYTES), ("depth", DEPTH_BYTES)],
        Traffic {
            write_per_pixel: HDR_BYTES + DEPTH_BYTES,
            read_per_pixel: 0,
            write_per_lit: 0,
            read_per_lit: LIGHT_BYTES,
        },
    )
}
