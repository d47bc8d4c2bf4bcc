//! `light_prepass` and `light_prepass_mono`: deferred lighting, as the blog
//! (deferred-shading-vs-deferred-lighting) lays it out.
//!
//! 1. Attributes pass: geometry → normal + specular exponent (RGBA16F), the specular colour
//!    (RGB10A2; GGX's Fresnel F0, which its irradiance holds) and depth, each the sample's own
//!    as forward computes it (a metallic-roughness texture varies them within a material).
//! 2. Irradiance pass (HDR-range targets, additive): a depth-stencil copy, then each light's
//!    volume (classes in `light_volumes.rs`) adds its diffuse irradiance and specular
//!    irradiance to two RGBA16F targets; `_mono` keeps only the specular luminance, in the
//!    diffuse alpha, and has no specular target.
//! 3. Shading pass: geometry again, tested against the copy (the scene's surface test, no
//!    writes), reads the irradiance at its pixel and applies the material colours.
//!
//! MSAA (tiled-deferred-tricks, as `deferred`): every target holds each sample. After the
//! copy a full-screen pass sets the stencil's edge bit on the pixels whose samples need
//! irradiance of their own (`attributes_differ`: geometry against sky, another exponent
//! (under GGX another specular colour), plane or normal; another material alone is no edge,
//! see `light_prepass_attributes.wgsl`); every volume class is drawn per pixel where the bit is
//! clear (the irradiance at the pixel centre, written to every sample) and per sample where
//! it is set. The copy is kept for pass 3, which draws the geometry twice on the same bit:
//! per pixel elsewhere (sample 0's irradiance, which is every sample's), per sample on edge
//! pixels (each sample's own). Material edges need no per-sample pass 3: the rasterizer
//! gives each triangle's fragment exactly its own samples.
//!
//! Groups: pass 1: 0 scene. Pass 2: 0 scene, 1 depth-copy source, 2 attributes + depth +
//! specular colour.
//! Pass 3: 0 scene, 1 irradiance.
//!
//! `tiled_light_prepass` is compute-based deferred lighting [And11], the baseline Forward+ is
//! measured against (forward-plus §5, Fig. 3): pass 2 is the tile grid (`LightCuller`, as
//! every grid pipeline) and one compute pass, one invocation per pixel, that loops its tile's
//! lights and writes the mono irradiance (`tiled_light_prepass.wgsl`). Its groups: 0 scene,
//! 1 grid, 2 attributes + depth, 3 irradiance + count (storage). With MSAA the kernel is
//! edge-aware (`tiled_light_prepass_msaa.wgsl`, structured as `tiled_deferred_msaa.wgsl`:
//! a pixel computed once at its centre, an edge pixel's samples queued and shared over the
//! workgroup, `attributes_edge` the volume variants' test) and stores each sample's
//! irradiance in a buffer (group 3); a render pass then copies the depth into a
//! depth-stencil copy, writes the samples into the multisampled irradiance target
//! (`fs_expand_irradiance`, group 1 the buffer) and marks the edges, and pass 3 runs as the
//! volume variants' (`TiledMsaa`).

use super::RenderSettings;
use super::{
    draw_scene, geometry_pipeline, FrameEncoder, FrameInputs, GeometryPipelineDesc,
    PipelineContext, Technique, TransparentLights,
};
use crate::consts::SCREEN_WORKGROUP;
use crate::culling::LightCuller;
use crate::error::Result;
use crate::frame::targets::counts_in_target;
use crate::memory::{MemoryModel, Traffic, DEPTH_BYTES, HDR_BYTES, INDEX_BYTES, LIGHT_BYTES};
use crate::passes::geometry::geometry_pipeline_on;
use crate::passes::{
    additive, classify_lights, Fullscreen, FullscreenVolumeDesc, LightVolumes, Shading, VolumeDraw,
    VolumePipelineDesc, COUNT_FORMAT, FULLSCREEN_WGSL, HDR_FORMAT, MSAA_SURFACES_WGSL, VOLUME_WGSL,
};
use crate::passes::{
    cleared, loaded, multisampled_texture, sampled_texture_entry, VOLUME_DEPTH_BYTES,
};
use crate::shader::{
    compute_pipeline, create_module, parts, src, ComposedShader, SampleStage, SamplesKey,
    ShaderKey, SCENE_PARTS,
};

