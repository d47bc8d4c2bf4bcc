//! The viewer's presentation: what the blit draws onto a surface-format target and the
//! screenshot reads back must be the display target's bytes, for sRGB and linear surfaces,
//! RGBA and BGRA orders, and sizes whose rows need padding.

use lightgrid::gpu::GpuContext;
use lightgrid_viewer::present::{upload_image, Blit, Capture};

fn gpu() -> GpuContext {
    // Under CI a missing adapter is a failure, never a skip.
    GpuContext::new(None).expect("a GPU adapter (lavapipe: mesa-vulkan-drivers)")
}

fn gradient(w: u32, h: u32) -> image::RgbaImage {
    image::RgbaImage::from_fn(w, h, |x, y| {
        image::Rgba([
            (x * 255 / w.max(2).saturating_sub(1).max(1)).min(255) as u8,
            (y * 255 / h.max(2).saturating_sub(1).max(1)).min(255) as u8,
            ((x * 7 + y * 13) % 256) as u8,
            255,
        ])
    })
}

#[test]
fn screenshot_equals_the_display_target_on_every_surface_format() {
    let ctx = gpu();
    for (w, h) in [(67, 33), (128, 96), (1, 1)] {
        let src = gradient(w, h);
        let view = upload_image(&ctx.device, &ctx.queue, &src);
        for format in [
            wgpu::TextureFormat::Rgba8UnormSrgb,
            wgpu::TextureFormat::Bgra8UnormSrgb,
            wgpu::TextureFormat::Rgba8Unorm,
            wgpu::TextureFormat::Bgra8Unorm,
        ] {
            let blit = Blit::new(&ctx.device, format);
            let capture = Capture::new(&ctx.device, format, (w, h));
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            blit.encode(&ctx.device, &mut encoder, &view, &capture.view);
            ctx.queue.submit([encoder.finish()]);
            let got = capture.read(&ctx.device, &ctx.queue).unwrap();
            assert_eq!(got.dimensions(), (w, h));
            let worst = src
                .pixels()
                .zip(got.pixels())
                .flat_map(|(a, b)| (0..3).map(move |i| a[i].abs_diff(b[i])))
                .max()
                .unwrap();
            // The sRGB encode in the shader (linear surfaces) may round one level off.
            assert!(
                worst <= 1,
                "{format:?} {w}x{h}: a channel differs by {worst}"
            );
        }
    }
}

#[test]
fn a_smaller_source_is_clamped_not_wrapped() {
    // After a resize the window may briefly be larger than the last frame: the blit repeats
    // the edge texels instead of reading out of bounds.
    let ctx = gpu();
    let src = gradient(8, 8);
    let view = upload_image(&ctx.device, &ctx.queue, &src);
    let format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let blit = Blit::new(&ctx.device, format);
    let capture = Capture::new(&ctx.device, format, (12, 10));
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    blit.encode(&ctx.device, &mut encoder, &view, &capture.view);
    ctx.queue.submit([encoder.finish()]);
    let got = capture.read(&ctx.device, &ctx.queue).unwrap();
    assert_eq!(got.get_pixel(11, 9), src.get_pixel(7, 7));
    assert_eq!(got.get_pixel(3, 9), src.get_pixel(3, 7));
    assert_eq!(got.get_pixel(2, 2), src.get_pixel(2, 2));
}
