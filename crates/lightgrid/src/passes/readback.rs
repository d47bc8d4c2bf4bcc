//! Reading a 4-byte-per-pixel texture (display, counts, depth) back to the CPU.

use crate::error::Result;
use crate::gpu::read_buffer;
use crate::shader::{SampleStage, SamplesKey, ShaderKey};

/// A MAP_READ buffer sized for one texture, with rows padded to the copy alignment.
pub struct Readback {
    buffer: wgpu::Buffer,
    width: u32,
    height: u32,
    padded_row: u32,
}

impl Readback {
    /// A readback (buffer labelled `label`) for one `width` × `height` texture, 4 bytes a texel.
    pub fn new(device: &wgpu::Device, label: &str, width: u32, height: u32) -> Self {
        let padded_row = (width * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: u64::from(padded_row) * u64::from(height),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Readback {
            buffer,
            width,
            height,
            padded_row,
        }
    }

    /// Record the copy of `texture` (one aspect) into the buffer.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        texture: &wgpu::Texture,
        aspect: wgpu::TextureAspect,
    ) {
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &self.buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.padded_row),
                    rows_per_image: Some(self.height),
                },
            },
            wgpu::Extent3d {
                width: self.width,
                height: self.height,
                depth_or_array_layers: 1,
            },
        );
    }

    /// The texture's bytes, rows packed (waits for the GPU).
    pub fn read(&self, device: &wgpu::Device) -> Result<Vec<u8>> {
        Ok(self.packed(&read_buffer(device, &self.buffer)?))
    }

    /// As [`Self::read`] without waiting (the web page, where nothing may block): `done` gets
    /// the bytes, or why there are none, once the copy's submission is done and the buffer
    /// mapped (on native, when the device is next polled).
    pub fn read_later(
        self,
        done: impl FnOnce(std::result::Result<Vec<u8>, String>) + wgpu::WasmNotSend + 'static,
    ) {
        let buffer = self.buffer.clone();
        buffer.map_async(wgpu::MapMode::Read, .., move |mapped| {
            let bytes = mapped.map_err(|e| e.to_string()).and_then(|()| {
                let data = (self.buffer.get_mapped_range(..)).map_err(|e| e.to_string())?;
                let bytes = self.packed(&data);
                drop(data);
                self.buffer.unmap();
                Ok(bytes)
            });
            done(bytes);
        });
    }

    /// The rows of `bytes` (as copied, each padded) without their padding.
    fn packed(&self, bytes: &[u8]) -> Vec<u8> {
        let row = (self.width * 4) as usize;
        bytes
            .chunks_exact(self.padded_row as usize)
            .flat_map(|r| r[..row].iter().copied())
            .collect()
    }

    /// As [`Self::read`], as 32-bit floats (depth or counts).
    pub fn read_f32(&self, device: &wgpu::Device) -> Result<Vec<f32>> {
        Ok(bytemuck::pod_collect_to_vec(&self.read(device)?))
    }
}

/// A MAP_READ buffer for copies of a storage buffer's first `bytes`.
pub(crate) struct BufferReadback {
    staging: wgpu::Buffer,
    bytes: u64,
}

impl BufferReadback {
    pub fn new(device: &wgpu::Device, label: &str, bytes: u64) -> Self {
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: bytes.max(4),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        BufferReadback { staging, bytes }
    }

    /// Record the copy of `source`'s first bytes.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, source: &wgpu::Buffer) {
        self.encode_from(encoder, source, 0);
    }

    /// Record the copy of `source`'s bytes from `offset` on.
    pub fn encode_from(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        source: &wgpu::Buffer,
        offset: u64,
    ) {
        encoder.copy_buffer_to_buffer(source, offset, &self.staging, 0, self.bytes);
    }

    /// The copied words (waits for the GPU).
    pub fn read<T: bytemuck::Pod>(&self, device: &wgpu::Device) -> Result<Vec<T>> {
        Ok(bytemuck::pod_collect_to_vec(&read_buffer(
            device,
            &self.staging,
        )?))
    }
}

