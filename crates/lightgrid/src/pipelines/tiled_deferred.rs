//! `tiled_deferred`, `tiled_deferred_single` and `clustered_deferred`.
//!
//! tiled_deferred (tiled-shading §2, §6): 1. G-buffer pass; 2. per-tile depth bounds and the
//! tile grid (`LightCuller`, the strategy `--assign` names); 3. compute pass, one invocation
//! per sample: read the G-buffer once, loop the tile's lights in registers.
//! Groups: 0 scene, 1 grid, 2 G-buffer, 3 outputs.
//!
//! tiled_deferred_single (§7): 1. G-buffer pass; 2. one kernel, one workgroup per tile:
//! depth bounds, frustum culling of all lights into workgroup memory, shading (with MSAA
//! edge-aware, `tiled_deferred_single_msaa.wgsl`, writing the same outputs as the grid
//! pipelines' MSAA kernel).
//! Groups: 0 scene, 1 tile params, 2 G-buffer, 3 outputs.
//!
//! clustered_deferred (tiled-forward-shading §4.8): as tiled_deferred, but step 2 bounds each
//! (tile, view-depth slice) cluster by its own samples and assigns lights to the clusters that
//! hold samples; the shading kernel is the same, the accessor finds each sample's cluster.

use super::RenderSettings;
use super::{FrameEncoder, FrameInputs, PipelineContext, Technique, TransparentLights};
use crate::consts::{SCREEN_WORKGROUP, TILE_THREADS};
use crate::culling::TILE_DEPTH_WGSL;
use crate::culling::{GridDims, LightCuller};
use crate::error::Result;
use crate::frame::CullConfig;
use crate::frame::MsaaResolve;
use crate::memory::{MemoryModel, Traffic, DEPTH_BYTES, HDR_BYTES, INDEX_BYTES, LIGHT_BYTES};
use crate::passes::{
    compute_outputs, compute_outputs_layout, GBuffer, GBufferLayout, COMPUTE_OUTPUTS_WGSL,
    GBUFFER_READ_WGSL,
};
use crate::shader::{
    compute_pipeline, compute_pipeline_with, every_sample_count, msaa_defs, overrides, parts, src,
    ComposedShader, Def, SampleStage, SamplesKey, ShaderKey,
};

/// Which deferred shading kernel: the grid pipelines' (`tiled_deferred`, `clustered_deferred`:
/// the light grid read in group 1) or the single kernel's (its own tile culling inside).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kernel {
    Grid,
    Single,
}

/// A deferred shading kernel over the G-buffer for `samples` samples per pixel: at one, one
/// sample per invocation with storage-texture outputs (`tiled_deferred.wgsl`,
/// `tiled_deferred_single.wgsl`); above, the edge-aware kernel (the edge test, the edge queue,
/// the per-sample outputs: `tiled_deferred_msaa.wgsl`, `tiled_deferred_single_msaa.wgsl`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct KernelKey {
    pub kernel: Kernel,
    pub samples: u32,
    /// The grid kernel's light loop (the single kernel culls and loops its own way: `Lane`).
    pub light_loop: crate::frame::LightLoop,
}

impl ShaderKey for KernelKey {
    const STAGE: &'static str = "tiled_deferred";

    fn all() -> Vec<Self> {
        use crate::frame::LightLoop;
        let loops = |kernel| match kernel {
            Kernel::Grid => LightLoop::ALL.to_vec(),
            Kernel::Single => vec![LightLoop::Lane],
        };
        [Kernel::Grid, Kernel::Single]
            .into_iter()
            .flat_map(|kernel| {
                loops(kernel).into_iter().flat_map(move |light_loop| {
                    every_sample_count().map(move |samples| Self {
                        kernel,
                        samples,
                        light_loop,
                    })
                })
            })
            .collect()
    }

    fn defs(self) -> Vec<Def> {
        msaa_defs(self.samples)
    }

