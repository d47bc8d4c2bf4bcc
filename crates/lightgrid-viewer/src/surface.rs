//! The window's wgpu surface: made from the context's instance (which knows the window
//! system's display), configured at the window's size in an 8-bit format, and acquired each
//! frame with every non-fatal outcome recovered from: an outdated or suboptimal surface is
//! reconfigured, a lost one recreated, a timeout or an occluded (minimised) window skips
//! the frame. Only a validation error is fatal.

use anyhow::{bail, Context, Result};
use std::sync::Arc;
use winit::window::Window;

use lightgrid::gpu::GpuContext;

/// Formats the viewer can present, best first. egui draws in gamma space, so a linear 8-bit
/// format (the blit encodes sRGB itself) comes before the sRGB ones (which encode on write).
/// A browser prefers one of the two linear formats and warns when another is used (an extra
/// copy): its preference comes first there (`caps.formats[0]`).
const PREFERRED: [wgpu::TextureFormat; 4] = [
    wgpu::TextureFormat::Bgra8Unorm,
    wgpu::TextureFormat::Rgba8Unorm,
    wgpu::TextureFormat::Bgra8UnormSrgb,
    wgpu::TextureFormat::Rgba8UnormSrgb,
];

pub struct WindowSurface {
    surface: wgpu::Surface<'static>,
    pub config: wgpu::SurfaceConfiguration,
    window: Arc<Window>,
    /// The last texture was suboptimal: configure before the next is acquired (not while
    /// one is held, which wgpu refuses).
    reconfigure: bool,
}

/// What acquiring a frame gave.
pub enum Acquired {
    Frame(wgpu::SurfaceTexture),
    /// Nothing to draw on this time (minimised, occluded, timed out, just reconfigured).
    Skip,
}

fn create(ctx: &GpuContext, window: &Arc<Window>) -> Result<wgpu::Surface<'static>> {
    let surface = ctx
        .instance
        .create_surface(window.clone())
        .context("creating the window's GPU surface")?;
    if !ctx.adapter.is_surface_supported(&surface) {
        bail!(
            "the adapter {} cannot present to this window (choose another with --adapter; see `lightgrid list`)",
            ctx.adapter_label()
        );
    }
    Ok(surface)
}

impl WindowSurface {
    pub fn new(ctx: &GpuContext, window: Arc<Window>) -> Result<WindowSurface> {
        let surface = create(ctx, &window)?;
        let caps = surface.get_capabilities(&ctx.adapter);
        let preferred = caps.formats.first().copied();
        let format = (cfg!(target_arch = "wasm32")
            && preferred.is_some_and(|f| PREFERRED.contains(&f)))
        .then_some(preferred)
        .flatten()
        .or_else(|| PREFERRED.into_iter().find(|f| caps.formats.contains(f)))
        .with_context(|| {
            format!(
                "the window offers none of the 8-bit formats the viewer draws ({:?})",
                caps.formats
            )
        })?;
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            color_space: wgpu::SurfaceColorSpace::Auto,
            width: size.width.max(1),
            height: size.height.max(1),
            // Fifo is the one mode every surface has; the frame time shows the GPU work
            // unless it is faster than the display.
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes[0],
            view_formats: vec![],
        };
        let s = WindowSurface {
            surface,
            config,
            window,
            reconfigure: false,
        };
        if size.width > 0 && size.height > 0 {
            s.surface.configure(&ctx.device, &s.config);
        }
        Ok(s)
    }

    pub fn format(&self) -> wgpu::TextureFormat {
        self.config.format
    }

    /// The configured size.
    pub fn size(&self) -> (u32, u32) {
        (self.config.width, self.config.height)
    }

    /// Configure for the window's current size; false at zero size (minimised: draw nothing).
    pub fn resize(&mut self, ctx: &GpuContext) -> bool {
        let size = self.window.inner_size();
        if size.width == 0 || size.height == 0 {
            return false;
        }
        self.config.width = size.width;
        self.config.height = size.height;
        self.surface.configure(&ctx.device, &self.config);
        true
    }

    /// The next texture to draw on, recovering from what can be recovered from.
    pub fn acquire(&mut self, ctx: &GpuContext) -> Result<Acquired> {
        use wgpu::CurrentSurfaceTexture as C;
        let size = self.window.inner_size();
        if size.width == 0 || size.height == 0 {
            return Ok(Acquired::Skip);
        }
        if (size.width, size.height) != self.size() || self.reconfigure {
            self.reconfigure = false;
            self.resize(ctx);
        }
        Ok(match self.surface.get_current_texture() {
            C::Success(t) => Acquired::Frame(t),
            C::Suboptimal(t) => {
                // Draw this one; the next frame gets a reconfigured surface.
                self.reconfigure = true;
                Acquired::Frame(t)
            }
            C::Timeout | C::Occluded => Acquired::Skip,
            C::Outdated => {
                self.resize(ctx);
                Acquired::Skip
            }
            C::Lost => {
                self.surface = create(ctx, &self.window).context("recreating a lost surface")?;
                self.resize(ctx);
                Acquired::Skip
            }
            C::Validation => bail!("the window surface reported a validation error"),
        })
    }
}
