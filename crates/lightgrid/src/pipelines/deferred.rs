//! `deferred`, `deferred_stencil` and `deferred_mono`: classic deferred shading with light
//! volumes (tiled-shading §1.1, §8 "Deferred" and "Deferred-Stencil"), and its mono-specular
//! form, the fair counterpart of `light_prepass_mono` (deferred-shading-vs-deferred-lighting).
//!
//! 1. G-buffer pass (shared with tiled deferred; 16- or 32-bit channels); `deferred_mono`'s
//!    keeps the specular albedo as one value in the diffuse target (`GBufferLayout`).
//! 2. One render pass into HDR + counts, depth-tested against a depth-stencil copy:
//!    a. copy the scene depth (full screen);
//!    b. the light-independent term (full screen);
//!    c. `deferred`: each light's volume, additively blended (classes in `light_volumes.rs`).
//!    d. `deferred_stencil`: per light, a two-sided z-fail stencil pass marks the samples
//!    inside the volume, then the volume's back faces shade only marked samples and clear the
//!    mark. Lights reaching the far plane fall back to the plain volume draws of c.
//!
//! Groups: 0 scene, 1 depth-copy source (copy draw only), 2 G-buffer.

use super::RenderSettings;
use super::{lighting_attachments, FrameEncoder, FrameInputs, PipelineContext, Technique};
use crate::error::Result;
use crate::memory::{MemoryModel, Traffic, DEPTH_BYTES, HDR_BYTES, LIGHT_BYTES};
use crate::passes::VOLUME_DEPTH_BYTES;
use crate::passes::{
    additive, classify_lights, LightVolumes, VolumeDraw, VolumePipelineDesc, VOLUME_WGSL,
};
use crate::passes::{GBuffer, GBufferLayout, COUNT_FORMAT, FULLSCREEN_WGSL, HDR_FORMAT};
use crate::shader::{compose, create_module, src, ComposedShader};

pub(super) fn shaders() -> Vec<ComposedShader> {
    vec![shader(GBufferLayout::Full)]
}

pub(super) fn shaders_mono() -> Vec<ComposedShader> {
    vec![shader(GBufferLayout::MonoSpecular)]
}

fn shader(layout: GBufferLayout) -> ComposedShader {
    // Light volumes shade single-sample G-buffers only (`PipelineInfo::msaa`).
    let single_sample = crate::shader::msaa_wgsl(1);
    let name = match layout {
        GBufferLayout::Full => "deferred",
        GBufferLayout::MonoSpecular => "deferred_mono",
    };
    compose(
        name,
        &[
            src::TYPES,
            src::SCENE_BINDINGS,
            src::LIGHTING,
            src::LIT_OUT,
            FULLSCREEN_WGSL,
            VOLUME_WGSL,
            &single_sample,
            layout.read_wgsl(),
            include_str!("deferred.wgsl"),
        ],
    )
}

struct Deferred {
    gbuffer: GBuffer,
    volumes: LightVolumes,
    copy: wgpu::RenderPipeline,
    base: wgpu::RenderPipeline,
    front: wgpu::RenderPipeline,
    back: wgpu::RenderPipeline,
    full: wgpu::RenderPipeline,
    /// (mark, light) for `deferred_stencil`.
    stencil: Option<(wgpu::RenderPipeline, wgpu::RenderPipeline)>,
}

/// HDR and count targets, both additive.
pub(super) fn volume_targets(count_blend: bool) -> [Option<wgpu::ColorTargetState>; 2] {
    [
        Some(additive(HDR_FORMAT)),
        count_blend.then(|| additive(COUNT_FORMAT)),
    ]
}

/// Which samples inside a light's volume are shaded.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Cull {
    /// Every fragment of the volume's front (or back) faces that passes the depth test.
    Volumes,
    /// Only the samples a z-fail stencil pass marks inside the volume.
    Stencil,
}

fn create(ctx: &PipelineContext, cull: Cull, layout: GBufferLayout) -> Box<dyn Technique> {
    let device = ctx.device;
    let (w, h) = (ctx.dims.width, ctx.dims.height);
    let gbuffer = GBuffer::new(
        device,
        ctx.scene_layout,
        ctx.settings.gbuffer,
        layout,
        (w, h),
        1,
    );
    let volumes = LightVolumes::new(device, w, h);
    let module = create_module(device, &shader(layout));
    let targets = volume_targets(ctx.count_blend);
    let layouts = [Some(ctx.scene_layout), None, Some(&gbuffer.read_layout)];
    let volume = |label, fragment_entry, draw| {
        volumes.pipeline(
            device,
            &VolumePipelineDesc {
                label,
                module: &module,
                fragment_entry,
                layouts: &layouts,
                color_targets: &targets,
                draw,
            },
        )
    };
    let base = {
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("deferred base"),
            bind_group_layouts: &layouts,
            immediate_size: 0,
        });
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("deferred base"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_base"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: volumes.depth_format,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_base"),
                compilation_options: Default::default(),
                targets: &targets,
            }),
            multiview_mask: None,
            cache: None,
        })
    };
    let stencil = (cull == Cull::Stencil).then(|| {
        (
            volume("stencil mark", "fs_light", VolumeDraw::StencilMark),
            volume("stencil light", "fs_light", VolumeDraw::StencilLight),
        )
    });
    Box::new(Deferred {
        copy: volumes.copy_pipeline(device, &module, ctx.scene_layout, &targets),
        base,
        front: volume("light volumes (front faces)", "fs_light", VolumeDraw::Front),
        back: volume("light volumes (back faces)", "fs_light", VolumeDraw::Back),
        full: volume("light volumes (full screen)", "fs_light", VolumeDraw::Full),
        stencil,
        gbuffer,
        volumes,
    })
}

