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
//! MSAA (tiled-deferred-tricks: edges marked in the stencil, their samples shaded apart): the
//! G-buffer, depth copy and HDR target hold every sample; after a. a full-screen pass marks
//! the edge pixels (`fs_mark_edges`, the edge-aware kernel's test), and b.–d. each run twice,
//! per pixel where the edge bit is clear and per sample where it is set (`light_volumes.rs`).
//!
//! Groups: 0 scene, 1 depth-copy source (copy draw only), 2 G-buffer.

use super::RenderSettings;
use super::{
    lighting_attachments, lighting_attachments_loaded, FrameEncoder, FrameInputs, PipelineContext,
    Technique,
};
use crate::error::Result;
use crate::frame::targets::counts_in_target;
use crate::memory::{MemoryModel, Traffic, DEPTH_BYTES, HDR_BYTES, LIGHT_BYTES};
use crate::passes::VOLUME_DEPTH_BYTES;
use crate::passes::{
    additive, classify_lights, Fullscreen, FullscreenVolumeDesc, LightVolumes, Shading, VolumeDraw,
    VolumePipelineDesc, MSAA_EDGES_WGSL, VOLUME_WGSL,
};
use crate::passes::{GBuffer, GBufferLayout, COUNT_FORMAT, FULLSCREEN_WGSL, HDR_FORMAT};
use crate::shader::{
    create_module, every_sample_count, msaa_defs, parts, src, ComposedShader, Def, ShaderKey,
};

pub(super) fn shaders() -> Vec<ComposedShader> {
    layout_shaders(GBufferLayout::Full)
}

pub(super) fn shaders_mono() -> Vec<ComposedShader> {
    layout_shaders(GBufferLayout::MonoSpecular)
}

/// Every value of [`DeferredKey`] with G-buffer `layout`.
fn layout_shaders(layout: GBufferLayout) -> Vec<ComposedShader> {
    DeferredKey::all()
        .into_iter()
        .filter(|k| k.layout == layout)
        .map(DeferredKey::shader)
        .collect()
}

/// The pipelines' shader: the G-buffer's layout and samples per pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct DeferredKey {
    pub layout: GBufferLayout,
    pub samples: u32,
}

impl ShaderKey for DeferredKey {
    const STAGE: &'static str = "deferred";

    fn all() -> Vec<Self> {
        GBufferLayout::ALL
            .into_iter()
            .flat_map(|layout| every_sample_count().map(move |samples| Self { layout, samples }))
            .collect()
    }

    fn defs(self) -> Vec<Def> {
        msaa_defs(self.samples)
    }

    fn parts(self) -> Vec<&'static str> {
        parts![
            src::TYPES,
            src::GRID_PARAMS,
            src::SCENE_BINDINGS,
            src::LIGHTING,
            src::LIT_OUT,
            FULLSCREEN_WGSL,
            VOLUME_WGSL,
            src::MSAA,
            self.layout.read_wgsl(),
            MSAA_EDGES_WGSL,
            include_str!("deferred.wgsl"),
        ]
    }
}

/// The pipelines of one [`Shading`]: per pixel, or per sample on MSAA edge pixels.
struct Shaders {
    shading: Shading,
    base: wgpu::RenderPipeline,
    front: wgpu::RenderPipeline,
    back: wgpu::RenderPipeline,
    full: wgpu::RenderPipeline,
    /// `deferred_stencil`'s light draw (after the mark).
    stencil_light: Option<wgpu::RenderPipeline>,
}

struct Deferred {
    gbuffer: GBuffer,
    volumes: LightVolumes,
    copy: wgpu::RenderPipeline,
    /// MSAA: the edge-marking pass.
    mark_edges: Option<wgpu::RenderPipeline>,
    /// `deferred_stencil`'s z-fail marking.
    stencil_mark: Option<wgpu::RenderPipeline>,
    /// Per pixel, then (MSAA) per sample.
    shaders: Vec<Shaders>,
}

