//! The geometry passes every pipeline shares: a render pipeline over the scene's vertices with
//! the shared vertex stage, the draw of the whole scene, and the forward lighting pass into
//! HDR + counts.

use crate::frame::FrameInputs;
use crate::gpu::PassTimer;
use crate::shader::overrides;

/// A render pipeline drawing the scene geometry with the shared vertex stage.
#[derive(Clone, Copy)]
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
    /// shader counts into the per-pixel counts (`count_pixel`, `lit_out.wgsl`'s `MULTISAMPLED`).
    pub samples: u32,
}

/// One pipeline per material shader (tiled-forward-shading §4.7: forward shading draws each
/// material's geometry with its own shader), each specialised through the WGSL override
/// `MATERIAL_SHADER`; or, for `MaterialDraws::Uber`, one pipeline branching on the material.
///
/// Alpha-tested runs need more where the pass writes depth: its lighting stages force the
/// early depth test (they count), so a fragment their alpha test discards has already written
/// its depth and would hide what is behind it. There the alpha-tested runs first draw their
/// depth with `fs_depth` (which discards before writing; colour writes off), then shade at
/// equal depth without writing, through pipelines made the first time a frame has such runs.
pub(crate) struct MaterialPipelines {
    shading: Vec<wgpu::RenderPipeline>,
    /// What the alpha-tested variants are made from (passes that write depth only).
    alpha_desc: Option<OwnedDesc>,
    alpha: std::sync::OnceLock<AlphaTested>,
}

/// A [`GeometryPipelineDesc`] that owns its parts.
struct OwnedDesc {
    label: String,
    module: wgpu::ShaderModule,
    fragment_entry: String,
    layouts: Vec<wgpu::BindGroupLayout>,
    color_targets: Vec<Option<wgpu::ColorTargetState>>,
    samples: u32,
}

struct AlphaTested {
    depth: wgpu::RenderPipeline,
    shading: wgpu::RenderPipeline,
}

impl OwnedDesc {
    fn alpha_tested(&self, device: &wgpu::Device) -> AlphaTested {
        let layouts: Vec<Option<&wgpu::BindGroupLayout>> = self.layouts.iter().map(Some).collect();
        let silent: Vec<Option<wgpu::ColorTargetState>> = self
            .color_targets
            .iter()
            .map(|t| {
                t.clone().map(|t| wgpu::ColorTargetState {
                    write_mask: wgpu::ColorWrites::empty(),
                    ..t
                })
            })
            .collect();
        let base = GeometryPipelineDesc {
            label: &self.label,
            module: &self.module,
            fragment_entry: Some("fs_depth"),
            layouts: &layouts,
            color_targets: &silent,
            depth_write: true,
            depth_compare: crate::depth::SURFACE,
            samples: self.samples,
        };
        AlphaTested {
            depth: geometry_pipeline(device, &base),
            shading: specialised_pipeline(
                device,
                &GeometryPipelineDesc {
                    fragment_entry: Some(&self.fragment_entry),
                    color_targets: &self.color_targets,
                    depth_write: false,
                    depth_compare: crate::depth::SURFACE,
                    ..base
                },
                crate::consts::MATERIAL_SHADER_ANY,
            ),
        }
    }
}

impl MaterialPipelines {
    pub(crate) fn new(
        device: &wgpu::Device,
        d: &GeometryPipelineDesc,
        draws: crate::frame::MaterialDraws,
    ) -> Self {
        use crate::consts::{MATERIAL_SHADERS, MATERIAL_SHADER_ANY};
        let shading = match draws {
            crate::frame::MaterialDraws::PerMaterial => (0..MATERIAL_SHADERS)
                .map(|k| specialised_pipeline(device, d, k))
                .collect(),
            crate::frame::MaterialDraws::Uber => {
                vec![specialised_pipeline(device, d, MATERIAL_SHADER_ANY)]
            }
        };
        let alpha_desc = match (d.depth_write, d.fragment_entry) {
            (true, Some(entry)) => Some(OwnedDesc {
                label: format!("{} (alpha tested)", d.label),
                module: d.module.clone(),
                fragment_entry: entry.to_string(),
                layouts: d.layouts.iter().flatten().map(|&l| l.clone()).collect(),
                color_targets: d.color_targets.to_vec(),
                samples: d.samples,
            }),
            _ => None,
        };
        MaterialPipelines {
            shading,
            alpha_desc,
            alpha: std::sync::OnceLock::new(),
        }
    }

    /// The pipeline for draws of material shader `shader`.
    fn get(&self, shader: u32) -> &wgpu::RenderPipeline {
        &self.shading[(shader as usize).min(self.shading.len() - 1)]
    }
}

/// A pipeline drawing with the shaders' default `MATERIAL_SHADER` (every material through
/// the branch, or no lighting at all: depth, G-buffer and attribute passes).
pub(crate) fn geometry_pipeline(
    device: &wgpu::Device,
    d: &GeometryPipelineDesc,
) -> wgpu::RenderPipeline {
    pipeline_with_constants(device, d, &[], None)
}

