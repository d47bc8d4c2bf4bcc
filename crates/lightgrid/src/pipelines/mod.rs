//! The pipeline registry: one module per pipeline id, one row in [`PIPELINES`] and its id in
//! [`ids`]. The CLI, the benchmark, the viewer, the default job and the tests iterate this
//! table (the `--assign` checks filtered by capability: `tests/common`'s `grid_pipelines()`).

mod axes;
mod deferred;
mod forward;
mod fragment_bounds;
mod grid;
mod light_prepass;
mod tiled_deferred;
mod tiled_forward;
mod transparent;

use crate::culling::{CullConfig, GridDims, LightCuller};
use crate::error::Error;
use crate::error::Result;
use crate::memory::MemoryModel;
use crate::shader::ComposedShader;

pub use crate::culling::Assign;
use crate::frame::GBufferFormat;
pub(crate) use crate::frame::{FrameEncoder, FrameInputs};
pub use crate::frame::{RenderSettings, SpotCull};
pub use axes::{check_axes_apply, find_axis, value_of, Axis, AxisValue, SettingValue, AXES};
pub(crate) use grid::PipelineGrid;
pub(crate) use transparent::{TransparentLights, TransparentPass};

/// What a pipeline needs to create its GPU objects.
pub struct PipelineContext<'a> {
    /// The device the pipeline's GPU objects are created on.
    pub device: &'a wgpu::Device,
    /// Its queue (a grid's culler keeps a clone).
    pub queue: &'a wgpu::Queue,
    /// Group 0 layout (`shading/scene_bindings.wgsl`), shared by all pipelines.
    pub scene_layout: &'a wgpu::BindGroupLayout,
    /// The same with the light bounds visible to compute (the single-kernel tiled deferred
    /// pass, which culls in its kernel; `passes::SceneBounds`).
    pub(crate) scene_culling_layout: &'a wgpu::BindGroupLayout,
    /// The frame's size and tiles in pixels (`--tile`), as a one-slice grid; a clustered grid
    /// adds its view-depth slices each frame.
    pub dims: GridDims,
    /// The renderer's settings, shared by every pipeline it creates.
    pub settings: RenderSettings,
    /// The BRDF and light units every module holding the light function is made for
    /// (`ComposedShader::specialized`).
    pub shading: crate::scene::Shading,
    /// The adapter can blend into the R32Float count target.
    pub count_blend: bool,
    /// The adapter runs the compute grid (`Renderer::runs_compute`): `--grid-storage auto`
    /// picks buffers.
    pub(crate) compute_grid: bool,
}

impl PipelineContext<'_> {
    /// A grid pipeline's grid: a [`LightCuller`] made with `config` (the settings' own,
    /// [`RenderSettings::grid`], or a variant of it) as any caller's is. `depth`: bounded by
    /// the frame's depth (else near..far); `forward_opaque`: a forward pass shades the opaque
    /// geometry from it (with MSAA its fragments go into the bounds).
    pub(crate) fn grid(
        &self,
        config: &CullConfig,
        depth: bool,
        forward_opaque: bool,
    ) -> Result<PipelineGrid> {
        PipelineGrid::new(self, config, depth, forward_opaque)
    }
}

/// A rendering technique: records a frame that fills `targets.hdr`, `targets.depth` and
/// `targets.counts`, with no readback and no wait (the frame's one submission is the
/// renderer's; only the `cpu` strategy with depth bounds reads the cell bounds back).
pub(crate) trait Technique {
    /// Record the frame into `enc`.
    fn encode(&mut self, f: &FrameInputs, enc: &mut FrameEncoder) -> Result<()>;
    /// The grid builder of a grid pipeline with an `--assign` strategy: analysis downloads
    /// its grid, and the frame counters size its lists.
    fn culler(&mut self) -> Option<&mut LightCuller> {
        None
    }
    /// The grid a pipeline built on the CPU into textures (`--grid-storage textures`), as
    /// its last frame left it: analysis reports it as it does a culler's.
    fn texture_grid(&self) -> Option<&crate::culling::texture_grid::BuiltTextureGrid> {
        None
    }
    /// Where the frame's transparent fragments find their lights (after `encode`): a grid
    /// pipeline's own grid, or by default a grid the transparent pass builds.
    fn transparent_lights(&self) -> TransparentLights<'_> {
        TransparentLights::Own
    }
    /// Did the last recorded frame write the display target itself (the MSAA kernels'
    /// in-kernel resolve), so the tonemap must not run?
    fn resolved_to_display(&self) -> bool {
        false
    }
    /// Does it shade one light at a time, re-using one light's shadow maps
    /// (`FrameInputs::reused_shadow_maps`; the light-volume pipelines)?
    fn reuses_shadow_maps(&self) -> bool {
        false
    }
}

