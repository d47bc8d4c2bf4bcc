//! The real-time frame loop: a scene's animation rendered back to back the way a game would
//! ([`Renderer::render_frame`]: one submission per frame, frames in flight, no analysis), with
//! each frame's period on the CPU and its GPU time from timestamps resolved asynchronously.
//! `lightgrid play` prints it; `lightgrid bench` takes its frame times from it.

use crate::error::{Error, Result};
use crate::frame::FinishedFrame;
use crate::gpu::PassTiming;
use crate::renderer::Renderer;
use crate::scene::Scene;
use crate::stats::Distribution;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicBool, Ordering};
use web_time::Instant;

/// One frame of a real-time run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlayedFrame {
    /// The animation frame.
    pub frame: u32,
    /// Which pass over the frames (0-based).
    pub pass: u32,
    /// Wall time from this frame's start to the next one's: the frame period a game would see.
    /// The last frame's is the wait for the frames still in flight divided by their number.
    pub frame_ms: f64,
    /// GPU time of the frame (its submissions' timestamp spans, summed); None without
    /// timestamps.
    pub gpu_ms: Option<f64>,
    /// Each timed pass's GPU time, in recording order (empty without timestamps).
    pub passes: Vec<PassTiming>,
    /// CPU time spent waiting for older frames (more than `MAX_FRAMES_IN_FLIGHT` in flight).
    pub throttle_ms: f64,
    /// CPU time the frame itself waited on the GPU (the `cpu` strategy's read-back).
    pub cpu_wait_ms: f64,
    /// Queue submissions the frame made.
    pub submits: u32,
    /// Bytes the frame read back with a wait for the GPU.
    pub readback_bytes: u64,
    /// Bytes uploaded to the GPU for the frame (lights, uniforms, moving geometry).
    pub upload_bytes: u64,
    /// Some light list did not fit (the frame is missing lights; lists grew for later ones).
    pub overflowed: bool,
    /// Shader loops that ended before their bound (the frame is wrong).
    pub truncated_loops: u32,
}

/// A whole real-time run.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PlayRun {
    /// The recorded frames in play order (warm-up frames excluded).
    pub frames: Vec<PlayedFrame>,
    /// Stopped (Ctrl-C) before the end.
    pub interrupted: bool,
}

impl PlayRun {
    /// The distribution of frame periods in milliseconds; None when no frame was played.
    pub fn frame_ms(&self) -> Option<Distribution> {
        Distribution::of(self.frames.iter().map(|f| f.frame_ms))
    }

    /// None when any frame lacks a GPU time (no timestamps).
    pub fn gpu_ms(&self) -> Option<Distribution> {
        let v: Option<Vec<f64>> = self.frames.iter().map(|f| f.gpu_ms).collect();
        Distribution::of(v?)
    }

    /// Frames per second: frames over the sum of their periods (with the queue full when the
    /// run starts, each frame's GPU work is counted once).
    pub fn fps(&self) -> f64 {
        let total: f64 = self.frames.iter().map(|f| f.frame_ms).sum();
        if total > 0.0 {
            self.frames.len() as f64 / (total / 1e3)
        } else {
            0.0
        }
    }

    fn per_frame(&self, f: impl Fn(&PlayedFrame) -> f64) -> f64 {
        if self.frames.is_empty() {
            return 0.0;
        }
        self.frames.iter().map(f).sum::<f64>() / self.frames.len() as f64
    }

    /// Mean queue submissions per frame (0 without frames).
    pub fn submits_per_frame(&self) -> f64 {
        self.per_frame(|f| f64::from(f.submits))
    }

    /// Mean bytes read back with a wait per frame (0 without frames).
    pub fn readback_bytes_per_frame(&self) -> f64 {
        self.per_frame(|f| f.readback_bytes as f64)
    }

    /// Mean bytes uploaded per frame (0 without frames).
    pub fn upload_bytes_per_frame(&self) -> f64 {
        self.per_frame(|f| f.upload_bytes as f64)
    }

