//! The benchmark (tiled-shading §8, forward-plus §5): every scene × G-buffer setting ×
//! pipeline over a range of animation frames, recording per frame the GPU time per pass,
//! lighting computations, the ideal count, lights per tile and the memory model; then
//! `report` writes results.json / results.csv / plots / summary.md and `claims` checks the
//! papers' claims against the measurements. `scaling` measures light assignment strategies
//! against the light count; [`advise`] times the candidate configurations of one scene on
//! this adapter and recommends one. [`plot`] draws the charts (plotters, with an embedded font).
//!
//! Everything renders through the `lightgrid` library; this crate only plans, measures and
//! writes.

pub mod advise;
mod claims;
mod outdir;
pub mod plot;
mod report;
mod run;
mod scaling;

pub use claims::{evaluate_claims, Band, Basis, Claim, Threshold, Verdict};
pub use outdir::{
    check_out_dir, manifest_name, Earlier, OutDir, Outcome, LOCK_FILE, MANIFEST_FILE,
    STOPPED_BY_SIGNAL,
};
pub use report::{read_results, write_report, REPORT_FILES, SCHEMA_VERSION};
pub use run::{
    prepare, run, AxisValues, BenchConfig, BenchResults, FrameRange, FrameRecord, PreparedBench,
    Progress, RunRecord, RunSummary, SpotRayTest, TimesFrom, SOURCES, SPOTS_SUFFIX,
};
pub use scaling::{
    run_scaling, scaling_growth, scaling_table, write_scaling, ScalingConfig, ScalingPoint,
    ScalingResults, SCALING_FILES,
};

/// `lightgrid::Error::Invalid` with a reason (the library's own shorthand is crate-private).
pub(crate) fn invalid(what: &'static str, reason: impl Into<String>) -> lightgrid::Error {
    lightgrid::Error::Invalid {
        what,
        reason: reason.into(),
    }
}

/// Real-time frames played before a series' measured ones, so the measurement starts with
/// a full queue of frames in flight.
pub const PLAY_QUEUE_FILL: u32 = lightgrid::MAX_FRAMES_IN_FLIGHT as u32;

/// Most `--warmup` renders and `--repeat` / `--runs` measurements a run takes: more is hours
/// of rendering on a software adapter for no better median.
pub const MAX_REPEATS: u32 = 1000;
