//! `lightgrid play`: a scene's animation rendered back to back on the real-time path (one
//! queue submission per frame, frames in flight, no analysis), with frames per second and
//! the frame-time distribution (`lightgrid::realtime`).

use crate::args::{
    check_applies, parse_size, progress_bar, stop_on_ctrl_c, RendererArgs, SceneOptions, Size,
    MAX_COUNT,
};
use crate::files::{Files, Kind};
use anyhow::{bail, Result};
use clap::Args;
use lightgrid::gpu::GpuContext;
use lightgrid::image_io::write_atomic;
use lightgrid::pipelines::{self, REFERENCE};
use lightgrid::realtime::{play as play_frames, PlayPlan, PlayRun};
use lightgrid::Distribution;
use lightgrid::Renderer;
use lightgrid_bench::{FrameRange, Progress};
use serde::Serialize;
use std::path::PathBuf;

#[derive(Args)]
pub(crate) struct PlayArgs {
    #[command(flatten)]
    pub(crate) scene: SceneOptions,
    /// Pipeline id (see `lightgrid list`).
    #[arg(long, default_value = REFERENCE)]
    pub(crate) pipeline: String,
    /// Animation frames A..B (inclusive; A..B:STEP or N also work). Default: the whole
    /// animation.
    #[arg(long)]
    pub(crate) frames: Option<String>,
    /// Frame size WIDTHxHEIGHT (default: the scene's own size).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_size)]
    pub(crate) size: Option<Size>,
    /// Passes over the frames, 1 to 1000.
    #[arg(long, allow_hyphen_values = true, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=MAX_COUNT))]
    pub(crate) loops: u32,
    /// Frames rendered first and not measured (shader compilation, list growth), 0 to 1000.
    #[arg(long, allow_hyphen_values = true, default_value_t = 3, value_parser = clap::value_parser!(u32).range(0..=MAX_COUNT))]
    pub(crate) warmup: u32,
    /// Write the results as JSON here.
    #[arg(long)]
    pub(crate) json: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) renderer: RendererArgs,
}

/// The `--json` file.
#[derive(Serialize)]
struct PlayJson<'a> {
    scene: &'a str,
    pipeline: &'a str,
    /// The strategy that built the grid (`auto` resolved); null for pipelines without one.
    assign: Option<&'static str>,
    adapter: String,
    width: u32,
    height: u32,
    /// Frames measured (the animation frames times the loops).
    frames: usize,
    first_frame: u32,
    last_frame: u32,
    loops: u32,
    warmup: u32,
    fps: f64,
    /// Wall time from one frame's start to the next's: what a game would see.
    frame_ms: Option<Distribution>,
    /// GPU time per frame: its submissions' spans of pass timestamps (first pass start to last
    /// pass end), resolved without
    /// waiting; null where the adapter has no timestamps.
    gpu_ms: Option<Distribution>,
    submits_per_frame: f64,
    /// Bytes read back with a wait per frame (0 but for `--assign cpu` with depth bounds).
    readback_bytes_per_frame: f64,
    upload_bytes_per_frame: f64,
    /// Frames whose light lists did not fit (sized from earlier frames; grown after).
    overflow_frames: usize,
    /// Frames with shader loops cut short (wrong frames; `play` exits non-zero).
    truncated_frames: usize,
    interrupted: bool,
    per_frame: &'a [lightgrid::realtime::PlayedFrame],
}

/// `--frames` (every frame of the animation without it), within the scene's animation.
fn frame_range(frames: Option<&str>, scene: &lightgrid::scene::Scene) -> Result<FrameRange> {
    let range = match frames {
        Some(s) => FrameRange::parse(s)?,
        None => FrameRange {
            start: 0,
            end: scene.frame_count() - 1,
            step: 1,
        },
    };
    if range.end >= scene.frame_count() {
        bail!(
            "--frames {}..{}: {} has frames 0..={}",
            range.start,
            range.end,
            scene.name,
            scene.frame_count() - 1
        );
    }
    Ok(range)
}

