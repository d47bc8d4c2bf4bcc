//! `lightgrid scaling`: light-assignment strategies against the light count.

use crate::args::{
    check_applies, format_duration, parse_non_negative, parse_size, progress_bar, run_outcome,
    setting, stop_on_ctrl_c, Size, MAX_COUNT,
};
use anyhow::Result;
use clap::Args;
use lightgrid::gpu::GpuContext;
use lightgrid::pipelines::ids;
use lightgrid::pipelines::{find_axis, Assign};
use lightgrid_bench::{check_out_dir, OutDir};
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
        value_parser = setting::<Assign>(),
        value_delimiter = ',',
        default_value = "cpu,gather,scatter,bvh,bvh-gpu"
    )]
    pub(crate) assign: Vec<Assign>,
    /// Grid pipeline to render with.
    #[arg(long, default_value = ids::CLUSTERED_DEFERRED)]
    pub(crate) pipeline: String,
    /// Scene with a variable light count.
    #[arg(long, default_value = "stress")]
    pub(crate) scene: String,
    /// Frame size WIDTHxHEIGHT.
    #[arg(long, allow_hyphen_values = true, default_value = "640x360", value_parser = parse_size)]
    pub(crate) size: Size,
    /// Screen tile edge in pixels.
    #[arg(long, allow_hyphen_values = true, default_value_t = lightgrid::consts::DEFAULT_TILE_SIZE)]
    pub(crate) tile: u32,
    /// View-depth slices of clustered pipelines (1 to 256) [default: 32].
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) slices: Option<u32>,
    #[arg(long, allow_hyphen_values = true, default_value_t = 1)]
    pub(crate) seed: u64,
    /// Measured renders per point, 1 to 1000 (the median assignment time is kept).
    #[arg(long, allow_hyphen_values = true, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=MAX_COUNT))]
    pub(crate) runs: u32,
    /// Discarded renders before each point (shader compilation, buffer growth), 0 to 1000.
    #[arg(long, allow_hyphen_values = true, default_value_t = 1, value_parser = clap::value_parser!(u32).range(0..=MAX_COUNT))]
    pub(crate) warmup: u32,
    /// A strategy whose assignment takes longer than this many seconds (more than 0) is not
    /// run at larger light counts.
    #[arg(long = "budget", allow_hyphen_values = true, default_value_t = 5.0, value_parser = parse_non_negative)]
    pub(crate) budget_s: f64,
    /// Output directory (created; files an earlier scaling run wrote there and this one does not
    /// are removed, other commands' files are kept; an existing directory lightgrid did not
    /// make must be empty; two runs into one directory at once are refused).
    #[arg(long, default_value = "scaling")]
    pub(crate) out: PathBuf,
    /// Write into an existing directory that lightgrid did not make and that is not empty,
    /// and over files there that lightgrid (or another command of it) did not write.
    #[arg(long)]
    pub(crate) force: bool,
}

pub(crate) fn scaling(adapter: Option<&str>, a: &ScalingArgs) -> Result<()> {
    // Only whether it can be written, here: what the directory holds is checked by the claim
    // below, after the options (which a user fixes first) and before anything is rendered.
    check_out_dir(&a.out, true)?;
    let info = lightgrid::pipelines::find(&a.pipeline)?;
    let given: Vec<_> = a
        .slices
        .iter()
        .filter_map(|_| find_axis("slices"))
        .collect();
    check_applies(&given, &[info], &Default::default())?;
    let config = lightgrid_bench::ScalingConfig {
        scene: a.scene.clone(),
        pipeline: a.pipeline.clone(),
        lights: a.lights.clone(),
        strategies: a.assign.clone(),
        size: (a.size.0, a.size.1),
        tile_size: a.tile,
        slices: a.slices.unwrap_or(lightgrid::consts::DEFAULT_SLICES),
        seed: a.seed,
        runs: a.runs,
        warmup: a.warmup,
        budget_ms: a.budget_s * 1e3,
    };
    config.validate()?;
    let ctx = GpuContext::new(adapter)?;
    let dir = OutDir::claim(&a.out, "scaling", a.force)?;
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
    let written = lightgrid_bench::write_scaling(&results, dir.staging())?;
    crate::files::Files::default().placed("--out", &a.out, &written)?;
    let committed = dir.commit(
        &written,
        lightgrid_bench::Earlier::Remove,
        results.outcome.is_complete(),
    )?;
    outln!("{}", lightgrid_bench::scaling_table(&results));
    outln!("{}", lightgrid_bench::scaling_growth(&results));
    outln!(
        "{} points in {}; {} in {}",
        results.points.len(),
        format_duration(start.elapsed().as_secs_f64()),
        lightgrid_bench::SCALING_FILES.join(", "),
        a.out.display()
    );
    run_outcome(&results.outcome, &a.out, &committed)
}
