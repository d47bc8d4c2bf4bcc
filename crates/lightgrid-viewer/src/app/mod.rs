//! The window (`lightgrid view`): winit events in, one real-time frame per redraw out. This
//! file holds the state and the event handler; `settle.rs` what holds a scripted session and
//! how changes are applied, `frame.rs` one redraw, `after.rs` what follows a shown frame
//! (screenshots, leaving, analysis jobs), `input.rs` keys and the mouse.
//!
//! One redraw, in order:
//! 1. collect the analysis frames that came back (never waited for: [`crate::analysis`]);
//! 2. when nothing is pending, run the script steps that are due;
//! 3. apply the panel's draft once it has stopped changing ([`Controls::rebuild_for`] says
//!    whether that switches the pipeline, makes a renderer or reopens the scene); a change
//!    that fails is reverted with its message;
//! 4. follow the window's size (a new renderer once it has been still for [`SETTLE`]);
//! 5. move the fly camera, advance the animation, render on the real-time path
//!    (`Renderer::render_frame`: one submission, no wait) and collect finished frames'
//!    timings and counters;
//! 6. blit the display target (or the debug view's image) onto the surface, draw the panel,
//!    present;
//! 7. take queued screenshots, count the frame, send the next analysis job.
//!
//! "Pending" (a renderer not at the window's size yet, a draft not applied, a debug view
//! older than the state it shows) holds scripts, screenshots and `--exit-after-frames`, so a
//! scripted run captures exactly the state it asked for.

use crate::analysis::{Analysed, Done, Job};
use crate::controls::{refusal, Controls, Rebuild};
use crate::fly::{FlyCamera, Movement};
use crate::live::LiveFigures;
use crate::panel::{self, PanelAction, PanelInfo};
use crate::present::{upload_image, Blit, Capture};
use crate::script::{Action, Step};
use crate::surface::{Acquired, WindowSurface};
use anyhow::{anyhow, bail, Context, Result};
use lightgrid::debug_view::DebugView;
use lightgrid::frame::GBufferFormat;
use lightgrid::gpu::GpuContext;
use lightgrid::pipelines::{self, PIPELINES};
use lightgrid::scene::{Scene, SceneRequest};
use lightgrid::{FinishedFrame, RenderSettings, Renderer};
use std::collections::{HashSet, VecDeque};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver, Sender, TryRecvError};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use web_time::Instant;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, KeyEvent, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

mod after;
mod frame;
mod input;
mod settle;
#[cfg(target_arch = "wasm32")]
pub mod web;

/// A size must hold this long before the renderer is rebuilt for it (dragging a window edge
/// would otherwise make a renderer per pixel); meanwhile the blit clamps the old image.
pub const SETTLE: Duration = Duration::from_millis(100);
/// The panel's draft is applied once it has not changed for this long (a slider drag makes
/// one new scene, not one per step).
const DRAFT_SETTLE: Duration = Duration::from_millis(300);
/// A scripted run that stays pending this long has a step that cannot complete.
const SCRIPT_PATIENCE: Duration = Duration::from_secs(60);
/// Frames a screenshot waits for one whose lists did not overflow.
const MAX_SCREENSHOT_RETRIES: u32 = 10;
/// How long to wait before trying again when the surface gave no frame (occluded, timed
/// out): rendering unseen frames as fast as possible would only load the machine.
const SKIP_PAUSE: Duration = Duration::from_millis(16);
/// The smallest window the panel is drawn in.
const MIN_PANEL_WINDOW: (u32, u32) = (240, 160);
/// A debug view is refreshed this often while the animation plays.
const DEBUG_REFRESH: Duration = Duration::from_millis(250);

/// What `lightgrid view` asked for.
pub struct ViewOptions {
    pub adapter: Option<String>,
    pub request: SceneRequest,
    pub pipeline: String,
    pub settings: RenderSettings,
    /// The window's inner size in physical pixels (default: the scene's own size).
    pub size: Option<(u32, u32)>,
    /// The animation frame to start at.
    pub frame: u32,
    pub paused: bool,
    pub view: DebugView,
    pub script: Vec<Step>,
    /// Leave after this many settled frames (and the script's steps) are displayed.
    pub exit_after_frames: Option<u32>,
    /// Written when leaving after `exit_after_frames`.
    pub screenshot: Option<PathBuf>,
}

/// What a session did.
#[derive(Debug, Default)]
pub struct ViewReport {
    pub adapter: String,
    pub frames: u64,
    pub screenshots: Vec<PathBuf>,
    pub overflowed: u64,
    pub truncated: u64,
    /// Frames per second over the last second shown, and the mean GPU milliseconds of the
    /// newest frames (up to the live figures' history).
    pub fps: Option<f64>,
    pub gpu_ms: Option<f64>,
}