pub(crate) fn play(adapter: Option<&str>, a: &PlayArgs) -> Result<()> {
    let info = pipelines::find(&a.pipeline)?;
    let settings = a.renderer.settings()?;
    check_applies(&a.renderer.given(), &[info], &settings)?;
    let mut files = Files::default();
    files.output("--json", a.json.as_deref(), Kind::Data)?;
    a.scene.claim(&mut files)?;
    let scene = a.scene.build()?;
    let range = frame_range(a.frames.as_deref(), &scene)?;
    let frames = range.frames(scene.frame_count());
    let ctx = GpuContext::new(adapter)?;
    let (w, h) = Size::or_scene(a.size, &scene);
    let mut renderer = Renderer::new(&ctx, w, h, settings)?;
    let assign = info.assign.then(|| {
        settings
            .grid
            .strategy
            .resolve(scene.lights.len(), ctx.is_software())
            .name()
    });
    let stop = stop_on_ctrl_c()?;
    eprintln!(
        "playing {} frames {}..{} x {} with {}{} at {w}x{h} on {}",
        scene.name,
        range.start,
        range.end,
        a.loops,
        info.id,
        assign.map_or(String::new(), |s| format!(" (assign {s})")),
        ctx.adapter_label()
    );
    let plan = PlayPlan {
        scene: &scene,
        pipeline: info.id,
        frames: &frames,
        passes: a.loops,
        warmup: a.warmup,
    };
    let mut bar = progress_bar();
    let run = play_frames(&mut renderer, &plan, &stop, &mut |done, total| {
        bar(&Progress {
            done,
            total,
            label: format!("{} {}", scene.name, info.id),
        })
    })?;
    eprintln!();
    print_summary(&run)?;
    if let Some(path) = &a.json {
        let json = PlayJson {
            scene: &scene.name,
            pipeline: info.id,
            assign,
            adapter: ctx.adapter_label(),
            width: w,
            height: h,
            frames: run.frames.len(),
            first_frame: range.start,
            last_frame: *frames.last().expect("non-empty"),
            loops: a.loops,
            warmup: a.warmup,
            fps: run.fps(),
            frame_ms: run.frame_ms(),
            gpu_ms: run.gpu_ms(),
            submits_per_frame: run.submits_per_frame(),
            readback_bytes_per_frame: run.readback_bytes_per_frame(),
            upload_bytes_per_frame: run.upload_bytes_per_frame(),
            overflow_frames: run.overflow_frames(),
            truncated_frames: run.truncated_frames(),
            interrupted: run.interrupted,
            per_frame: &run.frames,
        };
        write_atomic(path, &serde_json::to_vec_pretty(&json)?)?;
    }
    if run.truncated_frames() > 0 {
        bail!(
            "{} of {} frames had shader loops cut short by the adapter (their images miss light); \
             use fewer lights, a larger --tile or more --slices, or a hardware GPU",
            run.truncated_frames(),
            run.frames.len()
        );
    }
    if run.interrupted {
        bail!("interrupted after {} frames", run.frames.len());
    }
    Ok(())
}

fn print_summary(run: &PlayRun) -> Result<()> {
    let dist = |d: Option<Distribution>| {
        d.map_or("n/a".into(), |d| {
            format!(
                "mean {:.2}  median {:.2}  p95 {:.2}  max {:.2}",
                d.mean, d.median, d.p95, d.max
            )
        })
    };
    outln!("{} frames, {:.2} fps", run.frames.len(), run.fps());
    outln!("frame ms (wall, frame to frame): {}", dist(run.frame_ms()));
    outln!("GPU ms (timestamp span):          {}", dist(run.gpu_ms()));
    outln!(
        "per frame: {:.2} submissions, {:.0} bytes read back, {:.0} bytes uploaded; {} frames overflowed their lists, {} had truncated loops",
        run.submits_per_frame(),
        run.readback_bytes_per_frame(),
        run.upload_bytes_per_frame(),
        run.overflow_frames(),
        run.truncated_frames()
    );
    Ok(())
}
