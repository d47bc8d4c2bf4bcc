//! The geometry passes every pipeline shares: a render pipeline over the scene's vertices with
//! the shared vertex stage, the draw of the whole scene, and the forward lighting pass into
//! HDR + counts.

use crate::frame::FrameInputs;
use crate::gpu::PassTimer;

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
    /// Samples per pixel of the targets (`RenderSettings::msaa`). Above one, a lighting
    /// shader counts into `pixel_counts` (`lit_out.wgsl`'s `MULTISAMPLED`).
    pub samples: u32,
}

/// One pipeline per material shader (tiled-forward-shading §4.7: forward shading draws each
/// material's geometry with its own shader), each specialised through the WGSL override
/// `MATERIAL_SHADER`; or, for `MaterialDraws::Uber`, one pipeline branching on the material.
pub(crate) struct MaterialPipelines(Vec<wgpu::RenderPipeline>);

impl MaterialPipelines {
    pub(crate) fn new(
        device: &wgpu::Device,
        d: &GeometryPipelineDesc,
        draws: crate::frame::MaterialDraws,
    ) -> Self {
        use crate::consts::{MATERIAL_SHADERS, MATERIAL_SHADER_ANY};
        match draws {
            crate::frame::MaterialDraws::PerMaterial => MaterialPipelines(
                (0..MATERIAL_SHADERS)
                    .map(|k| specialised_pipeline(device, d, k))
                    .collect(),
            ),
            crate::frame::MaterialDraws::Uber => {
                MaterialPipelines(vec![specialised_pipeline(device, d, MATERIAL_SHADER_ANY)])
            }
        }
    }

    /// The pipeline for draws of material shader `shader`.
    fn get(&self, shader: u32) -> &wgpu::RenderPipeline {
        &self.0[(shader as usize).min(self.0.len() - 1)]
    }
}

/// A pipeline drawing with the shaders' default `MATERIAL_SHADER` (every material through
/// the branch, or no lighting at all: depth, G-buffer and attribute passes).
pub(crate) fn geometry_pipeline(
    device: &wgpu::Device,
    d: &GeometryPipelineDesc,
) -> wgpu::RenderPipeline {
    pipeline_with_constants(device, d, &[])
}

fn specialised_pipeline(
    device: &wgpu::Device,
    d: &GeometryPipelineDesc,
    shader: u32,
) -> wgpu::RenderPipeline {
    pipeline_with_constants(device, d, &[("MATERIAL_SHADER", f64::from(shader))])
}

fn pipeline_with_constants(
    device: &wgpu::Device,
    d: &GeometryPipelineDesc,
    constants: &[(&str, f64)],
) -> wgpu::RenderPipeline {
    let mut constants = constants.to_vec();
    if d.samples > 1 {
        constants.push(("MULTISAMPLED", 1.0));
    }
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
        multisample: wgpu::MultisampleState {
            count: d.samples,
            ..Default::default()
        },
        fragment: d.fragment_entry.map(|entry| wgpu::FragmentState {
            module: d.module,
            entry_point: Some(entry),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants: &constants,
                ..Default::default()
            },
            targets: d.color_targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// Bind group 0 (+ `extra` from group 1 on), the scene's buffers, and draw the opaque
/// geometry with the pipeline already set (depth, G-buffer and attribute passes).
pub(crate) fn draw_scene(pass: &mut wgpu::RenderPass, f: &FrameInputs, extra: &[&wgpu::BindGroup]) {
    bind(pass, f, extra);
    for d in f.opaque {
        pass.draw_indexed(d.first..d.first + d.count, 0, 0..1);
    }
}

/// The opaque geometry, each run of one material shader with its own pipeline.
pub(crate) fn draw_scene_materials(
    pass: &mut wgpu::RenderPass,
    f: &FrameInputs,
    extra: &[&wgpu::BindGroup],
    pipelines: &MaterialPipelines,
) {
    draw_runs(pass, f, extra, pipelines, f.opaque);
}

/// The transparent objects in the frame's back-to-front order, each run with its shader's
/// pipeline.
pub(crate) fn draw_transparent(
    pass: &mut wgpu::RenderPass,
    f: &FrameInputs,
    extra: &[&wgpu::BindGroup],
    pipelines: &MaterialPipelines,
) {
    draw_runs(pass, f, extra, pipelines, f.transparent);
}

fn draw_runs(
    pass: &mut wgpu::RenderPass,
    f: &FrameInputs,
    extra: &[&wgpu::BindGroup],
    pipelines: &MaterialPipelines,
    runs: &[crate::scene::Draw],
) {
    bind(pass, f, extra);
    for d in runs {
        pass.set_pipeline(pipelines.get(d.shader));
        pass.draw_indexed(d.first..d.first + d.count, 0, 0..1);
    }
}

fn bind(pass: &mut wgpu::RenderPass, f: &FrameInputs, extra: &[&wgpu::BindGroup]) {
    pass.set_bind_group(0, f.scene_bind_group, &[]);
    for (i, g) in extra.iter().enumerate() {
        pass.set_bind_group(1 + i as u32, *g, &[]);
    }
    pass.set_vertex_buffer(0, f.vertices.slice(..));
    pass.set_index_buffer(f.indices.slice(..), wgpu::IndexFormat::Uint32);
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
        depth_stencil_attachment: Some(if depth_cleared {
            crate::passes::cleared_depth(&f.targets.depth)
        } else {
            crate::passes::loaded_depth(&f.targets.depth)
        }),
        timestamp_writes: timer.render_pass(label),
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// HDR (cleared to black) and, when countable, the count target (cleared to zero); with
/// MSAA the counts go to `pixel_counts` instead.
pub(crate) fn lighting_attachments<'a>(
    f: &'a FrameInputs,
) -> [Option<wgpu::RenderPassColorAttachment<'a>>; 2] {
    [
        Some(crate::passes::cleared(&f.targets.hdr, wgpu::Color::BLACK)),
        crate::frame::targets::counts_in_target(f.count_blend, f.targets.samples)
            .then(|| crate::passes::cleared(&f.targets.counts, wgpu::Color::TRANSPARENT)),
    ]
}

/// Colour targets of a forward lighting pipeline: HDR and (when countable, without MSAA) the
/// count target.
pub(crate) fn lighting_targets(
    count_blend: bool,
    samples: u32,
) -> [Option<wgpu::ColorTargetState>; 2] {
    [
        Some(crate::passes::HDR_FORMAT.into()),
        crate::passes::count_target(crate::frame::targets::counts_in_target(
            count_blend,
            samples,
        )),
    ]
}
