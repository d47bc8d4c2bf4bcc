//! The papers' claims, checked against a benchmark's measurements. Each claim names its
//! source, the evidence measured on this adapter, and whether it held. One file per paper
//! holds its checks; `PER_SCENE` lists those run on every scene, in summary.md's order, and
//! `evaluate_claims` adds the families that compare runs across scenes or settings.

use super::{BenchResults, RunRecord};
use lightgrid::pipelines::ids;

mod culling;
mod deferred_lighting;
mod forward_plus;
mod shadows;
mod tiled_forward_shading;
mod tiled_shading;

use culling::*;
use deferred_lighting::*;
use forward_plus::*;
use lightgrid::frame::{CellBox, DepthBounds, DepthMask};
use serde::Serialize;
use tiled_forward_shading::*;
use tiled_shading::*;
pub(crate) use tiled_shading::{fit_cost, frame_costs};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Verdict {
    Held,
    NotHeld,
    /// The pipelines or settings the claim needs were not in the run.
    NotMeasured,
}

impl Verdict {
    pub fn label(self) -> &'static str {
        match self {
            Verdict::Held => "held",
            Verdict::NotHeld => "did not hold",
            Verdict::NotMeasured => "not measured",
        }
    }
}

/// What a verdict rests on: frames measured on this adapter, or a traffic model evaluated at
/// a measured quantity (the deferred-lighting blog's byte budgets: a verdict on the model, not
/// a measurement of bytes).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Basis {
    Measured,
    Model,
}

/// The paper's words for a quantity and the interval of its measured value that counts as
/// them (both ends included; `f64::INFINITY` for "at least"). Where a paper gives a figure
/// ("about 25%", "1.5 to 2 times", "6x") the band is that figure with the margin written
/// beside the constant; the verdict is `contains`, and the summary prints `describe`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Band {
    /// The paper's words.
    pub words: &'static str,
    /// What is measured, as a ratio or a value.
    pub quantity: &'static str,
    pub low: f64,
    pub high: f64,
}

impl Band {
    pub fn contains(&self, x: f64) -> bool {
        x >= self.low && x <= self.high
    }

    /// "'by about 25%': tiled_forward_prez ms / tiled_deferred ms in 1.15 to 1.35".
    pub fn describe(&self) -> String {
        // Two decimals at most, trailing zeros dropped (4/3 as 1.33, 1.5 as 1.5).
        let num = |x: f64| {
            let s = format!("{x:.2}");
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        };
        let range = match (self.low, self.high) {
            (l, h) if h.is_infinite() => format!("at least {}", num(l)),
            (l, h) if l <= 0.0 => format!("at most {}", num(h)),
            (l, h) => format!("{} to {}", num(l), num(h)),
        };
        format!("\"{}\": {} {range}", self.words, self.quantity)
    }
}

/// A claim's threshold: a [`Band`] around the paper's figure, or a rule in words for the
/// claims that order pipelines rather than give a figure.
#[derive(Clone, Copy, Debug)]
pub enum Threshold {
    Band(&'static Band),
    Rule(&'static str),
}

impl Threshold {
    fn describe(self) -> String {
        match self {
            Threshold::Band(b) => b.describe(),
            Threshold::Rule(r) => r.to_string(),
        }
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct Claim {
    pub scene: String,
    pub statement: &'static str,
    pub source: &'static str,
    /// What counts as the statement holding: the paper's words and the measured interval.
    pub threshold: String,
    pub basis: Basis,
    pub evidence: String,
    pub verdict: Verdict,
}

impl Claim {
    fn new(
        scene: impl Into<String>,
        statement: &'static str,
        source: &'static str,
        threshold: Threshold,
        (evidence, verdict): (String, Verdict),
    ) -> Self {
        Claim {
            scene: scene.into(),
            statement,
            source,
            threshold: threshold.describe(),
            basis: Basis::Measured,
            evidence,
            verdict,
        }
    }
}

/// The run of `pipeline` on `scene`, with the 16-bit G-buffer if it has one (or `bits`).
fn find<'a>(
    r: &'a BenchResults,
    scene: &str,
    pipeline: &str,
    bits: Option<u32>,
) -> Option<&'a RunRecord> {
    find_msaa(r, scene, pipeline, bits, 1)
}

/// As [`find`], at `samples` MSAA samples per pixel.
fn find_msaa<'a>(
    r: &'a BenchResults,
    scene: &str,
    pipeline: &str,
    bits: Option<u32>,
    samples: u32,
) -> Option<&'a RunRecord> {
    find_run(r, scene, pipeline, bits, samples, DepthBounds::Both)
}