/// How a pipeline renders with MSAA (`--msaa` above 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Msaa {
    /// Every target multisampled, resolved by the tonemap.
    Supported,
    /// Refused with the reason (README, "MSAA").
    Refused(&'static str),
}

/// Every pipeline's id, as a constant: code that names a pipeline uses these, so a renamed
/// or removed pipeline is a compile error there, not a silently unmatched string.
pub mod ids {
    /// Brute-force forward shading, every light for every fragment: the reference image.
    pub const FORWARD: &str = "forward";
    pub(crate) const FORWARD_MONO: &str = "forward_mono";
    pub(crate) const FORWARD_MONO_ALBEDO: &str = "forward_mono_albedo";
    /// Tile grid without depth bounds (every tile spans near..far), read by forward shading
    /// (tiled-shading §3).
    pub const TILED_FORWARD: &str = "tiled_forward";
    /// Depth pre-pass, per-tile depth bounds, tile grid, forward shading with early-Z
    /// (forward-plus; tiled-shading §6.3).
    pub const TILED_FORWARD_PREZ: &str = "tiled_forward_prez";
    /// G-buffer, per-tile depth bounds, tile grid, one compute pass shading each sample
    /// (tiled-shading §2, §6).
    pub const TILED_DEFERRED: &str = "tiled_deferred";
    pub(crate) const TILED_DEFERRED_SINGLE: &str = "tiled_deferred_single";
    /// Depth pre-pass, grid of (tile, view-depth slice) clusters holding samples, forward
    /// shading (tiled-forward-shading §4.8).
    pub const CLUSTERED_FORWARD: &str = "clustered_forward";
    /// G-buffer, cluster grid, one compute pass shading each sample from its cluster
    /// (tiled-forward-shading §4.8).
    pub const CLUSTERED_DEFERRED: &str = "clustered_deferred";
    /// Classic deferred shading: G-buffer, then each light's volume rasterized with additive
    /// blending.
    pub const DEFERRED: &str = "deferred";
    /// As [`DEFERRED`], with a two-sided stencil pass per light so only samples inside its
    /// volume are shaded.
    pub const DEFERRED_STENCIL: &str = "deferred_stencil";
    /// As [`DEFERRED`], with a one-value specular albedo in the diffuse target's alpha (three
    /// G-buffer targets); checked against `forward_mono_albedo`.
    pub const DEFERRED_MONO: &str = "deferred_mono";
    /// Deferred lighting (light pre-pass): diffuse and specular irradiance per light volume,
    /// then a second geometry pass applies the materials.
    pub const LIGHT_PREPASS: &str = "light_prepass";
    /// Light pre-pass with monochrome specular irradiance in the diffuse target's alpha;
    /// checked against `forward_mono`.
    pub const LIGHT_PREPASS_MONO: &str = "light_prepass_mono";
    /// Compute-based deferred lighting (forward-plus §5's baseline): one compute pass per tile
    /// accumulates its lights into one mono-specular irradiance target, then a geometry pass.
    pub const TILED_LIGHT_PREPASS: &str = "tiled_light_prepass";
}