    fn parts(self) -> Vec<&'static str> {
        let mut parts = parts![
            src::TYPES,
            src::GRID_PARAMS,
            src::SCENE_BINDINGS,
            src::LIGHTING,
            src::MSAA,
            GBUFFER_READ_WGSL,
        ];
        match self.kernel {
            Kernel::Grid => parts.extend(parts![
                src::LIGHT_GRID,
                super::light_loop_wgsl(self.light_loop)
            ]),
            Kernel::Single => parts.extend(parts![
                TILE_DEPTH_WGSL,
                crate::culling::LIGHT_CULL_SCENE_WGSL,
                crate::culling::TILE_FRUSTUM_WGSL
            ]),
        }
        if self.samples == 1 {
            parts.push(COMPUTE_OUTPUTS_WGSL);
            parts.push(match self.kernel {
                Kernel::Grid => include_str!("tiled_deferred.wgsl"),
                Kernel::Single => include_str!("tiled_deferred_single.wgsl"),
            });
        } else {
            parts.extend(parts![
                crate::passes::MSAA_EDGES_WGSL,
                src::TONE,
                MSAA_EDGE_QUEUE_WGSL,
                MSAA_SAMPLE_OUTPUTS_WGSL,
                match self.kernel {
                    Kernel::Grid => include_str!("tiled_deferred_msaa.wgsl"),
                    Kernel::Single => include_str!("tiled_deferred_single_msaa.wgsl"),
                },
            ]);
        }
        parts
    }
}

/// Every value of [`KernelKey`] of `kernel`.
fn kernel_shaders(kernel: Kernel) -> Vec<ComposedShader> {
    KernelKey::all()
        .into_iter()
        .filter(|k| k.kernel == kernel)
        .map(KernelKey::shader)
        .collect()
}

pub(super) fn shaders() -> Vec<ComposedShader> {
    let mut out = kernel_shaders(Kernel::Grid);
    out.extend(ExpandKey::all_shaders());
    out
}

pub(super) fn shaders_single() -> Vec<ComposedShader> {
    let mut out = kernel_shaders(Kernel::Single);
    out.extend(ExpandKey::all_shaders());
    out
}

/// The MSAA kernels' outputs (group 3 of `SampleOutputs`), shared by the grid and the single
/// kernel.
const MSAA_SAMPLE_OUTPUTS_WGSL: &str = include_str!("msaa_sample_outputs.wgsl");
/// The edge-aware kernels' queue of edge samples and counts (also the tiled light pre-pass's).
pub(super) const MSAA_EDGE_QUEUE_WGSL: &str = include_str!("msaa_edge_queue.wgsl");

/// The pass writing the MSAA kernel's per-sample colours into the multisampled HDR target:
/// only above one sample per pixel.
pub(super) type ExpandKey = SamplesKey<ExpandStage>;

pub(super) enum ExpandStage {}

impl SampleStage for ExpandStage {
    const STAGE: &'static str = "sample_expand";

    // Only above one sample per pixel (a 1x target needs no expansion).
    fn requested(samples: u32) -> bool {
        samples > 1
    }

    fn parts(_samples: u32) -> Vec<&'static str> {
        vec![
            crate::passes::FULLSCREEN_WGSL,
            src::MSAA,
            include_str!("sample_expand.wgsl"),
        ]
    }
}

enum Variant {
    /// Multi-pass: grid + shading kernel.
    Multi {
        builder: Box<super::PipelineGrid>,
        label: &'static str,
    },
    /// Single kernel; group 1 holds the tile size.
    Single {
        params: wgpu::Buffer,
        params_group: wgpu::BindGroup,
    },
}

/// Where the shading kernel writes.
enum Outputs {
    /// The HDR and count targets as storage textures (group 3, `compute_outputs.wgsl`).
    Targets(wgpu::BindGroupLayout),
    /// MSAA: the per-sample colour buffer (group 3 of the kernel), and the pass that writes
    /// it into the multisampled HDR target.
    Samples(SampleOutputs),
}

struct SampleOutputs {
    kernel_group: wgpu::BindGroup,
    expand: wgpu::RenderPipeline,
    expand_group: wgpu::BindGroup,
    /// The in-kernel resolve's display colours (`--msaa-resolve kernel`), copied into the
    /// display target.
    resolved: wgpu::Texture,
    /// The kernel variant resolving inside (Trick 1), and whether the last frame used it.
    resolving_kernel: Option<wgpu::ComputePipeline>,
    resolved_last: bool,
}

