//! Arguments and helpers every command shares: frame size, scene and renderer settings,
//! `--assign` values, Ctrl-C handling and the progress bar.

use anyhow::{Context, Result};
use clap::Args;
use lightgrid::passes::GBufferFormat;
use lightgrid::scene::catalog::{self, SceneParams};
use lightgrid::RenderSettings;

/// `--assign` values.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub(crate) enum AssignArg {
    /// On a software adapter (lavapipe) cpu at every light count (measured fastest there from
    /// 1k to 1M lights); on a hardware GPU gather up to 8192 lights, bvh-gpu above.
    Auto,
    /// On the CPU: projected sphere rectangles, per-cell depth test; grid uploaded.
    Cpu,
    /// GPU: one workgroup per cell tests every light.
    Gather,
    /// GPU: one thread per light emits (cell, light) pairs, radix-sorted by cell.
    Scatter,
    /// Light hierarchy built on the CPU each frame, walked per cell on the GPU.
    Bvh,
    /// Light hierarchy built on the GPU each frame (Morton codes, radix sort), walked as bvh.
    BvhGpu,
}

impl From<AssignArg> for lightgrid::pipelines::Assign {
    fn from(a: AssignArg) -> Self {
        use lightgrid::pipelines::Assign;
        match a {
            AssignArg::Auto => Assign::Auto,
            AssignArg::Cpu => Assign::Cpu,
            AssignArg::Gather => Assign::Gather,
            AssignArg::Scatter => Assign::Scatter,
            AssignArg::Bvh => Assign::Bvh,
            AssignArg::BvhGpu => Assign::BvhGpu,
        }
    }
}

/// Frame size as WIDTHxHEIGHT.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Size(pub(crate) u32, pub(crate) u32);

impl Size {
    /// `size`, or the scene's own frame size when none was given.
    pub(crate) fn or_scene(size: Option<Size>, scene: &lightgrid::scene::Scene) -> (u32, u32) {
        let Size(w, h) = size.unwrap_or(Size(scene.default_size.0, scene.default_size.1));
        (w, h)
    }
}

pub(crate) fn parse_size(s: &str) -> Result<Size, String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("'{s}' is not WIDTHxHEIGHT (e.g. 640x360)"))?;
    let edge = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|_| format!("'{v}' in '{s}' is not a positive whole number"))
    };
    let (w, h) = (edge(w)?, edge(h)?);
    if w == 0 || h == 0 {
        return Err(format!("{w}x{h}: both edges must be at least 1"));
    }
    Ok(Size(w, h))
}

#[derive(Args, Clone)]
pub(crate) struct SceneArgs {
    /// Scene from the catalog (see `lightgrid list`).
    #[arg(long, default_value = "robots-many")]
    pub(crate) scene: String,
    /// Animation frame to render.
    #[arg(long, default_value_t = 0)]
    pub(crate) frame: u32,
    /// Frame size WIDTHxHEIGHT (default: the scene's own size).
    #[arg(long, value_parser = parse_size)]
    pub(crate) size: Option<Size>,
    /// Light count, for scenes that take one (stress: 1 to 1000000).
    #[arg(long)]
    pub(crate) lights: Option<u32>,
    /// Seed of the scene's random placement.
    #[arg(long, default_value_t = 1)]
    pub(crate) seed: u64,
    /// Screen tile edge in pixels for grid pipelines (4 to 64).
    #[arg(long, default_value_t = lightgrid::consts::DEFAULT_TILE_SIZE)]
    pub(crate) tile: u32,
    /// View-depth slices of clustered pipelines (exponential spacing, 1 to 256).
    #[arg(long, default_value_t = lightgrid::consts::DEFAULT_SLICES)]
    pub(crate) slices: u32,
    /// Who builds the light grid of grid pipelines (tiled_deferred_single culls inside its
    /// kernel and ignores this).
    #[arg(long, value_enum, default_value = "auto")]
    pub(crate) assign: AssignArg,
    /// G-buffer channel precision in bits for deferred pipelines.
    #[arg(long, default_value = "16", value_parser = parse_gbuffer)]
    pub(crate) gbuffer: GBufferFormat,
    /// Frames rendered and discarded before the measured one (drivers such as lavapipe compile
    /// shaders at first use, inside the first frame's GPU time).
    #[arg(long, default_value_t = 1)]
    pub(crate) warmup: u32,
}