    /// Frames in which some light list did not fit.
    pub fn overflow_frames(&self) -> usize {
        self.frames.iter().filter(|f| f.overflowed).count()
    }

    /// Frames with at least one shader loop cut short.
    pub fn truncated_frames(&self) -> usize {
        self.frames.iter().filter(|f| f.truncated_loops > 0).count()
    }
}

/// What to play.
pub struct PlayPlan<'a> {
    /// The scene whose animation is played.
    pub scene: &'a Scene,
    /// Id of the pipeline to render with.
    pub pipeline: &'a str,
    /// Animation frames, in order; played `passes` times.
    pub frames: &'a [u32],
    /// How many times `frames` is played through (at least 1).
    pub passes: u32,
    /// Frames played first and not recorded (cycling through `frames`): shader compilation,
    /// list growth, and a full queue of frames in flight when the measurement starts.
    pub warmup: u32,
}

/// Render `plan` back to back on the real-time path. `stop` is polled between frames;
/// `progress(done, total)` is called after each submission.
pub fn play(
    renderer: &mut Renderer,
    plan: &PlayPlan,
    stop: &AtomicBool,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<PlayRun> {
    if plan.frames.is_empty() || plan.passes == 0 {
        return Err(Error::invalid("frames", "nothing to play"));
    }
    // Frames of an earlier use of the renderer are not this run's.
    renderer.finish()?;
    for &frame in plan.frames {
        plan.scene.check_frame(frame)?;
    }
    // The scene once; each frame is then its state (as a game's frame would be).
    renderer.use_scene(plan.scene)?;
    for &frame in plan.frames.iter().cycle().take(plan.warmup as usize) {
        if stop.load(Ordering::Relaxed) {
            return Ok(PlayRun {
                interrupted: true,
                ..Default::default()
            });
        }
        renderer.render_frame(&plan.scene.frame(frame), plan.pipeline)?;
        renderer.poll_finished()?;
    }
    let total = plan.frames.len() as u64 * u64::from(plan.passes);
    let mut run = PlayRun::default();
    let mut first_serial = None;
    let mut finished: Vec<FinishedFrame> = Vec::new();
    let mut last_start = Instant::now();
    'passes: for pass in 0..plan.passes {
        for &frame in plan.frames {
            if stop.load(Ordering::Relaxed) {
                run.interrupted = true;
                break 'passes;
            }
            let now = Instant::now();
            if let Some(prev) = run.frames.last_mut() {
                prev.frame_ms = (now - last_start).as_secs_f64() * 1e3;
            }
            last_start = now;
            let s = renderer.render_frame(&plan.scene.frame(frame), plan.pipeline)?;
            first_serial.get_or_insert(s.serial);
            run.frames.push(PlayedFrame {
                frame,
                pass,
                frame_ms: 0.0,
                gpu_ms: None,
                passes: Vec::new(),
                throttle_ms: s.throttle_ms,
                cpu_wait_ms: s.io.cpu_wait_ms,
                submits: s.io.submits,
                readback_bytes: s.io.readback_bytes,
                upload_bytes: s.upload_bytes,
                overflowed: false,
                truncated_loops: 0,
            });
            finished.extend(renderer.poll_finished()?);
            progress(run.frames.len() as u64, total);
        }
    }
    // The last frame's period: draining the queue finishes every frame still in flight.
    let draining = renderer.frames_in_flight().max(1);
    finished.extend(renderer.finish()?);
    let end = Instant::now();
    if let Some(prev) = run.frames.last_mut() {
        prev.frame_ms = (end - last_start).as_secs_f64() * 1e3 / draining as f64;
    }
    // The renderer numbers its frames one after another: frame i of the run is serial first + i.
    let first = first_serial.unwrap_or(0);
    for f in finished {
        let at = f.serial.checked_sub(first);
        if let Some(p) = at.and_then(|i| run.frames.get_mut(i as usize)) {
            p.gpu_ms = f.gpu_ms;
            p.passes = f.passes;
            p.overflowed = f.overflowed;
            p.truncated_loops = f.truncated_loops;
        }
    }
    Ok(run)
}
