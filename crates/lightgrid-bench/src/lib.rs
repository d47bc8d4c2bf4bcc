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
    check_out_dir, manifest_name, Committed, Earlier, OutDir, Outcome, LOCK_FILE, MANIFEST_FILE,
    STOPPED_BY_SIGNAL,
};
pub use report::{read_results, write_derived, write_report, REPORT_FILES, SCHEMA_VERSION};
pub use run::{
    prepare, run, AxisValues, BenchConfig, BenchResults, FrameRange, FrameRecord, PreparedBench,
    Progress, RunRecord, RunSummary, SpotRayTest, TimesFrom, MAX_RANGE_SCALE, SOURCES,
    SPOTS_SUFFIX,
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

/// Refuse a list option whose values would measure one series twice: `key` gives each
/// value's identity (`1` and `1.0` are one number, an alias and its name one setting, two
/// spellings or links of a file one file). The one rule for every list option of `bench`,
/// `scaling` and `memory`.
pub fn check_distinct<T: std::fmt::Display, K: PartialEq>(
    flag: &str,
    values: &[T],
    key: impl Fn(&T) -> K,
) -> lightgrid::Result<()> {
    let keys: Vec<K> = values.iter().map(key).collect();
    for (i, k) in keys.iter().enumerate() {
        if let Some(j) = keys[..i].iter().position(|e| e == k) {
            let (a, b) = (values[j].to_string(), values[i].to_string());
            let what = if a == b {
                format!("{b} is listed twice")
            } else {
                format!("{a} and {b} are the same value")
            };
            return Err(invalid(
                "option list",
                format!("{flag}: {what} (each value names one measured series); give each once"),
            ));
        }
    }
    Ok(())
}

/// Real-time frames played before a series' measured ones, so the measurement starts with
/// a full queue of frames in flight.
pub const PLAY_QUEUE_FILL: u32 = lightgrid::MAX_FRAMES_IN_FLIGHT as u32;

/// Most `--warmup` renders and `--repeat` / `--runs` measurements a run takes: more is hours
/// of rendering on a software adapter for no better median.
pub const MAX_REPEATS: u32 = 1000;
