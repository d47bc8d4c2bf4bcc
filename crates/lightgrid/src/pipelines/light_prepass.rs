//! `light_prepass` and `light_prepass_mono`: deferred lighting, as the blog
//! (deferred-shading-vs-deferred-lighting) lays it out.
//!
//! 1. Attributes pass: geometry → normal + specular exponent (RGBA16F) and depth.
//! 2. Irradiance pass (HDR-range targets, additive): a depth copy, then each light's volume
//!    (classes in `light_volumes.rs`) adds its diffuse irradiance and specular irradiance to two
//!    RGBA16F targets; `_mono` keeps only the specular luminance, in the diffuse alpha, and has
//!    no specular target.
//! 3. Shading pass: geometry again (depth LessEqual against pass 1, no writes) reads the
//!    irradiance at its pixel and applies the material colours.
//!
//! Groups: pass 1: 0 scene. Pass 2: 0 scene, 1 depth-copy source, 2 attributes + depth.
//! Pass 3: 0 scene, 1 irradiance.

use super::RenderSettings;
use super::{
    draw_scene, geometry_pipeline, FrameEncoder, FrameInputs, GeometryPipelineDesc,
    PipelineContext, Technique,
};
use crate::error::Result;
use crate::memory::{MemoryModel, Traffic, DEPTH_BYTES, HDR_BYTES, LIGHT_BYTES};
use crate::passes::{
    additive, classify_lights, LightVolumes, VolumeDraw, VolumePipelineDesc, COUNT_FORMAT,
    FULLSCREEN_WGSL, HDR_FORMAT, VOLUME_WGSL,
};
use crate::passes::{cleared, render_texture, texture_entry, VOLUME_DEPTH_BYTES};
use crate::shader::{compose, create_module, ComposedShader, SCENE_PARTS};

/// Attributes and irradiance targets are RGBA16F, as the blog's X16R16G16B16 / A8R8G8B8 layout
/// rounded up to what every adapter renders and blends.
const TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

pub(super) fn shaders() -> Vec<ComposedShader> {
    let mut parts = SCENE_PARTS.to_vec();
    parts.extend([
        FULLSCREEN_WGSL,
        VOLUME_WGSL,
        include_str!("light_prepass.wgsl"),
    ]);
    vec![compose("light_prepass", &parts)]
}

struct LightPrepass {
    mono: bool,
    attributes: wgpu::RenderPipeline,
    volumes: LightVolumes,
    copy: wgpu::RenderPipeline,
    irradiance: [wgpu::RenderPipeline; 3],
    shade: wgpu::RenderPipeline,
    attr_view: wgpu::TextureView,
    diffuse_view: wgpu::TextureView,
    specular_view: Option<wgpu::TextureView>,
    attr_layout: wgpu::BindGroupLayout,
    irr_layout: wgpu::BindGroupLayout,
}

fn texture_layout(
    device: &wgpu::Device,
    label: &str,
    second: wgpu::TextureSampleType,
) -> wgpu::BindGroupLayout {
    let first = wgpu::TextureSampleType::Float { filterable: false };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &[texture_entry(0, first), texture_entry(1, second)],
    })
}

fn target(device: &wgpu::Device, label: &str, w: u32, h: u32) -> wgpu::TextureView {
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
    render_texture(device, label, TARGET_FORMAT, (w, h), usage).create_view(&Default::default())
}

fn create(ctx: &PipelineContext, mono: bool) -> Box<dyn Technique> {
    let device = ctx.device;
    let (w, h) = (ctx.dims.width, ctx.dims.height);
    let module = create_module(device, &shaders()[0]);
    let attributes = geometry_pipeline(
        device,
        &GeometryPipelineDesc {
            label: "light pre-pass attributes",
            module: &module,
            fragment_entry: Some("fs_attributes"),
            layouts: &[Some(ctx.scene_layout)],
            color_targets: &[Some(TARGET_FORMAT.into())],
            depth_write: true,
            depth_compare: wgpu::CompareFunction::Less,
            samples: 1,
        },
    );
    let volumes = LightVolumes::new(device, w, h);
    let attr_layout = texture_layout(
        device,
        "light pre-pass attributes",
        wgpu::TextureSampleType::Depth,
    );
    let irr_layout = texture_layout(
        device,
        "light pre-pass irradiance",
        wgpu::TextureSampleType::Float { filterable: false },
    );
    let irr_targets = [
        Some(additive(TARGET_FORMAT)),
        (!mono).then(|| additive(TARGET_FORMAT)),
        ctx.count_blend.then(|| additive(COUNT_FORMAT)),
    ];
    let layouts = [Some(ctx.scene_layout), None, Some(&attr_layout)];
    let entry = if mono {
        "fs_irradiance_mono"
    } else {
        "fs_irradiance"
    };
    let irradiance = [VolumeDraw::Front, VolumeDraw::Back, VolumeDraw::Full].map(|draw| {
        volumes.pipeline(
            device,
            &VolumePipelineDesc {
                label: "light pre-pass irradiance",
                module: &module,
                fragment_entry: entry,
                layouts: &layouts,
                color_targets: &irr_targets,
                draw,
            },
        )
    });
    let shade = geometry_pipeline(
        device,
        &GeometryPipelineDesc {
            label: "light pre-pass shading",
            module: &module,
            fragment_entry: Some(if mono { "fs_shade_mono" } else { "fs_shade" }),
            layouts: &[Some(ctx.scene_layout), Some(&irr_layout)],
            color_targets: &[Some(HDR_FORMAT.into())],
            depth_write: false,
            depth_compare: wgpu::CompareFunction::LessEqual,
            samples: 1,
        },
    );
    Box::new(LightPrepass {
        mono,
        attributes,
        copy: volumes.copy_pipeline(device, &module, ctx.scene_layout, &irr_targets),
        volumes,
        irradiance,
        shade,
        attr_view: target(device, "attributes (normal, shininess)", w, h),
        diffuse_view: target(device, "diffuse irradiance", w, h),
        specular_view: (!mono).then(|| target(device, "specular irradiance", w, h)),
        attr_layout,
        irr_layout,
    })
}

