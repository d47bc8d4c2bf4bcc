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
//! - Drobot 2017, "Improved culling for tiled and clustered rendering" (`--assign zbin`
//!   against the clustered grid the default strategy builds, clustered pipelines): z-binning's
//!   per-tile light masks and depth bins are at least as tight as clusters, in no more memory.

use super::{differs_only_in, verdict, BenchResults, Claim, RunRecord, Threshold, Verdict};
use lightgrid::frame::{Assign, CellBox, DepthMask};
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
    out.extend(
        pairs::<Assign>(r, Assign::Auto, Assign::ZBin, clustered)
            .into_iter()
            .map(|(clusters, zbins)| {
                Claim::new(
                    clusters.scene.as_str(),
                    "Z-binning (lights sorted by depth, per-bin index ranges, per-tile light masks) is at least as tight as clusters, in no more memory",
                    "Drobot 2017, \"Improved culling for tiled and clustered rendering\"",
                    Threshold::Rule(AS_TIGHT),
                    as_tight_in_no_more_memory(
                        &clusters.pipeline,
                        [computations(clusters), computations(zbins)],
                        [grid_bytes(clusters), grid_bytes(zbins)],
                    ),
                )
            }),
    );
    out
}

/// "As tight in no more memory": z-binning against clusters.
pub const AS_TIGHT: &str = "\"as tight\": z-binning's lighting computations at most the clusters', summed over the same frames, and its grid's bytes (mean over the frames) at most theirs";

/// Did z-binning (`[clusters, zbins]`) evaluate no more lights than clusters in no more grid
/// memory ([`AS_TIGHT`])?
pub fn as_tight_in_no_more_memory(
    pipeline: &str,
    [c, z]: [Option<u64>; 2],
    [cb, zb]: [Option<u64>; 2],
) -> (String, Verdict) {
    let (Some(c), Some(z), Some(cb), Some(zb)) = (c, z, cb, zb) else {
        return super::not_measured("the lighting computations and grid bytes of both runs");
    };
    let ratio = z as f64 / (c as f64).max(1.0);
    (
        format!(
            "{pipeline}: {z} lighting computations with z-bins, {c} with clusters ({ratio:.3}x); grid {:.1} KiB against {:.1} KiB",
            zb as f64 / 1024.0,
            cb as f64 / 1024.0
        ),
        verdict(c > 0 && z <= c && zb <= cb),
    )
}

/// The run's grid bytes, mean over its frames (None when any frame lacks them).
fn grid_bytes(x: &RunRecord) -> Option<u64> {
    let sum: Option<u64> = x.frames.iter().map(|f| f.stats.memory.grid_bytes).sum();
    sum.map(|s| s / (x.frames.len() as u64).max(1))
}

/// Runs of the setting `T` at `off` (with `keep`, and the other per-sample culling setting
/// off) paired with the run that differs only in `T` being `on`.
fn pairs<T: SettingValue + PartialEq>(
    r: &BenchResults,
    off: T,
    on: T,
    keep: fn(&RunRecord) -> bool,
) -> Vec<(&RunRecord, &RunRecord)> {
    // The other settings off: each claim compares one technique against the plain grid.
    let plain = |x: &RunRecord| {
        let mask_off = T::FLAG == DepthMask::FLAG || x.settings.grid.depth_mask == DepthMask::Off;
        let box_off = T::FLAG == CellBox::FLAG || x.settings.grid.cell_box == CellBox::Off;
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

    #[test]
    fn z_binning_holds_only_as_tight_and_no_larger() {
        let held = |c, z, cb, zb| as_tight_in_no_more_memory("p", [c, z], [cb, zb]).1;
        assert_eq!(
            held(Some(100), Some(100), Some(10), Some(10)),
            Verdict::Held
        );
        assert_eq!(held(Some(100), Some(80), Some(10), Some(5)), Verdict::Held);
        // Looser, or larger, or both.
        assert_eq!(
            held(Some(100), Some(101), Some(10), Some(5)),
            Verdict::NotHeld
        );
        assert_eq!(
            held(Some(100), Some(80), Some(10), Some(11)),
            Verdict::NotHeld
        );
        assert_eq!(held(Some(0), Some(0), Some(10), Some(5)), Verdict::NotHeld);
        assert_eq!(
            held(Some(100), Some(80), None, Some(5)),
            Verdict::NotMeasured
        );
        let (evidence, _) =
            as_tight_in_no_more_memory("c", [Some(200), Some(150)], [Some(2048), Some(1024)]);
        assert!(
            evidence.contains("0.750x") && evidence.contains("1.0 KiB against 2.0 KiB"),
            "{evidence}"
        );
    }
}