/// Attributes and irradiance targets are RGBA16F, as the blog's X16R16G16B16 / A8R8G8B8 layout
/// rounded up to what every adapter renders and blends.
const TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The specular colour (F0, in 0..1): 10 bits a channel keeps a dielectric's 0.04 within
/// 0.2 % (8 bits would round it to 0.039), in 4 bytes.
const SPECULAR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgb10a2Unorm;

/// Bytes of the specular-colour target.
const SPECULAR_BYTES: u32 = 4;

pub(super) fn shaders() -> Vec<ComposedShader> {
    LightPrepassKey::all_shaders()
}

/// The light pre-pass's shader for targets of `samples` samples per pixel.
pub(super) type LightPrepassKey = SamplesKey<LightPrepassStage>;

pub(super) enum LightPrepassStage {}

impl SampleStage for LightPrepassStage {
    const STAGE: &'static str = "light_prepass";

    fn parts(_samples: u32) -> Vec<&'static str> {
        let mut parts = SCENE_PARTS.to_vec();
        parts.extend([
            src::MSAA,
            FULLSCREEN_WGSL,
            VOLUME_WGSL,
            MSAA_SURFACES_WGSL,
            ATTRIBUTES_WGSL,
            include_str!("light_prepass.wgsl"),
        ]);
        parts
    }
}

/// Group 2 of the irradiance passes and the surface they read from it (both variants).
const ATTRIBUTES_WGSL: &str = include_str!("light_prepass_attributes.wgsl");

/// The tiled variant's shaders: the light pre-pass's and the irradiance kernel.
pub(super) fn shaders_tiled() -> Vec<ComposedShader> {
    let mut out = shaders();
    out.extend(TiledKernelKey::all_shaders());
    out
}

/// The irradiance kernel for attributes of `samples` samples per pixel: one pixel per
/// invocation, or above one the edge-aware kernel (`tiled_light_prepass_msaa.wgsl`), with the
/// light loop `light_loop`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct TiledKernelKey {
    pub samples: u32,
    pub light_loop: crate::frame::LightLoop,
}

impl crate::shader::ShaderKey for TiledKernelKey {
    const STAGE: &'static str = "tiled_light_prepass";

    fn all() -> Vec<Self> {
        crate::frame::LightLoop::ALL
            .into_iter()
            .flat_map(|light_loop| {
                crate::shader::every_sample_count().map(move |samples| Self {
                    samples,
                    light_loop,
                })
            })
            .collect()
    }

    fn defs(self) -> Vec<crate::shader::Def> {
        crate::shader::msaa_defs(self.samples)
    }

    fn parts(self) -> Vec<&'static str> {
        let samples = self.samples;

        // The kernel and what it shares: the storage outputs at 1x, the edge queue above.
        let (shared, kernel) = if samples > 1 {
            (
                super::tiled_deferred::MSAA_EDGE_QUEUE_WGSL,
                include_str!("tiled_light_prepass_msaa.wgsl"),
            )
        } else {
            (
                crate::passes::COMPUTE_OUTPUTS_WGSL,
                include_str!("tiled_light_prepass.wgsl"),
            )
        };
        parts![
            src::TYPES,
            src::GRID_PARAMS,
            src::SCENE_BINDINGS,
            src::LIGHTING,
            src::MSAA,
            src::LIGHT_GRID,
            super::light_loop_wgsl(self.light_loop),
            MSAA_SURFACES_WGSL,
            ATTRIBUTES_WGSL,
            shared,
            kernel,
        ]
    }
}

/// Which light pre-pass.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Mode {
    /// Diffuse and specular irradiance targets, light volumes.
    Full,
    /// Specular luminance in the diffuse alpha, light volumes.
    Mono,
    /// Mono irradiance accumulated per tile in a compute pass [And11].
    Tiled,
}

/// The volume pipelines of one [`Shading`]: per pixel, or per sample on MSAA edge pixels.
struct VolumeShaders {
    shading: Shading,
    /// MSAA: the full-screen draw counting edge pixels and irradiance samples.
    count: Option<wgpu::RenderPipeline>,
    /// Front, back and full-screen volume classes.
    classes: [wgpu::RenderPipeline; 3],
}

/// How the irradiance is accumulated (pass 2).
enum Irradiance {
    /// Each light's volume rasterized, blending into the irradiance targets.
    Volumes {
        volumes: Box<LightVolumes>,
        copy: wgpu::RenderPipeline,
        /// MSAA: the edge-marking pass.
        mark_edges: Option<wgpu::RenderPipeline>,
        /// Per pixel, then (MSAA) per sample.
        shaders: Vec<VolumeShaders>,
    },
    /// The tile grid, then one compute pass over the pixels.
    Tiled {
        builder: Box<super::PipelineGrid>,
        kernel: wgpu::ComputePipeline,
        outputs_layout: wgpu::BindGroupLayout,
        /// MSAA: the kernel's per-sample output and the pass expanding it.
        msaa: Option<Box<TiledMsaa>>,
    },
}

