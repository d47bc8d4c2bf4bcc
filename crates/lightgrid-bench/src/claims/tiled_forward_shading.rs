//! Claims of tiled-forward-shading: the plain case, MSAA and the
//! Z-reduction (Fig. 4.1, §4.6), depth bounds (§4.4), clusters against tiles (Fig. 4.6) and
//! light ranges (Fig. 4.2(a)).

use super::*;
use lightgrid::pipelines::ids;

/// 7. Tiled deferred vs tiled forward in the plain case.
pub(super) fn plain_case(r: &BenchResults, scene: &str) -> (String, Verdict) {
    match (
        find(r, scene, ids::TILED_DEFERRED, None).and_then(avg_ms),
        find(r, scene, ids::TILED_FORWARD_PREZ, None).and_then(avg_ms),
    ) {
        (Some(td), Some(tf)) => (
            format!("avg ms: tiled_deferred {td:.1}, tiled_forward_prez {tf:.1}"),
            verdict(td < tf),
        ),
        _ => missing(),
    }
}

/// 9. MSAA: hardware MSAA in forward against per-sample deferred shading.
pub(super) fn msaa_forward_faster(r: &BenchResults, scene: &str) -> (String, Verdict) {
    match (
        find_msaa(r, scene, ids::TILED_DEFERRED, None, 4).and_then(avg_ms),
        find_msaa(r, scene, ids::TILED_FORWARD_PREZ, None, 4).and_then(avg_ms),
    ) {
        (Some(td), Some(tf)) => {
            let ratio = td / tf.max(1e-9);
            (
                format!(
                    "avg ms at 4x MSAA: tiled_deferred {td:.1}, tiled_forward_prez {tf:.1}: forward {ratio:.3}x faster{}",
                    if ratio > 2.0 { " (beyond the paper's 2x)" } else { "" }
                ),
                verdict(ratio >= 1.5),
            )
        }
        _ => missing(),
    }
}

/// 10. The Z-reduction over every sample scales with the sample count.
pub(super) fn z_reduction_scales(r: &BenchResults, scene: &str) -> (String, Verdict) {
    let mut reduction: Vec<(u32, f64)> = r
        .runs
        .iter()
        .filter(|x| x.scene == scene && x.pipeline == ids::TILED_FORWARD_PREZ)
        .filter_map(|x| Some((x.msaa(), cell_bounds_ms(x)?)))
        .collect();
    reduction.sort_by_key(|&(n, _)| n);
    match (reduction.first(), reduction.last()) {
        (Some(&(1, one)), Some(&(n, most))) if n > 1 => {
            let list: Vec<String> = reduction
                .iter()
                .map(|(n, ms)| format!("{n}x {ms:.2} ms"))
                .collect();
            let growth = most / one.max(1e-9);
            (
                format!(
                    "tiled_forward_prez cell bounds over every sample: {} ({growth:.1}x for {n}x the samples)",
                    list.join(", ")
                ),
                verdict(growth >= f64::from(n) / 2.0),
            )
        }
        _ => missing(),
    }
}

/// tiled-forward-shading Fig. 4.2(a) over a `--range-scale` sweep: as the lights grow, the
/// tiles list more of them until tiling culls nothing, and the gain over brute force shrinks.
pub(super) fn range_claims(r: &BenchResults) -> Vec<Claim> {
    use crate::run::RANGE_SUFFIX;
    let mut bases: Vec<&str> = r
        .runs
        .iter()
        .filter_map(|x| x.scene.split_once(RANGE_SUFFIX).map(|(b, _)| b))
        .collect();
    bases.dedup();
    let mut out = Vec::new();
    for base in bases {
        // (factor, run name) in factor order.
        let mut scenes: Vec<(f64, String)> = r
            .runs
            .iter()
            .filter_map(|x| {
                let f = x.scene.strip_prefix(base)?.strip_prefix(RANGE_SUFFIX)?;
                Some((f.parse::<f64>().ok()?, x.scene.clone()))
            })
            .collect();
        scenes.sort_by(|a, b| a.0.total_cmp(&b.0));
        scenes.dedup();
        let mut listed = Vec::new();
        let mut speedups = Vec::new();
        for (f, scene) in &scenes {
            let tiled = find(r, scene, ids::TILED_DEFERRED, None);
            let share = tiled.and_then(|t| {
                Some(t.summary.as_ref()?.lights_per_tile_avg? / f64::from(t.lights?.max(1)))
            });
            if let Some(s) = share {
                listed.push((*f, s));
            }
            let ms = |p| find(r, scene, p, None).and_then(avg_ms);
            if let (Some(fw), Some(t)) = (ms(ids::FORWARD), ms(ids::TILED_DEFERRED)) {
                speedups.push((*f, fw / t.max(1e-9)));
            }
        }
        let name = format!(
            "{base} (light ranges x{})",
            scenes
                .iter()
                .map(|s| s.0.to_string())
                .collect::<Vec<_>>()
                .join(", x")
        );
        let source = "tiled-forward-shading §4.2, Fig. 4.2(a)";
        let mut claim = |statement, result| out.push(Claim::new(&name, statement, source, result));
        claim(
            "Lights too large leave nothing to cull: as the ranges grow every tile lists more of the lights, until (almost: 90%) all of them",
            if listed.len() >= 2 {
                tiles_fill_up(&listed)
            } else {
                not_measured("tiled_deferred at two or more --range-scale factors")
            },
        );
        claim(
            "The gain of tiled shading over brute force shrinks as the lights grow",
            if speedups.len() >= 2 {
                gain_shrinks(&speedups)
            } else {
                not_measured("forward and tiled_deferred at two or more --range-scale factors")
            },
        );
    }
    out
}

