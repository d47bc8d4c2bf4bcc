//! The viewer as a web page (wasm32 only): the same [`App`] on the browser's WebGPU, started
//! by the page crate (`crates/lightgrid-web`) from JavaScript. This file is the one seam
//! between the native viewer and the page:
//! - the GPU context is made asynchronously ([`GpuContext::for_page`]) and winit's event
//!   loop is handed to the browser (`spawn_app`), which calls back on each animation frame;
//! - there is no analysis worker (no threads) and nothing may wait for the GPU, so the
//!   debug views and analysis frames are native-only; the live counters of the real-time
//!   path (read back asynchronously) are shown as on native;
//! - screenshots are read back asynchronously into [`Shared`], where the page's JavaScript
//!   collects them as PNG files;
//! - GPU errors arrive late (a page's error scopes answer after the call), a frame after
//!   the change that caused them: the change is undone with its message, and the message is
//!   also written to the browser's console.

use super::*;
use lightgrid::gpu::DeviceLimits;
use std::cell::RefCell;
use std::collections::HashMap;

/// What the page asked for, from its address's query, e.g.
/// `?scene=robots-many&pipeline=clustered_forward&frame=130&size=320x240&paused`.
pub struct PageOptions {
    pub view: ViewOptions,
    /// `limits=adapter|webgpu`: the device gets the adapter's limits or WebGPU's defaults.
    pub limits: DeviceLimits,
}

impl PageOptions {
    /// Keys: `scene` (a catalog scene), `pipeline`, `frame`, `size` (`WxH`, the canvas's
    /// size in physical pixels), `tile`, `msaa`, `paused`, `limits` (`webgpu`, the
    /// default: WebGPU's default limits, what every browser offers; or `adapter`: the
    /// adapter's own), `script` (the viewer's
    /// `at N ACTION; ...`). An unknown key or a bad value is an error, never ignored.
    pub fn from_query(query: &str) -> Result<PageOptions> {
        let mut limits = DeviceLimits::WebGpu;
        let mut view = ViewOptions {
            adapter: None,
            request: SceneRequest::new("robots-many"),
            pipeline: "clustered_forward".into(),
            settings: RenderSettings::default(),
            size: None,
            frame: 0,
            paused: false,
            view: DebugView::Shaded,
            script: Vec::new(),
            exit_after_frames: None,
            screenshot: None,
        };
        for pair in query.trim_start_matches('?').split('&') {
            if pair.is_empty() {
                continue;
            }
            let (key, value) = pair.split_once('=').unwrap_or((pair, ""));
            let value = decode(value);
            let bad = |what: &str| anyhow!("the page's address: {key}={value}: {what}");
            match key {
                "scene" => {
                    lightgrid::scene::catalog::find(&value)?;
                    view.request = SceneRequest::new(&value);
                }
                "pipeline" => view.pipeline = pipelines::find(&value)?.id.to_string(),
                "frame" => view.frame = value.parse().map_err(|_| bad("not a frame number"))?,
                "size" => {
                    let (w, h) = value
                        .split_once('x')
                        .and_then(|(w, h)| Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?)))
                        .filter(|&(w, h)| (1..=8192).contains(&w) && (1..=8192).contains(&h))
                        .ok_or_else(|| bad("not WIDTHxHEIGHT, 1 to 8192 each"))?;
                    view.size = Some((w, h));
                }
                "tile" => {
                    view.settings.grid.tile_size = value.parse().map_err(|_| bad("not a tile size"))?
                }
                "msaa" => view.settings.grid.samples = value.parse().map_err(|_| bad("not 1 or 4"))?,
                "paused" => view.paused = true,
                "limits" => {
                    limits = match value.as_str() {
                        "webgpu" => DeviceLimits::WebGpu,
                        "adapter" => DeviceLimits::Adapter,
                        _ => return Err(bad("adapter or webgpu")),
                    }
                }
                "script" => {
                    view.script = crate::script::parse(&value).map_err(|e| bad(&e))?;
                }
                // A glTF file on the page's origin: the page's script fetches it and opens it
                // as a picked one (`open_file`).
                "gltf" if !value.is_empty() => {}
                "gltf" => return Err(bad("a path to a glTF file on this page's origin")),
                _ => bail!(
                    "the page's address: unknown key '{key}'; valid: scene, pipeline, frame, size, tile, msaa, paused, limits, script, gltf"
                ),
            }
        }
        view.settings
            .validate()
            .map_err(|e| anyhow!("the page's address: {e}"))?;
        Ok(PageOptions { view, limits })
    }
}

