//! The frame's render targets and their formats: HDR colour, depth, the lighting-count
//! target and the sRGB display target every pipeline renders into.

/// HDR colour target every pipeline accumulates light into.
pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Scene depth buffer.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Display target: the tonemap pass writes linear values and the format encodes sRGB.
pub const LDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// Per-pixel lighting-computation counts: every lighting shader adds the number of times it
/// ran the light function for the sample (additive blending or a storage write), and the
/// renderer sums the target. 32-bit float holds integers exactly up to 2^24 per pixel.
pub(crate) const COUNT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// The MSAA sample counts the adapter offers for every multisampled target of a frame (HDR
/// colour, depth, and the G-buffer in `gbuffer`'s format), ascending; always has 1.
pub fn msaa_counts(ctx: &crate::gpu::GpuContext, gbuffer: super::GBufferFormat) -> Vec<u32> {
    ctx.sample_counts(&[HDR_FORMAT, DEPTH_FORMAT, gbuffer.texture_format()])
}

/// Refuse a sample count the adapter cannot render every target of a frame with.
pub fn check_msaa(
    ctx: &crate::gpu::GpuContext,
    samples: u32,
    gbuffer: super::GBufferFormat,
) -> crate::error::Result<()> {
    let counts = msaa_counts(ctx, gbuffer);
    if counts.contains(&samples) {
        return Ok(());
    }
    let list: Vec<String> = counts.iter().map(u32::to_string).collect();
    Err(crate::error::Error::invalid(
        "msaa",
        format!(
            "{samples} samples: this adapter ({}) supports {} for every target (with the {}-bit G-buffer)",
            ctx.info.name,
            list.join(", "),
            gbuffer.bits()
        ),
    ))
}

/// Does a frame count its lighting computations in the count target (`COUNT_FORMAT`)? Where
/// the adapter blends R32Float and without MSAA; with MSAA every pass adds into
/// the per-pixel counts after the frame counters (`gpu/counters.rs`) instead.
pub(crate) fn counts_in_target(count_blend: bool, samples: u32) -> bool {
    count_blend && samples == 1
}

/// A single-sample 2D texture of the frame's size.
pub(crate) fn render_texture(
    device: &wgpu::Device,
    label: &str,
    format: wgpu::TextureFormat,
    size: (u32, u32),
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    multisampled_texture(device, label, format, size, 1, usage)
}

/// A 2D texture of the frame's size with `samples` samples per pixel.
pub(crate) fn multisampled_texture(
    device: &wgpu::Device,
    label: &str,
    format: wgpu::TextureFormat,
    (width, height): (u32, u32),
    samples: u32,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: samples,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// A colour attachment cleared to `color` at the start of the pass and stored.
pub fn cleared(
    view: &wgpu::TextureView,
    color: wgpu::Color,
) -> wgpu::RenderPassColorAttachment<'_> {
    wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations {
            load: wgpu::LoadOp::Clear(color),
            store: wgpu::StoreOp::Store,
        },
    }
}

/// The scene depth attachment, cleared to the background (`depth::CLEAR`) and stored.
pub(crate) fn cleared_depth(
    view: &wgpu::TextureView,
) -> wgpu::RenderPassDepthStencilAttachment<'_> {
    wgpu::RenderPassDepthStencilAttachment {
        view,
        depth_ops: Some(wgpu::Operations {
            load: wgpu::LoadOp::Clear(crate::depth::CLEAR),
            store: wgpu::StoreOp::Store,
        }),
        stencil_ops: None,
    }
}

/// A colour attachment that keeps what the target holds (a pass drawing over an image).
pub fn loaded(view: &wgpu::TextureView) -> wgpu::RenderPassColorAttachment<'_> {
    wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations {
            load: wgpu::LoadOp::Load,
            store: wgpu::StoreOp::Store,
        },
    }
}