/// One registry row.
pub struct PipelineInfo {
    /// The id used on the command line and in stats.
    pub id: &'static str,
    /// One line on what the pipeline does, for `lightgrid list` and the viewer's tooltips.
    pub description: &'static str,
    /// Where the technique is described.
    pub paper: &'static str,
    /// Reads a light grid. `forward` never does: it is the reference.
    pub uses_grid: bool,
    /// Builds its grid with the strategy `--assign` names (a `LightCuller`).
    pub assign: bool,
    /// Its grid is clustered: `--slices` view-depth slices per tile.
    pub clustered: bool,
    /// Its grid's cells are bounded by the depth of their samples (a depth pre-pass or a
    /// G-buffer read before assignment): `--depth-bounds` chooses which side it culls by.
    pub depth_bounds: bool,
    /// Shades the opaque geometry in a forward pass, a pipeline per material shader
    /// (`--material-draws`; every pipeline's transparent pass does too).
    pub forward_shading: bool,
    /// The pipeline whose image this one must reproduce: `forward`, or a reference with the
    /// same approximations (e.g. `forward_mono`).
    pub reference: &'static str,
    /// With MSAA: supported, or refused and why.
    pub msaa: Msaa,
    /// Its MSAA shading kernel can resolve the samples itself (`--msaa-resolve kernel`,
    /// tiled-deferred-tricks Trick 1): tiled and clustered deferred and the single kernel.
    pub kernel_resolve: bool,
    /// Can keep its grid in textures built on the CPU (`--grid-storage`; tiled forward
    /// without compute: `culling/texture_grid.rs`).
    pub texture_grid: bool,
    /// Every composed shader the pipeline creates (validated by the tests without a GPU).
    pub shaders: fn() -> Vec<ComposedShader>,
    pub(crate) create: fn(&PipelineContext) -> Result<Box<dyn Technique>>,
    /// Render targets and the traffic model (`memory.rs`).
    pub memory: fn(&RenderSettings) -> MemoryModel,
}

impl PipelineInfo {
    /// The render targets and traffic model with `settings` (per sample with MSAA).
    pub fn memory_model(&self, settings: &RenderSettings) -> MemoryModel {
        (self.memory)(settings).multisampled(settings.grid.samples)
    }

    /// Whether the pipeline has a G-buffer (its memory depends on `--gbuffer`).
    pub fn uses_gbuffer(&self) -> bool {
        let with = |gbuffer| {
            self.memory_model(&RenderSettings {
                gbuffer,
                ..Default::default()
            })
        };
        with(GBufferFormat::F16) != with(GBufferFormat::F32)
    }
}