/// As [`find`], culling by `bounds` (`--depth-bounds`).
fn find_bounds<'a>(
    r: &'a BenchResults,
    scene: &str,
    pipeline: &str,
    bounds: DepthBounds,
) -> Option<&'a RunRecord> {
    find_run(r, scene, pipeline, None, 1, bounds)
}

/// The one search the three above name: a run recorded without a depth-bounds setting
/// culled by both bounds (the default), and without 2.5D depth masks or tight cell boxes.
fn find_run<'a>(
    r: &'a BenchResults,
    scene: &str,
    pipeline: &str,
    bits: Option<u32>,
    samples: u32,
    bounds: DepthBounds,
) -> Option<&'a RunRecord> {
    r.runs.iter().find(|x| {
        x.scene == scene
            && x.pipeline == pipeline
            && x.msaa() == samples
            && (x.gbuffer_bits().is_none() || x.gbuffer_bits() == bits.or(Some(16)))
            && x.varied::<DepthBounds>().unwrap_or_default() == bounds
            // The papers' grids have no 2.5D masks or tight boxes (`--preset culling`
            // measures both).
            && x.varied::<DepthMask>().unwrap_or_default() == DepthMask::Off
            && x.varied::<CellBox>().unwrap_or_default() == CellBox::Off
    })
}

/// Are `a` and `b` the same series but for the setting `T` is the type of (the scene, the
/// pipeline, the frame size and every other setting of the library's table equal)? How a
/// claim pairs runs that differ in one setting.
pub(crate) fn differs_only_in<T: lightgrid::pipelines::SettingValue>(
    a: &RunRecord,
    b: &RunRecord,
) -> bool {
    a.scene == b.scene
        && a.pipeline == b.pipeline
        && (a.width, a.height, a.tile_size) == (b.width, b.height, b.tile_size)
        && lightgrid::pipelines::AXES
            .iter()
            .filter(|axis| axis.flag != T::FLAG)
            .all(|axis| (axis.get)(&a.settings) == (axis.get)(&b.settings))
        && lightgrid::pipelines::value_of::<T>(&a.settings)
            != lightgrid::pipelines::value_of::<T>(&b.settings)
}

/// The average GPU time of the cell-bounds pass (the Z-reduction) of a run.
fn cell_bounds_ms(x: &RunRecord) -> Option<f64> {
    x.summary
        .as_ref()?
        .passes
        .iter()
        .find(|p| p.label == lightgrid::culling::labels::CELL_BOUNDS)
        .map(|p| p.ms)
}

fn avg_ms(x: &RunRecord) -> Option<f64> {
    x.summary.as_ref().map(|s| s.gpu_ms.mean)
}

fn avg_count(x: &RunRecord) -> Option<f64> {
    x.summary.as_ref()?.lighting_computations.map(|s| s.mean)
}

/// Pearson correlation of two series (None when either is constant or too short).
fn correlation(a: &[f64], b: &[f64]) -> Option<f64> {
    if a.len() < 3 {
        return None;
    }
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let (va, vb): (f64, f64) = (
        a.iter().map(|x| (x - ma).powi(2)).sum(),
        b.iter().map(|y| (y - mb).powi(2)).sum(),
    );
    (va > 0.0 && vb > 0.0).then(|| cov / (va * vb).sqrt())
}

fn verdict(ok: bool) -> Verdict {
    if ok {
        Verdict::Held
    } else {
        Verdict::NotHeld
    }
}

/// Pipelines that cull (everything but the brute-force references).
fn culled<'a>(r: &'a BenchResults, scene: &str) -> Vec<&'a RunRecord> {
    r.runs
        .iter()
        .filter(|x| {
            x.scene == scene
                && !x.pipeline.starts_with(ids::FORWARD)
                && x.gbuffer_bits().unwrap_or(16) == 16
                && x.msaa() == 1
        })
        .collect()
}

