//! Culling past the papers (`--preset culling`): what came after them, checked as their own
//! claims are. Each pairs runs that differ only in the one setting (`differs_only_in`) and
//! compares their lighting computations over the same frames.
//!
//! - Harada, McKee and Yang 2012, "A 2.5D culling for Forward+": a tile's 32-bin depth mask
//!   culls the lights floating between the surfaces of a tile that straddles a depth
//!   discontinuity, so tiles list fewer lights (`--depth-mask on` against off, tiled grids).
//! - Tight clusters (Olsson, Billeter and Assarsson 2012 bound each cluster by its samples;
//!   `--cell-box on` against off, clustered grids): the box of a cluster's samples is smaller
//!   than its frustum piece, so clusters list fewer lights.

use super::{differs_only_in, verdict, BenchResults, Claim, RunRecord, Threshold, Verdict};
use lightgrid::frame::{CellBox, DepthMask};
use lightgrid::pipelines::SettingValue;

/// "Fewer": the culled run's lighting computations below the plain run's.
pub const FEWER: &str =
    "\"fewer\": lighting computations with ÷ without, summed over the same frames, below 1";

/// The claims of the runs `r` holds in pairs (a setting's `off` and `on` runs of one series).
pub(super) fn culling_claims(r: &BenchResults) -> Vec<Claim> {
    let mut out = pairs::<DepthMask>(r, DepthMask::Off, DepthMask::On, |x| !clustered(x))
        .into_iter()
        .map(|(off, on)| {
            Claim::new(
                off.scene.as_str(),
                "2.5D culling (a 32-bit mask of each tile's depth bins holding samples) reduces the lighting computations of tiles with depth discontinuities",
                "Harada et al. 2012, \"A 2.5D culling for Forward+\"",
                Threshold::Rule(FEWER),
                fewer(&off.pipeline, "masks", computations(off), computations(on)),
            )
        })
        .collect::<Vec<_>>();
    out.extend(
        pairs::<CellBox>(r, CellBox::Off, CellBox::On, clustered)
            .into_iter()
            .map(|(off, on)| {
                Claim::new(
                    off.scene.as_str(),
                    "Tight clusters (each cluster bounded by the box of its own samples) list fewer lights than clusters bounded by their frustum pieces",
                    "Olsson, Billeter and Assarsson 2012 (cluster bounds from the samples)",
                    Threshold::Rule(FEWER),
                    fewer(&off.pipeline, "boxes", computations(off), computations(on)),
                )
            }),
    );
    out
}

/// Runs of the setting `T` at `off` (with `keep`, and the other per-sample culling setting
/// off) paired with the run that differs only in `T` being `on`.
fn pairs<T: SettingValue + PartialEq>(
    r: &BenchResults,
    off: T,
    on: T,
    keep: fn(&RunRecord) -> bool,
) -> Vec<(&RunRecord, &RunRecord)> {
    // The other setting off: each claim compares one technique against the plain grid.
    let plain = |x: &RunRecord| {
        let mask_off = T::FLAG == DepthMask::FLAG || x.settings.depth_mask == DepthMask::Off;
        let box_off = T::FLAG == CellBox::FLAG || x.settings.cell_box == CellBox::Off;
        mask_off && box_off
    };
    r.runs
        .iter()
        .filter(|x| x.varied::<T>() == Some(off) && keep(x) && plain(x))
        .filter_map(|x| {
            let y = r
                .runs
                .iter()
                .find(|y| y.varied::<T>() == Some(on) && differs_only_in::<T>(x, y))?;
            Some((x, y))
        })
        .collect()
}

/// Is the run's pipeline a clustered one (the registry's `clustered`)?
fn clustered(x: &RunRecord) -> bool {
    lightgrid::pipelines::find(&x.pipeline).is_ok_and(|p| p.clustered)
}

/// The run's lighting computations summed over its frames (None when any frame lacks them).
fn computations(x: &RunRecord) -> Option<u64> {
    x.frames.iter().map(|f| f.stats.lighting_computations).sum()
}

/// Did `with` come out fewer than `without` ([`FEWER`])?
pub fn fewer(
    pipeline: &str,
    what: &str,
    without: Option<u64>,
    with: Option<u64>,
) -> (String, Verdict) {
    let (Some(a), Some(b)) = (without, with) else {
        return super::not_measured("the lighting computations of both runs");
    };
    let ratio = b as f64 / (a as f64).max(1.0);
    (
        format!("{pipeline}: {b} lighting computations with {what}, {a} without ({ratio:.3}x)"),
        verdict(a > 0 && b < a),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fewer_holds_only_below_the_plain_count() {
        assert_eq!(fewer("p", "masks", Some(100), Some(90)).1, Verdict::Held);
        assert_eq!(
            fewer("p", "masks", Some(100), Some(100)).1,
            Verdict::NotHeld
        );
        assert_eq!(
            fewer("p", "masks", Some(100), Some(120)).1,
            Verdict::NotHeld
        );
        assert_eq!(fewer("p", "masks", Some(0), Some(0)).1, Verdict::NotHeld);
        assert_eq!(fewer("p", "masks", None, Some(1)).1, Verdict::NotMeasured);
        assert!(fewer("tiled_deferred", "boxes", Some(200), Some(150))
            .0
            .contains("0.750x"));
    }
}
