//! The window (`lightgrid view`): winit events in, one real-time frame per redraw out.
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

use crate::analysis::{self, Analysed, Done, Job};
use crate::controls::{refusal, Controls, Rebuild};
use crate::fly::{FlyCamera, Movement};
use crate::live::LiveFigures;
use crate::panel::{self, PanelAction, PanelInfo};
use crate::present::{upload_image, Blit, Capture};
use crate::script::{Action, Step};
use crate::surface::{Acquired, WindowSurface};
use anyhow::{anyhow, bail, Context, Result};
use lightgrid::debug_view::DebugView;
use lightgrid::gpu::GpuContext;
use lightgrid::pipelines::{self, PIPELINES};
use lightgrid::scene::{Scene, SceneRequest};
use lightgrid::{FinishedFrame, RenderSettings, Renderer};
use std::collections::{HashSet, VecDeque};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver, Sender, TryRecvError};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, KeyEvent, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

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
/// have been shown.
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
    let ctx = &ctx;
    std::thread::scope(|s| {
        s.spawn(move || analysis::serve(ctx, job_rx, done_tx));
        let mut app = App::new(ctx, opts, opened.scene, jobs, done, lost);
        let ran = event_loop.run_app(&mut app);
        // Dropping the app drops the job sender, which ends the worker.
        let App {
            fatal,
            mut report,
            figures,
            ..
        } = app;
        report.fps = figures.fps();
        report.gpu_ms = LiveFigures::recent_mean(&figures.gpu_ms, crate::live::HISTORY);
        ran.context("the window's event loop failed")?;
        match fatal {
            Some(e) => Err(e),
            None => Ok(report),
        }
    })
}

/// The parts that exist while the window does.
struct Win<'c> {
    window: Arc<Window>,
    surface: WindowSurface,
    blit: Blit,
    egui: EguiLayer,
    renderer: Renderer<'c>,
    /// The debug view's image on the GPU, with the analysis result it came from.
    debug_texture: Option<(u64, wgpu::TextureView)>,
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
    /// The newest result, its state generation and a serial (which result it is).
    latest: Option<(u64, u64, Analysed)>,
    serial: u64,
    failed_generation: Option<u64>,
    last_request: Option<Instant>,
    every_second: bool,
    wanted_now: bool,
}

/// How a screenshot attempt ended.
enum Shot {
    Taken,
    /// The frame was shown wrong (its lists overflowed and have grown): try the next one.
    Retry,
}

struct App<'c> {
    ctx: &'c GpuContext,
    win: Option<Win<'c>>,
    /// Size the window opens at.
    initial_size: (u32, u32),
    applied: Controls,
    draft: Controls,
    /// The last state that rendered; a failing change goes back to it.
    last_good: Controls,
    draft_edited: Option<Instant>,
    /// The scene as opened (shared with the analysis thread), and the copy rendered, whose
    /// camera path the fly camera replaces.
    base: Arc<Scene>,
    scene: Scene,
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
}