/// `tiled_light_prepass` with MSAA: the edge-aware kernel stores each sample's irradiance in
/// a buffer; a render pass copies the depth into a depth-stencil copy, writes the samples
/// into the multisampled irradiance target and marks the edge pixels (the kernel's test), so
/// the shading pass runs as the volume variants' does.
struct TiledMsaa {
    /// The kernel's group 3 (the per-sample buffer, written).
    kernel_group: wgpu::BindGroup,
    /// The expand draw's group 1 (the same buffer, read).
    expand_group: wgpu::BindGroup,
    /// Only its depth-stencil copy and full-screen draws: no volume is drawn.
    volumes: LightVolumes,
    copy: wgpu::RenderPipeline,
    expand: wgpu::RenderPipeline,
    mark_edges: wgpu::RenderPipeline,
}

impl TiledMsaa {
    fn new(
        ctx: &PipelineContext,
        module: &wgpu::ShaderModule,
        attr_layout: &wgpu::BindGroupLayout,
    ) -> (wgpu::BindGroupLayout, Self) {
        use crate::gpu::{bind_resources, buffer_entry, STORAGE_READ, STORAGE_RW};
        let device = ctx.device;
        let (w, h, samples) = (ctx.dims.width, ctx.dims.height, ctx.settings.grid.samples);
        let buffer = crate::gpu::storage_buffer(
            device,
            "msaa sample irradiance",
            u64::from(w) * u64::from(h) * u64::from(samples) * u64::from(TARGET_BYTES),
        );
        let kernel_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("msaa irradiance kernel output (group 3)"),
            entries: &[buffer_entry(0, STORAGE_RW)],
        });
        let expand_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("msaa irradiance expand (group 1)"),
            entries: &[wgpu::BindGroupLayoutEntry {
                visibility: wgpu::ShaderStages::FRAGMENT,
                ..buffer_entry(0, STORAGE_READ)
            }],
        });
        let group =
            |label, layout| bind_resources(device, label, layout, &[buffer.as_entire_binding()]);
        let volumes = LightVolumes::new(device, w, h, samples);
        let targets = [Some(TARGET_FORMAT.into())];
        let fullscreen =
            |label: &str, fragment_entry, layouts: &[Option<&wgpu::BindGroupLayout>], kind| {
                volumes.fullscreen_pipeline(
                    device,
                    &FullscreenVolumeDesc {
                        label,
                        module,
                        fragment_entry,
                        layouts,
                        color_targets: &targets,
                        kind,
                    },
                )
            };
        // Drawn before the marks, so the per-pixel stencil test (edge bit clear) passes on
        // every pixel; the entry reads `sample_index`, so it runs per sample.
        let expand = fullscreen(
            "msaa irradiance expand",
            "fs_expand_irradiance",
            &[
                Some(ctx.scene_layout),
                Some(&expand_layout),
                Some(attr_layout),
            ],
            Fullscreen::Shade(Shading::PerPixel),
        );
        // The edges the kernel shaded per sample, read from what it stored
        // (`fs_mark_irradiance_edges`), not decided again.
        let mark_edges = fullscreen(
            "msaa edge marking",
            "fs_mark_irradiance_edges",
            &[
                Some(ctx.scene_layout),
                Some(&expand_layout),
                Some(attr_layout),
            ],
            Fullscreen::MarkEdges,
        );
        let msaa = TiledMsaa {
            kernel_group: group("msaa irradiance kernel output", &kernel_layout),
            expand_group: group("msaa irradiance expand", &expand_layout),
            copy: volumes.copy_pipeline(device, module, ctx.scene_layout, &targets),
            expand,
            mark_edges,
            volumes,
        };
        (kernel_layout, msaa)
    }
}

const CLASSES: [VolumeDraw; 3] = [VolumeDraw::Front, VolumeDraw::Back, VolumeDraw::Full];

struct LightPrepass {
    mono: bool,
    samples: u32,
    attributes: wgpu::RenderPipeline,
    irradiance: Irradiance,
    /// Pass 3 per pixel, then (MSAA) per sample on the edge pixels.
    shade: Vec<(Shading, wgpu::RenderPipeline)>,
    attr_view: wgpu::TextureView,
    specular_attr_view: wgpu::TextureView,
    diffuse_view: wgpu::TextureView,
    specular_view: Option<wgpu::TextureView>,
    attr_layout: wgpu::BindGroupLayout,
    irr_layout: wgpu::BindGroupLayout,
}