/// HDR and count targets, both additive (no count target with MSAA: the per-pixel counts after the frame counters).
fn volume_targets(count_blend: bool, samples: u32) -> [Option<wgpu::ColorTargetState>; 2] {
    [
        Some(additive(HDR_FORMAT)),
        counts_in_target(count_blend, samples).then(|| additive(COUNT_FORMAT)),
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

/// What every light-volume and full-screen pipeline of one deferred technique shares.
struct Volumes<'a> {
    device: &'a wgpu::Device,
    volumes: &'a LightVolumes,
    module: &'a wgpu::ShaderModule,
    layouts: [Option<&'a wgpu::BindGroupLayout>; 3],
    targets: &'a [Option<wgpu::ColorTargetState>],
}

impl Volumes<'_> {
    fn volume(
        &self,
        label: &str,
        fragment_entry: &str,
        draw: VolumeDraw,
        shading: Shading,
    ) -> wgpu::RenderPipeline {
        self.volumes.pipeline(
            self.device,
            &VolumePipelineDesc {
                label,
                module: self.module,
                fragment_entry,
                layouts: &self.layouts,
                color_targets: self.targets,
                draw,
                shading,
            },
        )
    }

    fn fullscreen(
        &self,
        label: &str,
        fragment_entry: &str,
        kind: Fullscreen,
    ) -> wgpu::RenderPipeline {
        self.volumes.fullscreen_pipeline(
            self.device,
            &FullscreenVolumeDesc {
                label,
                module: self.module,
                fragment_entry,
                layouts: &self.layouts,
                color_targets: self.targets,
                kind,
            },
        )
    }

    /// The base pass and the volume classes shaded per pixel or per sample.
    fn shaders(&self, shading: Shading, cull: Cull) -> Shaders {
        let (suffix, light, base) = match shading {
            Shading::PerPixel => ("", "fs_light", "fs_base"),
            Shading::PerSample => (" per sample", "fs_light_sample", "fs_base_sample"),
        };
        let label = |what: &str| format!("{what}{suffix}");
        let volume = |what: &str, draw| self.volume(&label(what), light, draw, shading);
        Shaders {
            shading,
            base: self.fullscreen(&label("deferred base"), base, Fullscreen::Shade(shading)),
            front: volume("light volumes (front faces)", VolumeDraw::Front),
            back: volume("light volumes (back faces)", VolumeDraw::Back),
            full: volume("light volumes (full screen)", VolumeDraw::Full),
            stencil_light: (cull == Cull::Stencil)
                .then(|| volume("stencil light", VolumeDraw::StencilLight)),
        }
    }
}

fn create(ctx: &PipelineContext, cull: Cull, layout: GBufferLayout) -> Result<Box<dyn Technique>> {
    let device = ctx.device;
    let (w, h) = (ctx.dims.width, ctx.dims.height);
    let samples = ctx.settings.grid.samples;
    let gbuffer = GBuffer::new(
        device,
        ctx.scene_layout,
        ctx.settings.gbuffer,
        layout,
        (w, h),
        samples,
        ctx.shading,
    )?;
    let volumes = LightVolumes::new(device, w, h, samples);
    let module = create_module(
        device,
        &DeferredKey { layout, samples }
            .shader()
            .specialized(ctx.shading.reusing_maps()),
    );
    let targets = volume_targets(ctx.count_blend, samples);
    let pipelines = Volumes {
        device,
        volumes: &volumes,
        module: &module,
        layouts: [Some(ctx.scene_layout), None, Some(&gbuffer.read_layout)],
        targets: &targets,
    };
    let shaders = Shading::of(samples)
        .iter()
        .map(|&shading| pipelines.shaders(shading, cull))
        .collect();
    let mark_edges = (samples > 1)
        .then(|| pipelines.fullscreen("msaa edge marking", "fs_mark_edges", Fullscreen::MarkEdges));
    let stencil_mark = (cull == Cull::Stencil).then(|| {
        pipelines.volume(
            "stencil mark",
            "fs_stencil_only",
            VolumeDraw::StencilMark,
            Shading::PerPixel,
        )
    });
    Ok(Box::new(Deferred {
        copy: volumes.copy_pipeline(device, &module, ctx.scene_layout, &targets),
        mark_edges,
        stencil_mark,
        shaders,
        gbuffer,
        volumes,
    }))
}

pub(super) fn create_plain(ctx: &PipelineContext) -> Result<Box<dyn Technique>> {
    create(ctx, Cull::Volumes, GBufferLayout::Full)
}

pub(super) fn create_stencil(ctx: &PipelineContext) -> Result<Box<dyn Technique>> {
    create(ctx, Cull::Stencil, GBufferLayout::Full)
}

pub(super) fn create_mono(ctx: &PipelineContext) -> Result<Box<dyn Technique>> {
    create(ctx, Cull::Volumes, GBufferLayout::MonoSpecular)
}

impl Technique for Deferred {
    fn encode(&mut self, f: &FrameInputs, enc: &mut FrameEncoder) -> Result<()> {
        let classes = classify_lights(&f.setup, f.lights, self.stencil_mark.is_some());
        // With re-used shadow maps, each shadowed light is drawn alone after its maps.
        let (together, alone) = match f.reused_shadow_maps {
            Some(maps) => classes.split(|i| maps.casts(i), f.lights),
            None => (classes, Default::default()),
        };
        self.volumes
            .upload_split(f.device, f.queue, &together, &alone);
        let alone = self.volumes.shadowed();
        let gbuffer_group = self.gbuffer.read_bind_group(f.device, f.targets);
        let copy_group = self.volumes.copy_bind_group(f.device, &f.targets.depth);
        let (encoder, timer) = enc.parts();
        self.gbuffer.encode(f, encoder, timer);
        let label = if self.stencil_mark.is_some() {
            "deferred lighting (stencil)"
        } else {
            "deferred lighting"
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &lighting_attachments(f),
            depth_stencil_attachment: Some(if alone.is_empty() {
                self.volumes.attachment()
            } else {
                self.volumes.kept_attachment()
            }),
            timestamp_writes: timer.render_pass(label),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        self.volumes
            .draw_depth_copy(&mut pass, f.scene_bind_group, &self.copy, &copy_group);
        pass.set_bind_group(2, &gbuffer_group, &[]);
        if let Some(mark) = &self.mark_edges {
            self.volumes.mark_edges(&mut pass, mark);
        }
        for s in &self.shaders {
            self.volumes.draw_fullscreen(&mut pass, &s.base, s.shading);
            for (pipeline, draw) in [
                (&s.front, VolumeDraw::Front),
                (&s.back, VolumeDraw::Back),
                (&s.full, VolumeDraw::Full),
            ] {
                pass.set_pipeline(pipeline);
                self.volumes.draw(&mut pass, draw, s.shading);
            }
        }
        if let Some(mark) = &self.stencil_mark {
            for k in 0..self.volumes.stencil_count() {
                pass.set_pipeline(mark);
                self.volumes.draw_stencil_light(
                    &mut pass,
                    k,
                    VolumeDraw::StencilMark,
                    Shading::PerPixel,
                );
                for s in &self.shaders {
                    let light = s.stencil_light.as_ref().expect("stencil pipelines");
                    pass.set_pipeline(light);
                    self.volumes.draw_stencil_light(
                        &mut pass,
                        k,
                        VolumeDraw::StencilLight,
                        s.shading,
                    );
                }
            }
        }
        drop(pass);
        for (slot, instance, light) in alone {
            let maps = f.reused_shadow_maps.expect("split by them");
            maps.encode_light(encoder, f, light as usize);
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("deferred lighting (one shadowed light)"),
                color_attachments: &lighting_attachments_loaded(f),
                depth_stencil_attachment: Some(self.volumes.reloaded_attachment()),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, f.scene_bind_group, &[]);
            pass.set_bind_group(2, &gbuffer_group, &[]);
            self.draw_alone(&mut pass, (slot, instance));
        }
        Ok(())
    }

    fn reuses_shadow_maps(&self) -> bool {
        true
    }
}

impl Deferred {
    /// One light of the one-at-a-time classes: its class's draws with every shader.
    fn draw_alone(&self, pass: &mut wgpu::RenderPass, at: (usize, u32)) {
        let class = LightVolumes::shadowed_class(at.0);
        if class == VolumeDraw::StencilLight {
            let mark = self.stencil_mark.as_ref().expect("stencil pipelines");
            pass.set_pipeline(mark);
            self.volumes
                .draw_one(pass, at, VolumeDraw::StencilMark, Shading::PerPixel);
        }
        for s in &self.shaders {
            let pipeline = match class {
                VolumeDraw::Front => &s.front,
                VolumeDraw::Back => &s.back,
                VolumeDraw::Full => &s.full,
                _ => s.stencil_light.as_ref().expect("stencil pipelines"),
            };
            pass.set_pipeline(pipeline);
            self.volumes.draw_one(pass, at, class, s.shading);
        }
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