/// A claim checked on each scene: its statement, its source, what counts as it holding, what
/// its verdict rests on, and the check.
struct PerScene {
    statement: &'static str,
    source: &'static str,
    threshold: Threshold,
    basis: Basis,
    check: fn(&BenchResults, &str) -> (String, Verdict),
}

/// The claims checked on every scene of a run, in the order summary.md lists them.
const PER_SCENE: &[PerScene] = &[
    PerScene {
        statement: "Tiled deferred shading is much less variable than traditional deferred shading",
        source: "tiled-shading §8.1, Fig. 2",
        threshold: Threshold::Band(&VARIABILITY),
        basis: Basis::Measured,
        check: variability,
    },
    PerScene {
        statement: "Deferred-Stencil performs the fewest lighting computations (closest to the ideal)",
        source: "tiled-shading §8, Fig. 3",
        threshold: Threshold::Rule("deferred_stencil's lighting computations at most every other culling pipeline's"),
        basis: Basis::Measured,
        check: stencil_fewest,
    },
    PerScene {
        statement: "Tiled forward is the least efficient and is substantially improved by a pre-Z pass and depth bounds",
        source: "tiled-shading §8, Fig. 3",
        threshold: Threshold::Band(&SUBSTANTIALLY_FEWER),
        basis: Basis::Measured,
        check: tiled_forward_worst,
    },
    PerScene {
        statement: "Frame times follow the lighting computations: a roughly fixed cost per lighting operation",
        source: "tiled-shading §8, Figs. 2-3",
        threshold: Threshold::Band(&FOLLOWS),
        basis: Basis::Measured,
        check: time_follows_computations,
    },
    PerScene {
        statement: "Traditional deferred slows with a fatter G-buffer; tiled deferred is much less affected",
        source: "tiled-shading §8.1, Tables 2-3",
        threshold: Threshold::Band(&GBUFFER_SLOWS),
        basis: Basis::Measured,
        check: gbuffer_size,
    },
    PerScene {
        statement: "Forward+ (tiled forward with pre-Z and culling) is faster in total than deferred lighting",
        source: "forward-plus §5, Fig. 3",
        threshold: Threshold::Rule("tiled_forward_prez's avg ms below deferred's and light_prepass's"),
        basis: Basis::Measured,
        check: forward_plus_vs_deferred,
    },
    PerScene {
        statement: "Forward+ is faster in total than compute-based deferred lighting [And11], stage by stage: pre-pass, light culling and lighting, final shading",
        source: "forward-plus §5, Fig. 3",
        threshold: Threshold::Rule("the three stages' total below tiled_light_prepass's"),
        basis: Basis::Measured,
        check: forward_plus_by_stages,
    },
    PerScene {
        statement: "Tiled deferred outperforms tiled forward (with pre-Z) in the plain case, by about 25%",
        source: "tiled-forward-shading Fig. 4.1(a)",
        threshold: Threshold::Band(&PLAIN_CASE),
        basis: Basis::Measured,
        check: plain_case,
    },
    PerScene {
        statement: "Deferred lighting gives at most a marginal GPU advantage over deferred shading",
        source: "deferred-shading-vs-deferred-lighting",
        threshold: Threshold::Band(&MARGINAL),
        basis: Basis::Measured,
        check: lighting_marginal,
    },
    PerScene {
        statement: "At 4x MSAA tiled forward outperforms tiled deferred with equal quality by 1.5 to 2 times",
        source: "tiled-forward-shading Fig. 4.1(c)",
        threshold: Threshold::Band(&MSAA_FASTER),
        basis: Basis::Measured,
        check: msaa_forward_faster,
    },
    PerScene {
        statement: "The Z-reduction over every sample grows almost linearly with the sample count (0.75 ms at 1x to 5.1 ms at 8x)",
        source: "tiled-forward-shading §4.6",
        threshold: Threshold::Band(&ALMOST_LINEAR),
        basis: Basis::Measured,
        check: z_reduction_scales,
    },
    PerScene {
        statement: "Tiled deferred has the fastest worst case of the culling techniques",
        source: "tiled-shading §8.3",
        threshold: Threshold::Rule("tiled_deferred's worst frame at most every other culling pipeline's worst"),
        basis: Basis::Measured,
        check: fastest_worst_case,
    },
    PerScene {
        statement: "With few lights, tiled forward shading is competitive with tiled deferred (within 25%)",
        source: "tiled-shading §8.3, Table 3",
        threshold: Threshold::Band(&COMPETITIVE),
        basis: Basis::Measured,
        check: few_lights_competitive,
    },
    PerScene {
        statement: "At equal lighting computations, tiled forward with pre-Z is about four times slower than tiled deferred, plus a constant offset",
        source: "tiled-shading §8.2",
        threshold: Threshold::Band(&FOUR_TIMES),
        basis: Basis::Measured,
        check: prez_per_computation,
    },
    PerScene {
        statement: "Deferred-Stencil is competitive (within 25% of tiled deferred) with a 16-bit G-buffer, not with a 32-bit one",
        source: "tiled-shading §8.1, Tables 2-3",
        threshold: Threshold::Rule(STENCIL_RULE),
        basis: Basis::Measured,
        check: stencil_gbuffer,
    },
    PerScene {
        statement: "Deferred lighting writes more than deferred shading once more than 0.5 lights reach a pixel on average (the traffic model at the measured lights per pixel)",
        source: "deferred-shading-vs-deferred-lighting",
        threshold: Threshold::Rule("lighting's modelled writes above shading's exactly when the measured lights per pixel exceed 0.5"),
        basis: Basis::Model,
        check: write_break_even,
    },
    PerScene {
        statement: "With monochrome specular on both sides, deferred lighting writes as much as deferred shading (the traffic model at the measured lights per pixel)",
        source: "deferred-shading-vs-deferred-lighting (the compromise)",
        threshold: Threshold::Rule("the modelled writes within 5% of each other"),
        basis: Basis::Model,
        check: mono_writes,
    },
    PerScene {
        statement: "With monochrome specular on both sides, deferred lighting reads less than deferred shading once more than 2 lights reach a pixel on average",
        source: "deferred-shading-vs-deferred-lighting (the compromise)",
        threshold: Threshold::Rule("lighting's modelled reads below shading's exactly when the measured lights per pixel exceed 2"),
        basis: Basis::Model,
        check: mono_reads,
    },
    PerScene {
        statement: "With monochrome specular on both sides, deferred lighting needs less render-target memory per pixel than deferred shading (16 against 20 bytes)",
        source: "deferred-shading-vs-deferred-lighting (the compromise)",
        threshold: Threshold::Rule("light_prepass_mono's render targets per pixel fewer than deferred_mono's"),
        basis: Basis::Measured,
        check: mono_memory,
    },
];