/// The registry, reference first.
pub const PIPELINES: &[PipelineInfo] = &[
    PipelineInfo {
        id: ids::FORWARD,
        description: "every light evaluated for every fragment; the reference image",
        paper: "all (brute force)",
        uses_grid: false,
        assign: false,
        forward_shading: true,
        clustered: false,
        depth_bounds: false,
        reference: ids::FORWARD,
        msaa: Msaa::Supported,
        kernel_resolve: false,
        texture_grid: false,
        shaders: forward::shaders,
        create: forward::create,
        memory: forward::memory,
    },
    PipelineInfo {
        id: ids::FORWARD_MONO,
        description: "forward with the light pre-pass's monochrome specular; the reference for light_prepass_mono",
        paper: "deferred-shading-vs-deferred-lighting (the compromise)",
        uses_grid: false,
        assign: false,
        forward_shading: true,
        clustered: false,
        depth_bounds: false,
        reference: ids::FORWARD_MONO,
        msaa: Msaa::Supported,
        kernel_resolve: false,
        texture_grid: false,
        shaders: forward::shaders,
        create: forward::create_mono,
        memory: forward::memory,
    },
    PipelineInfo {
        id: ids::FORWARD_MONO_ALBEDO,
        description: "forward with a one-value (luminance) specular albedo; the reference for deferred_mono",
        paper: "deferred-shading-vs-deferred-lighting (the fair counterpart)",
        uses_grid: false,
        assign: false,
        forward_shading: true,
        clustered: false,
        depth_bounds: false,
        reference: ids::FORWARD_MONO_ALBEDO,
        msaa: Msaa::Supported,
        kernel_resolve: false,
        texture_grid: false,
        shaders: forward::shaders,
        create: forward::create_mono_albedo,
        memory: forward::memory,
    },
    PipelineInfo {
        id: ids::TILED_FORWARD,
        description: "tile grid without depth bounds (every tile spans near..far), read by forward shading",
        paper: "tiled-shading §3",
        uses_grid: true,
        assign: true,
        forward_shading: true,
        clustered: false,
        depth_bounds: false,
        reference: ids::FORWARD,
        msaa: Msaa::Supported,
        kernel_resolve: false,
        texture_grid: true,
        shaders: tiled_forward::shaders,
        create: tiled_forward::create_plain,
        memory: tiled_forward::memory_plain,
    },
    PipelineInfo {
        id: ids::TILED_FORWARD_PREZ,
        description: "depth pre-pass, per-tile depth bounds, tile grid, forward shading with early-Z",
        paper: "tiled-shading §6.3, forward-plus, tiled-forward-shading §4.4",
        uses_grid: true,
        assign: true,
        forward_shading: true,
        clustered: false,
        depth_bounds: true,
        reference: ids::FORWARD,
        msaa: Msaa::Supported,
        kernel_resolve: false,
        texture_grid: true,
        shaders: tiled_forward::shaders,
        create: tiled_forward::create_prez,
        memory: tiled_forward::memory_prez,
    },
    PipelineInfo {
        id: ids::TILED_DEFERRED,
        description: "G-buffer, per-tile depth bounds, tile grid, one compute pass shading each sample",
        paper: "tiled-shading §2, §6, §8",
        uses_grid: true,
        assign: true,
        forward_shading: false,
        clustered: false,
        depth_bounds: true,
        reference: ids::FORWARD,
        msaa: Msaa::Supported,
        kernel_resolve: true,
        texture_grid: false,
        shaders: tiled_deferred::shaders,
        create: tiled_deferred::create_multi,
        memory: tiled_deferred::memory_multi,
    },
    PipelineInfo {
        id: ids::TILED_DEFERRED_SINGLE,
        description: "G-buffer, then one kernel: per tile depth bounds, cull all lights in workgroup memory, shade one pixel per invocation",
        paper: "tiled-shading §7",
        uses_grid: true,
        assign: false,
        forward_shading: false,
        clustered: false,
        depth_bounds: false,
        reference: ids::FORWARD,
        msaa: Msaa::Supported,
        kernel_resolve: true,
        texture_grid: false,
        shaders: tiled_deferred::shaders_single,
        create: tiled_deferred::create_single,
        memory: tiled_deferred::memory_single,
    },
    PipelineInfo {
        id: ids::CLUSTERED_FORWARD,
        description: "depth pre-pass, per-cluster sample bounds, grid of (tile, view-depth slice) clusters holding samples, forward shading",
        paper: "tiled-forward-shading §4.8",
        uses_grid: true,
        assign: true,
        forward_shading: true,
        clustered: true,
        depth_bounds: true,
        reference: ids::FORWARD,
        msaa: Msaa::Supported,
        kernel_resolve: false,
        texture_grid: false,
        shaders: tiled_forward::shaders,
        create: tiled_forward::create_clustered,
        memory: tiled_forward::memory_clustered,
    },
    PipelineInfo {
        id: ids::CLUSTERED_DEFERRED,
        description: "G-buffer, per-cluster sample bounds, cluster grid, one compute pass shading each sample from its cluster",
        paper: "tiled-forward-shading §4.8",
        uses_grid: true,
        assign: true,
        forward_shading: false,
        clustered: true,
        depth_bounds: true,
        reference: ids::FORWARD,
        msaa: Msaa::Supported,
        kernel_resolve: true,
        texture_grid: false,
        shaders: tiled_deferred::shaders,
        create: tiled_deferred::create_clustered,
        memory: tiled_deferred::memory_clustered,
    },
    PipelineInfo {
        id: ids::DEFERRED,
        description: "G-buffer, then each light's volume rasterized with additive blending",
        paper: "tiled-shading §1.1, §8 (Deferred)",
        uses_grid: false,
        assign: false,
        forward_shading: false,
        clustered: false,
        depth_bounds: false,
        reference: ids::FORWARD,
        msaa: Msaa::Supported,
        kernel_resolve: false,
        texture_grid: false,
        shaders: deferred::shaders,
        create: deferred::create_plain,
        memory: deferred::memory,
    },
    PipelineInfo {
        id: ids::DEFERRED_STENCIL,
        description: "as deferred, with a two-sided stencil pass per light so only samples inside its volume are shaded",
        paper: "tiled-shading §8 (Deferred-Stencil)",
        uses_grid: false,
        assign: false,
        forward_shading: false,
        clustered: false,
        depth_bounds: false,
        reference: ids::FORWARD,
        msaa: Msaa::Supported,
        kernel_resolve: false,
        texture_grid: false,
        shaders: deferred::shaders,
        create: deferred::create_stencil,
        memory: deferred::memory,
    },
    PipelineInfo {
        id: ids::DEFERRED_MONO,
        description: "as deferred, with the specular albedo as one value in the diffuse target's alpha (three G-buffer targets): mono-specular deferred shading",
        paper: "deferred-shading-vs-deferred-lighting (the fair counterpart of light_prepass_mono)",
        uses_grid: false,
        assign: false,
        forward_shading: false,
        clustered: false,
        depth_bounds: false,
        reference: ids::FORWARD_MONO_ALBEDO,
        msaa: Msaa::Supported,
        kernel_resolve: false,
        texture_grid: false,
        shaders: deferred::shaders_mono,
        create: deferred::create_mono,
        memory: deferred::memory_mono,
    },
    PipelineInfo {
        id: ids::LIGHT_PREPASS,
        description: "deferred lighting: normal+exponent, diffuse and specular irradiance per light volume, second geometry pass",
        paper: "deferred-shading-vs-deferred-lighting",
        uses_grid: false,
        assign: false,
        forward_shading: false,
        clustered: false,
        depth_bounds: false,
        reference: ids::FORWARD,
        msaa: Msaa::Supported,
        kernel_resolve: false,
        texture_grid: false,
        shaders: light_prepass::shaders,
        create: light_prepass::create_full,
        memory: light_prepass::memory_full,
    },
    PipelineInfo {
        id: ids::LIGHT_PREPASS_MONO,
        description: "light pre-pass with monochrome specular irradiance in the diffuse target's alpha",
        paper: "deferred-shading-vs-deferred-lighting (the compromise)",
        uses_grid: false,
        assign: false,
        forward_shading: false,
        clustered: false,
        depth_bounds: false,
        reference: ids::FORWARD_MONO,
        msaa: Msaa::Supported,
        kernel_resolve: false,
        texture_grid: false,
        shaders: light_prepass::shaders,
        create: light_prepass::create_mono,
        memory: light_prepass::memory_mono,
    },
    PipelineInfo {
        id: ids::TILED_LIGHT_PREPASS,
        description: "compute-based deferred lighting: attributes pre-pass, one compute pass per tile accumulating its lights into one irradiance target (mono specular), a second geometry pass applying the materials",
        paper: "forward-plus §5 (its baseline [And11]), deferred-shading-vs-deferred-lighting",
        uses_grid: true,
        assign: true,
        forward_shading: false,
        clustered: false,
        depth_bounds: true,
        reference: ids::FORWARD_MONO,
        msaa: Msaa::Supported,
        kernel_resolve: false,
        texture_grid: false,
        shaders: light_prepass::shaders_tiled,
        create: light_prepass::create_tiled,
        memory: light_prepass::memory_tiled,
    },
];