/// The share of all lights an average tile lists, per range factor: it must not fall as the
/// factor grows (within 2%), and reach [`ALL_LIGHTS`] at the largest.
pub fn tiles_fill_up(share: &[(f64, f64)]) -> (String, Verdict) {
    let rising = share.windows(2).all(|w| w[1].1 >= w[0].1 * 0.98);
    let last = share.last().map_or(0.0, |s| s.1);
    (
        format!(
            "lights per tile / all lights: {}",
            share
                .iter()
                .map(|(f, s)| format!("x{f} {:.1}%", s * 100.0))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        verdict(rising && last >= ALL_LIGHTS),
    )
}

/// "Almost all" the lights of the scene in an average tile's list.
pub const ALL_LIGHTS: f64 = 0.9;

/// The speed-up of tiled deferred over forward, per range factor: it must not grow as the
/// factor grows (within 5%: frame-time noise).
pub fn gain_shrinks(speedup: &[(f64, f64)]) -> (String, Verdict) {
    let falling = speedup.windows(2).all(|w| w[1].1 <= w[0].1 * 1.05);
    (
        format!(
            "forward ms / tiled_deferred ms: {}",
            speedup
                .iter()
                .map(|(f, s)| format!("x{f} {s:.1}x"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        verdict(falling),
    )
}

/// tiled-forward-shading §4.4's steps (no pre-Z → pre-Z → pre-Z + depth bounds: 22.4 →
/// 15.6 → 10.9 ms) and its remark (§4.4, §4.8) that one side of the bounds can be enough;
/// for the scenes of a run that measured more than one `--depth-bounds`.
pub(super) fn depth_bound_claims(r: &BenchResults) -> Vec<Claim> {
    let mut scenes: Vec<&str> = r
        .runs
        .iter()
        .filter(|x| x.varied::<lightgrid::frame::DepthBounds>().is_some())
        .map(|x| x.scene.as_str())
        .collect();
    scenes.dedup();
    let mut out = Vec::new();
    for scene in scenes {
        let ms = |p: &str, b| find_bounds(r, scene, p, b).and_then(avg_ms);
        let source = "tiled-forward-shading §4.4";
        let mut claim = |statement, result| out.push(Claim::new(scene, statement, source, result));
        claim(
            "A depth pre-pass alone makes tiled forward shading faster (22.4 → 15.6 ms)",
            match (
                find(r, scene, ids::TILED_FORWARD, None).and_then(avg_ms),
                ms(ids::TILED_FORWARD_PREZ, DepthBounds::None),
            ) {
                (Some(no_prez), Some(prez)) => faster(
                    "tiled_forward_prez [bounds none]",
                    prez,
                    ids::TILED_FORWARD,
                    no_prez,
                ),
                _ => not_measured("tiled_forward and tiled_forward_prez --depth-bounds none"),
            },
        );
        claim(
            "Depth bounds after the pre-pass make it faster again (15.6 → 10.9 ms)",
            match (
                ms(ids::TILED_FORWARD_PREZ, DepthBounds::None),
                ms(ids::TILED_FORWARD_PREZ, DepthBounds::Both),
            ) {
                (Some(none), Some(both)) => faster(
                    "tiled_forward_prez [bounds both]",
                    both,
                    "tiled_forward_prez [bounds none]",
                    none,
                ),
                _ => not_measured("tiled_forward_prez --depth-bounds none,both"),
            },
        );
        for p in [ids::TILED_FORWARD_PREZ, ids::CLUSTERED_FORWARD] {
            claim(
                if p == ids::CLUSTERED_FORWARD {
                    "With clusters too, one side of the depth bounds (min or max only) is enough: within 10% of both (§4.8)"
                } else {
                    "One side of the depth bounds (min or max only) is enough: within 10% of both"
                },
                match (
                    ms(p, DepthBounds::Both),
                    ms(p, DepthBounds::Min),
                    ms(p, DepthBounds::Max),
                ) {
                    (Some(both), Some(min), Some(max)) => one_side_enough(p, both, min, max),
                    _ => not_measured(&format!("{p} --depth-bounds both,min,max")),
                },
            );
        }
    }
    out
}

/// "Enough": one side of the bounds within this factor of both sides' time.
pub const ONE_SIDE_ENOUGH: f64 = 1.10;

/// Is min-only or max-only culling within [`ONE_SIDE_ENOUGH`] of both bounds (avg ms)?
pub fn one_side_enough(pipeline: &str, both: f64, min: f64, max: f64) -> (String, Verdict) {
    let best = min.min(max);
    (
        format!(
            "{pipeline} avg ms: both {both:.2}, min only {min:.2}, max only {max:.2}; the better side is {:.2}x both",
            best / both.max(1e-9)
        ),
        verdict(best <= both * ONE_SIDE_ENOUGH),
    )
}

/// tiled-forward-shading Fig. 4.6's three claims, across random-top and random-fps (the
/// same 1,024 lights and field, top-down and first-person).
pub(super) fn view_dependence(r: &BenchResults) -> Vec<Claim> {
    let (top, fps) = ("random-top", "random-fps");
    let ms = |scene: &str, p: &str| find(r, scene, p, None).and_then(avg_ms);
    let count = |scene: &str, p: &str| find(r, scene, p, None).and_then(avg_count);
    let (tiled, clustered) = (ids::TILED_FORWARD_PREZ, ids::CLUSTERED_FORWARD);
    let mut out = Vec::new();
    let source = "tiled-forward-shading Fig. 4.6";
    let mut claim =
        |scene: &str, statement, result| out.push(Claim::new(scene, statement, source, result));
    if r.runs.iter().any(|x| x.scene == top) {
        claim(
            top,
            "In the top-down view tiled forward outperforms clustered forward (6.6 vs 9.3 ms)",
            match (ms(top, tiled), ms(top, clustered)) {
                (Some(t), Some(c)) => faster(ids::TILED_FORWARD_PREZ, t, ids::CLUSTERED_FORWARD, c),
                _ => not_measured("tiled_forward_prez and clustered_forward"),
            },
        );
    }
    if r.runs.iter().any(|x| x.scene == fps) {
        claim(
            fps,
            "In the first-person view tiled forward becomes slower than clustered forward (9.4 vs 9.1 ms)",
            match (ms(fps, tiled), ms(fps, clustered)) {
                (Some(t), Some(c)) => faster(ids::CLUSTERED_FORWARD, c, ids::TILED_FORWARD_PREZ, t),
                _ => not_measured("tiled_forward_prez and clustered_forward"),
            },
        );
    }
    let both = r.runs.iter().any(|x| x.scene == top) && r.runs.iter().any(|x| x.scene == fps);
    if both {
        let pair = |p| Some((count(top, p)?, count(fps, p)?));
        claim(
            "random-top vs random-fps",
            "Clustered shading depends much less on the view than tiled shading",
            match (pair(tiled), pair(clustered)) {
                (Some(t), Some(c)) => less_view_dependent(t, c),
                _ => not_measured("tiled_forward_prez and clustered_forward on both views"),
            },
        );
    }
    out
}

/// Is `a` faster than `b` (average ms)?
pub fn faster(a: &str, a_ms: f64, b: &str, b_ms: f64) -> (String, Verdict) {
    (
        format!("avg ms: {a} {a_ms:.2}, {b} {b_ms:.2}"),
        verdict(a_ms < b_ms),
    )
}

/// The change of lighting computations from the top-down to the first-person view, (top,
/// fps) for tiled and for clustered: clusters should change less (|ln fps/top| smaller).
pub fn less_view_dependent(tiled: (f64, f64), clustered: (f64, f64)) -> (String, Verdict) {
    let change = |(top, fps): (f64, f64)| fps / top.max(1.0);
    let (t, c) = (change(tiled), change(clustered));
    (
        format!(
            "avg lighting computations first-person / top-down: tiled_forward_prez {t:.2}x ({:.0} / {:.0}), clustered_forward {c:.2}x ({:.0} / {:.0})",
            tiled.1, tiled.0, clustered.1, clustered.0
        ),
        verdict(c.ln().abs() < t.ln().abs()),
    )
}
