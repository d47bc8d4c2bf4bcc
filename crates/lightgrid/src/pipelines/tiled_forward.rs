//! `tiled_forward`, `tiled_forward_prez` and `clustered_forward`: forward shading reading a
//! light grid built by a [`LightCuller`] (the strategy `--assign` names).
//!
//! tiled_forward (tiled-shading §3): 1. grid with every tile spanning near..far; 2. lighting
//! pass (depth test Less, writes depth).
//! tiled_forward_prez (Forward+; tiled-shading §6.3): 1. depth pre-pass; 2. per-tile depth
//! bounds and the tile grid; 3. lighting pass with depth test LessEqual against the pre-pass
//! depth, no depth writes, so early-Z shades each visible sample once.
//! clustered_forward (tiled-forward-shading §4.8): as tiled_forward_prez, with a grid of
//! (tile, view-depth slice) clusters, each bounded by its own samples; each fragment reads its
//! cluster's list.
//!
//! With `--grid-storage textures` (chosen by `auto` where the adapter cannot run the compute
//! grid: GL, WebGL2) tiled_forward and tiled_forward_prez keep the grid in textures built on
//! the CPU, with no compute pass (`culling/texture_grid.rs`); the pre-Z tile bounds are then
//! drawn by a fragment shader and read back. Clusters are bounded by the compute cell-bounds
//! kernel, so clustered_forward has no texture grid.

use super::{
    begin_lighting_pass, draw_scene_materials, lighting_targets, DepthPipelines, FrameEncoder,
    FrameInputs, MaterialPipelines,
};
use super::{GeometryPipelineDesc, PipelineContext, RenderSettings, Technique, TransparentLights};
use crate::culling::texture_grid::TextureGrid;
use crate::culling::LightCuller;
use crate::error::Result;
use crate::frame::{Assign, CellBox, DepthBounds, DepthMask, GridStorage, LightLoop};
use crate::memory::{MemoryModel, Traffic, DEPTH_BYTES, HDR_BYTES, INDEX_BYTES, LIGHT_BYTES};
use crate::shader::{compose, create_module, parts, ComposedShader, SCENE_PARTS};

pub(super) fn shaders() -> Vec<ComposedShader> {
    let mut out = crate::frame::LightLoop::ALL.map(shader).to_vec();
    out.push(texel_shader());
    out
}

/// The forward shading pass reading the texture grid (`--grid-storage textures`).
fn texel_shader() -> ComposedShader {
    let parts = parts![
        crate::shader::TEXEL_SCENE_PARTS,
        include_str!("tiled_forward.wgsl"),
    ];
    compose("tiled_forward (texture grid)", &parts)
}

/// Where the pipeline's grid lives (`--grid-storage`).
enum Grid {
    Buffers(Box<super::PipelineGrid>),
    Textures(Box<TextureGrid>),
}

impl Grid {
    fn layout(&self) -> &wgpu::BindGroupLayout {
        match self {
            Grid::Buffers(g) => g.bind_group_layout(),
            Grid::Textures(g) => g.bind_group_layout(),
        }
    }

    fn bind_group(&self) -> &wgpu::BindGroup {
        match self {
            Grid::Buffers(g) => g.bind_group(),
            Grid::Textures(g) => g.bind_group(),
        }
    }
}

/// The texture grid, for the settings it can be built with: one sample, CPU assignment,
/// each tile bounded by its samples' whole depth range, the lane loop.
fn texture_grid(ctx: &PipelineContext, prepass: bool) -> Result<TextureGrid> {
    let s = &ctx.settings;
    let g = &s.grid;
    let refused = [
        (
            g.samples > 1,
            "--msaa above 1 (it is built from single-sample depth)",
        ),
        (
            !matches!(g.strategy, Assign::Auto | Assign::Cpu),
            "--assign other than cpu (it is assigned on the CPU)",
        ),
        (
            g.depth_bounds != DepthBounds::Both,
            "--depth-bounds other than both",
        ),
        (g.depth_mask != DepthMask::Off, "--depth-mask on"),
        (g.cell_box != CellBox::Off, "--cell-box on"),
        (s.light_loop != LightLoop::Lane, "--light-loop subgroup"),
    ];
    if let Some((_, what)) = refused.iter().find(|(r, _)| *r) {
        return Err(crate::error::Error::invalid(
            "grid-storage",
            format!("the texture grid does not take {what}; use --grid-storage buffers"),
        ));
    }
    Ok(TextureGrid::new(ctx.device, ctx.queue, ctx.dims, prepass))
}

/// The forward shading pass with the light loop `l`.
fn shader(l: crate::frame::LightLoop) -> ComposedShader {
    let parts = parts![
        SCENE_PARTS,
        crate::shader::src::LIGHT_GRID,
        super::light_loop_wgsl(l),
        include_str!("tiled_forward.wgsl"),
    ];
    compose(&format!("tiled_forward ({} loop)", l.name()), &parts)
}

