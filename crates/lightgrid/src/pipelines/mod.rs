//! The pipeline registry: one module per pipeline id, one row in [`PIPELINES`]. The CLI, the
//! default job and the tests iterate this table; adding a pipeline touches nothing else.

mod deferred;
mod forward;
mod light_prepass;
mod tiled_deferred;
mod tiled_forward;

use crate::culling::{BuiltGrid, GridDims, ViewSetup};
use crate::error::Result;
use crate::gpu::{scoped, wait_idle, PassTimer};
use crate::memory::MemoryModel;
use crate::passes::{GBufferFormat, Targets};
use crate::scene::PointLight;
use crate::shader::ComposedShader;
use crate::Error;

pub use crate::culling::Assign;

/// Settings every pipeline of a renderer shares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderSettings {
    /// Screen tile edge in pixels (`--tile`).
    pub tile_size: u32,
    /// G-buffer channel precision (`--gbuffer 16|32`).
    pub gbuffer: GBufferFormat,
    /// View-depth slices of clustered grids (`--slices`).
    pub slices: u32,
    /// Who builds the grid (`--assign`).
    pub assign: Assign,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            tile_size: crate::consts::DEFAULT_TILE_SIZE,
            gbuffer: GBufferFormat::F16,
            slices: crate::consts::DEFAULT_SLICES,
            assign: Assign::default(),
        }
    }
}

/// What a pipeline needs to create its GPU objects.
pub struct PipelineContext<'a> {
    pub device: &'a wgpu::Device,
    /// Group 0 layout (`shading/scene_bindings.wgsl`), shared by all pipelines.
    pub scene_layout: &'a wgpu::BindGroupLayout,
    pub dims: GridDims,
    pub settings: RenderSettings,
    /// The adapter can blend into the R32Float count target.
    pub count_blend: bool,
    /// A CPU-emulated adapter (lavapipe): `--assign auto` keeps assignment on the CPU.
    pub software_adapter: bool,
    /// `GpuContext::loop_budget`: longest light loop a sample may run on this adapter.
    pub loop_budget: Option<u64>,
}

/// What a pipeline reads to render one frame.
pub struct FrameInputs<'a> {
    pub device: &'a wgpu::Device,
    pub queue: &'a wgpu::Queue,
    pub scene_bind_group: &'a wgpu::BindGroup,
    pub vertices: &'a wgpu::Buffer,
    pub indices: &'a wgpu::Buffer,
    pub index_count: u32,
    pub targets: &'a Targets,
    /// Camera and frame size, for CPU light assignment.
    pub setup: ViewSetup,
    /// The frame's lights (world space), as uploaded to group 0.
    pub lights: &'a [PointLight],
    /// The count target is blended into (see `PipelineContext::count_blend`).
    pub count_blend: bool,
}

/// The frame's command encoder, which a pipeline may submit part-way (e.g. to read depth
/// bounds back for CPU light assignment) and continue.
pub struct FrameEncoder<'a> {
    device: &'a wgpu::Device,
    queue: &'a wgpu::Queue,
    encoder: wgpu::CommandEncoder,
    pub timer: &'a mut PassTimer,
}

impl<'a> FrameEncoder<'a> {
    pub(crate) fn new(
        device: &'a wgpu::Device,
        queue: &'a wgpu::Queue,
        timer: &'a mut PassTimer,
    ) -> Self {
        let encoder = device.create_command_encoder(&Default::default());
        FrameEncoder {
            device,
            queue,
            encoder,
            timer,
        }
    }

    /// The encoder and the pass timer, to begin a pass.
    pub fn parts(&mut self) -> (&mut wgpu::CommandEncoder, &mut PassTimer) {
        (&mut self.encoder, self.timer)
    }

    /// Submit what was recorded and wait until the GPU has finished it.
    pub fn submit_and_wait(&mut self) -> Result<()> {
        let done = std::mem::replace(
            &mut self.encoder,
            self.device.create_command_encoder(&Default::default()),
        );
        scoped(self.device, "submitting a frame part", || {
            self.queue.submit([done.finish()])
        })?;
        wait_idle(self.device)
    }

    pub(crate) fn finish(self) -> wgpu::CommandEncoder {
        self.encoder
    }
}

/// A rendering technique: fills `targets.hdr`, `targets.depth` and `targets.counts`.
pub trait Technique {
    /// Record (and possibly submit part of) the frame. Returns the light grid the pipeline
    /// shaded with, when it builds one.
    fn render(&mut self, f: &FrameInputs, enc: &mut FrameEncoder) -> Result<Option<BuiltGrid>>;
}

/// What bounds the light loop one sample runs (checked against the adapter's loop budget).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightLoop {
    /// No loop over lights (light volumes: one draw per light).
    None,
    /// Every light of the frame.
    AllLights,
    /// The sample's cell list (`GridBuilder` checks it before shading).
    GridCell,
    /// The tile's list, culled in batches of TILE_LIGHT_BATCH inside the kernel.
    TileBatches,
}

