//! Depth read by fragment shaders (`depth_texels.wgsl`), for adapters that can neither copy
//! a depth texture to a buffer nor `textureLoad` one as depth (wgpu's GL backend, WebGL2):
//! the depth target bound as an unfilterable float texture (group 0 binding 0), drawn by a
//! full-screen triangle into a colour target.
//! - [`DepthTexelEntry::Bits`]: analysis's depth readback, each pixel's value into R32Uint;
//! - [`DepthTexelEntry::TileDepth`]: the texture grid's tile depth bounds, one texel per tile
//!   of the least and greatest depth of its samples (Rgba32Uint, f32 bits in x and y).

use crate::shader::{compose, parts, ComposedShader};

/// What a [`DepthTexelPass`] draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum DepthTexelEntry {
    Bits,
    TileDepth,
}

impl DepthTexelEntry {
    fn entry(self) -> &'static str {
        match self {
            DepthTexelEntry::Bits => "fs_depth_bits",
            DepthTexelEntry::TileDepth => "fs_tile_depth",
        }
    }

    /// The format of the target it draws into.
    pub fn format(self) -> wgpu::TextureFormat {
        match self {
            DepthTexelEntry::Bits => wgpu::TextureFormat::R32Uint,
            DepthTexelEntry::TileDepth => wgpu::TextureFormat::Rgba32Uint,
        }
    }
}

pub(crate) fn shader() -> ComposedShader {
    compose(
        "depth texels",
        &parts![super::FULLSCREEN_WGSL, include_str!("depth_texels.wgsl")],
    )
}

/// One full-screen pass reading the depth target in a fragment shader.
pub(crate) struct DepthTexelPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    label: &'static str,
}

impl DepthTexelPass {
    /// `tile`: the tile edge in pixels (`TileDepth`; ignored by `Bits`).
    pub fn new(device: &wgpu::Device, entry: DepthTexelEntry, tile: u32) -> Self {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("depth texels"),
            entries: &[super::texture_entry(
                0,
                wgpu::TextureSampleType::Float { filterable: false },
            )],
        });
        let label = match entry {
            DepthTexelEntry::Bits => "depth texels",
            DepthTexelEntry::TileDepth => "assign: tile depth (fragment)",
        };
        let constants = [(crate::shader::overrides::TILE, f64::from(tile))];
        let pipeline = super::fullscreen_pipeline(
            device,
            &super::FullscreenDesc {
                label,
                shader: &shader(),
                fragment_entry: entry.entry(),
                layout: &layout,
                target: entry.format(),
                samples: 1,
                constants: match entry {
                    DepthTexelEntry::Bits => &[],
                    DepthTexelEntry::TileDepth => &constants,
                },
            },
        );
        DepthTexelPass {
            pipeline,
            layout,
            label,
        }
    }

    /// Draw `depth` (a single-sample depth view) into `out` (a view of a texture of
    /// [`DepthTexelEntry::format`]: the frame's size for `Bits`, one texel per tile for
    /// `TileDepth`).
    pub fn draw(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        depth: &wgpu::TextureView,
        out: &wgpu::TextureView,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        super::draw_fullscreen(
            device,
            encoder,
            self.label,
            (&self.pipeline, &self.layout),
            depth,
            out,
            timestamp_writes,
        );
    }
}