impl<'c> App<'c> {
    fn new(
        ctx: &'c GpuContext,
        opts: ViewOptions,
        scene: Scene,
        jobs: Sender<Job>,
        done: Receiver<Done>,
        lost: Arc<Mutex<Option<String>>>,
    ) -> App<'c> {
        let controls = Controls {
            pipeline: opts.pipeline.clone(),
            settings: opts.settings,
            request: opts.request.clone(),
            view: opts.view,
        };
        let fly_speed = FlyCamera::from_camera(&scene.camera_path.at(opts.frame)).speed;
        App {
            ctx,
            win: None,
            initial_size: opts.size.unwrap_or(scene.default_size),
            applied: controls.clone(),
            draft: controls.clone(),
            last_good: controls,
            draft_edited: None,
            base: Arc::new(scene.clone()),
            scene,
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
                adapter: ctx.adapter_label(),
                ..Default::default()
            },
        }
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, e: anyhow::Error) {
        if self.fatal.is_none() {
            self.fatal = Some(e);
        }
        event_loop.exit();
    }

    fn open_window(&mut self, event_loop: &ActiveEventLoop) -> Result<Win<'c>> {
        let (w, h) = self.initial_size;
        let attributes = Window::default_attributes()
            .with_title(self.title())
            .with_inner_size(winit::dpi::PhysicalSize::new(w, h));
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .context("creating the window")?,
        );
        let surface = WindowSurface::new(self.ctx, window.clone())?;
        let device = &self.ctx.device;
        let blit = Blit::new(device, surface.format());
        let size = render_size(self.ctx, surface.size());
        let renderer = Renderer::new(self.ctx, size.0, size.1, self.applied.settings)?;
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
    fn replace_renderer(&mut self, renderer: Renderer<'c>) {
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
        self.base = Arc::new(scene.clone());
        self.scene = scene;
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

    // --- what holds scripts and screenshots -------------------------------------------------

    /// Something the next frames will change by themselves: scripts and screenshots wait.
    fn pending(&self, now: Instant) -> bool {
        let Some(win) = &self.win else { return true };
        let size_settling = win
            .size_changed_at
            .is_some_and(|t| now.duration_since(t) < SETTLE);
        let wrong_size = win.renderer.size() != render_size(self.ctx, win.surface.size());
        let debug_stale = self.applied.view != DebugView::Shaded
            && self.analysis.failed_generation != Some(self.generation)
            && !self.analysis_current(true);
        let resize_asked = self.requested_size.is_some_and(|s| s != win.surface.size());
        size_settling || wrong_size || resize_asked || self.draft != self.applied || debug_stale
    }

    /// The newest analysis frame shows the current state (and, paused, the current frame);
    /// with `image`, it also has the debug view's image.
    fn analysis_current(&self, image: bool) -> bool {
        self.analysis.latest.as_ref().is_some_and(|(g, _, a)| {
            *g == self.generation
                && (self.playing || a.stats.frame == self.frame)
                && (!image || a.image.is_some())
        })
    }

    /// Run the next step when it is due: one step per frame, so each step's change is
    /// shown (and settled) before the next one runs, and none while a screenshot waits.
    fn run_due_step(&mut self) -> Result<()> {
        if !self.screenshots.is_empty() {
            return Ok(());
        }
        let Some(step) = self.script.get(self.next_step).cloned() else {
            return Ok(());
        };
        if step.at > self.settled {
            return Ok(());
        }
        self.next_step += 1;
        self.run_step(&step)
            .with_context(|| format!("script step at {}: {:?}", step.at, step.action))
    }

    fn run_step(&mut self, step: &Step) -> Result<()> {
        let mut next = self.applied.clone();
        match &step.action {
            Action::Pipeline(id) => next.pipeline = pipelines::find(id)?.id.to_string(),
            Action::Tile(n) => next.settings.tile_size = *n,
            Action::Msaa(n) => next.settings.msaa = *n,
            Action::View(v) => next.view = *v,
            Action::Spots(f) => next.request.params.spot_fraction = *f,
            Action::Transparency(on) => next.request.params.transparency = *on,
            Action::AddLights(n) => {
                next.request.add_lights = (*n > 0).then_some(lightgrid::scene::AddLights {
                    count: *n,
                    range: None,
                })
            }
            Action::Resize(w, h) => {
                let win = self.win.as_ref().context("no window")?;
                let _ = win
                    .window
                    .request_inner_size(winit::dpi::PhysicalSize::new(*w, *h));
                // Pending until the surface has it (X11 answers with a later event).
                self.requested_size = Some((*w, *h));
                return Ok(());
            }
            Action::Frame(f) => {
                self.scene.check_frame(*f)?;
                self.jump_to(*f);
                return Ok(());
            }
            Action::Pause => {
                self.set_playing(false);
                return Ok(());
            }
            Action::Play => {
                self.set_playing(true);
                return Ok(());
            }
            Action::Panel(on) => {
                self.panel = *on;
                return Ok(());
            }
            Action::Screenshot(path) => {
                self.screenshots.push_back(path.clone());
                return Ok(());
            }
        }
        self.apply(next).map_err(|e| anyhow!(e))
    }

    // --- applying changes -------------------------------------------------------------------

    /// Go to `next`: switch, make a renderer or reopen the scene, as the change needs.
    fn apply(&mut self, next: Controls) -> Result<(), String> {
        let rebuild = self.applied.rebuild_for(&next);
        if rebuild == Rebuild::Nothing {
            return Ok(());
        }
        let info = pipelines::find(&next.pipeline).map_err(|e| e.to_string())?;
        if let Some(why) = refusal(info, &next.settings) {
            return Err(why);
        }
        // Everything is made before anything is replaced, so a failure leaves the viewer as
        // it was.
        let opened = match rebuild {
            Rebuild::Scene => {
                Some(lightgrid::scene::open(&next.request).map_err(|e| e.to_string())?)
            }
            _ => None,
        };
        let renderer = match rebuild {
            Rebuild::Scene | Rebuild::Renderer => {
                let win = self.win.as_ref().ok_or("no window")?;
                let (w, h) = win.renderer.size();
                Some(Renderer::new(self.ctx, w, h, next.settings).map_err(|e| e.to_string())?)
            }
            _ => None,
        };
        if let Some(opened) = opened {
            if let Some(w) = opened.warnings.first() {
                self.message = Some(format!(
                    "{} (and {} more warnings)",
                    w,
                    opened.warnings.len() - 1
                ));
            }
            self.set_scene(opened.scene);
        }
        if let Some(r) = renderer {
            self.replace_renderer(r);
        }
        self.applied = next;
        // A script's or key's change is the panel's draft from now on too.
        self.draft = self.applied.clone();
        self.generation += 1;
        self.figures.restart_times();
        if let Some(win) = &self.win {
            win.window.set_title(&self.title());
        }
        Ok(())
    }

    /// Apply the panel's draft once it has stopped changing (a pipeline or view at once).
    fn apply_draft(&mut self, now: Instant) -> Result<()> {
        if self.draft == self.applied {
            return Ok(());
        }
        let quick = self.applied.rebuild_for(&self.draft) == Rebuild::Switch;
        let still = self
            .draft_edited
            .is_none_or(|t| now.duration_since(t) >= DRAFT_SETTLE);
        if !(quick || still) {
            return Ok(());
        }
        let next = self.draft.clone();
        if let Err(e) = self.apply(next) {
            if self.scripted {
                bail!("{e}");
            }
            self.message = Some(e);
            self.draft = self.applied.clone();
        }
        Ok(())
    }

    /// A frame failed to render: go back to the last state that rendered, or give up.
    fn recover(&mut self, e: lightgrid::Error) -> Result<()> {
        if self.applied == self.last_good || self.scripted {
            return Err(anyhow!(e).context(format!("rendering with {}", self.applied.pipeline)));
        }
        self.message = Some(format!(
            "{}: {e}; back to the last setting that rendered",
            self.applied.pipeline
        ));
        let good = self.last_good.clone();
        // A new renderer for the old settings whatever the difference, so nothing of the
        // failed one stays.
        let win = self.win.as_ref().context("no window")?;
        let (w, h) = win.renderer.size();
        let renderer = Renderer::new(self.ctx, w, h, good.settings)?;
        if self.applied.request != good.request {
            let opened = lightgrid::scene::open(&good.request)?;
            self.set_scene(opened.scene);
        }
        self.replace_renderer(renderer);
        self.applied = good.clone();
        self.draft = good;
        if let Some(win) = &self.win {
            win.window.set_title(&self.title());
        }
        Ok(())
    }

    /// Make a renderer at the window's size once it has settled.
    fn follow_size(&mut self, now: Instant) -> Result<()> {
        let Some(win) = &mut self.win else {
            return Ok(());
        };
        let wanted = render_size(self.ctx, win.surface.size());
        let settling = win
            .size_changed_at
            .is_some_and(|t| now.duration_since(t) < SETTLE);
        if wanted == win.renderer.size() || settling {
            return Ok(());
        }
        let renderer = Renderer::new(self.ctx, wanted.0, wanted.1, self.applied.settings)?;
        self.replace_renderer(renderer);
        Ok(())
    }

    // --- one frame --------------------------------------------------------------------------

    fn redraw(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        if let Some(reason) = self.lost.lock().ok().and_then(|mut l| l.take()) {
            bail!("the GPU device was lost ({reason}); restart the viewer");
        }
        let now = Instant::now();
        self.check_patience(now)?;
        self.collect_analysis()?;
        if !self.pending(now) {
            self.run_due_step()?;
        }
        self.apply_draft(now)?;
        self.follow_size(now)?;
        let Some(win) = &self.win else { return Ok(()) };
        let size = win.window.inner_size();
        if size.width == 0 || size.height == 0 {
            return Ok(());
        }
        self.advance(now);
        if !self.render()? {
            return Ok(());
        }
        self.after_frame(event_loop, now)
    }

    /// Move the fly camera by the held keys and step the animation.
    fn advance(&mut self, now: Instant) {
        let dt = self
            .last_display
            .map_or(0.0, |t| now.duration_since(t).as_secs_f32().min(0.25));
        let axis = |plus: KeyCode, minus: KeyCode| {
            f32::from(u8::from(self.keys.contains(&plus)))
                - f32::from(u8::from(self.keys.contains(&minus)))
        };
        let m = Movement {
            forward: axis(KeyCode::KeyW, KeyCode::KeyS),
            right: axis(KeyCode::KeyD, KeyCode::KeyA),
            up: axis(KeyCode::KeyE, KeyCode::KeyQ),
        };
        if !m.is_still() {
            let fast = if self.keys.contains(&KeyCode::ShiftLeft) {
                4.0
            } else {
                1.0
            };
            let speed = self.fly_speed * fast;
            let fly = self.fly_camera();
            fly.speed = speed;
            fly.advance(m, dt);
            self.generation += 1;
        }
        if self.playing && !std::mem::take(&mut self.hold_frame) {
            self.frame = (self.frame + 1) % self.scene.frame_count();
        }
        self.scene.camera_path = match &self.fly {
            Some(f) => f.hold(&self.base.camera_path),
            None => self.base.camera_path.clone(),
        };
    }

    /// The fly camera, starting where the path's camera is now.
    fn fly_camera(&mut self) -> &mut FlyCamera {
        let camera = self.base.camera_path.at(self.frame);
        let speed = self.fly_speed;
        self.fly.get_or_insert_with(|| FlyCamera {
            speed,
            ..FlyCamera::from_camera(&camera)
        })
    }

    /// Render and present one frame; false when nothing was shown.
    fn render(&mut self) -> Result<bool> {
        let ctx = self.ctx;
        let pipeline = self.applied.pipeline.clone();
        let win = self.win.as_mut().context("no window")?;
        // The surface first: a frame is rendered only when it can be shown.
        let texture = match win.surface.acquire(ctx)? {
            Acquired::Frame(t) => t,
            Acquired::Skip => {
                self.idle_until = Some(Instant::now() + SKIP_PAUSE);
                return Ok(false);
            }
        };
        match win
            .renderer
            .render_frame(&self.scene, self.frame, &pipeline)
        {
            Ok(s) => {
                self.submitted = Some(s.serial);
                self.last_good = self.applied.clone();
            }
            Err(e) => {
                self.recover(e)?;
                return Ok(false);
            }
        }
        let finished = win.renderer.poll_finished()?;
        self.observe(finished);
        self.present(texture)
    }

    fn observe(&mut self, finished: Vec<FinishedFrame>) {
        for f in finished {
            self.figures.finished(&f);
            if self.recent.len() == 8 {
                self.recent.pop_front();
            }
            self.recent.push_back(f);
        }
        self.report.overflowed = self.figures.overflowed;
        self.report.truncated = self.figures.truncated;
    }

    /// The image the window shows now: the debug view's (once one came back) or the frame.
    fn source<'a>(win: &'a Win, view: DebugView) -> &'a wgpu::TextureView {
        match (&win.debug_texture, view) {
            (Some((_, t)), v) if v != DebugView::Shaded => t,
            _ => win.renderer.display_view(),
        }
    }

    fn present(&mut self, texture: wgpu::SurfaceTexture) -> Result<bool> {
        let ctx = self.ctx;
        let win = self.win.as_mut().context("no window")?;
        let target = texture.texture.create_view(&Default::default());
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let source = Self::source(win, self.applied.view);
        win.blit.encode(&ctx.device, &mut encoder, source, &target);
        let actions = self.draw_ui(&mut encoder, &target)?;
        ctx.queue.submit([encoder.finish()]);
        ctx.queue.present(texture);
        let now = Instant::now();
        if let Some(t) = self.last_display {
            self.figures
                .displayed(now.duration_since(t).as_secs_f64() * 1e3);
        }
        self.last_display = Some(now);
        self.report.frames += 1;
        for a in actions {
            self.panel_action(a);
        }
        Ok(true)
    }

    /// The panel (or, hidden, the one status line) drawn over `target`.
    fn draw_ui(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
    ) -> Result<Vec<PanelAction>> {
        let analysis_current = self.analysis_current(false);
        let win = self.win.as_mut().context("no window")?;
        let input = win.egui.state.take_egui_input(&win.window);
        let before = self.draft.clone();
        let msaa = lightgrid::frame::msaa_counts(self.ctx, self.draft.settings.gbuffer);
        let adapter = self.report.adapter.clone();
        let info = PanelInfo {
            adapter: &adapter,
            scene: &self.scene.name,
            variable_lights: !self.applied.request.is_file()
                && lightgrid::scene::catalog::find(&self.applied.request.spec)
                    .is_ok_and(|s| s.variable_lights),
            lights: self.scene.lights.len(),
            frame: self.frame,
            frame_count: self.scene.frame_count(),
            playing: self.playing,
            flying: self.fly.is_some(),
            fly_speed: self.fly_speed,
            render_size: win.renderer.size(),
            msaa_counts: &msaa,
            figures: &self.figures,
            analysis: self
                .analysis
                .latest
                .as_ref()
                .map(|(_, _, a)| (a, analysis_current)),
            analysing: self.analysis.in_flight,
            sample_every_second: self.analysis.every_second,
            message: self.message.as_deref(),
            applying: self.draft != self.applied,
        };
        // A window too small for the panel leaves it out rather than letting egui shrink it
        // to that size (it would stay shrunk when the window grows back).
        let (sw, sh) = win.surface.size();
        let panel_on = self.panel && sw >= MIN_PANEL_WINDOW.0 && sh >= MIN_PANEL_WINDOW.1;
        let draft = &mut self.draft;
        let mut actions = Vec::new();
        let output = win.egui.ctx.run_pass(input, |ctx| {
            if panel_on {
                actions = panel::draw(ctx, draft, &info);
            } else {
                egui::Area::new(egui::Id::unique("lightgrid status"))
                    .fixed_pos([6.0, 4.0])
                    .show(ctx, |ui| {
                        ui.label(
                            egui::RichText::new(info.figures.status_line())
                                .background_color(egui::Color32::from_black_alpha(160)),
                        );
                    });
            }
        });
        if self.draft != before {
            self.draft_edited = Some(Instant::now());
        }
        win.egui
            .state
            .handle_platform_output(&win.window, output.platform_output);
        let primitives = win
            .egui
            .ctx
            .tessellate(output.shapes, output.pixels_per_point);
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [win.surface.size().0, win.surface.size().1],
            pixels_per_point: output.pixels_per_point,
        };
        let device = &self.ctx.device;
        let queue = &self.ctx.queue;
        for (id, deltas) in &output.textures_delta.set {
            for delta in deltas {
                win.egui.renderer.update_texture(device, queue, *id, delta);
            }
        }
        let extra = win
            .egui
            .renderer
            .update_buffers(device, queue, encoder, &primitives, &screen);
        if !extra.is_empty() {
            queue.submit(extra);
        }
        {
            let mut pass = encoder
                .begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("viewer panel"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: target,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Load,
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                })
                .forget_lifetime();
            win.egui.renderer.render(&mut pass, &primitives, &screen);
        }
        for id in &output.textures_delta.free {
            win.egui.renderer.free_texture(id);
        }
        Ok(actions)
    }

    fn panel_action(&mut self, a: PanelAction) {
        match a {
            PanelAction::TogglePause => self.set_playing(!self.playing),
            PanelAction::Step(d) => self.step(d),
            PanelAction::JumpTo(f) => self.jump_to(f.min(self.scene.frame_count() - 1)),
            PanelAction::FollowPath => {
                self.fly = None;
                self.generation += 1;
            }
            PanelAction::FlySpeed(s) => self.fly_speed = s.clamp(0.01, 1e4),
            PanelAction::Analyse => self.analysis.wanted_now = true,
            PanelAction::SampleEverySecond(on) => self.analysis.every_second = on,
            PanelAction::Screenshot => self.queue_user_screenshot(),
            PanelAction::HidePanel => self.panel = false,
        }
    }

    fn step(&mut self, d: i32) {
        let n = self.scene.frame_count() as i64;
        self.set_playing(false);
        self.jump_to((i64::from(self.frame) + i64::from(d)).rem_euclid(n) as u32);
    }

    /// Show animation frame `f` next.
    fn jump_to(&mut self, f: u32) {
        self.frame = f;
        self.hold_frame = true;
        self.generation += 1;
    }

    fn queue_user_screenshot(&mut self) {
        let stem = format!(
            "lightgrid-{}-{}-{}",
            self.scene
                .name
                .replace(|c: char| !c.is_ascii_alphanumeric() && c != '-', "_"),
            self.applied.pipeline,
            self.frame
        );
        self.screenshots.push_back(free_name(Path::new("."), &stem));
    }

    // --- after the frame: screenshots, the script's clock, leaving, analysis ---------------

    /// A scripted run that has waited too long (for a settled view or a screenshot) ends
    /// with what it waited for, rather than hanging.
    fn check_patience(&mut self, now: Instant) -> Result<()> {
        if let Some(s) = self.requested_size {
            if self.win.as_ref().is_some_and(|w| w.surface.size() == s) {
                self.requested_size = None;
            }
        }
        let waiting = self.pending(now) || !self.screenshots.is_empty();
        if !waiting {
            self.pending_since = None;
            return Ok(());
        }
        let since = *self.pending_since.get_or_insert(now);
        if self.scripted && now.duration_since(since) > SCRIPT_PATIENCE {
            let win = self.win.as_ref().context("no window")?;
            bail!(
                "the scripted session waited {} s for the view to settle (window {:?}{}, renderer {:?}, {} screenshot(s) waiting)",
                SCRIPT_PATIENCE.as_secs(),
                win.surface.size(),
                self.requested_size
                    .map_or(String::new(), |s| format!(" of the {s:?} asked for")),
                win.renderer.size(),
                self.screenshots.len()
            );
        }
        Ok(())
    }

    fn after_frame(&mut self, event_loop: &ActiveEventLoop, now: Instant) -> Result<()> {
        if !self.pending(now) {
            if let Some(path) = self.screenshots.front().cloned() {
                let taken = match self.screenshot(&path) {
                    Ok(Shot::Retry) if self.screenshot_retries < MAX_SCREENSHOT_RETRIES => {
                        self.screenshot_retries += 1;
                        Ok(false)
                    }
                    Ok(Shot::Retry) => Err(anyhow!(
                        "{}: {MAX_SCREENSHOT_RETRIES} frames in a row overflowed their light lists; no screenshot written",
                        path.display()
                    )),
                    Ok(Shot::Taken) => Ok(true),
                    Err(e) => Err(e),
                };
                match taken {
                    Ok(false) => {}
                    Ok(true) => {
                        eprintln!(
                            "screenshot {} ({}, frame {}, {}, {:?})",
                            path.display(),
                            self.applied.pipeline,
                            self.frame,
                            self.applied.view.name(),
                            self.win
                                .as_ref()
                                .map(|w| w.renderer.size())
                                .unwrap_or_default()
                        );
                        self.screenshots.pop_front();
                        self.screenshot_retries = 0;
                        self.report.screenshots.push(path);
                    }
                    Err(e) if self.scripted => return Err(e),
                    Err(e) => {
                        self.screenshots.pop_front();
                        self.screenshot_retries = 0;
                        self.message = Some(format!("{e:#}"));
                    }
                }
            } else {
                self.settled = self.settled.saturating_add(1);
            }
        }
        self.leave_when_done(event_loop);
        self.request_analysis(now)
    }

    fn leave_when_done(&mut self, event_loop: &ActiveEventLoop) {
        let Some(n) = self.exit_after else { return };
        if self.settled < n || self.next_step < self.script.len() {
            return;
        }
        if !self.leaving {
            self.leaving = true;
            if let Some(p) = self.final_screenshot.take() {
                self.screenshots.push_back(p);
            }
        }
        if self.screenshots.is_empty() {
            event_loop.exit();
        }
    }

    /// Draw what the window shows (without the panel) into a texture of the surface's format
    /// and write it. A shaded frame is first waited for and checked: an overflowed frame is
    /// retried on the next one, a frame with loops cut short is refused.
    fn screenshot(&mut self, path: &Path) -> Result<Shot> {
        let ctx = self.ctx;
        let view = self.applied.view;
        let win = self.win.as_mut().context("no window")?;
        let debug = view != DebugView::Shaded && win.debug_texture.is_some();
        if !debug {
            let finished = win.renderer.finish()?;
            self.observe(finished);
            let serial = self.submitted.context("no frame rendered yet")?;
            let Some(report) = self.recent.iter().rfind(|f| f.serial == serial) else {
                return Ok(Shot::Retry);
            };
            if report.truncated_loops > 0 || report.fragments_off_bounds > 0 {
                bail!(
                    "{}: the frame shown was wrong ({} shader loops cut short, {} fragments off their cell's bounds); no screenshot written",
                    path.display(),
                    report.truncated_loops,
                    report.fragments_off_bounds
                );
            }
            if report.overflowed {
                return Ok(Shot::Retry);
            }
        }
        let win = self.win.as_ref().context("no window")?;
        let size = match (&self.analysis.latest, debug) {
            (Some((_, _, a)), true) => a
                .image
                .as_ref()
                .map_or(win.renderer.size(), |i| i.image.dimensions()),
            _ => win.renderer.size(),
        };
        let capture = Capture::new(&ctx.device, win.surface.format(), size);
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        win.blit.encode(
            &ctx.device,
            &mut encoder,
            Self::source(win, view),
            &capture.view,
        );
        ctx.queue.submit([encoder.finish()]);
        let image = capture.read(&ctx.device, &ctx.queue)?;
        let bytes = lightgrid::image_io::encode_png(&image, path)?;
        lightgrid::image_io::write_atomic(path, &bytes)?;
        Ok(Shot::Taken)
    }

    fn collect_analysis(&mut self) -> Result<()> {
        loop {
            match self.done.try_recv() {
                Ok(done) => {
                    self.analysis.in_flight = false;
                    match done.result {
                        Ok(a) => {
                            self.analysis.serial += 1;
                            self.upload_debug(&a);
                            self.analysis.latest = Some((done.generation, self.analysis.serial, a));
                        }
                        Err(e) if self.scripted => bail!("analysis frame: {e}"),
                        Err(e) => {
                            self.analysis.failed_generation = Some(done.generation);
                            self.message = Some(format!("analysis frame: {e}"));
                        }
                    }
                }
                Err(TryRecvError::Empty) => return Ok(()),
                Err(TryRecvError::Disconnected) => bail!("the analysis thread stopped"),
            }
        }
    }

    fn upload_debug(&mut self, a: &Analysed) {
        let Some(win) = &mut self.win else { return };
        win.debug_texture = a.image.as_ref().map(|img| {
            (
                self.analysis.serial,
                upload_image(&self.ctx.device, &self.ctx.queue, &img.image),
            )
        });
    }

    /// Send the next analysis job: continuously while a debug view shows, else on demand or
    /// once a second when asked to.
    fn request_analysis(&mut self, now: Instant) -> Result<()> {
        let a = &self.analysis;
        if a.in_flight {
            return Ok(());
        }
        let since = a.last_request.map(|t| now.duration_since(t));
        let due = |every: Duration| since.is_none_or(|s| s >= every);
        let want = if self.applied.view != DebugView::Shaded {
            let current = self.analysis_current(false);
            (!current && a.failed_generation != Some(self.generation))
                || (self.playing && due(DEBUG_REFRESH))
        } else {
            a.wanted_now || (a.every_second && due(Duration::from_secs(1)))
        };
        if !want {
            return Ok(());
        }
        let win = self.win.as_ref().context("no window")?;
        let job = Job {
            generation: self.generation,
            scene: self.base.clone(),
            camera: self.scene.camera_path.clone(),
            frame: self.frame,
            pipeline: pipelines::find(&self.applied.pipeline)?.id,
            settings: self.applied.settings,
            size: win.renderer.size(),
            view: self.applied.view,
        };
        self.jobs
            .send(job)
            .map_err(|_| anyhow!("the analysis thread stopped"))?;
        self.analysis.in_flight = true;
        self.analysis.wanted_now = false;
        self.analysis.last_request = Some(now);
        Ok(())
    }

    // --- input ------------------------------------------------------------------------------

    fn key(&mut self, event_loop: &ActiveEventLoop, code: KeyCode, pressed: bool, repeat: bool) {
        if !pressed {
            self.keys.remove(&code);
            return;
        }
        self.keys.insert(code);
        if repeat {
            return;
        }
        match code {
            KeyCode::Escape => event_loop.exit(),
            KeyCode::Space => self.set_playing(!self.playing),
            KeyCode::Period => self.step(1),
            KeyCode::Comma => self.step(-1),
            KeyCode::BracketRight => self.cycle_pipeline(1),
            KeyCode::BracketLeft => self.cycle_pipeline(-1),
            KeyCode::KeyV => self.draft.view = self.draft.view.next(),
            KeyCode::KeyH | KeyCode::F1 => self.panel = !self.panel,
            KeyCode::KeyI => self.analysis.wanted_now = true,
            KeyCode::KeyC => {
                self.fly = None;
                self.generation += 1;
            }
            KeyCode::F12 | KeyCode::KeyP => self.queue_user_screenshot(),
            _ => {}
        }
    }

    /// The next pipeline of the registry that runs with the current settings.
    fn cycle_pipeline(&mut self, d: i32) {
        let n = PIPELINES.len() as i32;
        let at = PIPELINES
            .iter()
            .position(|p| p.id == self.draft.pipeline)
            .unwrap_or(0) as i32;
        for k in 1..=n {
            let p = &PIPELINES[(at + d * k).rem_euclid(n) as usize];
            if refusal(p, &self.draft.settings).is_none() {
                self.draft.pipeline = p.id.to_string();
                return;
            }
        }
    }

    fn mouse_button(&mut self, button: MouseButton, pressed: bool, over_panel: bool) {
        let turns = button == MouseButton::Right || (button == MouseButton::Left && !over_panel);
        if pressed && turns {
            self.drag = Some((button, None));
        } else if !pressed && self.drag.is_some_and(|(b, _)| b == button) {
            self.drag = None;
        }
    }

    fn cursor(&mut self, x: f64, y: f64) {
        let Some((button, last)) = self.drag else {
            return;
        };
        if let Some((lx, ly)) = last {
            let (dx, dy) = ((x - lx) as f32, (y - ly) as f32);
            if dx != 0.0 || dy != 0.0 {
                self.fly_camera().turn(dx, dy);
                self.generation += 1;
            }
        }
        self.drag = Some((button, Some((x, y))));
    }

    fn wheel(&mut self, lines: f32) {
        if lines.is_finite() {
            self.fly_speed = (self.fly_speed * 1.25f32.powf(lines)).clamp(0.01, 1e4);
        }
    }
}

