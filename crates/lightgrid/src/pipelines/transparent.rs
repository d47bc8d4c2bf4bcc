//! The transparent pass every pipeline ends with (tiled-shading §4, tiled-forward-shading
//! §4.5): the transparent objects, sorted back to front per frame (`Scene::frame_geometry`),
//! forward-shaded and alpha-blended over the opaque HDR image, depth-tested against the opaque
//! depth without writing it. Their lighting computations add to the count target.
//!
//! Where the lights come from ([`TransparentLights`]): `forward` loops every light (the
//! reference); a grid pipeline reads its own frame's grid, whose transparent lists cover
//! near..opaque max (`GridLists`); deferred, deferred_stencil, the light pre-passes and the
//! single-kernel tiled deferred have no grid of their own (the papers note classic deferred
//! has no answer for transparency), so this pass builds one with `gather` over the opaque
//! depth (a GPU strategy: the frame stays one submission without readback).

use super::{FrameEncoder, FrameInputs, GeometryPipelineDesc, PipelineContext};
use crate::culling::{GridBuffers, GridLists, LightCuller};
use crate::error::{Error, Result};
use crate::frame::targets::counts_in_target;
use crate::frame::Assign;
use crate::frame::CullConfig;
use crate::passes::geometry::{draw_transparent, MaterialPipelines};
use crate::shader::{compose, create_module, parts, ComposedShader, SCENE_PARTS};

/// The transparent pass with the light loop `l`.
pub(super) fn shader(l: crate::frame::LightLoop) -> ComposedShader {
    let parts = parts![
        SCENE_PARTS,
        crate::shader::src::LIGHT_GRID,
        super::light_loop_wgsl(l),
        include_str!("transparent.wgsl"),
    ];
    compose(&format!("transparent ({} loop)", l.name()), &parts)
}

/// Where a technique's transparent fragments find their lights.
pub(crate) enum TransparentLights<'a> {
    /// Every light (`forward`).
    All,
    /// The technique's own grid, built this frame with transparent lists.
    Grid(&'a LightCuller),
    /// No grid of its own: the pass builds one.
    Own,
}

/// The pass's two pipelines and the grid it builds for techniques without one.
pub(crate) struct TransparentPass {
    all_lights: MaterialPipelines,
    grid: MaterialPipelines,
    own_grid: Option<super::PipelineGrid>,
}

/// Colour blending over the opaque image (alpha kept), counts added.
fn blended_targets(count_blend: bool) -> [Option<wgpu::ColorTargetState>; 2] {
    [
        Some(wgpu::ColorTargetState {
            format: crate::passes::HDR_FORMAT,
            blend: Some(wgpu::BlendState {
                color: wgpu::BlendComponent {
                    src_factor: wgpu::BlendFactor::SrcAlpha,
                    dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
                    operation: wgpu::BlendOperation::Add,
                },
                alpha: wgpu::BlendComponent {
                    src_factor: wgpu::BlendFactor::Zero,
                    dst_factor: wgpu::BlendFactor::One,
                    operation: wgpu::BlendOperation::Add,
                },
            }),
            write_mask: wgpu::ColorWrites::ALL,
        }),
        crate::passes::count_target(count_blend),
    ]
}

impl TransparentPass {
    pub fn new(ctx: &PipelineContext) -> Result<Self> {
        let module = create_module(
            ctx.device,
            &shader(ctx.settings.light_loop).specialized(ctx.shading),
        );
        let grid_layout = GridBuffers::layout(ctx.device);
        let targets = blended_targets(counts_in_target(ctx.count_blend, ctx.settings.grid.samples));
        let pipeline = |label, entry, layouts: &[Option<&wgpu::BindGroupLayout>]| {
            MaterialPipelines::new(
                ctx.device,
                &GeometryPipelineDesc {
                    label,
                    module: &module,
                    fragment_entry: Some(entry),
                    layouts,
                    color_targets: &targets,
                    depth_write: false,
                    depth_compare: crate::depth::NEARER,
                    samples: ctx.settings.grid.samples,
                },
                ctx.settings.material_draws,
            )
        };
        Ok(TransparentPass {
            all_lights: pipeline(
                "transparent (all lights)",
                "fs_all_lights",
                &[Some(ctx.scene_layout)],
            ),
            grid: pipeline(
                "transparent (grid)",
                "fs_grid",
                &[Some(ctx.scene_layout), Some(&grid_layout)],
            ),
            own_grid: None,
        })
    }

    /// Create the grid the pass builds for techniques without one (`TransparentLights::Own`),
    /// once, when the first such technique is created: a renderer that never needs it (a GL
    /// device running `forward`, which has no compute) never makes its compute pipelines.
    pub fn ensure_own_grid(&mut self, ctx: &PipelineContext) -> Result<()> {
        if self.own_grid.is_some() {
            return Ok(());
        }
        // A GPU strategy (gather), so the frame still makes one submission and no readback,
        // over the opaque depth; one list per tile covering near..max.
        // Not the technique's grid: `--depth-bounds`, `--depth-mask` and `--cell-box` are
        // about that one.
        self.own_grid = Some(ctx.grid(
            &CullConfig {
                strategy: Assign::Gather,
                lists: GridLists::Shared,
                depth_bounds: crate::frame::DepthBounds::Both,
                depth_reduction: crate::frame::DepthReduction::Atomics,
                depth_mask: crate::frame::DepthMask::Off,
                cell_box: crate::frame::CellBox::Off,
                ..ctx.settings.grid.tiled()
            },
            true,
            false,
        )?);
        Ok(())
    }

    /// Record the pass after a technique's opaque passes (nothing when the frame has no
    /// transparent geometry). Returns the frame number of its own grid's culler when it
    /// built that grid.
    pub fn encode(
        &mut self,
        f: &FrameInputs,
        enc: &mut FrameEncoder,
        lights: TransparentLights,
    ) -> Result<Option<u64>> {
        if !f.has_transparency() {
            return Ok(None);
        }
        let mut own_frame = None;
        let grid = match lights {
            TransparentLights::All => None,
            TransparentLights::Grid(b) => Some(b.bind_group()),
            TransparentLights::Own => {
                let own = self.own_grid.as_mut().ok_or_else(|| Error::Gpu {
                    stage: "transparent pass".into(),
                    message: "its own grid was not created with the technique".into(),
                })?;
                own.encode(f, enc)?;
                own_frame = Some(own.culler().last_frame());
                Some(own.bind_group())
            }
        };
        let (encoder, timer) = enc.parts();
        let label = "transparent";
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &[
                Some(crate::passes::loaded(&f.targets.hdr)),
                counts_in_target(f.count_blend, f.targets.samples)
                    .then(|| crate::passes::loaded(&f.targets.counts)),
            ],
            depth_stencil_attachment: Some(crate::passes::loaded_depth(&f.targets.depth)),
            timestamp_writes: timer.render_pass(label),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        match grid {
            None => draw_transparent(&mut pass, f, &[], &self.all_lights),
            Some(g) => draw_transparent(&mut pass, f, &[g], &self.grid),
        }
        Ok(own_frame)
    }

    /// The grid it builds for techniques without one (its reports come from its culler).
    pub fn culler_mut(&mut self) -> Option<&mut LightCuller> {
        self.own_grid.as_mut().map(|g| g.culler_mut())
    }
}