/// Textures of `samples` samples per pixel, of these sample types by binding.
fn texture_layout(
    device: &wgpu::Device,
    label: &str,
    types: &[wgpu::TextureSampleType],
    samples: u32,
) -> wgpu::BindGroupLayout {
    let entries: Vec<_> = (0u32..)
        .zip(types)
        .map(|(binding, &ty)| sampled_texture_entry(binding, ty, samples))
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &entries,
    })
}

/// A target's sample type as the passes after it read it.
const UNFILTERED: wgpu::TextureSampleType = wgpu::TextureSampleType::Float { filterable: false };

/// A target of `samples` samples per pixel read by a later pass and written as `written` (a
/// render attachment or storage).
fn target(
    device: &wgpu::Device,
    label: &str,
    size: (u32, u32),
    samples: u32,
    written: wgpu::TextureUsages,
) -> wgpu::TextureView {
    let usage = written | wgpu::TextureUsages::TEXTURE_BINDING;
    multisampled_texture(device, label, TARGET_FORMAT, size, samples, usage)
        .create_view(&Default::default())
}

/// Pass 2 of the light-volume variants.
fn volume_irradiance(
    ctx: &PipelineContext,
    module: &wgpu::ShaderModule,
    attr_layout: &wgpu::BindGroupLayout,
    mono: bool,
) -> Irradiance {
    let device = ctx.device;
    let (w, h) = (ctx.dims.width, ctx.dims.height);
    let samples = ctx.settings.grid.samples;
    let volumes = Box::new(LightVolumes::new(device, w, h, samples));
    let irr_targets = [
        Some(additive(TARGET_FORMAT)),
        (!mono).then(|| additive(TARGET_FORMAT)),
        counts_in_target(ctx.count_blend, samples).then(|| additive(COUNT_FORMAT)),
    ];
    let layouts = [Some(ctx.scene_layout), None, Some(attr_layout)];
    let fullscreen = |label: &str, fragment_entry, kind| {
        volumes.fullscreen_pipeline(
            device,
            &FullscreenVolumeDesc {
                label,
                module,
                fragment_entry,
                layouts: &layouts,
                color_targets: &irr_targets,
                kind,
            },
        )
    };
    let shaders = Shading::of(samples)
        .iter()
        .map(|&shading| {
            let (entry, count) = match (shading, mono) {
                (Shading::PerPixel, false) => ("fs_irradiance", "fs_count"),
                (Shading::PerPixel, true) => ("fs_irradiance_mono", "fs_count"),
                (Shading::PerSample, false) => ("fs_irradiance_sample", "fs_count_sample"),
                (Shading::PerSample, true) => ("fs_irradiance_mono_sample", "fs_count_sample"),
            };
            VolumeShaders {
                shading,
                count: (samples > 1).then(|| {
                    fullscreen(
                        "light pre-pass msaa counts",
                        count,
                        Fullscreen::Shade(shading),
                    )
                }),
                classes: CLASSES.map(|draw| {
                    volumes.pipeline(
                        device,
                        &VolumePipelineDesc {
                            label: "light pre-pass irradiance",
                            module,
                            fragment_entry: entry,
                            layouts: &layouts,
                            color_targets: &irr_targets,
                            draw,
                            shading,
                        },
                    )
                }),
            }
        })
        .collect();
    Irradiance::Volumes {
        copy: volumes.copy_pipeline(device, module, ctx.scene_layout, &irr_targets),
        mark_edges: (samples > 1)
            .then(|| fullscreen("msaa edge marking", "fs_mark_edges", Fullscreen::MarkEdges)),
        shaders,
        volumes,
    }
}

