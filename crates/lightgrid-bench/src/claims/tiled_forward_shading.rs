//! Claims of tiled-forward-shading: the plain case, MSAA and the
//! Z-reduction (Fig. 4.1, §4.6), depth bounds (§4.4), clusters against tiles (Fig. 4.6) and
//! light ranges (Fig. 4.2(a)).

use super::*;
use lightgrid::pipelines::ids;

/// "By about 25%": the paper's quarter within ten points either side.
pub const PLAIN_CASE: Band = Band {
    words: "by about 25%",
    quantity: "tiled_forward_prez ÷ tiled_deferred avg ms",
    low: 1.15,
    high: 1.35,
};

/// 7. Tiled deferred vs tiled forward in the plain case.
pub(super) fn plain_case(r: &BenchResults, scene: &str) -> (String, Verdict) {
    match (
        find(r, scene, ids::TILED_DEFERRED, None).and_then(avg_ms),
        find(r, scene, ids::TILED_FORWARD_PREZ, None).and_then(avg_ms),
    ) {
        (Some(td), Some(tf)) => {
            let ratio = tf / td.max(1e-9);
            (
                format!("avg ms: tiled_deferred {td:.1}, tiled_forward_prez {tf:.1} ({ratio:.2}x)"),
                verdict(PLAIN_CASE.contains(ratio)),
            )
        }
        _ => missing(),
    }
}

/// "By 1.5 to 2 times", as the paper says it.
pub const MSAA_FASTER: Band = Band {
    words: "by 1.5 to 2 times",
    quantity: "tiled_deferred ÷ tiled_forward_prez avg ms at 4x MSAA",
    low: 1.5,
    high: 2.0,
};

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
                    "avg ms at 4x MSAA: tiled_deferred {td:.1}, tiled_forward_prez {tf:.1}: forward {ratio:.3}x faster"
                ),
                verdict(MSAA_FASTER.contains(ratio)),
            )
        }
        _ => missing(),
    }
}

/// "Almost linearly": the paper's 0.75 → 5.1 ms is 6.8x for 8x the samples (0.85 of linear);
/// a quarter either side of linear.
pub const ALMOST_LINEAR: Band = Band {
    words: "almost linearly (0.75 ms at 1x to 5.1 ms at 8x)",
    quantity: "cell-bounds time growth ÷ sample-count growth",
    low: 0.75,
    high: 1.25,
};

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
                verdict(ALMOST_LINEAR.contains(growth / f64::from(n))),
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
        let mut claim = |statement, threshold, result| {
            out.push(Claim::new(&name, statement, source, threshold, result))
        };
        claim(
            "Lights too large leave nothing to cull: as the ranges grow every tile lists more of the lights, until (almost: 90%) all of them",
            Threshold::Rule("the share of the lights an average tile lists never falls by more than 2% from one factor to the next, and is at least 90% at the largest"),
            if listed.len() >= 2 {
                tiles_fill_up(&listed)
            } else {
                not_measured("tiled_deferred at two or more --range-scale factors")
            },
        );
        claim(
            "The gain of tiled shading over brute force shrinks as the lights grow",
            Threshold::Rule("forward ÷ tiled_deferred avg ms never grows by more than 5% (frame-time noise) from one factor to the next"),
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
        let mut claim = |statement, threshold, result| {
            out.push(Claim::new(scene, statement, source, threshold, result))
        };
        claim(
            "A depth pre-pass alone makes tiled forward shading faster (22.4 → 15.6 ms)",
            Threshold::Rule(FASTER),
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
            Threshold::Rule(FASTER),
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
                Threshold::Band(&ONE_SIDE_ENOUGH),
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

/// "Enough": one side of the bounds within 10% of both sides' time.
pub const ONE_SIDE_ENOUGH: Band = Band {
    words: "within 10% of both",
    quantity: "the better one-sided bound's avg ms ÷ both bounds'",
    low: 0.0,
    high: 1.10,
};

/// The claims that say only "faster" (the paper's times in the statement).
const FASTER: &str = "the first pipeline's avg ms below the second's";

/// Is min-only or max-only culling [`ONE_SIDE_ENOUGH`] (avg ms)?
pub fn one_side_enough(pipeline: &str, both: f64, min: f64, max: f64) -> (String, Verdict) {
    let best = min.min(max);
    (
        format!(
            "{pipeline} avg ms: both {both:.2}, min only {min:.2}, max only {max:.2}; the better side is {:.2}x both",
            best / both.max(1e-9)
        ),
        verdict(ONE_SIDE_ENOUGH.contains(best / both.max(1e-9))),
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
    let mut claim = |scene: &str, statement, threshold, result| {
        out.push(Claim::new(scene, statement, source, threshold, result))
    };
    if r.runs.iter().any(|x| x.scene == top) {
        claim(
            top,
            "In the top-down view tiled forward outperforms clustered forward (6.6 vs 9.3 ms)",
            Threshold::Rule(FASTER),
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
            Threshold::Rule(FASTER),
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
            Threshold::Rule("clustered_forward's first-person ÷ top-down lighting computations closer to 1 (in log) than tiled_forward_prez's"),
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
