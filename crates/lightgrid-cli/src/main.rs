//! `lightgrid`: render catalog scenes and glTF files with any registry pipeline, compare images, play
//! animations in real time, benchmark, list what exists. With no arguments it runs the
//! default job: every pipeline on `robots-many`, with each image's difference from the
//! `forward` reference. One module per command.

#[macro_use]
mod out;

mod advise;
mod args;
mod bench;
mod compare;
mod diff;
mod export;
mod files;
mod list;
mod memory;
mod play;
mod render;
mod scaling;
mod view;

use args::{RendererArgs, SceneArgs, Size};
use clap::{Parser, Subcommand};
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "lightgrid",
    version,
    about = "Many-lights renderer: forward, deferred, tiled and clustered shading side by side.\n\nWith no command, runs the default job (`lightgrid compare`): robots-many at 640x360 with every pipeline, images in out/."
)]
struct Cli {
    /// Adapter to use: an index from `lightgrid list`, a backend (vulkan, gl), or part of
    /// the adapter's name (e.g. llvmpipe). Default: the best one (hardware first).
    #[arg(long, global = true)]
    adapter: Option<String>,
    /// For the default job: write into out/ even if it holds files lightgrid did not write
    /// (files of the same names are replaced). Commands take their own --force.
    #[arg(long)]
    force: bool,
    #[command(subcommand)]
    command: Option<Command>,
}

// Parsed once per process: the size of its largest variant (bench's options) costs nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand)]
enum Command {
    /// Render one frame of a scene with one pipeline.
    Render(render::RenderArgs),
    /// Render a frame with every pipeline and compare each with the forward reference.
    Compare(compare::CompareArgs),
    /// Per-pixel difference of two images, in 8-bit sRGB levels of the colour channels; a
    /// difference in alpha is reported beside it (alpha_max), not measured in it.
    Diff(diff::DiffArgs),
    /// Render-target memory and the traffic model of every pipeline at a frame size.
    Memory(memory::MemoryArgs),
    /// Reproduce the papers' evaluations: frame times, lighting computations and memory over
    /// scene animations, written as results.json/.csv, plots and summary.md.
    Bench(bench::BenchArgs),
    /// Rewrite a benchmark's summary.md, results.csv and plots from its results.json (which is
    /// only read, never rewritten).
    Report(bench::ReportArgs),
    /// Light-assignment scaling: assignment time, index-list size and lighting computations
    /// per strategy (cpu, gather, scatter, bvh, bvh-gpu) on `stress` from 1k to 1M lights.
    Scaling(scaling::ScalingArgs),
    /// Play a scene's animation in real time (one submission per frame, no analysis) and
    /// print frames per second and the frame-time distribution.
    Play(play::PlayArgs),
    /// Write a scene at one frame as a glTF 2.0 binary (.glb): geometry, materials,
    /// KHR_lights_punctual lights with their ranges, and the camera.
    Export(export::ExportArgs),
    /// Open the interactive viewer: fly through a scene, switch pipelines and settings live,
    /// see lights per cell, cell depth bounds and wasted work, frame and GPU times.
    View(view::ViewArgs),
    /// Time every pipeline, tile size and assignment strategy on one scene on this adapter
    /// within a budget, and recommend the fastest with its reasons.
    Advise(advise::AdviseArgs),
    /// List adapters, scenes and pipelines.
    List,
}

/// Let a closed stdout end the process quietly, as other command-line tools do
/// (`lightgrid list | head`): Rust ignores SIGPIPE, so `println!` would panic instead.
fn default_sigpipe() {
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of SIGPIPE before any thread is started.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn main() {
    default_sigpipe();
    let cli = Cli::parse();
    if cli.force && cli.command.is_some() {
        eprintln!("error: --force before a command applies to the default job only; give it after the command (lightgrid bench --force ...)");
        std::process::exit(2);
    }
    if let Err(e) = args::handle_signals() {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
    let result = match cli.command {
        None => compare::compare(
            cli.adapter.as_deref(),
            &compare::CompareArgs {
                scene: SceneArgs {
                    options: args::SceneOptions::catalog("robots-many"),
                    frame: compare::DEFAULT_JOB_FRAME,
                    size: Some(Size(640, 360)),
                    renderer: RendererArgs {
                        tile: lightgrid::consts::DEFAULT_TILE_SIZE,
                        axes: Default::default(),
                    },
                    warmup: 1,
                },
                out_dir: PathBuf::from("out"),
                force: cli.force,
            },
        ),
        Some(Command::Render(a)) => render::render(cli.adapter.as_deref(), &a),
        Some(Command::Compare(a)) => compare::compare(cli.adapter.as_deref(), &a),
        Some(Command::Diff(a)) => diff::diff_cmd(&a),
        Some(Command::Memory(a)) => memory::memory(&a),
        Some(Command::Bench(a)) => bench::bench(cli.adapter.as_deref(), &a),
        Some(Command::Report(a)) => bench::report(&a),
        Some(Command::Scaling(a)) => scaling::scaling(cli.adapter.as_deref(), &a),
        Some(Command::Play(a)) => play::play(cli.adapter.as_deref(), &a),
        Some(Command::Export(a)) => export::export(&a),
        Some(Command::View(a)) => view::view(cli.adapter.as_deref(), &a),
        Some(Command::Advise(a)) => advise::advise(cli.adapter.as_deref(), &a),
        Some(Command::List) => list::list(),
    };
    // Output still buffered must reach stdout, or the command fails saying so.
    let result = result.and_then(|()| out::flush());
    if let Err(e) = result {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