impl SampleOutputs {
    /// The kernel's group-3 layout and the outputs of a `w` x `h` frame of `samples` samples.
    fn new(
        device: &wgpu::Device,
        (w, h): (u32, u32),
        samples: u32,
    ) -> (wgpu::BindGroupLayout, Self) {
        use crate::gpu::{bind_resources, STORAGE_RW};
        let buffer = crate::gpu::storage_buffer(
            device,
            "msaa sample colours",
            u64::from(w) * u64::from(h) * u64::from(samples) * 8,
        );
        let resolved = crate::passes::render_texture(
            device,
            "msaa resolved in kernel",
            wgpu::TextureFormat::Rgba8Unorm,
            (w, h),
            wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
        );
        let kernel_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("msaa kernel outputs (group 3)"),
            entries: &[
                crate::gpu::buffer_entry(0, STORAGE_RW),
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format: wgpu::TextureFormat::Rgba8Unorm,
                        view_dimension: wgpu::TextureViewDimension::D2,
                    },
                    count: None,
                },
            ],
        });
        let resolved_view = resolved.create_view(&Default::default());
        let kernel_group = bind_resources(
            device,
            "msaa kernel outputs",
            &kernel_layout,
            &[
                buffer.as_entire_binding(),
                wgpu::BindingResource::TextureView(&resolved_view),
            ],
        );
        let expand_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sample expand"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: true },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let expand_group = bind_resources(
            device,
            "sample expand",
            &expand_layout,
            &[buffer.as_entire_binding()],
        );
        let expand = crate::passes::fullscreen_pipeline(
            device,
            &crate::passes::FullscreenDesc {
                label: "sample expand",
                shader: &ExpandKey::new(samples).shader(),
                fragment_entry: "fs_expand",
                layout: &expand_layout,
                target: crate::passes::HDR_FORMAT,
                samples,
                constants: &[(overrides::WIDTH, f64::from(w))],
            },
        );
        (
            kernel_layout,
            SampleOutputs {
                kernel_group,
                expand,
                expand_group,
                resolved,
                resolving_kernel: None,
                resolved_last: false,
            },
        )
    }

    /// The in-kernel resolve's colours into the display target.
    fn encode_copy(&self, f: &FrameInputs, enc: &mut FrameEncoder) {
        let (encoder, _) = enc.parts();
        encoder.copy_texture_to_texture(
            self.resolved.as_image_copy(),
            f.targets.ldr_texture.as_image_copy(),
            self.resolved.size(),
        );
    }

    /// The per-sample colours into the multisampled HDR target.
    fn encode_expand(&self, f: &FrameInputs, enc: &mut FrameEncoder) {
        let (encoder, timer) = enc.parts();
        let label = "msaa sample expand";
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &[Some(crate::passes::cleared(
                &f.targets.hdr,
                wgpu::Color::BLACK,
            ))],
            depth_stencil_attachment: None,
            timestamp_writes: timer.render_pass(label),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.expand);
        pass.set_bind_group(0, &self.expand_group, &[]);
        pass.draw(0..3, 0..1);
    }
}

/// The shading kernel's group-3 layout and outputs: the targets, or with MSAA the per-sample
/// colours.
fn kernel_outputs(
    device: &wgpu::Device,
    (w, h): (u32, u32),
    samples: u32,
) -> (wgpu::BindGroupLayout, Outputs) {
    if samples > 1 {
        let (layout, outputs) = SampleOutputs::new(device, (w, h), samples);
        (layout, Outputs::Samples(outputs))
    } else {
        let layout = compute_outputs_layout(device);
        (layout.clone(), Outputs::Targets(layout))
    }
}

struct TiledDeferred {
    gbuffer: GBuffer,
    outputs: Outputs,
    shading: wgpu::ComputePipeline,
    variant: Variant,
    dims: GridDims,
}

pub(super) fn create_multi(ctx: &PipelineContext) -> Result<Box<dyn Technique>> {
    create_grid(ctx, 1, "tiled deferred shading")
}

pub(super) fn create_clustered(ctx: &PipelineContext) -> Result<Box<dyn Technique>> {
    create_grid(ctx, ctx.settings.grid.slices, "clustered deferred shading")
}