/// As [`geometry_pipeline`], testing against another depth-stencil target than the scene
/// depth (`depth_stencil` replaces the format, depth and stencil state the description
/// implies): the light pre-pass's shading pass on the volumes' copy, whose stencil marks the
/// MSAA edge pixels.
pub(crate) fn geometry_pipeline_on(
    device: &wgpu::Device,
    d: &GeometryPipelineDesc,
    depth_stencil: wgpu::DepthStencilState,
) -> wgpu::RenderPipeline {
    pipeline_with_constants(device, d, &[], Some(depth_stencil))
}

fn specialised_pipeline(
    device: &wgpu::Device,
    d: &GeometryPipelineDesc,
    shader: u32,
) -> wgpu::RenderPipeline {
    pipeline_with_constants(
        device,
        d,
        &[(overrides::MATERIAL_SHADER, f64::from(shader))],
        None,
    )
}

fn pipeline_with_constants(
    device: &wgpu::Device,
    d: &GeometryPipelineDesc,
    constants: &[(&str, f64)],
    depth_stencil: Option<wgpu::DepthStencilState>,
) -> wgpu::RenderPipeline {
    let mut constants = constants.to_vec();
    if d.samples > 1 {
        constants.push((overrides::MULTISAMPLED, 1.0));
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
        depth_stencil: Some(depth_stencil.unwrap_or(wgpu::DepthStencilState {
            format: crate::passes::DEPTH_FORMAT,
            depth_write_enabled: Some(d.depth_write),
            depth_compare: Some(d.depth_compare),
            stencil: Default::default(),
            bias: Default::default(),
        })),
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

/// A depth-only pass: its runs drawn without a fragment stage, but alpha-tested runs with
/// `fs_depth` (`geometry.wgsl`), which discards what the alpha test removes, so the depth
/// buffer holds exactly the surfaces the shading passes keep.
pub(crate) struct DepthPipelines {
    plain: wgpu::RenderPipeline,
    alpha_tested: wgpu::RenderPipeline,
}

impl DepthPipelines {
    /// From a description whose `fragment_entry` is ignored.
    pub(crate) fn new(device: &wgpu::Device, d: &GeometryPipelineDesc) -> Self {
        DepthPipelines {
            plain: geometry_pipeline(
                device,
                &GeometryPipelineDesc {
                    fragment_entry: None,
                    ..*d
                },
            ),
            alpha_tested: geometry_pipeline(
                device,
                &GeometryPipelineDesc {
                    fragment_entry: Some("fs_depth"),
                    ..*d
                },
            ),
        }
    }

    /// Bind group 0 and draw the opaque runs, each with its pipeline.
    pub(crate) fn draw(&self, pass: &mut wgpu::RenderPass, f: &FrameInputs) {
        bind(pass, f, &[]);
        for d in f.opaque {
            pass.set_pipeline(if d.alpha_test {
                &self.alpha_tested
            } else {
                &self.plain
            });
            pass.draw_indexed(d.first..d.first + d.count, 0, 0..1);
        }
    }
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
    let alpha = match &pipelines.alpha_desc {
        Some(desc) if runs.iter().any(|d| d.alpha_test) => {
            let alpha = pipelines.alpha.get_or_init(|| desc.alpha_tested(f.device));
            pass.set_pipeline(&alpha.depth);
            for d in runs.iter().filter(|d| d.alpha_test) {
                pass.draw_indexed(d.first..d.first + d.count, 0, 0..1);
            }
            Some(alpha)
        }
        _ => None,
    };
    for d in runs {
        match alpha {
            Some(a) if d.alpha_test => pass.set_pipeline(&a.shading),
            _ => pass.set_pipeline(pipelines.get(d.shader)),
        }
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
/// MSAA the counts go to the per-pixel counts after the frame counters instead.
pub(crate) fn lighting_attachments<'a>(
    f: &'a FrameInputs,
) -> [Option<wgpu::RenderPassColorAttachment<'a>>; 2] {
    [
        Some(crate::passes::cleared(&f.targets.hdr, wgpu::Color::BLACK)),
        crate::frame::targets::counts_in_target(f.count_blend, f.targets.samples)
            .then(|| crate::passes::cleared(&f.targets.counts, wgpu::Color::TRANSPARENT)),
    ]
}

/// [`lighting_attachments`] as an earlier pass left them (the light-volume passes between
/// re-used shadow maps).
pub(crate) fn lighting_attachments_loaded<'a>(
    f: &'a FrameInputs,
) -> [Option<wgpu::RenderPassColorAttachment<'a>>; 2] {
    [
        Some(crate::passes::loaded(&f.targets.hdr)),
        crate::frame::targets::counts_in_target(f.count_blend, f.targets.samples)
            .then(|| crate::passes::loaded(&f.targets.counts)),
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
