//! Putting a frame on the window: the renderer's display target (or a debug view's image)
//! drawn over the whole surface by one full-screen triangle, then the panel. The same drawing
//! into an offscreen texture of the surface's format gives the screenshot of exactly what the
//! window shows.

use anyhow::{Context, Result};

use lightgrid::passes::{
    draw_fullscreen, fullscreen_pipeline, texture_entry, FullscreenDesc, Readback,
};

const BLIT_WGSL: &str = r#"
override ENCODE_SRGB: bool = false;

@group(0) @binding(0) var source: texture_2d<f32>;

@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(i);
}

fn encode(c: f32) -> f32 {
    if c <= 0.0031308 { return c * 12.92; }
    return 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

@fragment
fn fs_blit(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    // One texel per pixel: the source has the surface's size (a resize recreates both).
    let dims = vec2<i32>(textureDimensions(source));
    let p = min(vec2<i32>(pos.xy), dims - vec2<i32>(1));
    let c = textureLoad(source, p, 0);
    if ENCODE_SRGB {
        return vec4<f32>(encode(c.r), encode(c.g), encode(c.b), 1.0);
    }
    return vec4<f32>(c.rgb, 1.0);
}
"#;

/// The full-screen copy of an sRGB source onto a surface of `format`.
pub struct Blit {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    pub format: wgpu::TextureFormat,
}

impl Blit {
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Blit {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("viewer blit"),
            entries: &[texture_entry(
                0,
                wgpu::TextureSampleType::Float { filterable: false },
            )],
        });
        // An sRGB surface encodes on write; a linear one gets the encoding from the shader,
        // so both show the display target's bytes.
        let constants = [("ENCODE_SRGB", if format.is_srgb() { 0.0 } else { 1.0 })];
        let shader = lightgrid::compose(
            "viewer blit",
            &[lightgrid::passes::FULLSCREEN_WGSL, BLIT_WGSL],
        );
        let pipeline = fullscreen_pipeline(
            device,
            &FullscreenDesc {
                label: "viewer blit",
                shader: &shader,
                fragment_entry: "fs_blit",
                layout: &layout,
                target: format,
                samples: 1,
                constants: &constants,
            },
        );
        Blit {
            pipeline,
            layout,
            format,
        }
    }

    /// Record the copy of `source` onto `target` (cleared first).
    pub fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        source: &wgpu::TextureView,
        target: &wgpu::TextureView,
    ) {
        draw_fullscreen(
            device,
            encoder,
            "viewer blit",
            (&self.pipeline, &self.layout),
            source,
            target,
            None,
        );
    }
}

/// A texture of the display format (`LDR_FORMAT`) holding a CPU image: a debug view.
pub fn upload_image(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    image: &image::RgbaImage,
) -> wgpu::TextureView {
    let (width, height) = image.dimensions();
    let size = wgpu::Extent3d {
        width,
        height,
        depth_or_array_layers: 1,
    };
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("debug view"),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: lightgrid::passes::LDR_FORMAT,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture: &texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        image.as_raw(),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(4 * width),
            rows_per_image: Some(height),
        },
        size,
    );
    texture.create_view(&Default::default())
}

/// An offscreen target of the surface's format the screenshot is drawn into.
pub struct Capture {
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
    width: u32,
    height: u32,
}

impl Capture {
    pub fn new(
        device: &wgpu::Device,
        format: wgpu::TextureFormat,
        (width, height): (u32, u32),
    ) -> Capture {
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("screenshot"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        Capture {
            texture,
            view,
            width,
            height,
        }
    }

    /// Wait for what was drawn and return it as RGBA (BGRA surfaces swizzled).
    pub fn read(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<image::RgbaImage> {
        let bytes =
            (self.copy(device, queue).read(device)).context("reading the screenshot back")?;
        Ok(self.image(bytes))
    }

    /// As [`Self::read`] without waiting (the web page): `done` gets the image, or why there
    /// is none, once the browser has mapped the copy.
    pub fn read_later(
        self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        done: impl FnOnce(std::result::Result<image::RgbaImage, String>) + wgpu::WasmNotSend + 'static,
    ) {
        let readback = self.copy(device, queue);
        readback.read_later(move |bytes| done(bytes.map(|b| self.image(b))));
    }

    /// Submit the copy of what was drawn into a readback buffer.
    fn copy(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Readback {
        let readback = Readback::new(device, "screenshot", self.width, self.height);
        let mut encoder = device.create_command_encoder(&Default::default());
        readback.encode(&mut encoder, &self.texture, wgpu::TextureAspect::All);
        queue.submit([encoder.finish()]);
        readback
    }

    /// The copied bytes as an opaque RGBA image (BGRA surfaces swizzled).
    fn image(&self, mut bytes: Vec<u8>) -> image::RgbaImage {
        let bgra = matches!(
            self.texture.format(),
            wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
        );
        for px in bytes.chunks_exact_mut(4) {
            if bgra {
                px.swap(0, 2);
            }
            px[3] = 255;
        }
        image::RgbaImage::from_raw(self.width, self.height, bytes).expect("size matches")
    }
}
