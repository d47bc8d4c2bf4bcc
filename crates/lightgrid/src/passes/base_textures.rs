//! The scene's base-colour textures on the GPU (group 0, bindings 6 and 7): one 2D texture
//! array with a layer per texture, every texture resampled to one square power-of-two edge
//! (a texture array's layers share a size), sRGB so sampling decodes to linear, a full mip
//! chain built on the CPU, and a repeating trilinear sampler. A scene without textures binds
//! a single white texel.

use crate::consts::{MAX_TEXTURES, MAX_TEXTURE_EDGE};
use crate::scene::Texture;
use image::imageops::FilterType;
use wgpu::util::DeviceExt;

/// Budget of the whole array with its mips; the edge halves until it fits.
pub(crate) const MAX_TEXTURE_BYTES: u64 = 256 << 20;

pub(crate) const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// The scene's base-colour texture array and its samplers (see the module docs).
pub struct BaseTextures {
    /// `D2Array` view: one layer per texture, full mip chain (group 0, binding 5).
    pub view: wgpu::TextureView,
    /// Repeating trilinear sampler (group 0, binding 7).
    pub sampler: wgpu::Sampler,
    /// Nearest-texel magnification (a glTF sampler's `magFilter` NEAREST: pixel art).
    pub nearest: wgpu::Sampler,
    /// Bytes uploaded (every layer and mip).
    pub bytes: u64,
}

/// The layer edge for these textures: the power of two at or above the largest, at most
/// [`MAX_TEXTURE_EDGE`], halved until the array fits [`MAX_TEXTURE_BYTES`].
pub(crate) fn layer_edge(textures: &[Texture]) -> u32 {
    let largest = textures
        .iter()
        .map(|t| t.width.max(t.height))
        .max()
        .unwrap_or(1);
    let mut edge = largest.next_power_of_two().min(MAX_TEXTURE_EDGE);
    let bytes = |e: u32| u64::from(e) * u64::from(e) * 4 * textures.len() as u64 * 4 / 3;
    while edge > 1 && bytes(edge) > MAX_TEXTURE_BYTES {
        edge /= 2;
    }
    edge
}

/// The mip chain of one texture resampled to `edge` × `edge` (triangle filter, in sRGB
/// space), level 0 first, down to 1 × 1.
fn mips(t: &Texture, edge: u32) -> Vec<Vec<u8>> {
    let img = image::RgbaImage::from_raw(t.width, t.height, t.rgba.clone())
        .expect("validated: width × height × 4 bytes");
    let mut levels = Vec::new();
    let mut e = edge;
    loop {
        let level = if (t.width, t.height) == (e, e) {
            img.clone()
        } else {
            image::imageops::resize(&img, e, e, FilterType::Triangle)
        };
        levels.push(level.into_raw());
        if e == 1 {
            return levels;
        }
        e /= 2;
    }
}

impl BaseTextures {
    /// Upload `textures` (none: one white texel; `Scene::validate` bounds the count by
    /// `MAX_TEXTURES`).
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, textures: &[Texture]) -> Self {
        debug_assert!(textures.len() <= MAX_TEXTURES);
        let white = [Texture {
            width: 1,
            height: 1,
            rgba: vec![255; 4],
        }];
        let textures = if textures.is_empty() {
            &white[..]
        } else {
            textures
        };
        let edge = layer_edge(textures);
        let levels = edge.ilog2() + 1;
        // Layer-major, then mip: the order `create_texture_with_data` expects.
        let mut data = Vec::new();
        for t in textures {
            for level in mips(t, edge) {
                data.extend_from_slice(&level);
            }
        }
        let texture = device.create_texture_with_data(
            queue,
            &wgpu::TextureDescriptor {
                label: Some("base-colour textures"),
                size: wgpu::Extent3d {
                    width: edge,
                    height: edge,
                    depth_or_array_layers: textures.len() as u32,
                },
                mip_level_count: levels,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: FORMAT,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            &data,
        );
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let sampler = device.create_sampler(&sampler_descriptor());
        let nearest = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("base-colour sampler, nearest"),
            mag_filter: wgpu::FilterMode::Nearest,
            min_filter: wgpu::FilterMode::Nearest,
            ..sampler_descriptor()
        });
        BaseTextures {
            view,
            sampler,
            nearest,
            bytes: data.len() as u64,
        }
    }
}

/// The trilinear, repeating sampler (wrapping other than repeat is applied to the coordinates
/// in the shader).
fn sampler_descriptor() -> wgpu::SamplerDescriptor<'static> {
    wgpu::SamplerDescriptor {
        label: Some("base-colour sampler"),
        address_mode_u: wgpu::AddressMode::Repeat,
        address_mode_v: wgpu::AddressMode::Repeat,
        address_mode_w: wgpu::AddressMode::Repeat,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Linear,
        ..Default::default()
    }
}

/// The layout entries of binding 10, the nearest sampler, and 11, the same array again for
/// it (fragment stage): GLSL combines a texture with one sampler, so the GL backend cannot
/// sample one binding through two samplers.
pub(crate) fn nearest_layout_entries() -> [wgpu::BindGroupLayoutEntry; 2] {
    let [mut texture, mut sampler] = layout_entries();
    texture.binding = 11;
    sampler.binding = 10;
    [sampler, texture]
}

/// The layout entries of bindings 5 (the array) and 6 (the sampler), fragment stage.
pub(crate) fn layout_entries() -> [wgpu::BindGroupLayoutEntry; 2] {
    [
        wgpu::BindGroupLayoutEntry {
            binding: 5,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: true },
                view_dimension: wgpu::TextureViewDimension::D2Array,
                multisampled: false,
            },
            count: None,
        },
        wgpu::BindGroupLayoutEntry {
            binding: 6,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            count: None,
        },
    ]
}
