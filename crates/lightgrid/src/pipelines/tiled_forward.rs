//! `tiled_forward`, `tiled_forward_prez` and `clustered_forward`: forward shading reading a
//! CPU-built light grid.
//!
//! tiled_forward (tiled-shading §3): 1. CPU assignment against near..far; 2. upload;
//! 3. lighting pass (depth test Less, writes depth).
//! tiled_forward_prez (Forward+; tiled-shading §6.3): 1. depth pre-pass; 2. per-tile depth
//! bounds on the GPU, read back; 3. CPU assignment pruned by the bounds; 4. upload;
//! 5. lighting pass with depth test LessEqual against the pre-pass depth, no depth writes, so
//! early-Z shades each visible sample once.
//! clustered_forward (tiled-forward-shading §4.8): 1. depth pre-pass; 2. the depth buffer read
//! back; 3. on the CPU: tile depth bounds, the clusters holding samples, and assignment to
//! (tile, view-depth slice) clusters; 4. upload; 5. lighting pass as in 5. above, each fragment
//! reading its cluster's list.

use super::{
    begin_lighting_pass, draw_scene, geometry_pipeline, lighting_targets, FrameEncoder, FrameInputs,
};
use super::{Assign, RenderSettings};
use super::{GeometryPipelineDesc, PipelineContext, Technique};
use crate::culling::{
    assign_cpu, cluster_occupancy, depth_bounds_cpu, to_view_bounds, DepthBoundsPass, DepthRange,
    GatherPass, GridBuffers, GridDims, LightGrid,
};
use crate::memory::{MemoryModel, Traffic, DEPTH_BYTES, HDR_BYTES, INDEX_BYTES, LIGHT_BYTES};
use crate::passes::Readback;
use crate::shader::{compose, create_module, ComposedShader, SCENE_PARTS};
use crate::Result;

pub(super) fn shaders() -> Vec<ComposedShader> {
    let mut parts = SCENE_PARTS.to_vec();
    parts.push(crate::shader::src::LIGHT_GRID);
    parts.push(include_str!("tiled_forward.wgsl"));
    vec![compose("tiled_forward", &parts)]
}

/// How the grid is built.
enum Mode {
    Plain,
    PreZ(Box<DepthBoundsPass>, Option<Box<GatherPass>>),
    Clustered { readback: Readback, slices: u32 },
}

struct TiledForward {
    mode: Mode,
    /// The depth pre-pass (pre-Z and clustered).
    depth_only: Option<wgpu::RenderPipeline>,
    shading: wgpu::RenderPipeline,
    grid: GridBuffers,
    dims: GridDims,
}

#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Plain,
    PreZ,
    Clustered,
}

fn create(ctx: &PipelineContext, kind: Kind) -> Box<dyn Technique> {
    let module = create_module(ctx.device, &shaders()[0]);
    let grid = GridBuffers::new(ctx.device);
    let prepass = kind != Kind::Plain;
    let shading = geometry_pipeline(
        ctx.device,
        &GeometryPipelineDesc {
            label: "tiled forward shading",
            module: &module,
            fragment_entry: Some("fs_main"),
            layouts: &[Some(ctx.scene_layout), Some(&grid.layout)],
            color_targets: &lighting_targets(ctx.count_blend),
            depth_write: !prepass,
            depth_compare: if prepass {
                wgpu::CompareFunction::LessEqual
            } else {
                wgpu::CompareFunction::Less
            },
        },
    );
    let depth_only = prepass.then(|| {
        geometry_pipeline(
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
        )
    });
    let mode = match kind {
        Kind::Plain => Mode::Plain,
        Kind::PreZ => Mode::PreZ(
            Box::new(DepthBoundsPass::new(ctx.device, ctx.dims)),
            (ctx.settings.assign == Assign::Gather)
                .then(|| Box::new(GatherPass::new(ctx.device, ctx.scene_layout, ctx.dims))),
        ),
        Kind::Clustered => Mode::Clustered {
            readback: Readback::new(
                ctx.device,
                "depth for clusters",
                ctx.dims.width,
                ctx.dims.height,
            ),
            slices: ctx.settings.slices,
        },
    };
    Box::new(TiledForward {
        mode,
        depth_only,
        shading,
        grid,
        dims: ctx.dims,
    })
}