/// Pass 2 of the tiled variant: the grid over the attributes pass's depth, and the kernel
/// (with MSAA the edge-aware one, and the pass expanding its samples).
fn tiled_irradiance(
    ctx: &PipelineContext,
    module: &wgpu::ShaderModule,
    attr_layout: &wgpu::BindGroupLayout,
) -> Result<Irradiance> {
    let builder = ctx.grid(&ctx.settings.grid.tiled(), true, false)?;
    let samples = ctx.settings.grid.samples;
    let (outputs_layout, msaa) = if samples > 1 {
        let (layout, msaa) = TiledMsaa::new(ctx, module, attr_layout);
        (layout, Some(Box::new(msaa)))
    } else {
        (crate::passes::compute_outputs_layout(ctx.device), None)
    };
    let kernel = compute_pipeline(
        ctx.device,
        "tiled light pre-pass irradiance",
        &TiledKernelKey {
            samples,
            light_loop: ctx.settings.light_loop,
        }
        .shader()
        .specialized(ctx.shading),
        "main",
        &[
            Some(ctx.scene_layout),
            Some(builder.bind_group_layout()),
            Some(attr_layout),
            Some(&outputs_layout),
        ],
    );
    Ok(Irradiance::Tiled {
        builder: Box::new(builder),
        kernel,
        outputs_layout,
        msaa,
    })
}

impl Irradiance {
    /// The depth-stencil copy the shading pass tests (its stencil holds the MSAA edge bits):
    /// the volume variants', or the tiled variant's with MSAA; `None`: the scene depth.
    fn copy(&self) -> Option<&LightVolumes> {
        match self {
            Irradiance::Volumes { volumes, .. } => Some(volumes),
            Irradiance::Tiled { msaa, .. } => msaa.as_ref().map(|m| &m.volumes),
        }
    }
}

/// The second geometry pass's pipelines, per pixel and (with MSAA) per sample: the material
/// lit by the irradiance targets, drawn where the copy of the volume depth-stencil says.
fn shade_pipelines(
    ctx: &PipelineContext,
    module: &wgpu::ShaderModule,
    irr_layout: &wgpu::BindGroupLayout,
    irradiance: &Irradiance,
    mono: bool,
) -> Vec<(Shading, wgpu::RenderPipeline)> {
    let samples = ctx.settings.grid.samples;
    Shading::of(samples)
        .iter()
        .map(|&shading| {
            let entry = match (shading, mono) {
                (Shading::PerPixel, false) => "fs_shade",
                (Shading::PerPixel, true) => "fs_shade_mono",
                (Shading::PerSample, false) => "fs_shade_sample",
                (Shading::PerSample, true) => "fs_shade_mono_sample",
            };
            let desc = GeometryPipelineDesc {
                label: "light pre-pass shading",
                module,
                fragment_entry: Some(entry),
                layouts: &[Some(ctx.scene_layout), Some(irr_layout)],
                color_targets: &[Some(HDR_FORMAT.into())],
                depth_write: false,
                depth_compare: crate::depth::SURFACE,
                samples,
            };
            let pipeline = match irradiance.copy() {
                Some(copy) => geometry_pipeline_on(ctx.device, &desc, copy.surface_test()),
                None => geometry_pipeline(ctx.device, &desc),
            };
            (shading, pipeline)
        })
        .collect()
}

fn create(ctx: &PipelineContext, mode: Mode) -> Result<Box<dyn Technique>> {
    let mono = mode != Mode::Full;
    let device = ctx.device;
    let size = (ctx.dims.width, ctx.dims.height);
    let samples = ctx.settings.grid.samples;
    // The volume variants shade one light at a time and re-use one light's shadow maps.
    let shading = match mode {
        Mode::Tiled => ctx.shading,
        Mode::Full | Mode::Mono => ctx.shading.reusing_maps(),
    };
    let module = create_module(
        device,
        &LightPrepassKey::new(samples).shader().specialized(shading),
    );
    let attributes = geometry_pipeline(
        device,
        &GeometryPipelineDesc {
            label: "light pre-pass attributes",
            module: &module,
            fragment_entry: Some("fs_attributes"),
            layouts: &[Some(ctx.scene_layout)],
            color_targets: &[Some(TARGET_FORMAT.into()), Some(SPECULAR_FORMAT.into())],
            depth_write: true,
            depth_compare: crate::depth::SURFACE,
            samples,
        },
    );
    let attr_layout = texture_layout(
        device,
        "light pre-pass attributes",
        &[UNFILTERED, wgpu::TextureSampleType::Depth, UNFILTERED],
        samples,
    );
    let irr_layout = texture_layout(
        device,
        "light pre-pass irradiance",
        &[UNFILTERED, UNFILTERED],
        samples,
    );
    let irradiance = match mode {
        Mode::Tiled => tiled_irradiance(ctx, &module, &attr_layout)?,
        _ => volume_irradiance(ctx, &module, &attr_layout, mono),
    };
    // The 1x tiled kernel stores the irradiance; with MSAA (a multisampled texture cannot be
    // a storage texture) the expand pass renders it.
    let written = if mode == Mode::Tiled && samples == 1 {
        wgpu::TextureUsages::STORAGE_BINDING
    } else {
        wgpu::TextureUsages::RENDER_ATTACHMENT
    };
    let shade = shade_pipelines(ctx, &module, &irr_layout, &irradiance, mono);
    let attachment = wgpu::TextureUsages::RENDER_ATTACHMENT;
    Ok(Box::new(LightPrepass {
        mono,
        samples,
        attributes,
        irradiance,
        shade,
        attr_view: target(
            device,
            "attributes (normal, shininess)",
            size,
            samples,
            attachment,
        ),
        specular_attr_view: multisampled_texture(
            device,
            "attributes (specular colour)",
            SPECULAR_FORMAT,
            size,
            samples,
            attachment | wgpu::TextureUsages::TEXTURE_BINDING,
        )
        .create_view(&Default::default()),
        diffuse_view: target(device, "diffuse irradiance", size, samples, written),
        specular_view: (!mono)
            .then(|| target(device, "specular irradiance", size, samples, attachment)),
        attr_layout,
        irr_layout,
    }))
}