pub fn evaluate_claims(r: &BenchResults) -> Vec<Claim> {
    let mut out = Vec::new();
    let mut scenes: Vec<&str> = r.runs.iter().map(|x| x.scene.as_str()).collect();
    scenes.dedup();
    for scene in scenes {
        for c in PER_SCENE {
            out.push(Claim {
                basis: c.basis,
                ..Claim::new(
                    scene,
                    c.statement,
                    c.source,
                    c.threshold,
                    (c.check)(r, scene),
                )
            });
        }
    }
    out.extend(view_dependence(r));
    out.extend(depth_bound_claims(r));
    out.extend(range_claims(r));
    out.extend(reduction_claims(r));
    out.extend(culling_claims(r));
    out.extend(shadows::shadow_claims(r));
    out
}

/// The evidence of a claim whose runs the benchmark did not include.
fn missing() -> (String, Verdict) {
    not_measured("runs that are missing")
}

fn not_measured(what: &str) -> (String, Verdict) {
    (format!("needs {what}"), Verdict::NotMeasured)
}
#[cfg(test)]
mod tests {
    use super::*;

    fn rows(v: &[(&str, f64)]) -> Vec<(String, f64)> {
        v.iter().map(|(p, m)| (p.to_string(), *m)).collect()
    }

    #[test]
    fn subgroup_reduction_claim_on_both_sides() {
        let (e, v) = subgroup_faster(ids::TILED_DEFERRED, 6.0, 1.0);
        assert_eq!(v, Verdict::Held);
        assert!(e.contains("(6.00x)"), "{e}");
        assert_eq!(subgroup_faster("p", 8.4, 12.7).1, Verdict::NotHeld);
    }