/// `%XX` and `+` of a query value.
fn decode(s: &str) -> String {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'+' => out.push(b' '),
            b'%' if i + 2 < bytes.len() => {
                let hex = std::str::from_utf8(&bytes[i + 1..i + 3]).ok();
                match hex.and_then(|h| u8::from_str_radix(h, 16).ok()) {
                    Some(b) => {
                        out.push(b);
                        i += 2;
                    }
                    None => out.push(b'%'),
                }
            }
            b => out.push(b),
        }
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// What the page's JavaScript reads and asks for. The app writes it once per frame
/// ([`App::publish`]); the page crate's exported functions read it between frames.
#[derive(Default)]
pub struct Shared {
    /// The app's state as JSON (`status()` in the page).
    pub status: String,
    /// Screenshots asked for by name, not yet queued.
    pub shot_requests: Vec<String>,
    /// Screenshots taken (PNG), or why not.
    pub shots: HashMap<String, Result<Vec<u8>, String>>,
    /// Where the panel's widgets are, in CSS pixels of the canvas ([x, y, w, h]):
    /// `pipeline` (the combo box), `pipeline:<id>` (its entries, while it is open) and
    /// `screenshot` (the button).
    pub spots: HashMap<String, [f32; 4]>,
    /// The error that ended the app, if one did.
    pub fatal: Option<String>,
    /// glTF files the page was given (its file picker, or dropped on it): name and bytes.
    pub files: Vec<(String, Vec<u8>)>,
    /// Screenshots the user took, for the page to download: file name and PNG.
    pub downloads: Vec<(String, Vec<u8>)>,
}

thread_local! {
    pub static SHARED: RefCell<Shared> = RefCell::default();
}

/// Write `message` to the browser's console as an error.
pub fn console_error(message: &str) {
    web_sys::console::error_1(&message.into());
}

/// Open the scene, make the GPU context and hand the app to the browser's event loop; the
/// page's canvas is appended to the document's body.
pub async fn start(opts: PageOptions) -> Result<()> {
    // A panic is a bug: the console says where, and the page shows it.
    std::panic::set_hook(Box::new(|info| {
        let message = format!("lightgrid panicked: {info}");
        console_error(&message);
        SHARED.with(|s| {
            if let Ok(mut s) = s.try_borrow_mut() {
                s.fatal = Some(message);
            }
        });
    }));
    let limits = opts.limits;
    let opts = opts.view;
    let opened = lightgrid::scene::open(&opts.request)?;
    opened.scene.check_frame(opts.frame)?;
    let ctx = GpuContext::for_page(limits).await?;
    let lost = Arc::new(Mutex::new(None::<String>));
    let flag = lost.clone();
    ctx.device.set_device_lost_callback(move |reason, message| {
        // Destroyed: the page is being left (the device is dropped with it), not lost.
        if reason == wgpu::DeviceLostReason::Destroyed {
            return;
        }
        if let Ok(mut l) = flag.lock() {
            *l = Some(format!("{reason:?}: {message}"));
        }
    });
    let event_loop =
        EventLoop::new().map_err(|e| anyhow!("starting the page's event loop: {e}"))?;
    // No analysis worker on the web: the job and answer channels stay open with nobody on
    // their other ends (the app sends no job there).
    let (jobs, job_rx) = mpsc::channel();
    let (done_tx, done) = mpsc::channel();
    std::mem::forget((job_rx, done_tx));
    // The native app shares its context with the analysis thread; on the web it is alone.
    #[allow(clippy::arc_with_non_send_sync)]
    let ctx = Arc::new(ctx);
    let app = App::new(ctx, opts, opened.scene, jobs, done, lost);
    use winit::platform::web::EventLoopExtWebSys;
    event_loop.spawn_app(app);
    Ok(())
}