pub(super) fn create_full(ctx: &PipelineContext) -> Result<Box<dyn Technique>> {
    create(ctx, Mode::Full)
}

pub(super) fn create_mono(ctx: &PipelineContext) -> Result<Box<dyn Technique>> {
    create(ctx, Mode::Mono)
}

pub(super) fn create_tiled(ctx: &PipelineContext) -> Result<Box<dyn Technique>> {
    create(ctx, Mode::Tiled)
}

/// A group of texture views by binding.
fn bind_views(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    views: &[&wgpu::TextureView],
) -> wgpu::BindGroup {
    let entries: Vec<_> = (0u32..)
        .zip(views)
        .map(|(binding, view)| wgpu::BindGroupEntry {
            binding,
            resource: wgpu::BindingResource::TextureView(view),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout,
        entries: &entries,
    })
}

impl LightPrepass {
    /// Pass 2 of the tiled variant: the grid, the irradiance kernel, and with MSAA the pass
    /// expanding its samples (and marking the edges) into the multisampled target.
    fn encode_tiled(
        &mut self,
        f: &FrameInputs,
        enc: &mut FrameEncoder,
        attr_group: &wgpu::BindGroup,
    ) -> Result<()> {
        let Irradiance::Tiled {
            builder,
            kernel,
            outputs_layout,
            msaa,
        } = &mut self.irradiance
        else {
            unreachable!("the tiled variant's irradiance")
        };
        builder.encode(f, enc)?;
        let outputs = match msaa {
            Some(_) => None,
            None => Some(crate::passes::compute_outputs_to(
                f.device,
                outputs_layout,
                &self.diffuse_view,
                &f.targets.counts,
            )),
        };
        let (encoder, timer) = enc.parts();
        {
            let label = "tiled irradiance (mono specular)";
            let mut pass = timer.begin_compute(encoder, label);
            pass.set_pipeline(kernel);
            pass.set_bind_group(0, f.scene_bind_group, &[]);
            pass.set_bind_group(1, builder.bind_group(), &[]);
            pass.set_bind_group(2, attr_group, &[]);
            let group3 = match (&outputs, msaa.as_deref()) {
                (Some(outputs), _) => outputs,
                (None, Some(m)) => &m.kernel_group,
                (None, None) => unreachable!("outputs without MSAA"),
            };
            pass.set_bind_group(3, group3, &[]);
            pass.dispatch_workgroups(
                f.targets.width.div_ceil(SCREEN_WORKGROUP),
                f.targets.height.div_ceil(SCREEN_WORKGROUP),
                1,
            );
        }
        if let Some(m) = msaa.as_deref() {
            let copy_group = m.volumes.copy_bind_group(f.device, &f.targets.depth);
            let label = "msaa irradiance expand";
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(label),
                color_attachments: &[Some(cleared(&self.diffuse_view, wgpu::Color::TRANSPARENT))],
                depth_stencil_attachment: Some(m.volumes.kept_attachment()),
                timestamp_writes: timer.render_pass(label),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            m.volumes
                .draw_depth_copy(&mut pass, f.scene_bind_group, &m.copy, &copy_group);
            pass.set_bind_group(1, &m.expand_group, &[]);
            pass.set_bind_group(2, attr_group, &[]);
            m.volumes
                .draw_fullscreen(&mut pass, &m.expand, Shading::PerPixel);
            m.volumes.mark_edges(&mut pass, &m.mark_edges);
        }
        Ok(())
    }