    #[test]
    fn fig3_stages_of_pass_labels() {
        for (label, stage) in [
            ("depth pre-pass", Some(0)),
            ("light pre-pass attributes", Some(0)),
            ("assign: cell bounds", Some(1)),
            ("assign: lights", Some(1)),
            ("assign: gather spill", Some(1)),
            ("tiled irradiance (mono specular)", Some(1)),
            ("tiled forward shading (pre-z)", Some(2)),
            ("light pre-pass shading", Some(2)),
            ("transparent", None),
            ("tonemap", None),
        ] {
            assert_eq!(fig3_stage(label), Ok(stage), "{label}");
        }
        assert_eq!(fig3_stage("depth prepass"), Err(()), "an unknown label");
    }

    #[test]
    fn forward_plus_stages_on_both_sides() {
        let (e, v) = forward_plus_stages(&[1.0, 2.0, 5.0], &[2.0, 3.0, 4.0]);
        assert_eq!(v, Verdict::Held);
        assert!(e.contains("1.0 + 2.0 + 5.0 = 8.0"), "{e}");
        assert_eq!(
            forward_plus_stages(&[1.0, 2.0, 7.0], &[2.0, 3.0, 4.0]).1,
            Verdict::NotHeld
        );
    }

    #[test]
    fn range_sweep_claims_on_both_sides() {
        let full = [(0.5, 0.01), (1.0, 0.03), (4.0, 0.5), (16.0, 0.92)];
        assert_eq!(tiles_fill_up(&full).1, Verdict::Held);
        // Not reaching all the lights, or falling on the way, does not hold.
        assert_eq!(tiles_fill_up(&full[..3]).1, Verdict::NotHeld);
        assert_eq!(
            tiles_fill_up(&[(1.0, 0.5), (2.0, 0.3), (4.0, 0.95)]).1,
            Verdict::NotHeld
        );
        assert!(tiles_fill_up(&full).0.contains("x16 92.0%"));
        let shrinking = [(0.5, 50.0), (1.0, 32.0), (2.0, 32.5), (16.0, 2.1)];
        assert_eq!(gain_shrinks(&shrinking).1, Verdict::Held);
        assert_eq!(
            gain_shrinks(&[(1.0, 10.0), (2.0, 12.0)]).1,
            Verdict::NotHeld
        );
    }

    #[test]
    fn one_side_of_the_bounds_on_both_sides() {
        assert_eq!(one_side_enough("p", 10.0, 10.9, 14.0).1, Verdict::Held);
        assert_eq!(one_side_enough("p", 10.0, 14.0, 10.5).1, Verdict::Held);
        assert_eq!(one_side_enough("p", 10.0, 11.5, 12.0).1, Verdict::NotHeld);
        let (evidence, _) = one_side_enough(ids::TILED_FORWARD_PREZ, 10.0, 11.0, 12.0);
        assert!(evidence.contains("1.10x both"), "{evidence}");
    }

    #[test]
    fn fastest_worst_case_on_both_sides() {
        let held = fastest_worst(&rows(&[
            (ids::TILED_DEFERRED, 20.0),
            (ids::DEFERRED, 35.0),
            (ids::TILED_FORWARD, 21.0),
        ]));
        assert_eq!(held.unwrap().1, Verdict::Held);
        let not = fastest_worst(&rows(&[
            (ids::TILED_DEFERRED, 22.0),
            (ids::DEFERRED, 35.0),
            (ids::TILED_FORWARD, 21.0),
        ]));
        assert_eq!(not.unwrap().1, Verdict::NotHeld);
        assert!(fastest_worst(&rows(&[(ids::DEFERRED, 3.0)])).is_none());
    }

