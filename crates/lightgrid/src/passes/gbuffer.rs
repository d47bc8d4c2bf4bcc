//! The G-buffer pass and the group-2 bindings deferred compute passes read it through
//! (`gbuffer_read.wgsl` + the layout's specular piece). Four colour targets of four channels
//! (three in the mono-specular layout), 16-bit float by default or 32-bit (`--gbuffer 32`), as
//! tiled-shading §8 measures both; depth is the shared target.

use super::geometry::{draw_scene, geometry_pipeline, GeometryPipelineDesc};
use super::Targets;
use crate::frame::FrameInputs;
use crate::gpu::PassTimer;
use crate::scene::Shading;
use crate::shader::{compose, create_module, ComposedShader, SCENE_PARTS};

pub use crate::frame::GBufferFormat;

pub(crate) fn shader() -> ComposedShader {
    let mut parts = SCENE_PARTS.to_vec();
    parts.push(include_str!("gbuffer.wgsl"));
    compose("gbuffer", &parts)
}

/// The G-buffer's bindings and the reads both layouts share.
const GBUFFER_READ: &str = include_str!("gbuffer_read.wgsl");

/// WGSL a deferred pass includes to read the full G-buffer ([`GBufferLayout::Full`]).
pub(crate) const GBUFFER_READ_WGSL: &[&str] =
    &[GBUFFER_READ, include_str!("gbuffer_specular.wgsl")];

/// WGSL a deferred pass includes to read the mono-specular G-buffer.
pub const GBUFFER_READ_MONO_WGSL: &[&str] =
    &[GBUFFER_READ, include_str!("gbuffer_specular_mono.wgsl")];

/// The targets by location (and group-2 binding): normal + material, diffuse, specular +
/// exponent, the light-independent term.
const TARGET_NAMES: [&str; 4] = [
    "gbuffer normal",
    "gbuffer diffuse",
    "gbuffer specular",
    "gbuffer base",
];
/// The location of the specular target, which the mono-specular layout leaves out.
const SPECULAR: usize = 2;
/// The group-2 binding of the depth the G-buffer was rendered with.
const DEPTH_BINDING: u32 = 4;

/// What the G-buffer stores (deferred-shading-vs-deferred-lighting).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GBufferLayout {
    /// Normal + material, diffuse, specular colour + exponent, light-independent term.
    Full,
    /// The blog's fair counterpart of mono-specular deferred lighting: the specular albedo as
    /// one value in the diffuse target's alpha (`mono_albedo`), no specular target.
    MonoSpecular,
}

impl GBufferLayout {
    /// Every layout (the deferred shaders' keys).
    pub const ALL: [GBufferLayout; 2] = [GBufferLayout::Full, GBufferLayout::MonoSpecular];

    /// Colour targets written per pixel.
    pub fn targets(self) -> u32 {
        (0..TARGET_NAMES.len()).filter(|&l| self.has(l)).count() as u32
    }

    /// Targets a lighting computation reads (every one but the light-independent term).
    pub fn lit_reads(self) -> u32 {
        self.targets() - 1
    }

    /// The WGSL that reads this layout (group 2).
    pub fn read_wgsl(self) -> &'static [&'static str] {
        match self {
            GBufferLayout::Full => GBUFFER_READ_WGSL,
            GBufferLayout::MonoSpecular => GBUFFER_READ_MONO_WGSL,
        }
    }

    fn fragment_entry(self) -> &'static str {
        match self {
            GBufferLayout::Full => "fs_gbuffer",
            GBufferLayout::MonoSpecular => "fs_gbuffer_mono",
        }
    }

    fn has(self, location: usize) -> bool {
        location != SPECULAR || self == GBufferLayout::Full
    }
}

pub(crate) struct GBuffer {
    /// By location; `None` where the layout has no target.
    views: Vec<Option<wgpu::TextureView>>,
    pipeline: wgpu::RenderPipeline,
    pub read_layout: wgpu::BindGroupLayout,
}