fn create_grid(
    ctx: &PipelineContext,
    slices: u32,
    label: &'static str,
) -> Result<Box<dyn Technique>> {
    let (w, h) = (ctx.dims.width, ctx.dims.height);
    let samples = ctx.settings.grid.samples;
    let gbuffer = GBuffer::new(
        ctx.device,
        ctx.scene_layout,
        ctx.settings.gbuffer,
        GBufferLayout::Full,
        (w, h),
        samples,
        ctx.shading,
    )?;
    let builder = ctx.grid(
        &CullConfig {
            slices,
            ..ctx.settings.grid
        },
        true,
        false,
    )?;
    let (outputs_layout, mut outputs) = kernel_outputs(ctx.device, (w, h), samples);
    let layouts = [
        Some(ctx.scene_layout),
        Some(builder.bind_group_layout()),
        Some(&gbuffer.read_layout),
        Some(&outputs_layout),
    ];
    let kernel = KernelKey {
        kernel: Kernel::Grid,
        samples,
        light_loop: ctx.settings.light_loop,
    }
    .shader()
    .specialized(ctx.shading);
    let shading = compute_pipeline(
        ctx.device,
        "tiled deferred shading",
        &kernel,
        "main",
        &layouts,
    );
    if let (Outputs::Samples(o), MsaaResolve::Kernel) = (&mut outputs, ctx.settings.msaa_resolve) {
        o.resolving_kernel = Some(compute_pipeline_with(
            ctx.device,
            "tiled deferred shading (resolve in kernel)",
            &kernel,
            "main",
            &layouts,
            &[(overrides::RESOLVE_IN_KERNEL, 1.0)],
        ));
    }
    Ok(Box::new(TiledDeferred {
        gbuffer,
        outputs,
        shading,
        variant: Variant::Multi {
            builder: Box::new(builder),
            label,
        },
        dims: ctx.dims,
    }))
}

pub(super) fn create_single(ctx: &PipelineContext) -> Result<Box<dyn Technique>> {
    let (w, h) = (ctx.dims.width, ctx.dims.height);
    let samples = ctx.settings.grid.samples;
    let gbuffer = GBuffer::new(
        ctx.device,
        ctx.scene_layout,
        ctx.settings.gbuffer,
        GBufferLayout::Full,
        (w, h),
        samples,
        ctx.shading,
    )?;
    let (outputs_layout, mut outputs) = kernel_outputs(ctx.device, (w, h), samples);
    let params_layout = ctx
        .device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("tile params"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
    let params = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("tile params"),
        size: std::mem::size_of::<crate::gpu_types::GridParams>() as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let params_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("tile params"),
        layout: &params_layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: params.as_entire_binding(),
        }],
    });
    let layouts = [
        Some(ctx.scene_culling_layout),
        Some(&params_layout),
        Some(&gbuffer.read_layout),
        Some(&outputs_layout),
    ];
    let kernel = KernelKey {
        kernel: Kernel::Single,
        samples,
        light_loop: crate::frame::LightLoop::Lane,
    }
    .shader()
    .specialized(ctx.shading);
    let shading = compute_pipeline(
        ctx.device,
        "tiled deferred single kernel",
        &kernel,
        "main",
        &layouts,
    );
    if let (Outputs::Samples(o), MsaaResolve::Kernel) = (&mut outputs, ctx.settings.msaa_resolve) {
        o.resolving_kernel = Some(compute_pipeline_with(
            ctx.device,
            "tiled deferred single kernel (resolve in kernel)",
            &kernel,
            "main",
            &layouts,
            &[(overrides::RESOLVE_IN_KERNEL, 1.0)],
        ));
    }
    Ok(Box::new(TiledDeferred {
        gbuffer,
        outputs,
        shading,
        variant: Variant::Single {
            params,
            params_group,
        },
        dims: ctx.dims,
    }))
}