/// Open the window and run until it is closed, `Esc` is pressed or `exit_after_frames`
/// have been shown. (The page starts the same app with `web::start`.)
#[cfg(not(target_arch = "wasm32"))]
pub fn run(opts: ViewOptions) -> Result<ViewReport> {
    let opened = lightgrid::scene::open(&opts.request)?;
    for w in &opened.warnings {
        eprintln!("warning: {}: {w}", opts.request.spec);
    }
    opened.scene.check_frame(opts.frame)?;
    let event_loop = EventLoop::new().map_err(|e| {
        anyhow!(
            "cannot open a window: {e} (is a display available? set DISPLAY or WAYLAND_DISPLAY; \
             on a machine without one, run under Xvfb: `xvfb-run lightgrid view ...`)"
        )
    })?;
    event_loop.set_control_flow(ControlFlow::Wait);
    let display = event_loop.owned_display_handle();
    let ctx = GpuContext::with_display(Some(Box::new(display)), opts.adapter.as_deref())?;
    let lost = Arc::new(Mutex::new(None::<String>));
    let flag = lost.clone();
    ctx.device.set_device_lost_callback(move |reason, message| {
        if let Ok(mut l) = flag.lock() {
            *l = Some(format!("{reason:?}: {message}"));
        }
    });
    let (jobs, job_rx) = mpsc::channel();
    let (done_tx, done) = mpsc::channel();
    // Shared with the analysis worker; renderers own clones of its device and queue.
    let ctx = Arc::new(ctx);
    let worker_ctx = ctx.clone();
    std::thread::scope(|s| {
        s.spawn(move || crate::analysis::serve(&worker_ctx, job_rx, done_tx));
        let mut app = App::new(ctx, opts, opened.scene, jobs, done, lost);
        let ran = run_catching_display_loss(|| event_loop.run_app(&mut app));
        // Dropping the app drops the job sender, which ends the worker.
        let App {
            fatal,
            mut report,
            figures,
            ..
        } = app;
        report.fps = figures.fps();
        report.overflowed = figures.overflowed;
        report.truncated = figures.truncated;
        report.gpu_ms = LiveFigures::recent_mean(&figures.gpu_ms, crate::live::HISTORY);
        ran?.context("the window's event loop failed")?;
        match fatal {
            Some(e) => Err(e),
            None => Ok(report),
        }
    })
}

/// Run the event loop, turning the panic winit raises when the X server goes away (its X11
/// backend unwraps every request's reply: `Connection(IoError(..))`) into a "display lost"
/// error, with no panic message printed; any other panic goes on as a panic.
#[cfg(not(target_arch = "wasm32"))]
fn run_catching_display_loss<T>(run: impl FnOnce() -> T) -> Result<T> {
    fn message(payload: &(dyn std::any::Any + Send)) -> String {
        payload
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_default()
    }
    // The X11 connection's errors as winit's unwraps print them (x11rb's ConnectionError).
    fn display_gone(msg: &str) -> bool {
        msg.contains("Connection(") || msg.contains("ConnectionError") || msg.contains("IoError")
    }
    let previous = Arc::new(std::panic::take_hook());
    let chained = previous.clone();
    std::panic::set_hook(Box::new(move |info| {
        if !display_gone(&message(info.payload())) {
            chained(info);
        }
    }));
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(run));
    // Back to the hook the process had (the previous one is only shared with ours, now gone).
    drop(std::panic::take_hook());
    if let Ok(previous) = Arc::try_unwrap(previous) {
        std::panic::set_hook(previous);
    }
    match result {
        Ok(v) => Ok(v),
        Err(payload) if display_gone(&message(payload.as_ref())) => Err(anyhow!(
            "display lost: the connection to the display server failed ({})",
            message(payload.as_ref())
        )),
        Err(payload) => std::panic::resume_unwind(payload),
    }
}

/// The parts that exist while the window does.
struct Win {
    window: Arc<Window>,
    surface: WindowSurface,
    blit: Blit,
    egui: EguiLayer,
    renderer: Renderer,
    /// The debug view's image of the newest analysis result, on the GPU.
    debug_texture: Option<wgpu::TextureView>,
    size_changed_at: Option<Instant>,
}

struct EguiLayer {
    ctx: egui::Context,
    state: egui_winit::State,
    renderer: egui_wgpu::Renderer,
}

/// The analysis frames: at most one in flight.
#[derive(Default)]
struct AnalysisState {
    in_flight: bool,
    /// The newest result and the state generation it was rendered for.
    latest: Option<(u64, Analysed)>,
    failed_generation: Option<u64>,
    last_request: Option<Instant>,
    every_second: bool,
    wanted_now: bool,
}

