//! The pipeline registry: one module per pipeline id, one row in [`PIPELINES`]. The CLI, the
//! default job and the tests iterate this table; adding a pipeline touches nothing else.

mod forward;

use crate::error::{Error, Result};
use crate::gpu::PassTimer;
use crate::passes::Targets;
use crate::shader::ComposedShader;

/// What a pipeline needs to create its GPU objects.
pub struct PipelineContext<'a> {
    pub device: &'a wgpu::Device,
    /// Group 0 layout (`shading/scene_bindings.wgsl`), shared by all pipelines.
    pub scene_layout: &'a wgpu::BindGroupLayout,
}

/// What a pipeline reads to render one frame.
pub struct FrameInputs<'a> {
    pub device: &'a wgpu::Device,
    pub scene_bind_group: &'a wgpu::BindGroup,
    pub vertices: &'a wgpu::Buffer,
    pub indices: &'a wgpu::Buffer,
    pub index_count: u32,
    pub targets: &'a Targets,
}

/// A rendering technique: records the passes that fill `targets.hdr` (and `targets.depth`).
pub trait Technique {
    fn encode(
        &self,
        frame: &FrameInputs,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut PassTimer,
    );
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
    /// Every composed shader the pipeline creates (validated by the tests without a GPU).
    pub shaders: fn() -> Vec<ComposedShader>,
    pub create: fn(&PipelineContext) -> Box<dyn Technique>,
}

/// The registry, reference first.
pub const PIPELINES: &[PipelineInfo] = &[PipelineInfo {
    id: "forward",
    description: "every light evaluated for every fragment; the reference image",
    paper: "all (brute force)",
    uses_grid: false,
    shaders: forward::shaders,
    create: forward::create,
}];

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
    pub fragment_entry: &'a str,
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
        fragment: Some(wgpu::FragmentState {
            module: d.module,
            entry_point: Some(d.fragment_entry),
            compilation_options: Default::default(),
            targets: d.color_targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}