impl App {
    /// Share the app's state with the page and take the screenshots it asked for.
    pub(super) fn publish(&mut self) {
        let spots = self
            .win
            .as_ref()
            .map(|w| crate::panel::spots(&w.egui.ctx))
            .unwrap_or_default();
        let requested = SHARED.with(|s| {
            let mut s = s.borrow_mut();
            let (w, h) = self
                .win
                .as_ref()
                .map(|w| w.renderer.size())
                .unwrap_or_default();
            s.status = serde_json::json!({
                "scene": self.scene.name,
                "pipeline": self.applied.pipeline,
                "draft": self.draft.pipeline,
                "frame": self.frame,
                "settled": self.settled,
                "pending": self.pending(Instant::now()),
                "width": w,
                "height": h,
                "adapter": self.report.adapter,
                "storage_buffers": self.ctx.device.limits().max_storage_buffers_per_shader_stage,
                "frames": self.report.frames,
                "message": self.message.clone().unwrap_or_default(),
                "screenshots_waiting": self.screenshots.len(),
            })
            .to_string();
            s.spots = spots;
            (
                std::mem::take(&mut s.shot_requests),
                std::mem::take(&mut s.files),
            )
        });
        let (requested, files) = requested;
        self.screenshots
            .extend(requested.into_iter().map(PathBuf::from));
        for (name, bytes) in files {
            self.open_file(name, bytes);
        }
    }

    /// Open a file the page was given, through the same loader as a path (`scene::open`,
    /// with the bytes in the request, so later changes reopen it too); a file that cannot
    /// be opened leaves the scene as it was, with the loader's message in the panel.
    fn open_file(&mut self, name: String, bytes: Vec<u8>) {
        if !lightgrid::scene::gltf::is_gltf_path(&name) {
            self.message = Some(format!(
                "{name}: not a glTF file (the page opens *.glb and *.gltf files)"
            ));
            return;
        }
        let mut next = self.applied.clone();
        next.request = SceneRequest {
            contents: Some(lightgrid::scene::FileContents(bytes.into())),
            ..SceneRequest::new(&name)
        };
        match self.apply(next) {
            Ok(()) => self.message = None,
            Err(e) => self.message = Some(e),
        }
    }

    /// The end of the app: kept for the page to show.
    pub(super) fn publish_fatal(&self, e: &anyhow::Error) {
        let message = format!("{e:#}");
        console_error(&format!("lightgrid: {message}"));
        SHARED.with(|s| s.borrow_mut().fatal = Some(message));
    }
}

/// Read `capture` back without waiting: the PNG (or the error) lands in [`Shared::shots`]
/// under `name` once the browser has mapped the buffer.
pub(super) fn read_later(ctx: &GpuContext, capture: Capture, name: String) {
    capture.read_later(&ctx.device, &ctx.queue, move |image| {
        let png = image.and_then(|image| {
            let mut png = Vec::new();
            image
                .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
                .map_err(|e| e.to_string())?;
            Ok(png)
        });
        SHARED.with(|s| {
            let mut s = s.borrow_mut();
            // A file name is a screenshot the user asked for (F12, P, the panel's button):
            // the page downloads it. Other names are the page script's.
            match (name.ends_with(".png"), png) {
                (true, Ok(png)) => {
                    let file = name.rsplit('/').next().unwrap_or(&name).to_string();
                    s.downloads.push((file, png));
                }
                (true, Err(e)) => console_error(&format!("lightgrid: screenshot {name}: {e}")),
                (false, png) => {
                    s.shots.insert(name, png);
                }
            }
        });
    });
}