/// How a screenshot attempt ended.
enum Shot {
    Taken,
    /// The shown frame's report has not come back yet (the web): try the next frame.
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
    Wait,
    /// The frame was shown wrong (its lists overflowed and have grown): try the next one.
    Retry,
}

struct App {
    ctx: Arc<GpuContext>,
    win: Option<Win>,
    /// Size the window opens at.
    initial_size: (u32, u32),
    applied: Controls,
    draft: Controls,
    /// The last state that rendered; a failing change goes back to it.
    last_good: Controls,
    draft_edited: Option<Instant>,
    /// The scene as opened: one copy, shared with the window's renderer and the analysis
    /// thread's (`Renderer::set_scene`); each frame is its state, with the fly camera's view.
    scene: Arc<Scene>,
    frame: u32,
    playing: bool,
    /// The frame was just chosen (a jump or a step): show it before the animation moves on.
    hold_frame: bool,
    fly: Option<FlyCamera>,
    fly_speed: f32,
    keys: HashSet<KeyCode>,
    drag: Option<(MouseButton, Option<(f64, f64)>)>,
    figures: LiveFigures,
    /// Bumped by every change of what the image shows but the playing animation.
    generation: u64,
    analysis: AnalysisState,
    jobs: Sender<Job>,
    done: Receiver<Done>,
    panel: bool,
    message: Option<String>,
    script: Vec<Step>,
    next_step: usize,
    scripted: bool,
    exit_after: Option<u32>,
    final_screenshot: Option<PathBuf>,
    /// Settled frames displayed (script steps are due by this count).
    settled: u32,
    pending_since: Option<Instant>,
    screenshots: VecDeque<PathBuf>,
    /// Frames the front screenshot was put off because they were shown wrong.
    screenshot_retries: u32,
    /// A size a script asked the window for, until the surface has it.
    requested_size: Option<(u32, u32)>,
    leaving: bool,
    last_display: Option<Instant>,
    /// No redraw before this (the surface gave no frame).
    idle_until: Option<Instant>,
    /// The newest submitted frame's serial, and recent finished frames' (serial, report).
    submitted: Option<u64>,
    recent: VecDeque<FinishedFrame>,
    lost: Arc<Mutex<Option<String>>>,
    fatal: Option<anyhow::Error>,
    report: ViewReport,
    /// The MSAA counts the adapter offers with a 16- and a 32-bit G-buffer (queried once:
    /// the panel shows them every frame).
    msaa_counts: [Vec<u32>; 2],
    /// Pipelines the GPU refused with given settings (a page learns it a frame late: its
    /// limits), with the reason: the panel greys them out.
    refused: Vec<(String, RenderSettings, String)>,
}

impl App {
    fn new(
        ctx: Arc<GpuContext>,
        opts: ViewOptions,
        scene: Scene,
        jobs: Sender<Job>,
        done: Receiver<Done>,
        lost: Arc<Mutex<Option<String>>>,
    ) -> App {
        let controls = Controls {
            pipeline: opts.pipeline.clone(),
            settings: opts.settings,
            request: opts.request.clone(),
            view: opts.view,
        };
        let fly_speed = FlyCamera::from_camera(&scene.camera_path.at(opts.frame)).speed;
        let adapter = ctx.adapter_label();
        let msaa_counts = [GBufferFormat::F16, GBufferFormat::F32]
            .map(|g| lightgrid::frame::msaa_counts(&ctx, g));
        App {
            ctx,
            win: None,
            initial_size: opts.size.unwrap_or(scene.default_size),
            applied: controls.clone(),
            draft: controls.clone(),
            last_good: controls,
            draft_edited: None,
            scene: Arc::new(scene),
            frame: opts.frame,
            playing: !opts.paused,
            hold_frame: true,
            fly: None,
            fly_speed,
            keys: HashSet::new(),
            drag: None,
            figures: LiveFigures::default(),
            generation: 0,
            analysis: AnalysisState::default(),
            jobs,
            done,
            panel: true,
            message: None,
            scripted: !opts.script.is_empty() || opts.exit_after_frames.is_some(),
            script: opts.script,
            next_step: 0,
            exit_after: opts.exit_after_frames,
            final_screenshot: opts.screenshot,
            settled: 0,
            pending_since: None,
            screenshots: VecDeque::new(),
            screenshot_retries: 0,
            requested_size: None,
            leaving: false,
            last_display: None,
            idle_until: None,
            submitted: None,
            recent: VecDeque::new(),
            lost,
            fatal: None,
            report: ViewReport {
                adapter,
                ..Default::default()
            },
            msaa_counts,
            refused: Vec::new(),
        }
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, e: anyhow::Error) {
        #[cfg(target_arch = "wasm32")]
        self.publish_fatal(&e);
        if self.fatal.is_none() {
            self.fatal = Some(e);
        }
        event_loop.exit();
    }