struct TiledForward {
    grid: Grid,
    /// The depth pre-pass (pre-Z and clustered).
    depth_only: Option<DepthPipelines>,
    shading: MaterialPipelines,
    label: &'static str,
}

#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Plain,
    PreZ,
    Clustered,
}

fn create(ctx: &PipelineContext, kind: Kind) -> Result<Box<dyn Technique>> {
    let prepass = kind != Kind::Plain;
    let textures = kind != Kind::Clustered
        && ctx.settings.grid_storage.resolve(ctx.compute_grid) == GridStorage::Textures;
    let source = match textures {
        true => texel_shader(),
        false => shader(ctx.settings.light_loop),
    };
    let module = create_module(ctx.device, &source.specialized(ctx.shading));
    let config = if kind == Kind::Clustered {
        ctx.settings.grid
    } else {
        ctx.settings.grid.tiled()
    };
    let grid = match textures {
        true => Grid::Textures(Box::new(texture_grid(ctx, prepass)?)),
        false => Grid::Buffers(Box::new(ctx.grid(&config, prepass, true)?)),
    };
    let shading = MaterialPipelines::new(
        ctx.device,
        &GeometryPipelineDesc {
            label: "tiled forward shading",
            module: &module,
            fragment_entry: Some("fs_main"),
            layouts: &[Some(ctx.scene_layout), Some(grid.layout())],
            color_targets: &lighting_targets(ctx.count_blend, ctx.settings.grid.samples),
            depth_write: !prepass,
            depth_compare: crate::depth::SURFACE,
            samples: ctx.settings.grid.samples,
        },
        ctx.settings.material_draws,
    );
    let depth_only = prepass.then(|| {
        DepthPipelines::new(
            ctx.device,
            &GeometryPipelineDesc {
                label: "depth pre-pass",
                module: &module,
                fragment_entry: None,
                layouts: &[Some(ctx.scene_layout)],
                color_targets: &[],
                depth_write: true,
                depth_compare: crate::depth::SURFACE,
                samples: ctx.settings.grid.samples,
            },
        )
    });
    Ok(Box::new(TiledForward {
        grid,
        depth_only,
        shading,
        label: match kind {
            Kind::Plain => "tiled forward shading",
            Kind::PreZ => "tiled forward shading (pre-z)",
            Kind::Clustered => "clustered forward shading",
        },
    }))
}

pub(super) fn create_plain(ctx: &PipelineContext) -> Result<Box<dyn Technique>> {
    create(ctx, Kind::Plain)
}

pub(super) fn create_prez(ctx: &PipelineContext) -> Result<Box<dyn Technique>> {
    create(ctx, Kind::PreZ)
}

pub(super) fn create_clustered(ctx: &PipelineContext) -> Result<Box<dyn Technique>> {
    create(ctx, Kind::Clustered)
}

impl Technique for TiledForward {
    fn encode(&mut self, f: &FrameInputs, enc: &mut FrameEncoder) -> Result<()> {
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
            depth_only.draw(&mut pass, f);
        }
        match &mut self.grid {
            Grid::Buffers(g) => g.encode(f, enc)?,
            Grid::Textures(g) => g.encode(f, enc)?,
        }
        let (encoder, timer) = enc.parts();
        let mut pass =
            begin_lighting_pass(encoder, timer, f, self.label, self.depth_only.is_none());
        draw_scene_materials(&mut pass, f, &[self.grid.bind_group()], &self.shading);
        drop(pass);
        Ok(())
    }

    fn culler(&mut self) -> Option<&mut LightCuller> {
        match &mut self.grid {
            Grid::Buffers(g) => Some(g.culler_mut()),
            Grid::Textures(_) => None,
        }
    }

    fn texture_grid(&self) -> Option<&crate::culling::texture_grid::BuiltTextureGrid> {
        match &self.grid {
            Grid::Buffers(_) => None,
            Grid::Textures(g) => g.last(),
        }
    }

    /// The texture grid holds opaque lists only: the transparent pass loops every light, as
    /// `forward`'s does (no compute, like the grid).
    fn transparent_lights(&self) -> TransparentLights<'_> {
        match &self.grid {
            Grid::Buffers(g) => TransparentLights::Grid(g.culler()),
            Grid::Textures(_) => TransparentLights::All,
        }
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

/// As `memory_plain`, plus the pre-pass depth write and the cell-bounds read.
pub(super) fn memory_prez(settings: &RenderSettings) -> MemoryModel {
    let mut m = memory_plain(settings);
    m.traffic.read_per_pixel += DEPTH_BYTES;
    m
}

/// As `memory_prez` (the cell-bounds kernel reads depth once, for any number of slices).
pub(super) fn memory_clustered(settings: &RenderSettings) -> MemoryModel {
    memory_prez(settings)
}