pub(super) fn create_full(ctx: &PipelineContext) -> Box<dyn Technique> {
    create(ctx, false)
}

pub(super) fn create_mono(ctx: &PipelineContext) -> Box<dyn Technique> {
    create(ctx, true)
}

fn bind_two(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    a: &wgpu::TextureView,
    b: &wgpu::TextureView,
) -> wgpu::BindGroup {
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(a),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(b),
            },
        ],
    })
}

impl Technique for LightPrepass {
    fn encode(&mut self, f: &FrameInputs, enc: &mut FrameEncoder) -> Result<()> {
        let classes = classify_lights(&f.setup, f.lights, false);
        self.volumes.upload(f.device, f.queue, &classes);
        let attr_group = bind_two(
            f.device,
            &self.attr_layout,
            &self.attr_view,
            &f.targets.depth,
        );
        // Mono has no specular target; its shader reads only binding 0.
        let specular = self.specular_view.as_ref().unwrap_or(&self.diffuse_view);
        let irr_group = bind_two(f.device, &self.irr_layout, &self.diffuse_view, specular);
        let copy_group = self.volumes.copy_bind_group(f.device, &f.targets.depth);
        let color = cleared;
        let (encoder, timer) = enc.parts();
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("light pre-pass attributes"),
                color_attachments: &[Some(color(&self.attr_view, wgpu::Color::TRANSPARENT))],
                depth_stencil_attachment: Some(crate::passes::cleared_depth(&f.targets.depth)),
                timestamp_writes: timer.render_pass("light pre-pass attributes"),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.attributes);
            draw_scene(&mut pass, f, &[]);
        }
        {
            let label = if self.mono {
                "irradiance (mono specular)"
            } else {
                "irradiance"
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(label),
                color_attachments: &[
                    Some(color(&self.diffuse_view, wgpu::Color::TRANSPARENT)),
                    self.specular_view
                        .as_ref()
                        .map(|v| color(v, wgpu::Color::TRANSPARENT)),
                    f.count_blend
                        .then(|| color(&f.targets.counts, wgpu::Color::TRANSPARENT)),
                ],
                depth_stencil_attachment: Some(self.volumes.attachment()),
                timestamp_writes: timer.render_pass(label),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            self.volumes
                .draw_depth_copy(&mut pass, f.scene_bind_group, &self.copy, &copy_group);
            pass.set_bind_group(2, &attr_group, &[]);
            for (pipeline, draw) in
                self.irradiance
                    .iter()
                    .zip([VolumeDraw::Front, VolumeDraw::Back, VolumeDraw::Full])
            {
                pass.set_pipeline(pipeline);
                self.volumes.draw(&mut pass, draw);
            }
        }
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("light pre-pass shading"),
            color_attachments: &[Some(color(&f.targets.hdr, wgpu::Color::BLACK))],
            depth_stencil_attachment: Some(crate::passes::loaded_depth(&f.targets.depth)),
            timestamp_writes: timer.render_pass("light pre-pass shading"),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.shade);
        draw_scene(&mut pass, f, &[&irr_group]);
        Ok(())
    }
}

/// Bytes of one attributes or irradiance target.
const TARGET_BYTES: u32 = 8;

/// Depth + attributes + two irradiance targets + HDR + the volumes' depth-stencil copy (the
/// blog's layout). Per pixel: attributes pass writes depth and attributes, the copy reads
/// depth and writes the copy, the shading pass reads the irradiance and writes HDR. Per
/// lighting computation: read depth, attributes and the light, blend into the irradiance
/// targets.
pub(super) fn memory_full(_: &RenderSettings) -> MemoryModel {
    memory_with(2)
}

/// As `memory_full` with one irradiance target.
pub(super) fn memory_mono(_: &RenderSettings) -> MemoryModel {
    memory_with(1)
}

fn memory_with(irradiance_targets: u32) -> MemoryModel {
    let irr = irradiance_targets * TARGET_BYTES;
    let mut targets = vec![
        ("depth", DEPTH_BYTES),
        ("attributes (normal, exponent)", TARGET_BYTES),
        ("diffuse irradiance", TARGET_BYTES),
    ];
    if irradiance_targets == 2 {
        targets.push(("specular irradiance", TARGET_BYTES));
    }
    targets.extend([
        ("hdr", HDR_BYTES),
        ("volume depth-stencil", VOLUME_DEPTH_BYTES),
    ]);
    MemoryModel::new(
        &targets,
        Traffic {
            write_per_pixel: DEPTH_BYTES + TARGET_BYTES + VOLUME_DEPTH_BYTES + HDR_BYTES,
            read_per_pixel: DEPTH_BYTES + irr,
            write_per_lit: irr,
            read_per_lit: DEPTH_BYTES + TARGET_BYTES + irr + LIGHT_BYTES,
        },
    )
}