    fn open_window(&mut self, event_loop: &ActiveEventLoop) -> Result<Win> {
        let (w, h) = self.initial_size;
        let attributes = Window::default_attributes()
            .with_title(self.title())
            .with_inner_size(winit::dpi::PhysicalSize::new(w, h));
        // The page's canvas, appended to the document's body.
        #[cfg(target_arch = "wasm32")]
        let attributes = {
            use winit::platform::web::WindowAttributesExtWebSys;
            attributes.with_append(true)
        };
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .context("creating the window")?,
        );
        let surface = WindowSurface::new(&self.ctx, window.clone())?;
        let device = &self.ctx.device;
        let blit = Blit::new(device, surface.format());
        let size = render_size(&self.ctx, surface.size());
        let renderer = Renderer::new(&self.ctx, size.0, size.1, self.applied.settings)?;
        let egui_ctx = egui::Context::default();
        let state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(self.ctx.max_texture_edge() as usize),
        );
        let egui_renderer = egui_wgpu::Renderer::new(
            device,
            surface.format(),
            egui_wgpu::RendererOptions::default(),
        );
        Ok(Win {
            window,
            surface,
            blit,
            egui: EguiLayer {
                ctx: egui_ctx,
                state,
                renderer: egui_renderer,
            },
            renderer,
            debug_texture: None,
            size_changed_at: None,
        })
    }

    /// Put `renderer` in the window's place: its frames are numbered anew, so nothing of the
    /// old one's reports may be read as its own.
    fn replace_renderer(&mut self, renderer: Renderer) {
        if let Some(win) = &mut self.win {
            win.renderer = renderer;
            win.debug_texture = None;
        }
        self.recent.clear();
        self.submitted = None;
        self.generation += 1;
        self.figures.restart_times();
    }

    /// A newly opened scene in place of the old one (the animation frame kept if it has it).
    fn set_scene(&mut self, scene: Scene) {
        self.frame = self.frame.min(scene.frame_count() - 1);
        self.scene = Arc::new(scene);
        self.generation += 1;
    }

    fn set_playing(&mut self, on: bool) {
        if self.playing != on {
            self.playing = on;
            // A paused view must show its own frame: the debug view is made again.
            self.generation += 1;
        }
    }

    fn title(&self) -> String {
        format!("lightgrid: {} / {}", self.scene.name, self.applied.pipeline)
    }
}

/// The renderer's size for a surface: the surface's, within lightgrid's and the adapter's
/// limits (a larger window shows the frame's edge repeated).
fn render_size(ctx: &GpuContext, (w, h): (u32, u32)) -> (u32, u32) {
    let limit = lightgrid::max_frame_edge(ctx);
    (w.clamp(1, limit), h.clamp(1, limit))
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.win.is_some() {
            return;
        }
        match self.open_window(event_loop) {
            Ok(win) => {
                win.window.request_redraw();
                self.win = Some(win);
            }
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(win) = &mut self.win else { return };
        let response = win.egui.state.on_window_event(&win.window, &event);
        let over_panel = win.egui.ctx.egui_wants_pointer_input();
        let typing = win.egui.ctx.egui_wants_keyboard_input();
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(_) => {
                win.size_changed_at = Some(Instant::now());
                win.surface.resize(&self.ctx);
                win.window.request_redraw();
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.redraw(event_loop) {
                    self.fail(event_loop, e);
                }
            }
            WindowEvent::KeyboardInput {
                event:
                    KeyEvent {
                        physical_key: PhysicalKey::Code(code),
                        state,
                        repeat,
                        ..
                    },
                ..
            } if !(typing && state == ElementState::Pressed) => {
                self.key(event_loop, code, state == ElementState::Pressed, repeat)
            }
            WindowEvent::MouseInput { state, button, .. } => {
                let over = over_panel || response.consumed;
                self.mouse_button(button, state == ElementState::Pressed, over)
            }
            WindowEvent::CursorMoved { position, .. } => self.cursor(position.x, position.y),
            WindowEvent::MouseWheel { delta, .. } if !response.consumed && !over_panel => self
                .wheel(match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                }),
            WindowEvent::Focused(false) => self.keys.clear(),
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if let Some(t) = self.idle_until {
            if Instant::now() < t {
                event_loop.set_control_flow(ControlFlow::WaitUntil(t));
                return;
            }
            self.idle_until = None;
            event_loop.set_control_flow(ControlFlow::Wait);
        }
        if let Some(win) = &self.win {
            let size = win.window.inner_size();
            // Minimised: no frames until the window comes back (a Resized event).
            if size.width > 0 && size.height > 0 {
                win.window.request_redraw();
            }
        }
    }
}