pub(super) fn create_plain(ctx: &PipelineContext) -> Box<dyn Technique> {
    create(ctx, Cull::Volumes, GBufferLayout::Full)
}

pub(super) fn create_stencil(ctx: &PipelineContext) -> Box<dyn Technique> {
    create(ctx, Cull::Stencil, GBufferLayout::Full)
}

pub(super) fn create_mono(ctx: &PipelineContext) -> Box<dyn Technique> {
    create(ctx, Cull::Volumes, GBufferLayout::MonoSpecular)
}

impl Technique for Deferred {
    fn encode(&mut self, f: &FrameInputs, enc: &mut FrameEncoder) -> Result<()> {
        let classes = classify_lights(&f.setup, f.lights, self.stencil.is_some());
        self.volumes.upload(f.device, f.queue, &classes);
        let gbuffer_group = self.gbuffer.read_bind_group(f.device, f.targets);
        let copy_group = self.volumes.copy_bind_group(f.device, &f.targets.depth);
        let (encoder, timer) = enc.parts();
        self.gbuffer.encode(f, encoder, timer);
        let label = if self.stencil.is_some() {
            "deferred lighting (stencil)"
        } else {
            "deferred lighting"
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &lighting_attachments(f),
            depth_stencil_attachment: Some(self.volumes.attachment()),
            timestamp_writes: timer.render_pass(label),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        self.volumes
            .draw_depth_copy(&mut pass, f.scene_bind_group, &self.copy, &copy_group);
        pass.set_bind_group(2, &gbuffer_group, &[]);
        pass.set_pipeline(&self.base);
        pass.draw(0..3, 0..1);
        for (pipeline, draw) in [
            (&self.front, VolumeDraw::Front),
            (&self.back, VolumeDraw::Back),
            (&self.full, VolumeDraw::Full),
        ] {
            pass.set_pipeline(pipeline);
            self.volumes.draw(&mut pass, draw);
        }
        if let Some((mark, light)) = &self.stencil {
            pass.set_stencil_reference(0);
            for k in 0..self.volumes.stencil_count() {
                pass.set_pipeline(mark);
                self.volumes.draw_stencil_light(&mut pass, k);
                pass.set_pipeline(light);
                self.volumes.draw_stencil_light(&mut pass, k);
            }
        }
        Ok(())
    }
}

/// Depth + four G-buffer targets + HDR + the volumes' depth-stencil copy. Per pixel: the
/// G-buffer pass writes depth and G-buffer, the copy and base passes read depth and the base
/// target and write the copy and HDR. Per lighting computation: read depth, three G-buffer
/// targets and the light, blend into HDR (read + write).
pub(super) fn memory(settings: &RenderSettings) -> MemoryModel {
    memory_with(settings, GBufferLayout::Full)
}

/// As `memory` with three G-buffer targets, two of them read per lighting computation (the
/// blog's mono-specular deferred shading: the specular target's bytes saved per pixel and per
/// lit pixel).
pub(super) fn memory_mono(settings: &RenderSettings) -> MemoryModel {
    memory_with(settings, GBufferLayout::MonoSpecular)
}

fn memory_with(settings: &RenderSettings, layout: GBufferLayout) -> MemoryModel {
    let g = settings.gbuffer.bytes_per_target();
    let name = format!("gbuffer ({} targets)", layout.targets());
    MemoryModel::new(
        &[
            ("depth", DEPTH_BYTES),
            (&name, layout.targets() * g),
            ("hdr", HDR_BYTES),
            ("volume depth-stencil", VOLUME_DEPTH_BYTES),
        ],
        Traffic {
            write_per_pixel: DEPTH_BYTES + layout.targets() * g + VOLUME_DEPTH_BYTES + HDR_BYTES,
            read_per_pixel: 2 * DEPTH_BYTES + g,
            write_per_lit: HDR_BYTES,
            read_per_lit: DEPTH_BYTES + layout.lit_reads() * g + HDR_BYTES + LIGHT_BYTES,
        },
    )
}