    /// Pass 2 with light volumes: the depth copy, (MSAA) the edge marks, then per shading the
    /// counting draw and each volume class blending in.
    fn encode_volumes(
        &mut self,
        f: &FrameInputs,
        enc: &mut FrameEncoder,
        attr_group: &wgpu::BindGroup,
    ) -> Result<()> {
        let LightPrepass {
            irradiance,
            mono,
            samples,
            diffuse_view,
            specular_view,
            ..
        } = self;
        let Irradiance::Volumes {
            volumes,
            copy,
            mark_edges,
            shaders,
        } = irradiance
        else {
            unreachable!("called for the volume variants only")
        };
        let classes = classify_lights(&f.setup, f.lights, false);
        // With re-used shadow maps, each shadowed light is drawn alone after its maps.
        let (together, alone) = match f.reused_shadow_maps {
            Some(maps) => classes.split(|i| maps.casts(i), f.lights),
            None => (classes, Default::default()),
        };
        volumes.upload_split(f.device, f.queue, &together, &alone);
        let alone = volumes.shadowed();
        let copy_group = volumes.copy_bind_group(f.device, &f.targets.depth);
        let label = if *mono {
            "irradiance (mono specular)"
        } else {
            "irradiance"
        };
        let (encoder, timer) = enc.parts();
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &[
                Some(cleared(diffuse_view, wgpu::Color::TRANSPARENT)),
                specular_view
                    .as_ref()
                    .map(|v| cleared(v, wgpu::Color::TRANSPARENT)),
                counts_in_target(f.count_blend, *samples)
                    .then(|| cleared(&f.targets.counts, wgpu::Color::TRANSPARENT)),
            ],
            depth_stencil_attachment: Some(volumes.kept_attachment()),
            timestamp_writes: timer.render_pass(label),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        volumes.draw_depth_copy(&mut pass, f.scene_bind_group, &*copy, &copy_group);
        pass.set_bind_group(2, attr_group, &[]);
        if let Some(mark) = mark_edges {
            volumes.mark_edges(&mut pass, mark);
        }
        for s in shaders.iter() {
            if let Some(count) = &s.count {
                volumes.draw_fullscreen(&mut pass, count, s.shading);
            }
            for (pipeline, draw) in s.classes.iter().zip(CLASSES) {
                pass.set_pipeline(pipeline);
                volumes.draw(&mut pass, draw, s.shading);
            }
        }
        drop(pass);
        for (slot, instance, light) in alone {
            let maps = f.reused_shadow_maps.expect("split by them");
            maps.encode_light(encoder, f, light as usize);
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("irradiance (one shadowed light)"),
                color_attachments: &[
                    Some(loaded(diffuse_view)),
                    specular_view.as_ref().map(loaded),
                    counts_in_target(f.count_blend, *samples).then(|| loaded(&f.targets.counts)),
                ],
                depth_stencil_attachment: Some(volumes.reloaded_attachment()),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, f.scene_bind_group, &[]);
            pass.set_bind_group(2, attr_group, &[]);
            let class = LightVolumes::shadowed_class(slot);
            let k = CLASSES
                .iter()
                .position(|&c| c == class)
                .expect("no stencil class");
            for s in shaders.iter() {
                pass.set_pipeline(&s.classes[k]);
                volumes.draw_one(&mut pass, (slot, instance), class, s.shading);
            }
        }
        Ok(())
    }
}

impl Technique for LightPrepass {
    fn reuses_shadow_maps(&self) -> bool {
        matches!(self.irradiance, Irradiance::Volumes { .. })
    }