pub(super) fn create_plain(ctx: &PipelineContext) -> Box<dyn Technique> {
    create(ctx, Kind::Plain)
}

pub(super) fn create_prez(ctx: &PipelineContext) -> Box<dyn Technique> {
    create(ctx, Kind::PreZ)
}

pub(super) fn create_clustered(ctx: &PipelineContext) -> Box<dyn Technique> {
    create(ctx, Kind::Clustered)
}

/// Clustered assignment: submit what is recorded, read the depth buffer back, then on the CPU
/// the tile depth bounds, the clusters that hold samples, and the lights per cluster.
pub(super) fn assign_clusters(
    f: &FrameInputs,
    enc: &mut FrameEncoder,
    readback: &Readback,
    tiles: GridDims,
    slices: u32,
) -> Result<LightGrid> {
    let (encoder, _) = enc.parts();
    readback.encode(
        encoder,
        &f.targets.depth_texture,
        wgpu::TextureAspect::DepthOnly,
    );
    enc.submit_and_wait()?;
    let depth = readback.read_f32(f.device)?;
    let depth = depth.as_slice();
    let dims = tiles.clustered(slices, f.setup.near, f.setup.far)?;
    let bounds = to_view_bounds(&f.setup, &depth_bounds_cpu(depth, &tiles));
    let occupied = cluster_occupancy(&f.setup, &dims, depth);
    Ok(assign_cpu(
        &f.setup,
        &dims,
        f.lights,
        DepthRange::Clusters {
            tile_bounds: &bounds,
            occupied: &occupied,
        },
    ))
}

impl Technique for TiledForward {
    fn render(&mut self, f: &FrameInputs, enc: &mut FrameEncoder) -> Result<Option<LightGrid>> {
        if let Some(depth_only) = &self.depth_only {
            let (encoder, timer) = enc.parts();
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("depth pre-pass"),
                color_attachments: &[],
                depth_stencil_attachment: Some(crate::passes::cleared_depth(&f.targets.depth)),
                timestamp_writes: timer.render_pass("depth pre-pass"),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(depth_only);
            draw_scene(&mut pass, f, &[]);
        }
        let grid = match &mut self.mode {
            Mode::Plain => assign_cpu(&f.setup, &self.dims, f.lights, DepthRange::NearFar),
            Mode::PreZ(bounds, gather) => {
                let (encoder, timer) = enc.parts();
                bounds.encode(f.device, f.queue, encoder, timer, &f.targets.depth);
                match gather {
                    Some(g) => g.run(f, enc, bounds, &mut self.grid)?,
                    None => {
                        enc.submit_and_wait()?;
                        let view_bounds = to_view_bounds(&f.setup, &bounds.read(f.device)?);
                        assign_cpu(
                            &f.setup,
                            &self.dims,
                            f.lights,
                            DepthRange::PerTile(&view_bounds),
                        )
                    }
                }
            }
            Mode::Clustered { readback, slices } => {
                assign_clusters(f, enc, readback, self.dims, *slices)?
            }
        };
        if !matches!(self.mode, Mode::PreZ(_, Some(_))) {
            self.grid.upload(f.device, f.queue, &grid);
        }
        let (encoder, timer) = enc.parts();
        let label = match self.mode {
            Mode::Plain => "tiled forward shading",
            Mode::PreZ(..) => "tiled forward shading (pre-z)",
            Mode::Clustered { .. } => "clustered forward shading",
        };
        let mut pass = begin_lighting_pass(encoder, timer, f, label, self.depth_only.is_none());
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

/// As `memory_prez`: the whole depth buffer is read back instead of the bounds.
pub(super) fn memory_clustered(settings: &RenderSettings) -> MemoryModel {
    memory_prez(settings)
}