/// One registry row.
pub struct PipelineInfo {
    /// The id used on the command line and in stats.
    pub id: &'static str,
    pub description: &'static str,
    /// Where the technique is described.
    pub paper: &'static str,
    /// Reads a light grid. `forward` never does: it is the reference.
    pub uses_grid: bool,
    /// Builds its grid with the strategy `--assign` names (a `GridBuilder`).
    pub assign: bool,
    /// What bounds the per-sample light loop.
    pub light_loop: LightLoop,
    /// The pipeline whose image this one must reproduce: `forward`, or a reference with the
    /// same approximations (e.g. `forward_mono`).
    pub reference: &'static str,
    /// Every composed shader the pipeline creates (validated by the tests without a GPU).
    pub shaders: fn() -> Vec<ComposedShader>,
    pub create: fn(&PipelineContext) -> Box<dyn Technique>,
    /// Render targets and the traffic model (`memory.rs`).
    pub memory: fn(&RenderSettings) -> MemoryModel,
}

/// The registry, reference first.
pub const PIPELINES: &[PipelineInfo] = &[
    PipelineInfo {
        id: "forward",
        description: "every light evaluated for every fragment; the reference image",
        paper: "all (brute force)",
        uses_grid: false,
        assign: false,
        light_loop: LightLoop::AllLights,
        reference: "forward",
        shaders: forward::shaders,
        create: forward::create,
        memory: forward::memory,
    },
    PipelineInfo {
        id: "forward_mono",
        description: "forward with the light pre-pass's monochrome specular; the reference for light_prepass_mono",
        paper: "deferred-shading-vs-deferred-lighting (the compromise)",
        uses_grid: false,
        assign: false,
        light_loop: LightLoop::AllLights,
        reference: "forward_mono",
        shaders: forward::shaders,
        create: forward::create_mono,
        memory: forward::memory,
    },
    PipelineInfo {
        id: "tiled_forward",
        description: "tile grid without depth bounds (every tile spans near..far), read by forward shading",
        paper: "tiled-shading §3",
        uses_grid: true,
        assign: true,
        light_loop: LightLoop::GridCell,
        reference: "forward",
        shaders: tiled_forward::shaders,
        create: tiled_forward::create_plain,
        memory: tiled_forward::memory_plain,
    },
    PipelineInfo {
        id: "tiled_forward_prez",
        description: "depth pre-pass, per-tile depth bounds, tile grid, forward shading with early-Z",
        paper: "tiled-shading §6.3, forward-plus, tiled-forward-shading §4.4",
        uses_grid: true,
        assign: true,
        light_loop: LightLoop::GridCell,
        reference: "forward",
        shaders: tiled_forward::shaders,
        create: tiled_forward::create_prez,
        memory: tiled_forward::memory_prez,
    },
    PipelineInfo {
        id: "tiled_deferred",
        description: "G-buffer, per-tile depth bounds, tile grid, one compute pass shading each sample",
        paper: "tiled-shading §2, §6, §8",
        uses_grid: true,
        assign: true,
        light_loop: LightLoop::GridCell,
        reference: "forward",
        shaders: tiled_deferred::shaders,
        create: tiled_deferred::create_multi,
        memory: tiled_deferred::memory_multi,
    },
    PipelineInfo {
        id: "tiled_deferred_single",
        description: "G-buffer, then one kernel per tile: depth bounds, cull all lights in workgroup memory, shade",
        paper: "tiled-shading §7",
        uses_grid: true,
        assign: false,
        light_loop: LightLoop::TileBatches,
        reference: "forward",
        shaders: tiled_deferred::shaders_single,
        create: tiled_deferred::create_single,
        memory: tiled_deferred::memory_single,
    },
    PipelineInfo {
        id: "clustered_forward",
        description: "depth pre-pass, per-cluster sample bounds, grid of (tile, view-depth slice) clusters holding samples, forward shading",
        paper: "tiled-forward-shading §4.8",
        uses_grid: true,
        assign: true,
        light_loop: LightLoop::GridCell,
        reference: "forward",
        shaders: tiled_forward::shaders,
        create: tiled_forward::create_clustered,
        memory: tiled_forward::memory_clustered,
    },
    PipelineInfo {
        id: "clustered_deferred",
        description: "G-buffer, per-cluster sample bounds, cluster grid, one compute pass shading each sample from its cluster",
        paper: "tiled-forward-shading §4.8",
        uses_grid: true,
        assign: true,
        light_loop: LightLoop::GridCell,
        reference: "forward",
        shaders: tiled_deferred::shaders,
        create: tiled_deferred::create_clustered,
        memory: tiled_deferred::memory_clustered,
    },
    PipelineInfo {
        id: "deferred",
        description: "G-buffer, then each light's volume rasterized with additive blending",
        paper: "tiled-shading §1.1, §8 (Deferred)",
        uses_grid: false,
        assign: false,
        light_loop: LightLoop::None,
        reference: "forward",
        shaders: deferred::shaders,
        create: deferred::create_plain,
        memory: deferred::memory,
    },
    PipelineInfo {
        id: "deferred_stencil",
        description: "as deferred, with a two-sided stencil pass per light so only samples inside its volume are shaded",
        paper: "tiled-shading §8 (Deferred-Stencil)",
        uses_grid: false,
        assign: false,
        light_loop: LightLoop::None,
        reference: "forward",
        shaders: deferred::shaders,
        create: deferred::create_stencil,
        memory: deferred::memory,
    },
    PipelineInfo {
        id: "light_prepass",
        description: "deferred lighting: normal+exponent, diffuse and specular irradiance per light volume, second geometry pass",
        paper: "deferred-shading-vs-deferred-lighting",
        uses_grid: false,
        assign: false,
        light_loop: LightLoop::None,
        reference: "forward",
        shaders: light_prepass::shaders,
        create: light_prepass::create_full,
        memory: light_prepass::memory_full,
    },
    PipelineInfo {
        id: "light_prepass_mono",
        description: "light pre-pass with monochrome specular irradiance in the diffuse target's alpha",
        paper: "deferred-shading-vs-deferred-lighting (the compromise)",
        uses_grid: false,
        assign: false,
        light_loop: LightLoop::None,
        reference: "forward_mono",
        shaders: light_prepass::shaders,
        create: light_prepass::create_mono,
        memory: light_prepass::memory_mono,
    },
];