impl Technique for TiledDeferred {
    fn encode(&mut self, f: &FrameInputs, enc: &mut FrameEncoder) -> Result<()> {
        let dims = self.dims;
        {
            let (encoder, timer) = enc.parts();
            self.gbuffer.encode(f, encoder, timer);
        }
        let read_group = self.gbuffer.read_bind_group(f.device, f.targets);
        let outputs = match &self.outputs {
            Outputs::Targets(layout) => compute_outputs(f.device, layout, f.targets),
            Outputs::Samples(s) => s.kernel_group.clone(),
        };
        // Trick 1 only where nothing blends over the samples after the kernel.
        let resolving = match &mut self.outputs {
            Outputs::Samples(s) => {
                s.resolved_last = s.resolving_kernel.is_some() && !f.has_transparency();
                s.resolving_kernel.as_ref().filter(|_| s.resolved_last)
            }
            Outputs::Targets(_) => None,
        };
        let shading = resolving.unwrap_or(&self.shading);
        // The single kernel culls in the kernel: its group 0 shows it the light bounds.
        let scene = match self.variant {
            Variant::Multi { .. } => f.scene_bind_group,
            Variant::Single { .. } => f.scene_culling_bind_group,
        };
        let (group1, label, groups) = match &mut self.variant {
            Variant::Multi { builder, label } => {
                builder.encode(f, enc)?;
                let groups = (
                    dims.width.div_ceil(SCREEN_WORKGROUP),
                    dims.height.div_ceil(SCREEN_WORKGROUP),
                );
                (builder.bind_group(), *label, groups)
            }
            Variant::Single {
                params,
                params_group,
            } => {
                f.queue
                    .write_buffer(params, 0, bytemuck::bytes_of(&dims.params()));
                // One workgroup per TILE_THREADS x TILE_THREADS block of a tile, so each
                // invocation shades one pixel (tiled_deferred_single.wgsl).
                let blocks = dims.tile_size.div_ceil(TILE_THREADS);
                (
                    &*params_group,
                    "tiled deferred single kernel",
                    (dims.tiles_x * blocks, dims.tiles_y * blocks),
                )
            }
        };
        let (encoder, timer) = enc.parts();
        let mut pass = timer.begin_compute(encoder, label);
        pass.set_pipeline(shading);
        pass.set_bind_group(0, scene, &[]);
        pass.set_bind_group(1, group1, &[]);
        pass.set_bind_group(2, &read_group, &[]);
        pass.set_bind_group(3, &outputs, &[]);
        pass.dispatch_workgroups(groups.0, groups.1, 1);
        drop(pass);
        if let Outputs::Samples(s) = &self.outputs {
            if s.resolved_last {
                s.encode_copy(f, enc);
            } else {
                s.encode_expand(f, enc);
            }
        }
        Ok(())
    }

    fn resolved_to_display(&self) -> bool {
        matches!(&self.outputs, Outputs::Samples(s) if s.resolved_last)
    }

    fn culler(&mut self) -> Option<&mut LightCuller> {
        match &mut self.variant {
            Variant::Multi { builder, .. } => Some(builder.culler_mut()),
            Variant::Single { .. } => None,
        }
    }

    /// The frame's grid for the transparent pass (tiled-shading §4); the single kernel has
    /// none, so the pass builds one.
    fn transparent_lights(&self) -> TransparentLights<'_> {
        match &self.variant {
            Variant::Multi { builder, .. } => TransparentLights::Grid(builder.culler()),
            Variant::Single { .. } => TransparentLights::Own,
        }
    }
}

/// Depth + four G-buffer targets + HDR; the shading kernel reads depth and the G-buffer once
/// per sample, the cell-bounds kernel depth once more; each lighting computation reads an
/// index and a light.
/// With MSAA the kernel's per-sample colours come on top (a per-sample buffer the size of
/// the HDR target).
pub(super) fn memory_multi(settings: &RenderSettings) -> MemoryModel {
    let g = settings.gbuffer.bytes_per_target();
    let mut targets = vec![
        ("depth", DEPTH_BYTES),
        ("gbuffer (4 targets)", 4 * g),
        ("hdr", HDR_BYTES),
    ];
    if settings.grid.samples > 1 {
        targets.push(("msaa sample colours", HDR_BYTES));
    }
    MemoryModel::new(
        &targets,
        Traffic {
            write_per_pixel: DEPTH_BYTES + 4 * g + HDR_BYTES,
            read_per_pixel: 2 * DEPTH_BYTES + 4 * g,
            write_per_lit: 0,
            read_per_lit: INDEX_BYTES + LIGHT_BYTES,
        },
    )
}

/// As `memory_multi`, but the tile's index list lives in workgroup memory.
pub(super) fn memory_single(settings: &RenderSettings) -> MemoryModel {
    let mut m = memory_multi(settings);
    m.traffic.read_per_lit = LIGHT_BYTES;
    m
}

/// As `memory_multi` (the cell-bounds kernel reads depth once, for any number of slices).
pub(super) fn memory_clustered(settings: &RenderSettings) -> MemoryModel {
    memory_multi(settings)
}