    fn encode(&mut self, f: &FrameInputs, enc: &mut FrameEncoder) -> Result<()> {
        let attr_group = bind_views(
            f.device,
            &self.attr_layout,
            &[&self.attr_view, &f.targets.depth, &self.specular_attr_view],
        );
        // Mono has no specular target; its shader reads only binding 0.
        let specular = self.specular_view.as_ref().unwrap_or(&self.diffuse_view);
        let irr_group = bind_views(f.device, &self.irr_layout, &[&self.diffuse_view, specular]);
        {
            let (encoder, timer) = enc.parts();
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("light pre-pass attributes"),
                color_attachments: &[
                    Some(cleared(&self.attr_view, wgpu::Color::TRANSPARENT)),
                    Some(cleared(&self.specular_attr_view, wgpu::Color::TRANSPARENT)),
                ],
                depth_stencil_attachment: Some(crate::passes::cleared_depth(&f.targets.depth)),
                timestamp_writes: timer.render_pass("light pre-pass attributes"),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.attributes);
            draw_scene(&mut pass, f, &[]);
        }
        match &mut self.irradiance {
            Irradiance::Volumes { .. } => self.encode_volumes(f, enc, &attr_group)?,
            Irradiance::Tiled { .. } => self.encode_tiled(f, enc, &attr_group)?,
        }
        // Pass 3 tests the kept copy where there is one (its stencil holds the edge bits),
        // else the scene depth.
        let depth = match self.irradiance.copy() {
            Some(copy) => copy.loaded_attachment(),
            None => crate::passes::loaded_depth(&f.targets.depth),
        };
        let (encoder, timer) = enc.parts();
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("light pre-pass shading"),
            color_attachments: &[Some(cleared(&f.targets.hdr, wgpu::Color::BLACK))],
            depth_stencil_attachment: Some(depth),
            timestamp_writes: timer.render_pass("light pre-pass shading"),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        for (shading, pipeline) in &self.shade {
            pass.set_pipeline(pipeline);
            if self.irradiance.copy().is_some() {
                pass.set_stencil_reference(shading.edge_bit());
            }
            draw_scene(&mut pass, f, &[&irr_group]);
        }
        Ok(())
    }

    fn culler(&mut self) -> Option<&mut LightCuller> {
        match &mut self.irradiance {
            Irradiance::Tiled { builder, .. } => Some(builder.culler_mut()),
            Irradiance::Volumes { .. } => None,
        }
    }

    /// The tiled variant's grid lights the transparent objects too; the volume variants have
    /// none, so the pass builds one.
    fn transparent_lights(&self) -> TransparentLights<'_> {
        match &self.irradiance {
            Irradiance::Tiled { builder, .. } => TransparentLights::Grid(builder.culler()),
            Irradiance::Volumes { .. } => TransparentLights::Own,
        }
    }
}

/// Bytes of one attributes or irradiance target.
const TARGET_BYTES: u32 = 8;

/// Depth + attributes (normal and exponent, the blog's layout, and the specular colour) + two
/// irradiance targets + HDR + the volumes' depth-stencil copy (each per sample with MSAA).
/// Per pixel: attributes pass writes depth and attributes, the copy reads depth and writes the copy (kept: the shading pass tests its
/// depth and edge bit where the other pipelines test the scene depth), the shading pass reads
/// the irradiance and writes HDR. Per
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
        ("attributes (specular colour)", SPECULAR_BYTES),
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
            write_per_pixel: DEPTH_BYTES
                + TARGET_BYTES
                + SPECULAR_BYTES
                + VOLUME_DEPTH_BYTES
                + HDR_BYTES,
            read_per_pixel: DEPTH_BYTES + irr,
            write_per_lit: irr,
            read_per_lit: DEPTH_BYTES + TARGET_BYTES + SPECULAR_BYTES + irr + LIGHT_BYTES,
        },
    )
}

/// The tiled variant [And11]: depth, attributes (as above), one (mono) irradiance target and HDR, no
/// volume depth-stencil. Per pixel: the attributes pass writes depth and attributes, the
/// cell-bounds kernel reads depth, the irradiance kernel reads depth and attributes once and
/// writes the irradiance once, the shading pass reads it and writes HDR. Per lighting
/// computation: an index and a light, accumulated in registers (no blending). With MSAA the
/// kernel's per-sample irradiance buffer and the depth-stencil copy whose stencil marks the
/// edges for the shading pass are added (each per sample, as every target).
pub(super) fn memory_tiled(settings: &RenderSettings) -> MemoryModel {
    let mut targets = vec![
        ("depth", DEPTH_BYTES),
        ("attributes (normal, exponent)", TARGET_BYTES),
        ("attributes (specular colour)", SPECULAR_BYTES),
        ("irradiance (diffuse, mono specular)", TARGET_BYTES),
        ("hdr", HDR_BYTES),
    ];
    if settings.grid.samples > 1 {
        targets.extend([
            ("msaa sample irradiance", TARGET_BYTES),
            ("volume depth-stencil", VOLUME_DEPTH_BYTES),
        ]);
    }
    MemoryModel::new(
        &targets,
        Traffic {
            write_per_pixel: DEPTH_BYTES + 2 * TARGET_BYTES + SPECULAR_BYTES + HDR_BYTES,
            read_per_pixel: 2 * DEPTH_BYTES + 2 * TARGET_BYTES + SPECULAR_BYTES,
            write_per_lit: 0,
            read_per_lit: INDEX_BYTES + LIGHT_BYTES,
        },
    )
}