/// The reference pipeline's id.
pub const REFERENCE: &str = "forward";

pub fn pipeline_names() -> String {
    PIPELINES
        .iter()
        .map(|p| p.id)
        .collect::<Vec<_>>()
        .join(", ")
}

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

/// A render pipeline drawing the scene geometry with the shared vertex stage.
pub(crate) struct GeometryPipelineDesc<'a> {
    pub label: &'a str,
    pub module: &'a wgpu::ShaderModule,
    /// None for a depth-only pass.
    pub fragment_entry: Option<&'a str>,
    pub layouts: &'a [Option<&'a wgpu::BindGroupLayout>],
    pub color_targets: &'a [Option<wgpu::ColorTargetState>],
    pub depth_write: bool,
    pub depth_compare: wgpu::CompareFunction,
}

pub(crate) fn geometry_pipeline(
    device: &wgpu::Device,
    d: &GeometryPipelineDesc,
) -> wgpu::RenderPipeline {
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(d.label),
        bind_group_layouts: d.layouts,
        immediate_size: 0,
    });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(d.label),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module: d.module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[Some(crate::passes::vertex_layout())],
        },
        // No culling: thin and open geometry is shaded two-sided (see geometry.wgsl).
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: crate::passes::DEPTH_FORMAT,
            depth_write_enabled: Some(d.depth_write),
            depth_compare: Some(d.depth_compare),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: d.fragment_entry.map(|entry| wgpu::FragmentState {
            module: d.module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            targets: d.color_targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// Bind group 0 (+ `extra` from group 1 on), the scene's buffers, and draw everything.
pub(crate) fn draw_scene(pass: &mut wgpu::RenderPass, f: &FrameInputs, extra: &[&wgpu::BindGroup]) {
    pass.set_bind_group(0, f.scene_bind_group, &[]);
    for (i, g) in extra.iter().enumerate() {
        pass.set_bind_group(1 + i as u32, *g, &[]);
    }
    pass.set_vertex_buffer(0, f.vertices.slice(..));
    pass.set_index_buffer(f.indices.slice(..), wgpu::IndexFormat::Uint32);
    pass.draw_indexed(0..f.index_count, 0, 0..1);
}

/// A forward lighting pass into HDR + counts. `depth_cleared`: clear and write depth (no
/// pre-pass) or load the pre-pass depth.
pub(crate) fn begin_lighting_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    timer: &mut PassTimer,
    f: &FrameInputs,
    label: &str,
    depth_cleared: bool,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &lighting_attachments(f),
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &f.targets.depth,
            depth_ops: Some(wgpu::Operations {
                load: if depth_cleared {
                    wgpu::LoadOp::Clear(1.0)
                } else {
                    wgpu::LoadOp::Load
                },
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: timer.render_pass(label),
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// HDR (cleared to black) and, when countable, the count target (cleared to zero).
pub(crate) fn lighting_attachments<'a>(
    f: &'a FrameInputs,
) -> [Option<wgpu::RenderPassColorAttachment<'a>>; 2] {
    [
        Some(crate::passes::cleared(&f.targets.hdr, wgpu::Color::BLACK)),
        f.count_blend
            .then(|| crate::passes::cleared(&f.targets.counts, wgpu::Color::TRANSPARENT)),
    ]
}

/// Colour targets of a forward lighting pipeline: HDR and (when countable) the count target.
pub(crate) fn lighting_targets(count_blend: bool) -> [Option<wgpu::ColorTargetState>; 2] {
    [
        Some(crate::passes::HDR_FORMAT.into()),
        crate::passes::count_target(count_blend),
    ]
}