pub(crate) fn parse_gbuffer(s: &str) -> Result<GBufferFormat, String> {
    match s {
        "16" => Ok(GBufferFormat::F16),
        "32" => Ok(GBufferFormat::F32),
        _ => Err(format!("'{s}': the G-buffer is 16 or 32 bits per channel")),
    }
}

impl SceneArgs {
    pub(crate) fn settings(&self) -> RenderSettings {
        RenderSettings {
            tile_size: self.tile,
            gbuffer: self.gbuffer,
            slices: self.slices,
            assign: self.assign.into(),
        }
    }
}

pub(crate) fn build_scene(a: &SceneArgs) -> Result<lightgrid::scene::Scene> {
    let params = SceneParams {
        seed: a.seed,
        lights: a.lights,
    };
    Ok(catalog::build(&a.scene, &params)?)
}

pub(crate) fn timing_label(t: lightgrid::TimingSource) -> &'static str {
    match t {
        lightgrid::TimingSource::GpuTimestamps => "GPU timestamps",
        lightgrid::TimingSource::WallClock => "wall clock",
    }
}

pub(crate) fn format_duration(secs: f64) -> String {
    let s = secs.max(0.0).round() as u64;
    if s >= 3600 {
        format!("{}h{:02}m", s / 3600, (s % 3600) / 60)
    } else if s >= 60 {
        format!("{}m{:02}s", s / 60, s % 60)
    } else {
        format!("{s}s")
    }
}

/// A flag set by the first Ctrl-C (long runs stop after the current frame and keep their
/// results); a second Ctrl-C exits at once.
pub(crate) fn stop_on_ctrl_c() -> Result<std::sync::Arc<std::sync::atomic::AtomicBool>> {
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let flag = stop.clone();
    ctrlc::set_handler(move || {
        if flag.swap(true, std::sync::atomic::Ordering::SeqCst) {
            std::process::exit(130);
        }
        eprintln!("\nstopping after the current frame (Ctrl-C again to abort without writing)...");
    })
    .context("cannot install the Ctrl-C handler")?;
    Ok(stop)
}

/// A progress bar with an ETA on stderr: redrawn in place at most every 200 ms on a terminal,
/// a plain log line every 10 s when stderr is a file or a pipe (no `\r` in logs).
pub(crate) fn progress_bar() -> impl FnMut(&lightgrid_bench::Progress) {
    use std::io::IsTerminal;
    // On a terminal one line redrawn in place; in a log, a plain line every 10 seconds.
    let terminal = std::io::stderr().is_terminal();
    let every = std::time::Duration::from_millis(if terminal { 200 } else { 10_000 });
    let start = std::time::Instant::now();
    let mut last: Option<std::time::Instant> = None;
    move |p: &lightgrid_bench::Progress| {
        let due = last.is_none_or(|t| t.elapsed() >= every);
        if !due && p.done < p.total {
            return;
        }
        last = Some(std::time::Instant::now());
        let frac = p.done as f64 / p.total.max(1) as f64;
        let elapsed = start.elapsed().as_secs_f64();
        let eta = if p.done > 0 {
            format_duration(elapsed / frac - elapsed)
        } else {
            "?".into()
        };
        let label = p.label.chars().take(48).collect::<String>();
        if terminal {
            let filled = (frac * 30.0) as usize;
            eprint!(
                "\r[{}{}] {:>3.0}% {}/{} ETA {:<7} {:<48}",
                "#".repeat(filled),
                " ".repeat(30 - filled),
                frac * 100.0,
                p.done,
                p.total,
                eta,
                label
            );
        } else {
            eprintln!(
                "{:>3.0}% {}/{} ETA {eta} {label}",
                frac * 100.0,
                p.done,
                p.total
            );
        }
    }
}

/// The exit of a long run stopped by Ctrl-C: an error (non-zero status) saying where the
/// partial results are.
pub(crate) fn interrupted_run(interrupted: bool, out: &std::path::Path) -> Result<()> {
    if interrupted {
        anyhow::bail!("interrupted: partial results written to {}", out.display());
    }
    Ok(())
}
