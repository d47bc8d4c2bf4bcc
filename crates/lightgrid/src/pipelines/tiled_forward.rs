//! `tiled_forward` and `tiled_forward_prez`: forward shading reading a CPU-built tile grid.
//!
//! tiled_forward (tiled-shading §3): 1. CPU assignment against near..far; 2. upload;
//! 3. lighting pass (depth test Less, writes depth).
//! tiled_forward_prez (Forward+; tiled-shading §6.3): 1. depth pre-pass; 2. per-tile depth
//! bounds on the GPU, read back; 3. CPU assignment pruned by the bounds; 4. upload;
//! 5. lighting pass with depth test LessEqual against the pre-pass depth, no depth writes, so
//! early-Z shades each visible sample once.

use super::RenderSettings;
use super::{
    begin_lighting_pass, draw_scene, geometry_pipeline, lighting_targets, FrameEncoder, FrameInputs,
};
use super::{GeometryPipelineDesc, PipelineContext, Technique};
use crate::culling::{
    assign_cpu, to_view_bounds, DepthBoundsPass, DepthRange, GridBuffers, GridDims, LightGrid,
};
use crate::memory::{MemoryModel, Traffic, DEPTH_BYTES, HDR_BYTES, INDEX_BYTES, LIGHT_BYTES};
use crate::shader::{compose, create_module, ComposedShader, SCENE_PARTS};
use crate::Result;

pub(super) fn shaders() -> Vec<ComposedShader> {
    let mut parts = SCENE_PARTS.to_vec();
    parts.push(crate::shader::src::LIGHT_GRID);
    parts.push(include_str!("tiled_forward.wgsl"));
    vec![compose("tiled_forward", &parts)]
}

struct TiledForward {
    prez: Option<(wgpu::RenderPipeline, DepthBoundsPass)>,
    shading: wgpu::RenderPipeline,
    grid: GridBuffers,
    dims: GridDims,
}

fn create(ctx: &PipelineContext, prez: bool) -> Box<dyn Technique> {
    let module = create_module(ctx.device, &shaders()[0]);
    let grid = GridBuffers::new(ctx.device);
    let shading = geometry_pipeline(
        ctx.device,
        &GeometryPipelineDesc {
            label: if prez {
                "tiled forward shading (pre-z)"
            } else {
                "tiled forward shading"
            },
            module: &module,
            fragment_entry: Some("fs_main"),
            layouts: &[Some(ctx.scene_layout), Some(&grid.layout)],
            color_targets: &lighting_targets(ctx.count_blend),
            depth_write: !prez,
            depth_compare: if prez {
                wgpu::CompareFunction::LessEqual
            } else {
                wgpu::CompareFunction::Less
            },
        },
    );
    let prez = prez.then(|| {
        let depth_only = geometry_pipeline(
            ctx.device,
            &GeometryPipelineDesc {
                label: "depth pre-pass",
                module: &module,
                fragment_entry: None,
                layouts: &[Some(ctx.scene_layout)],
                color_targets: &[],
                depth_write: true,
                depth_compare: wgpu::CompareFunction::Less,
            },
        );
        (depth_only, DepthBoundsPass::new(ctx.device, ctx.dims))
    });
    Box::new(TiledForward {
        prez,
        shading,
        grid,
        dims: ctx.dims,
    })
}

pub(super) fn create_plain(ctx: &PipelineContext) -> Box<dyn Technique> {
    create(ctx, false)
}

pub(super) fn create_prez(ctx: &PipelineContext) -> Box<dyn Technique> {
    create(ctx, true)
}

impl Technique for TiledForward {
    fn render(&mut self, f: &FrameInputs, enc: &mut FrameEncoder) -> Result<Option<LightGrid>> {
        let dims = self.dims;
        let grid = match &self.prez {
            None => assign_cpu(&f.setup, &dims, f.lights, DepthRange::NearFar),
            Some((depth_only, bounds)) => {
                {
                    let (encoder, timer) = enc.parts();
                    {
                        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                            label: Some("depth pre-pass"),
                            color_attachments: &[],
                            depth_stencil_attachment: Some(
                                wgpu::RenderPassDepthStencilAttachment {
                                    view: &f.targets.depth,
                                    depth_ops: Some(wgpu::Operations {
                                        load: wgpu::LoadOp::Clear(1.0),
                                        store: wgpu::StoreOp::Store,
                                    }),
                                    stencil_ops: None,
                                },
                            ),
                            timestamp_writes: timer.render_pass("depth pre-pass"),
                            occlusion_query_set: None,
                            multiview_mask: None,
                        });
                        pass.set_pipeline(depth_only);
                        draw_scene(&mut pass, f, &[]);
                    }
                    bounds.encode(f.device, f.queue, encoder, timer, &f.targets.depth);
                }
                enc.submit_and_wait()?;
                let view_bounds = to_view_bounds(&f.setup, &bounds.read(f.device)?);
                assign_cpu(&f.setup, &dims, f.lights, DepthRange::PerTile(&view_bounds))
            }
        };
        self.grid.upload(f.device, f.queue, &grid);
        let (encoder, timer) = enc.parts();
        let label = if self.prez.is_some() {
            "tiled forward shading (pre-z)"
        } else {
            "tiled forward shading"
        };
        let mut pass = begin_lighting_pass(encoder, timer, f, label, self.prez.is_none());
        pass.set_pipeline(&self.shading);
        draw_scene(&mut pass, f, &[self.grid.bind_group()]);
        drop(pass);
        Ok(Some(grid))
    }
}

/// HDR + depth (+ the grid, reported per frame); each lighting computation reads an index
/// and a light.
pub(super) fn memory_plain(_: &RenderSettings) -> MemoryModel {
    MemoryModel::new(
        &[("hdr", HDR_BYTES), ("depth", DEPTH_BYTES)],
        Traffic {
            write_per_pixel: HDR_BYTES + DEPTH_BYTES,
            read_per_pixel: 0,
            write_per_lit: 0,
            read_per_lit: INDEX_BYTES + LIGHT_BYTES,
        },
    )
}

/// As `memory_plain`, plus the pre-pass depth write and the depth-bounds read.
pub(super) fn memory_prez(settings: &RenderSettings) -> MemoryModel {
    let mut m = memory_plain(settings);
    m.traffic.read_per_pixel += DEPTH_BYTES;
    m
}