/// The WGSL light loop a grid-reading shader composes after `shader::src::LIGHT_GRID`.
pub(crate) fn light_loop_wgsl(l: crate::frame::LightLoop) -> &'static str {
    match l {
        crate::frame::LightLoop::Lane => crate::shader::src::LIGHT_LOOP_LANE,
        crate::frame::LightLoop::Subgroup => crate::shader::src::LIGHT_LOOP_SUBGROUP,
    }
}

/// Every shader the library can create, for the validation test: the shared passes, the
/// culling stages and the registry's pipelines, every value of each keyed stage
/// (`shader::ShaderKey::all`), once each (pipelines sharing a stage list it each).
pub fn all_shaders() -> Vec<ComposedShader> {
    let mut out = crate::passes::shaders();
    out.extend(crate::culling::shaders());
    out.push(fragment_bounds::shader());
    out.extend(crate::frame::LightLoop::ALL.map(transparent::shader));
    for p in PIPELINES {
        for s in (p.shaders)() {
            match out.iter().find(|o| o.name == s.name) {
                Some(o) => assert_eq!(o.source(), s.source(), "two shaders named {}", s.name),
                None => out.push(s),
            }
        }
    }
    out
}

/// The reference pipeline's id.
pub const REFERENCE: &str = "forward";

fn pipeline_names() -> String {
    PIPELINES
        .iter()
        .map(|p| p.id)
        .collect::<Vec<_>>()
        .join(", ")
}

/// The registry row with id `id`; an unknown id is an error listing every pipeline id.
pub fn find(id: &str) -> Result<&'static PipelineInfo> {
    PIPELINES
        .iter()
        .find(|p| p.id == id)
        .ok_or_else(|| Error::Unknown {
            what: "pipeline",
            name: id.to_string(),
            valid: pipeline_names(),
        })
}

pub(crate) use crate::passes::geometry::{
    begin_lighting_pass, draw_scene, draw_scene_materials, geometry_pipeline, lighting_attachments,
    lighting_attachments_loaded, lighting_targets, DepthPipelines, GeometryPipelineDesc,
    MaterialPipelines,
};