    #[test]
    fn four_times_on_both_sides() {
        // ms = 5 + 4e-6 × n against ms = 2 + 1e-6 × n: four times, held.
        let line = |a: f64, b: f64| -> Vec<(f64, f64)> {
            [1e6, 2e6, 4e6, 8e6]
                .iter()
                .map(|&n| (n, a + b * n))
                .collect()
        };
        let prez = fit_cost(&line(5.0, 4e-6)).unwrap();
        let deferred = fit_cost(&line(2.0, 1e-6)).unwrap();
        assert!((prez.1 - 4e-6).abs() < 1e-12 && (prez.0 - 5.0).abs() < 1e-6);
        assert_eq!(four_times(prez, deferred).1, Verdict::Held);
        // Equal cost per computation, or ten times: not held.
        assert_eq!(
            four_times(fit_cost(&line(9.0, 1e-6)).unwrap(), deferred).1,
            Verdict::NotHeld
        );
        assert_eq!(
            four_times(fit_cost(&line(0.0, 1e-5)).unwrap(), deferred).1,
            Verdict::NotHeld
        );
        // Constant counts cannot be fitted.
        assert!(fit_cost(&[(1.0, 2.0), (1.0, 3.0), (1.0, 4.0)]).is_none());
    }

    #[test]
    fn few_lights_competitive_on_both_sides() {
        assert_eq!(competitive(ids::TILED_FORWARD, 12.0, 10.0).1, Verdict::Held);
        assert_eq!(
            competitive(ids::TILED_FORWARD, 13.0, 10.0).1,
            Verdict::NotHeld
        );
    }

    #[test]
    fn view_dependence_on_both_sides() {
        // Tiled triples its work in the first-person view, clusters grow 20%: held.
        assert_eq!(
            less_view_dependent((100.0, 300.0), (80.0, 96.0)).1,
            Verdict::Held
        );
        // Clusters change as much, or shrink more than tiles grow: not held.
        assert_eq!(
            less_view_dependent((100.0, 150.0), (80.0, 160.0)).1,
            Verdict::NotHeld
        );
        assert_eq!(
            less_view_dependent((100.0, 150.0), (100.0, 50.0)).1,
            Verdict::NotHeld
        );
        assert_eq!(faster("a", 6.6, "b", 9.3).1, Verdict::Held);
        assert_eq!(faster("a", 9.4, "b", 9.1).1, Verdict::NotHeld);
    }

    #[test]
    fn write_break_even_on_both_sides() {
        // Above 0.5 lights per pixel the pre-pass should write more; below, less.
        assert_eq!(writes_more(2.0, 30.0, 20.0).1, Verdict::Held);
        assert_eq!(writes_more(2.0, 10.0, 20.0).1, Verdict::NotHeld);
        assert_eq!(writes_more(0.2, 10.0, 20.0).1, Verdict::Held);
        assert_eq!(writes_more(0.2, 30.0, 20.0).1, Verdict::NotHeld);
    }

    #[test]
    fn crossings_of_two_budgets() {
        // (lighting's budget, shading's, where they cross). The blog's own layouts: 16 + 16
        // against 20 + 8 written crosses at 0.5; its mono reads, 8 + 16 against 0 + 20, at 2.
        for (lighting, shading, expected) in [
            (
                (16, 16),
                (20, 8),
                "lighting moves more above 0.50 lights per pixel",
            ),
            (
                (8, 16),
                (0, 20),
                "lighting moves less above 2.00 lights per pixel",
            ),
            ((12, 68), (16, 76), "lighting moves less at any light count"),
            ((30, 16), (20, 8), "lighting moves more at any light count"),
            (
                (24, 8),
                (40, 8),
                "lighting moves 16 B per pixel less at any light count",
            ),
            ((4, 8), (4, 8), "equal at any light count"),
        ] {
            assert_eq!(crossing(lighting, shading), expected);
        }
    }

    #[test]
    fn mono_break_evens_on_both_sides() {
        use Verdict::{Held, NotHeld};
        // (side, lights per pixel, lighting's bytes against shading's 100, verdict). Writes:
        // equal within 5% holds, whichever side is larger; beyond it does not. Reads: lighting
        // should read less above 2 lights per pixel and more below.
        for (side, l, lighting, expected) in [
            (Side::Writes, 3.0, 103.0, Held),
            (Side::Writes, 3.0, 97.0, Held),
            (Side::Writes, 3.0, 80.0, NotHeld),
            (Side::Writes, 0.1, 120.0, NotHeld),
            (Side::Reads, 3.0, 90.0, Held),
            (Side::Reads, 3.0, 110.0, NotHeld),
            (Side::Reads, 1.0, 110.0, Held),
            (Side::Reads, 1.0, 90.0, NotHeld),
        ] {
            let (e, v) = mono_traffic(side, l, lighting, 100.0);
            assert_eq!(v, expected, "{side:?} at {l} lights per pixel: {e}");
        }
        let (e, _) = mono_traffic(Side::Reads, 2.5, 2097152.0, 4194304.0);
        assert!(
            e.contains("reads") && e.contains("2.0 MiB") && e.contains("(0.50x)"),
            "{e}"
        );
    }

