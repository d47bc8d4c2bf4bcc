//! A grid pipeline's light grid: lightgrid's renderer is a [`LightCuller`] caller like any
//! other. It hands the culler its depth, its camera-relative lights (the view a rotation,
//! the eye at the origin: `ViewSetup::relative`), the same lights on the CPU for `cpu` and
//! `bvh`, and through [`CullExtras`] its pass timer, its frame's CPU-side costs and, with
//! MSAA, the draws of its forward fragments (`fragment_bounds.rs`).

use super::fragment_bounds::FragmentDraws;
use super::PipelineContext;
use crate::culling::{CullConfig, CullError, CullExtras, CullInput, CullInputs, LightCuller};
use crate::error::{Error, Result};
use crate::frame::{FrameEncoder, FrameInputs};

/// The renderer's error for a culler's refusal: what the device could not do is a GPU
/// error, the rest (the grid's description, a frame too large for it) a setting's.
fn cull_error(e: CullError) -> Error {
    match e.input {
        CullInput::Device => Error::Gpu {
            stage: "light culling".into(),
            message: e.message,
        },
        _ => Error::invalid("light grid", e.message),
    }
}

/// One grid of a pipeline and how its frames reach it.
pub(crate) struct PipelineGrid {
    culler: LightCuller,
    /// Cells bounded by the frame's depth (a pre-pass or G-buffer), else near..far.
    depth: bool,
    /// With MSAA: the fragments shaded from the grid, drawn for the culler.
    fragments: Option<FragmentDraws>,
}

impl PipelineGrid {
    /// The grid `config` describes; `depth`: bounded by the frame's depth;
    /// `forward_opaque`: a forward pass shades the opaque geometry from it.
    pub(crate) fn new(
        ctx: &PipelineContext,
        config: &CullConfig,
        depth: bool,
        forward_opaque: bool,
    ) -> Result<Self> {
        let culler = LightCuller::new(ctx.device, ctx.queue, *config).map_err(cull_error)?;
        let fragments = culler
            .fragment_bounds_layout()
            .filter(|_| depth)
            .map(|layout| {
                FragmentDraws::new(
                    ctx.device,
                    ctx.scene_layout,
                    layout,
                    config.samples,
                    forward_opaque,
                )
            });
        Ok(PipelineGrid {
            culler,
            depth,
            fragments,
        })
    }

    /// Record frame `f`'s grid (after its depth, when bounded by it).
    pub(crate) fn encode(&mut self, f: &FrameInputs, enc: &mut FrameEncoder) -> Result<()> {
        let setup = &f.setup;
        let inputs = CullInputs {
            depth: self.depth.then_some(&f.targets.depth),
            // Cells spanning near..far already cover every transparent fragment.
            transparent: self.depth && f.has_transparency(),
            lights: f.light_buffer,
            cpu_lights: Some(bytemuck::cast_slice(f.gpu_lights)),
            light_count: f.gpu_lights.len() as u32,
            view: setup.view.to_cols_array_2d(),
            proj: f.proj.to_cols_array_2d(),
            near: setup.near,
            far: setup.far,
            viewport: [setup.width, setup.height],
        };
        let draw = |pass: &mut wgpu::RenderPass<'_>, group: &wgpu::BindGroup| {
            if let Some(d) = &self.fragments {
                d.draw(pass, group, f);
            }
        };
        let fragments = self.fragments.as_ref().filter(|d| d.draws(f));
        let (encoder, timer, io) = enc.split();
        let extras = CullExtras {
            timer: Some(timer),
            io: Some(io),
            fragments: fragments
                .map(|_| &draw as &dyn Fn(&mut wgpu::RenderPass<'_>, &wgpu::BindGroup)),
        };
        self.culler
            .encode_with(encoder, &inputs, extras)
            .map_err(cull_error)?;
        Ok(())
    }

    /// The culler (its reports, grid and bind group).
    pub(crate) fn culler(&self) -> &LightCuller {
        &self.culler
    }

    pub(crate) fn culler_mut(&mut self) -> &mut LightCuller {
        &mut self.culler
    }

    /// Group 1 of the shading passes.
    pub(crate) fn bind_group(&self) -> &wgpu::BindGroup {
        self.culler.bind_group()
    }

    pub(crate) fn bind_group_layout(&self) -> &wgpu::BindGroupLayout {
        self.culler.bind_group_layout()
    }
}
