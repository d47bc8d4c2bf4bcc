//! Tonemap: reads the HDR target, writes the sRGB display target (and resolves MSAA).
//! Bindings: group 0 binding 0 = HDR texture (textureLoad, no sampler).

use super::LDR_FORMAT;
use crate::gpu::PassTimer;
use crate::shader::{src, SampleStage, SamplesKey, ShaderKey};

/// The tonemap of an HDR target of `samples` samples per pixel (above one, it resolves).
pub(crate) type TonemapKey = SamplesKey<TonemapStage>;

pub(crate) enum TonemapStage {}

impl SampleStage for TonemapStage {
    const STAGE: &'static str = "tonemap";

    fn parts(_samples: u32) -> Vec<&'static str> {
        vec![
            super::FULLSCREEN_WGSL,
            src::MSAA,
            src::TONE,
            include_str!("tonemap.wgsl"),
        ]
    }
}

pub(crate) struct Tonemap {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

impl Tonemap {
    /// The tonemap of a frame with `samples` samples per pixel (above one, it resolves).
    pub fn new(device: &wgpu::Device, samples: u32) -> Self {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("tonemap"),
            entries: &[super::sampled_texture_entry(
                0,
                wgpu::TextureSampleType::Float { filterable: false },
                samples,
            )],
        });
        let pipeline = super::fullscreen_pipeline(
            device,
            &super::FullscreenDesc {
                label: "tonemap",
                shader: &TonemapKey::new(samples).shader(),
                fragment_entry: "fs_tonemap",
                layout: &layout,
                target: LDR_FORMAT,
                samples: 1,
                constants: &[],
            },
        );
        Tonemap { pipeline, layout }
    }

    pub fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut PassTimer,
        hdr: &wgpu::TextureView,
        out: &wgpu::TextureView,
    ) {
        super::draw_fullscreen(
            device,
            encoder,
            "tonemap",
            (&self.pipeline, &self.layout),
            hdr,
            out,
            timer.render_pass("tonemap"),
        );
    }
}
