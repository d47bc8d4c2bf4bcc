//! Analysis frames for the viewer, on a thread of their own so the window's render loop never
//! waits for one: lighting computations against the ideal, lights per cell and the debug
//! views need the CPU to see GPU data (`Renderer::render`: a blocking readback, the ideal
//! count rasterized on the CPU), which takes longer than a frame.
//!
//! The worker keeps its own [`Renderer`] on the shared device (rebuilt when the size or the
//! settings change), given the window's own scene (`Arc`-shared, never copied) and the
//! frame's state, and answers one [`Job`] at a time; the window sends the next only when the
//! last has come back.

use lightgrid::debug_view::{self, DebugImage, DebugView};
use lightgrid::gpu::GpuContext;
use lightgrid::scene::{FrameState, Scene};
use lightgrid::{FrameStats, RenderSettings, Renderer};
use std::sync::mpsc::{Receiver, Sender};
use std::sync::Arc;

/// One analysis frame to render: the state the window showed when it asked.
pub struct Job {
    /// The window's state generation this job was taken at (a result whose generation is
    /// older than the window's describes a view no longer shown).
    pub generation: u64,
    /// The scene as opened (shared with the window, never changed).
    pub scene: Arc<Scene>,
    /// The frame the window showed: its camera (the fly camera's, if flying), lights and
    /// object transforms.
    pub state: FrameState,
    pub pipeline: &'static str,
    pub settings: RenderSettings,
    pub size: (u32, u32),
    pub view: DebugView,
}

/// What came back.
pub struct Done {
    pub generation: u64,
    pub result: Result<Analysed, String>,
}

pub struct Analysed {
    pub stats: FrameStats,
    /// The debug view asked for (None for `shaded`).
    pub image: Option<DebugImage>,
    pub seconds: f64,
}

/// The worker's side: render each job that arrives until the sender is dropped.
pub fn serve(ctx: &GpuContext, jobs: Receiver<Job>, done: Sender<Done>) {
    let mut renderer: Option<Renderer> = None;
    for job in jobs {
        let start = web_time::Instant::now();
        // A panic in an analysis frame is this job's error, not the window's: the renderer
        // that panicked is dropped and the next job makes a new one.
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            run(ctx, &mut renderer, &job)
        }))
        .unwrap_or_else(|_| {
            renderer = None;
            Err("the analysis frame panicked".to_string())
        })
        .map(|(stats, image)| Analysed {
            stats,
            image,
            seconds: start.elapsed().as_secs_f64(),
        });
        if done
            .send(Done {
                generation: job.generation,
                result,
            })
            .is_err()
        {
            return;
        }
    }
}

fn run(
    ctx: &GpuContext,
    renderer: &mut Option<Renderer>,
    job: &Job,
) -> Result<(FrameStats, Option<DebugImage>), String> {
    let keep = renderer
        .as_ref()
        .is_some_and(|r| r.size() == job.size && r.settings() == job.settings);
    if !keep {
        *renderer = None;
        *renderer = Some(
            Renderer::new(ctx, job.size.0, job.size.1, job.settings).map_err(|e| e.to_string())?,
        );
    }
    let r = renderer.as_mut().expect("set above");
    if !r.scene().is_some_and(|s| Arc::ptr_eq(s, &job.scene)) {
        r.set_scene(job.scene.clone()).map_err(|e| e.to_string())?;
    }
    let out = r
        .render_state(&job.state, job.pipeline)
        .map_err(|e| e.to_string())?;
    let image = debug_view::draw(job.view, &out);
    Ok((out.stats, image))
}