impl GBuffer {
    pub fn new(
        device: &wgpu::Device,
        scene_layout: &wgpu::BindGroupLayout,
        format: GBufferFormat,
        layout: GBufferLayout,
        size: (u32, u32),
        samples: u32,
        shading: Shading,
    ) -> crate::error::Result<Self> {
        let tf = format.texture_format();
        // WebGPU's default limits allow 32 bytes of colour attachments per sample: the 16-bit
        // G-buffer's four targets; the 32-bit one asks for more (a refusal naming the limit,
        // never a validation error mid-frame).
        let targets = (0..TARGET_NAMES.len()).filter(|&l| layout.has(l)).count() as u32;
        let bytes = targets * format.bytes_per_target();
        let allowed = device.limits().max_color_attachment_bytes_per_sample;
        if bytes > allowed {
            return Err(crate::error::Error::invalid(
                "gbuffer",
                format!(
                    "the {}-bit G-buffer's {targets} targets need {bytes} bytes of colour attachments per sample; this device allows {allowed} (max_color_attachment_bytes_per_sample, 32 in WebGPU's default limits): use --gbuffer 16, or a device with the adapter's limits",
                    format.bits()
                ),
            ));
        }
        let views: Vec<Option<wgpu::TextureView>> = TARGET_NAMES
            .iter()
            .enumerate()
            .map(|(location, name)| {
                layout.has(location).then(|| {
                    super::multisampled_texture(
                        device,
                        name,
                        tf,
                        size,
                        samples,
                        wgpu::TextureUsages::RENDER_ATTACHMENT
                            | wgpu::TextureUsages::TEXTURE_BINDING,
                    )
                    .create_view(&Default::default())
                })
            })
            .collect();
        // The G-buffer pass evaluates no light, but reads the materials' inputs as `shading`
        // says.
        let module = create_module(device, &shader().specialized(shading));
        let targets: Vec<Option<wgpu::ColorTargetState>> = views
            .iter()
            .map(|v| v.as_ref().map(|_| tf.into()))
            .collect();
        let pipeline = geometry_pipeline(
            device,
            &GeometryPipelineDesc {
                label: "gbuffer",
                module: &module,
                fragment_entry: Some(layout.fragment_entry()),
                layouts: &[Some(scene_layout)],
                color_targets: &targets,
                depth_write: true,
                depth_compare: crate::depth::SURFACE,
                samples,
            },
        );
        Ok(GBuffer {
            read_layout: Self::read_layout(device, &views, samples),
            views,
            pipeline,
        })
    }

    /// Bindings 0-3 are the targets by location (those the layout has), 4 the depth.
    fn read_layout(
        device: &wgpu::Device,
        views: &[Option<wgpu::TextureView>],
        samples: u32,
    ) -> wgpu::BindGroupLayout {
        let tex =
            |binding, sample_type| super::sampled_texture_entry(binding, sample_type, samples);
        let float = wgpu::TextureSampleType::Float { filterable: false };
        let mut entries: Vec<wgpu::BindGroupLayoutEntry> = (0..)
            .zip(views)
            .filter(|(_, v)| v.is_some())
            .map(|(binding, _)| tex(binding, float))
            .collect();
        entries.push(tex(DEPTH_BINDING, wgpu::TextureSampleType::Depth));
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("gbuffer read (group 2)"),
            entries: &entries,
        })
    }

    /// Group 2 of a deferred pass: the G-buffer and the depth it was rendered with.
    pub fn read_bind_group(&self, device: &wgpu::Device, targets: &Targets) -> wgpu::BindGroup {
        let view = |binding, v| wgpu::BindGroupEntry {
            binding,
            resource: wgpu::BindingResource::TextureView(v),
        };
        let mut entries: Vec<wgpu::BindGroupEntry> = (0..)
            .zip(&self.views)
            .filter_map(|(binding, v)| Some(view(binding, v.as_ref()?)))
            .collect();
        entries.push(view(DEPTH_BINDING, &targets.depth));
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gbuffer read"),
            layout: &self.read_layout,
            entries: &entries,
        })
    }

    /// Rasterize the scene into the G-buffer and the depth target.
    pub fn encode(
        &self,
        f: &FrameInputs,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut PassTimer,
    ) {
        let attachments: Vec<Option<wgpu::RenderPassColorAttachment>> = self
            .views
            .iter()
            .map(|v| {
                Some(wgpu::RenderPassColorAttachment {
                    view: v.as_ref()?,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })
            })
            .collect();
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("gbuffer"),
            color_attachments: &attachments,
            depth_stencil_attachment: Some(crate::passes::cleared_depth(&f.targets.depth)),
            timestamp_writes: timer.render_pass("gbuffer"),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        draw_scene(&mut pass, f, &[]);
    }
}
