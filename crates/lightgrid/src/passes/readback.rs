//! Reading a 4-byte-per-pixel texture (display, counts, depth) back to the CPU.

use crate::error::Result;
use crate::gpu::read_buffer;

/// A MAP_READ buffer sized for one texture, with rows padded to the copy alignment.
pub struct Readback {
    buffer: wgpu::Buffer,
    width: u32,
    height: u32,
    padded_row: u32,
}

impl Readback {
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
        let bytes = read_buffer(device, &self.buffer)?;
        let row = (self.width * 4) as usize;
        Ok(bytes
            .chunks_exact(self.padded_row as usize)
            .flat_map(|r| r[..row].iter().copied())
            .collect())
    }

    /// As [`Self::read`], as 32-bit floats (depth or counts).
    pub fn read_f32(&self, device: &wgpu::Device) -> Result<Vec<f32>> {
        Ok(bytemuck::pod_collect_to_vec(&self.read(device)?))
    }
}