    #[test]
    fn mono_memory_on_both_sides() {
        let (e, v) = less_memory(32, 40, Some(178.0), Some(199.0));
        assert_eq!(v, Verdict::Held);
        assert!(e.contains("32 B") && e.contains("178.0"), "{e}");
        assert_eq!(less_memory(40, 40, None, None).1, Verdict::NotHeld);
        assert_eq!(less_memory(48, 40, None, None).1, Verdict::NotHeld);
    }

    #[test]
    fn stencil_competitive_on_both_sides() {
        assert_eq!(stencil_competitive(1.1, 1.6).1, Verdict::Held);
        assert_eq!(stencil_competitive(1.4, 1.6).1, Verdict::NotHeld);
        assert_eq!(stencil_competitive(1.1, 1.2).1, Verdict::NotHeld);
    }

    /// Every band holds at both ends and fails just outside them, holds the paper's own
    /// figure, and says its words and interval.
    #[test]
    fn bands_hold_at_both_ends_and_the_papers_figure() {
        // (band, the paper's own figure)
        let bands: [(&Band, f64); 13] = [
            (&VARIABILITY, 2.0),
            (&SUBSTANTIALLY_FEWER, 2.0),
            (&FOLLOWS, 0.9),
            (&GBUFFER_SLOWS, 1.2),
            (&PLAIN_CASE, 1.25),
            (&MARGINAL, 1.0),
            (&MSAA_FASTER, 1.75),
            (&ALMOST_LINEAR, 5.1 / 0.75 / 8.0),
            (&COMPETITIVE, 1.25),
            (&FOUR_TIMES, 4.0),
            (&SUBGROUP_SIX_TIMES, 6.0),
            (&ONE_SIDE_ENOUGH, 1.05),
            (&ONE_SIDE_ENOUGH, 1.10),
        ];
        for (band, figure) in bands {
            assert!(band.contains(figure), "{band:?} must hold {figure}");
            assert!(band.contains(band.low), "{band:?}: low end");
            assert!(!band.contains(band.low - 1e-9), "{band:?}: below");
            if band.high.is_finite() {
                assert!(band.contains(band.high), "{band:?}: high end");
                assert!(!band.contains(band.high + 1e-9), "{band:?}: above");
            }
            let text = band.describe();
            assert!(
                text.contains(band.words) && text.contains(band.quantity),
                "{text}"
            );
        }
        assert_eq!(
            PLAIN_CASE.describe(),
            "\"by about 25%\": tiled_forward_prez ÷ tiled_deferred avg ms 1.15 to 1.35"
        );
        assert!(VARIABILITY.describe().ends_with("at least 1.5"));
        assert!(SUBSTANTIALLY_FEWER.describe().ends_with("at least 1.33"));
        assert!(FOUR_TIMES.describe().ends_with("2.5 to 6"));
        assert!(ONE_SIDE_ENOUGH.describe().ends_with("at most 1.1"));
        // The paper's "1.5 to 2 times" is that interval, no wider.
        assert_eq!((MSAA_FASTER.low, MSAA_FASTER.high), (1.5, 2.0));
        // The Deferred-Stencil rule in words names the competitive bound.
        assert!(STENCIL_RULE.contains(&format!("at most {}", COMPETITIVE.high)));
    }

    #[test]
    fn model_verdicts_are_the_traffic_model_claims_and_every_claim_has_a_threshold() {
        let model: Vec<&str> = PER_SCENE
            .iter()
            .filter(|c| c.basis == Basis::Model)
            .map(|c| c.statement)
            .collect();
        assert_eq!(model.len(), 3, "{model:?}");
        assert!(model
            .iter()
            .all(|s| s.to_lowercase().contains("deferred lighting")));
        for c in PER_SCENE {
            assert!(!c.threshold.describe().is_empty(), "{}", c.statement);
        }
    }
}