/// The depth target as an earlier pass left it (tested against, not cleared).
pub(crate) fn loaded_depth(view: &wgpu::TextureView) -> wgpu::RenderPassDepthStencilAttachment<'_> {
    wgpu::RenderPassDepthStencilAttachment {
        view,
        depth_ops: Some(wgpu::Operations {
            load: wgpu::LoadOp::Load,
            store: wgpu::StoreOp::Store,
        }),
        stencil_ops: None,
    }
}

/// The frame's render targets. With MSAA (`samples` > 1) HDR colour and depth hold every
/// sample; the tonemap pass resolves them into the single-sample display target, and the
/// lighting counts are added per pixel after the frame counters (a count target per sample would
/// count a fragment once per covered sample, or, blended, lose the samples failing the depth
/// test: a fragment shader runs once per pixel and primitive).
pub(crate) struct Targets {
    pub width: u32,
    pub height: u32,
    pub samples: u32,
    pub hdr: wgpu::TextureView,
    pub depth_texture: wgpu::Texture,
    pub depth: wgpu::TextureView,
    pub counts_texture: wgpu::Texture,
    pub counts: wgpu::TextureView,
    pub ldr_texture: wgpu::Texture,
    pub ldr: wgpu::TextureView,
}

impl Targets {
    /// Bytes per pixel of the shared targets (HDR colour and depth per sample, lighting
    /// counts, LDR); a pipeline's own (G-buffers) come on top.
    pub fn bytes_per_pixel(samples: u32) -> u64 {
        let bytes = |f: wgpu::TextureFormat| u64::from(f.block_copy_size(None).unwrap_or(4));
        u64::from(samples) * (bytes(HDR_FORMAT) + bytes(DEPTH_FORMAT))
            + bytes(COUNT_FORMAT)
            + bytes(LDR_FORMAT)
    }

    /// Where R32Float does not blend (`GpuContext::count_blend`), forward pipelines do not
    /// count into the count target (`counts_in_target`) and it is not a render attachment
    /// (GL cannot render into R32Float at all).
    pub fn new(ctx: &crate::gpu::GpuContext, width: u32, height: u32, samples: u32) -> Self {
        let (device, count_blend) = (&ctx.device, ctx.count_blend);
        let make =
            |label, format, usage| render_texture(device, label, format, (width, height), usage);
        let make_ms = |label, format, usage| {
            multisampled_texture(device, label, format, (width, height), samples, usage)
        };
        use wgpu::TextureUsages as U;
        // A multisampled texture can be neither a storage texture nor copied.
        let (hdr_usage, depth_usage) = if samples > 1 {
            (U::empty(), U::empty())
        } else {
            (U::STORAGE_BINDING, U::COPY_SRC)
        };
        let hdr = make_ms(
            "hdr",
            HDR_FORMAT,
            U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | hdr_usage,
        );
        let depth_texture = make_ms(
            "depth",
            DEPTH_FORMAT,
            U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | depth_usage,
        );
        let rendered = if count_blend {
            U::RENDER_ATTACHMENT
        } else {
            U::empty()
        };
        let counts_texture = make(
            "lighting counts",
            COUNT_FORMAT,
            rendered | U::STORAGE_BINDING | U::COPY_SRC,
        );
        // COPY_DST: the MSAA kernels' in-kernel resolve copies its colours in;
        // TEXTURE_BINDING: the viewer draws it onto its window.
        let ldr_texture = make(
            "ldr",
            LDR_FORMAT,
            U::RENDER_ATTACHMENT | U::COPY_SRC | U::COPY_DST | U::TEXTURE_BINDING,
        );
        Targets {
            width,
            height,
            samples,
            hdr: hdr.create_view(&Default::default()),
            depth: depth_texture.create_view(&Default::default()),
            depth_texture,
            counts: counts_texture.create_view(&Default::default()),
            counts_texture,
            ldr: ldr_texture.create_view(&Default::default()),
            ldr_texture,
        }
    }
}
