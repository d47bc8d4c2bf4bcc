//! `lightgrid scaling`: light-assignment strategies against the light count.

use crate::args::{
    format_duration, interrupted_run, parse_size, progress_bar, stop_on_ctrl_c, AssignArg, Size,
};
use anyhow::{Context, Result};
use clap::Args;
use lightgrid::gpu::GpuContext;
use lightgrid::image_io::check_writable;
use std::path::PathBuf;

#[derive(Args)]
pub(crate) struct ScalingArgs {
    /// Light counts to measure.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "1000,4000,16000,64000,256000,1000000"
    )]
    pub(crate) lights: Vec<u32>,
    /// Strategies to measure.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "cpu,gather,scatter,bvh,bvh-gpu"
    )]
    pub(crate) assign: Vec<AssignArg>,
    /// Grid pipeline to render with.
    #[arg(long, default_value = "clustered_deferred")]
    pub(crate) pipeline: String,
    /// Scene with a variable light count.
    #[arg(long, default_value = "stress")]
    pub(crate) scene: String,
    /// Frame size WIDTHxHEIGHT.
    #[arg(long, default_value = "640x360", value_parser = parse_size)]
    pub(crate) size: Size,
    /// Screen tile edge in pixels.
    #[arg(long, default_value_t = lightgrid::consts::DEFAULT_TILE_SIZE)]
    pub(crate) tile: u32,
    /// View-depth slices of clustered pipelines.
    #[arg(long, default_value_t = lightgrid::consts::DEFAULT_SLICES)]
    pub(crate) slices: u32,
    #[arg(long, default_value_t = 1)]
    pub(crate) seed: u64,
    /// Measured renders per point (the median assignment time is kept).
    #[arg(long, default_value_t = 1)]
    pub(crate) runs: u32,
    /// Discarded renders before each point (shader compilation, buffer growth).
    #[arg(long, default_value_t = 1)]
    pub(crate) warmup: u32,
    /// A strategy whose assignment takes longer than this many seconds is not run at larger
    /// light counts.
    #[arg(long = "budget", default_value_t = 5.0)]
    pub(crate) budget_s: f64,
    /// Output directory.
    #[arg(long, default_value = "scaling")]
    pub(crate) out: PathBuf,
}

pub(crate) fn scaling(adapter: Option<&str>, a: &ScalingArgs) -> Result<()> {
    std::fs::create_dir_all(&a.out)
        .with_context(|| format!("cannot create {}", a.out.display()))?;
    check_writable(&a.out.join("scaling.json"))?;
    let config = lightgrid_bench::ScalingConfig {
        scene: a.scene.clone(),
        pipeline: a.pipeline.clone(),
        lights: a.lights.clone(),
        strategies: a.assign.iter().map(|&s| s.into()).collect(),
        size: (a.size.0, a.size.1),
        tile_size: a.tile,
        slices: a.slices,
        seed: a.seed,
        runs: a.runs,
        warmup: a.warmup,
        budget_ms: a.budget_s * 1e3,
    };
    config.validate()?;
    let ctx = GpuContext::new(adapter)?;
    let stop = stop_on_ctrl_c()?;
    eprintln!(
        "light assignment scaling on {}: {} at {}x{}, {} light counts x {} strategies, writing to {}",
        ctx.adapter_label(),
        config.pipeline,
        a.size.0,
        a.size.1,
        config.lights.len(),
        config.strategies.len(),
        a.out.display()
    );
    let start = std::time::Instant::now();
    let mut progress = progress_bar();
    let mut results = lightgrid_bench::run_scaling(&ctx, &config, &stop, &mut progress)?;
    eprintln!();
    results.command = std::env::args().collect::<Vec<_>>().join(" ");
    lightgrid_bench::write_scaling(&results, &a.out)?;
    println!("{}", lightgrid_bench::scaling_table(&results));
    println!("{}", lightgrid_bench::scaling_growth(&results));
    println!(
        "{} points in {}; {} in {}",
        results.points.len(),
        format_duration(start.elapsed().as_secs_f64()),
        lightgrid_bench::SCALING_FILES.join(", "),
        a.out.display()
    );
    interrupted_run(results.interrupted, &a.out)
}