/// The renderer's size for a surface: the surface's, within lightgrid's and the adapter's
/// limits (a larger window shows the frame's edge repeated).
fn render_size(ctx: &GpuContext, (w, h): (u32, u32)) -> (u32, u32) {
    let limit = ctx
        .max_texture_edge()
        .min(lightgrid::consts::MAX_FRAME_EDGE);
    (w.clamp(1, limit), h.clamp(1, limit))
}

/// `dir/stem.png`, or `dir/stem-2.png`, ... : a name nothing has yet.
fn free_name(dir: &Path, stem: &str) -> PathBuf {
    let mut path = dir.join(format!("{stem}.png"));
    let mut n = 2;
    while path.exists() {
        path = dir.join(format!("{stem}-{n}.png"));
        n += 1;
    }
    path
}

impl ApplicationHandler for App<'_> {
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
                win.surface.resize(self.ctx);
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn free_name_never_names_an_existing_file() {
        let dir = std::env::temp_dir().join(format!("lightgrid-free-name-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let a = free_name(&dir, "shot");
        assert_eq!(a, dir.join("shot.png"));
        std::fs::write(&a, b"x").unwrap();
        let b = free_name(&dir, "shot");
        assert_eq!(b, dir.join("shot-2.png"));
        std::fs::write(&b, b"x").unwrap();
        assert_eq!(free_name(&dir, "shot"), dir.join("shot-3.png"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