/// The copy of every sample of a depth target of `samples` samples per pixel.
pub(crate) type DepthSamplesKey = SamplesKey<DepthSamplesStage>;

pub(crate) enum DepthSamplesStage {}

impl SampleStage for DepthSamplesStage {
    const STAGE: &'static str = "depth_samples";

    fn parts(_samples: u32) -> Vec<&'static str> {
        vec![crate::shader::src::MSAA, include_str!("depth_samples.wgsl")]
    }
}

/// Analysis of an MSAA frame: every sample of the depth target, one plane per sample
/// (`depth_samples.wgsl`), read back.
pub(crate) struct DepthSamples {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    planes: wgpu::Buffer,
    readback: BufferReadback,
    size: (u32, u32),
    samples: u32,
}

impl DepthSamples {
    pub fn new(device: &wgpu::Device, (width, height): (u32, u32), samples: u32) -> Self {
        let shader = DepthSamplesKey::new(samples).shader();
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("depth samples"),
            entries: &[
                super::sampled_texture_entry(0, wgpu::TextureSampleType::Depth, samples),
                crate::gpu::buffer_entry(1, crate::gpu::STORAGE_RW),
            ],
        });
        let pipeline = crate::shader::compute_pipeline(
            device,
            "depth samples",
            &shader,
            "main",
            &[Some(&layout)],
        );
        let bytes = u64::from(width) * u64::from(height) * u64::from(samples) * 4;
        DepthSamples {
            pipeline,
            layout,
            planes: crate::gpu::storage_buffer(device, "depth samples", bytes),
            readback: BufferReadback::new(device, "depth samples readback", bytes),
            size: (width, height),
            samples,
        }
    }

    /// Record the copy of `depth` (a view of the frame's depth target).
    pub fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        depth: &wgpu::TextureView,
    ) {
        let group = crate::gpu::bind_resources(
            device,
            "depth samples",
            &self.layout,
            &[
                wgpu::BindingResource::TextureView(depth),
                self.planes.as_entire_binding(),
            ],
        );
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.dispatch_workgroups(self.size.0.div_ceil(8), self.size.1.div_ceil(8), 1);
        }
        self.readback.encode(encoder, &self.planes);
    }

    /// One plane of depth-buffer values per sample (waits for the GPU).
    pub fn read(&self, device: &wgpu::Device) -> Result<Vec<Vec<f32>>> {
        let all: Vec<f32> = self.readback.read(device)?;
        let plane = (self.size.0 * self.size.1) as usize;
        Ok(all
            .chunks_exact(plane)
            .take(self.samples as usize)
            .map(<[f32]>::to_vec)
            .collect())
    }
}

/// A single-sample depth target read back where it cannot be copied to a buffer (wgpu's GL
/// backend lacks `DownlevelFlags::DEPTH_TEXTURE_AND_BUFFER_COPIES`): drawn bit for bit into
/// an R32Uint target (`depth_texels.rs`), which is copied.
pub(crate) struct DepthBits {
    pass: super::depth_texels::DepthTexelPass,
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    readback: Readback,
}

impl DepthBits {
    pub fn new(device: &wgpu::Device, (width, height): (u32, u32)) -> Self {
        use super::depth_texels::{DepthTexelEntry, DepthTexelPass};
        let entry = DepthTexelEntry::Bits;
        let texture = crate::frame::targets::render_texture(
            device,
            "depth bits",
            entry.format(),
            (width, height),
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        DepthBits {
            pass: DepthTexelPass::new(device, entry, 1),
            view: texture.create_view(&Default::default()),
            texture,
            readback: Readback::new(device, "depth bits readback", width, height),
        }
    }

    /// Record the drawing of `depth` (the frame's depth target) and its copy.
    pub fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        depth: &wgpu::TextureView,
    ) {
        self.pass.draw(device, encoder, depth, &self.view, None);
        self.readback
            .encode(encoder, &self.texture, wgpu::TextureAspect::All);
    }

    /// The depth-buffer values (waits for the GPU).
    pub fn read(&self, device: &wgpu::Device) -> Result<Vec<f32>> {
        self.readback.read_f32(device)
    }
}
