//! `lightgrid advise`: which configuration to render a scene with on this adapter, measured
//! rather than modelled. Forward+ §5 leaves choosing the tile size automatically as future
//! work; the papers' tables show the answer moves with the scene, the light count, the
//! resolution and the hardware (tiled-shading §8: tiled deferred fastest in the worst case,
//! tiled forward competitive with few lights), so the advisor times the candidates here.
//!
//! Steps, within a wall-clock budget:
//! 1. **Survey**: every pipeline that reproduces `forward`'s image, at the default tile and
//!    the `auto` strategy, but brute-force `forward` itself.
//! 2. **Refine**: for the fastest grid pipelines of the survey, the other tile sizes and then
//!    the other assignment strategies at their best tile.
//! 3. **Reference**: `forward` last, with what is left of the budget (it is the baseline the
//!    reasons compare with, rarely the answer, and the slowest by far on many lights).
//!
//! Each candidate plays a few frames spread over the animation on the real-time path
//! (`realtime::play`, the same frame loop `lightgrid play` and the viewer use) after one
//! warm-up frame; a candidate whose warm-up frame shows it cannot finish inside what is left
//! of the budget is skipped, saying so. One analysis frame at the middle of the animation
//! gives its lighting computations against the ideal. The ranking is by median frame time;
//! the recommendation says why, against the runner-up.

use crate::run::Progress;
use lightgrid::frame::{Assign, CellBox, DepthMask, RenderSettings};
use lightgrid::gpu::GpuContext;
use lightgrid::pipelines::{self, Axis, Msaa, PipelineInfo, SettingValue, REFERENCE};
use lightgrid::realtime::{play, PlayPlan};
use lightgrid::scene::Scene;
use lightgrid::Renderer;
use serde::Serialize;
use std::collections::BTreeMap;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

/// Tile edges the refinement tries besides the default (the papers' 8, 16 and 32: Forward+
/// §5 measures 8x8 to 32x32; tiled-shading §8 and tiled-forward-shading use 32).
pub const TILES: [u32; 3] = [8, 16, 32];
/// Grid pipelines of the survey refined with the other tiles and strategies.
pub const REFINE_TOP: usize = 3;
/// Frames each candidate plays (spread over the animation).
pub const FRAMES: usize = 4;

/// Rows of the settings table the refinement tries, in this order, at each of their values
/// but the default (where the row applies to the pipeline and the settings validate): 2.5D
/// culling, tight cells, then the other strategies.
pub const REFINED: [&str; 3] = [DepthMask::FLAG, CellBox::FLAG, Assign::FLAG];

/// One configuration to measure.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Candidate {
    pub pipeline: &'static str,
    /// The tile edge (grid pipelines only).
    pub tile: Option<u32>,
    /// Rows of the settings table (`AXES`) the candidate sets, by the row's results column
    /// (`assign`, `depth_mask`, ...), each to a value of the row by name (the survey's `auto`
    /// resolved); the other settings as given.
    #[serde(flatten)]
    pub settings: BTreeMap<&'static str, &'static str>,
}

impl Candidate {
    /// The candidate with row `flag` set to `value`.
    fn with(&self, flag: &str, value: &'static str) -> Candidate {
        let axis = pipelines::find_axis(flag).expect("a row of the table");
        let mut c = self.clone();
        c.settings.insert(axis.column, value);
        c
    }

    /// The value it sets row `flag` to, if it sets it.
    pub fn setting(&self, flag: &str) -> Option<&'static str> {
        let axis = pipelines::find_axis(flag)?;
        self.settings.get(axis.column).copied()
    }

    /// Its settings as (row, value), in the table's order.
    fn rows(&self) -> impl Iterator<Item = (&'static Axis, &'static str)> + '_ {
        pipelines::AXES
            .iter()
            .filter_map(|a| Some((a, *self.settings.get(a.column)?)))
    }

    pub fn label(&self) -> String {
        let mut s = self.pipeline.to_string();
        if let Some(t) = self.tile {
            s += &format!(" tile {t}");
        }
        for (axis, value) in self.rows() {
            s += &format!(" {} {value}", axis.flag);
        }
        s
    }
}

/// How measuring a candidate ended.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "status", rename_all = "lowercase")]
pub enum Outcome {
    Measured {
        /// Median wall time from one frame to the next on the real-time path.
        frame_ms: f64,
        /// Median GPU time (timestamps), where the adapter has them.
        gpu_ms: Option<f64>,
        /// Frames whose lists overflowed or whose loops were cut short (a wrong frame).
        wrong_frames: usize,
    },
    Skipped {
        reason: String,
    },
    Failed {
        reason: String,
    },
}

/// A candidate with what was measured.
#[derive(Clone, Debug, Serialize)]
pub struct Measurement {
    #[serde(flatten)]
    pub candidate: Candidate,
    #[serde(flatten)]
    pub outcome: Outcome,
    /// Render targets plus the grid, bytes (targets only where no analysis frame ran).
    pub memory_bytes: u64,
    pub lighting_computations: Option<u64>,
    pub ideal_lighting_computations: Option<u64>,
    pub efficiency: Option<f64>,
    /// Renders with MSAA (some sample count above 1).
    pub msaa: bool,
}

impl Measurement {
    pub fn frame_ms(&self) -> Option<f64> {
        match self.outcome {
            Outcome::Measured {
                frame_ms,
                wrong_frames: 0,
                ..
            } => Some(frame_ms),
            _ => None,
        }
    }
}

/// What `advise` found.
#[derive(Clone, Debug, Serialize)]
pub struct Advice {
    pub scene: String,
    pub adapter: String,
    pub width: u32,
    pub height: u32,
    pub budget_s: f64,
    pub elapsed_s: f64,
    /// Every candidate, fastest first (unmeasured ones last, in the order tried).
    pub ranking: Vec<Measurement>,
    pub recommendation: Option<Recommendation>,
    /// Stopped by a signal (Ctrl-C or SIGTERM): the candidates after it were not measured, so
    /// the recommendation is the best of a part only, and the command exits non-zero.
    pub interrupted: bool,
}

#[derive(Clone, Debug, Serialize)]
pub struct Recommendation {
    #[serde(flatten)]
    pub candidate: Candidate,
    /// The command-line options that select it.
    pub options: String,
    pub reasons: Vec<String>,
}

/// The pipelines the advisor considers: those whose image is `forward`'s (the mono-specular
/// variants trade image quality for speed and are compared with their own reference).
pub fn considered() -> Vec<&'static PipelineInfo> {
    pipelines::PIPELINES
        .iter()
        .filter(|p| p.reference == REFERENCE)
        .collect()
}

/// Step 1: every considered pipeline but the reference at the default tile and `auto`.
pub fn survey(assign_auto: &'static str) -> Vec<Candidate> {
    considered()
        .into_iter()
        .filter(|p| p.id != REFERENCE)
        .map(|p| {
            let c = Candidate {
                pipeline: p.id,
                tile: p.uses_grid.then_some(lightgrid::consts::DEFAULT_TILE_SIZE),
                settings: BTreeMap::new(),
            };
            let assign = pipelines::find_axis(Assign::FLAG).expect("a row");
            if (assign.applies)(p, &RenderSettings::default()) {
                c.with(Assign::FLAG, assign_auto)
            } else {
                c
            }
        })
        .collect()
}

/// Step 3: brute force, the baseline.
pub fn reference_candidate() -> Candidate {
    Candidate {
        pipeline: REFERENCE,
        tile: None,
        settings: BTreeMap::new(),
    }
}

/// Step 2: for the fastest `REFINE_TOP` grid pipelines measured so far, the other tiles at
/// their settings, then every other value of each row of [`REFINED`] where the settings
/// table says it applies. Candidates already in `done` are left out.
pub fn refine(done: &[Measurement]) -> Vec<Candidate> {
    let ranked = rank(done.to_vec());
    let top: Vec<Candidate> = ranked
        .iter()
        .filter(|m| m.frame_ms().is_some() && m.candidate.tile.is_some())
        .map(|m| m.candidate.clone())
        .fold(Vec::new(), |mut seen: Vec<Candidate>, c| {
            if !seen.iter().any(|s| s.pipeline == c.pipeline) {
                seen.push(c);
            }
            seen
        })
        .into_iter()
        .take(REFINE_TOP)
        .collect();
    let mut out = Vec::new();
    let push = |c: Candidate, out: &mut Vec<Candidate>| {
        if !done.iter().any(|m| m.candidate == c) && !out.contains(&c) {
            out.push(c);
        }
    };
    for c in &top {
        for t in TILES {
            push(
                Candidate {
                    tile: Some(t),
                    ..c.clone()
                },
                &mut out,
            );
        }
    }
    for flag in REFINED {
        let axis = pipelines::find_axis(flag).expect("a row of the table");
        let default = (axis.get)(&RenderSettings::default());
        for c in &top {
            for v in (axis.values)().into_iter().filter(|v| v.name != default) {
                let next = c.with(flag, v.name);
                let settings = settings_of(&RenderSettings::default(), &next);
                if (axis.applies)(info(c), &settings) && settings.validate().is_ok() {
                    push(next, &mut out);
                }
            }
        }
    }
    out
}

/// Fastest first; measured before unmeasured (kept in the order tried); equal times by
/// memory.
pub fn rank(mut all: Vec<Measurement>) -> Vec<Measurement> {
    all.sort_by(|a, b| match (a.frame_ms(), b.frame_ms()) {
        (Some(x), Some(y)) => x.total_cmp(&y).then(a.memory_bytes.cmp(&b.memory_bytes)),
        (Some(_), None) => std::cmp::Ordering::Less,
        (None, Some(_)) => std::cmp::Ordering::Greater,
        (None, None) => std::cmp::Ordering::Equal,
    });
    all
}

fn mib(bytes: u64) -> String {
    format!("{:.1} MiB", bytes as f64 / f64::from(1u32 << 20))
}

/// The options that select `c` on the command line.
pub fn options(c: &Candidate) -> String {
    let mut s = format!("--pipeline {}", c.pipeline);
    if let Some(t) = c.tile {
        s += &format!(" --tile {t}");
    }
    for (axis, value) in c.rows() {
        s += &format!(" {} {value}", axis.option());
    }
    s
}

/// The fastest measured candidate, and why: its time against the runner-up's (and against
/// the brute-force reference's when measured), its memory against the runner-up's, its
/// lighting computations against the ideal, and what it supports.
pub fn recommend(ranking: &[Measurement]) -> Option<Recommendation> {
    let best = ranking.first().filter(|m| m.frame_ms().is_some())?;
    let ms = best.frame_ms()?;
    let mut reasons = vec![format!(
        "fastest measured: median {ms:.2} ms per frame ({:.1} fps)",
        1000.0 / ms.max(1e-9)
    )];
    if let Some(next) = ranking.get(1).filter(|m| m.frame_ms().is_some()) {
        let other = next.frame_ms().unwrap_or(ms);
        reasons.push(format!(
            "{:.2}x the speed of the runner-up, {} ({other:.2} ms){}",
            other / ms.max(1e-9),
            next.candidate.label(),
            if other / ms.max(1e-9) < 1.05 {
                ": within 5%, a tie on this adapter"
            } else {
                ""
            }
        ));
        let more = best.memory_bytes as f64 / next.memory_bytes.max(1) as f64;
        reasons.push(format!(
            "{} of render targets and grid ({:.2}x the runner-up's {})",
            mib(best.memory_bytes),
            more,
            mib(next.memory_bytes)
        ));
    } else {
        reasons.push(format!(
            "{} of render targets and grid",
            mib(best.memory_bytes)
        ));
    }
    if let Some(reference) = ranking
        .iter()
        .find(|m| m.candidate.pipeline == REFERENCE && m.frame_ms().is_some())
        .filter(|m| m.candidate != best.candidate)
    {
        let r = reference.frame_ms().unwrap_or(ms);
        reasons.push(format!(
            "{:.1}x faster than brute-force forward ({r:.2} ms)",
            r / ms.max(1e-9)
        ));
    }
    if let (Some(n), Some(ideal), Some(e)) = (
        best.lighting_computations,
        best.ideal_lighting_computations,
        best.efficiency,
    ) {
        reasons.push(format!(
            "{n} lighting computations for an ideal of {ideal} ({:.0}% efficient)",
            e * 100.0
        ));
    }
    reasons.push(if best.msaa {
        "renders with MSAA; transparent objects are lit from its grid".into()
    } else {
        "does not render with MSAA (choose the best MSAA-capable row for that)".into()
    });
    Some(Recommendation {
        candidate: best.candidate.clone(),
        options: options(&best.candidate),
        reasons,
    })
}

/// What `advise` measures.
pub struct AdvisePlan<'a> {
    pub scene: &'a Scene,
    pub size: (u32, u32),
    pub budget: Duration,
    /// Settings beside tile and strategy (MSAA, G-buffer, ...), as given.
    pub base: RenderSettings,
}

/// Measure the survey, then the refinements, within the budget.
pub fn advise(
    ctx: &GpuContext,
    plan: &AdvisePlan,
    stop: &AtomicBool,
    progress: &mut dyn FnMut(&Progress),
) -> lightgrid::Result<Advice> {
    let start = Instant::now();
    let auto = plan
        .base
        .grid
        .strategy
        .resolve(plan.scene.lights.len(), ctx.is_software())
        .name();
    let n = plan.scene.frame_count();
    let frames: Vec<u32> = (0..FRAMES as u32)
        .map(|i| (u64::from(n) * u64::from(i) / FRAMES as u64) as u32)
        .collect();
    let mut done: Vec<Measurement> = Vec::new();
    let mut queue = survey(auto);
    // The steps after the survey, made from what it measured when it is done.
    let mut next_steps = 2;
    // The shortest whole measurement so far (renderer, warm-up, frames, analysis).
    let mut quickest: Option<Duration> = None;
    let mut total = queue.len() as u64 + 1;
    loop {
        let Some(c) = (!queue.is_empty()).then(|| queue.remove(0)) else {
            match next_steps {
                2 => {
                    queue = refine(&done);
                    total += queue.len() as u64;
                }
                1 => queue = vec![reference_candidate()],
                _ => break,
            }
            next_steps -= 1;
            continue;
        };
        progress(&Progress {
            done: done.len() as u64,
            total,
            label: c.label(),
        });
        let left = plan.budget.saturating_sub(start.elapsed());
        let m = if stop.load(std::sync::atomic::Ordering::Relaxed) {
            unmeasured(
                plan,
                c,
                Outcome::Skipped {
                    reason: "interrupted".into(),
                },
            )
        } else if left.is_zero() || quickest.is_some_and(|q| left < q) {
            // Not even the quickest candidate so far would fit in what is left.
            unmeasured(
                plan,
                c,
                Outcome::Skipped {
                    reason: "the budget was spent".into(),
                },
            )
        } else {
            let t = Instant::now();
            let m = measure(ctx, plan, c, &frames, left, stop);
            if matches!(m.outcome, Outcome::Measured { .. }) {
                let took = t.elapsed();
                quickest = Some(quickest.map_or(took, |q| q.min(took)));
            }
            m
        };
        done.push(m);
    }
    let ranking = rank(done);
    Ok(Advice {
        scene: plan.scene.name.clone(),
        adapter: ctx.adapter_label(),
        width: plan.size.0,
        height: plan.size.1,
        budget_s: plan.budget.as_secs_f64(),
        elapsed_s: start.elapsed().as_secs_f64(),
        recommendation: recommend(&ranking),
        ranking,
        interrupted: stop.load(std::sync::atomic::Ordering::Relaxed),
    })
}

/// `base` with what `c` sets: its tile, and its rows of the settings table.
fn settings_of(base: &RenderSettings, c: &Candidate) -> RenderSettings {
    let mut s = *base;
    if let Some(t) = c.tile {
        s.grid.tile_size = t;
    }
    for (axis, value) in c.rows() {
        (axis.set)(&mut s, value).expect("a value of the row");
    }
    s
}

fn info(c: &Candidate) -> &'static PipelineInfo {
    pipelines::find(c.pipeline).expect("candidates come from the registry")
}

/// `c` ending in `outcome`, with what is known without rendering it: its render targets'
/// bytes and whether it renders with MSAA (a measurement fills in the rest).
fn unmeasured(plan: &AdvisePlan, c: Candidate, outcome: Outcome) -> Measurement {
    let settings = settings_of(&plan.base, &c);
    let p = info(&c);
    Measurement {
        candidate: c,
        outcome,
        memory_bytes: p
            .memory_model(&settings)
            .target_bytes(plan.size.0, plan.size.1),
        lighting_computations: None,
        ideal_lighting_computations: None,
        efficiency: None,
        msaa: !matches!(p.msaa, Msaa::Refused(_)),
    }
}

fn measure(
    ctx: &GpuContext,
    plan: &AdvisePlan,
    c: Candidate,
    frames: &[u32],
    left: Duration,
    stop: &AtomicBool,
) -> Measurement {
    try_measure(ctx, plan, c.clone(), frames, left, stop).unwrap_or_else(|e| {
        let reason = e.to_string();
        unmeasured(plan, c, Outcome::Failed { reason })
    })
}

/// The candidate's measurement, or skipped with the reason (its known facts only).
fn try_measure(
    ctx: &GpuContext,
    plan: &AdvisePlan,
    c: Candidate,
    frames: &[u32],
    left: Duration,
    stop: &AtomicBool,
) -> lightgrid::Result<Measurement> {
    let settings = settings_of(&plan.base, &c);
    let mut renderer = Renderer::new(ctx, plan.size.0, plan.size.1, settings)?;
    // The warm-up frame (shader compilation included) bounds what one frame costs.
    let t = Instant::now();
    renderer.use_scene(plan.scene)?;
    renderer.render_frame(&plan.scene.frame(frames[frames.len() / 2]), c.pipeline)?;
    renderer.finish()?;
    let first = t.elapsed();
    // The frames to play, their queue fill, and the analysis frame.
    let needed = first * (frames.len() as u32 + crate::PLAY_QUEUE_FILL + 1);
    if needed > left.saturating_sub(first) {
        let reason = format!(
            "its first frame took {:.2} s: {} frames would not fit in the {:.1} s of budget left",
            first.as_secs_f64(),
            frames.len() as u32 + crate::PLAY_QUEUE_FILL + 1,
            left.saturating_sub(first).as_secs_f64()
        );
        return Ok(unmeasured(plan, c, Outcome::Skipped { reason }));
    }
    let run = play(
        &mut renderer,
        &PlayPlan {
            scene: plan.scene,
            pipeline: c.pipeline,
            frames,
            passes: 1,
            warmup: crate::PLAY_QUEUE_FILL,
        },
        stop,
        &mut |_, _| {},
    )?;
    if run.interrupted {
        let reason = "interrupted".into();
        return Ok(unmeasured(plan, c, Outcome::Skipped { reason }));
    }
    let out = renderer.render(plan.scene, frames[frames.len() / 2], c.pipeline)?;
    let outcome = Outcome::Measured {
        frame_ms: run.frame_ms().map_or(f64::NAN, |d| d.median),
        gpu_ms: run.gpu_ms().map(|d| d.median),
        wrong_frames: run.overflow_frames() + run.truncated_frames(),
    };
    Ok(Measurement {
        memory_bytes: out.stats.memory.target_bytes + out.stats.memory.grid_bytes.unwrap_or(0),
        lighting_computations: out.stats.lighting_computations,
        ideal_lighting_computations: Some(out.stats.ideal_lighting_computations),
        efficiency: out.stats.efficiency,
        ..unmeasured(plan, c, outcome)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn measured(pipeline: &'static str, tile: Option<u32>, ms: f64, mem: u64) -> Measurement {
        Measurement {
            candidate: {
                let c = Candidate {
                    pipeline,
                    tile,
                    settings: BTreeMap::new(),
                };
                match tile {
                    Some(_) => c.with(Assign::FLAG, "cpu"),
                    None => c,
                }
            },
            outcome: Outcome::Measured {
                frame_ms: ms,
                gpu_ms: Some(ms * 0.9),
                wrong_frames: 0,
            },
            memory_bytes: mem,
            lighting_computations: Some(1000),
            ideal_lighting_computations: Some(500),
            efficiency: Some(0.5),
            msaa: true,
        }
    }

    #[test]
    fn the_survey_has_every_pipeline_of_forwards_image_once_but_the_reference() {
        let s = survey("cpu");
        assert_eq!(s.len(), considered().len() - 1);
        assert!(s.iter().all(|c| c.pipeline != REFERENCE));
        assert!(s.iter().all(|c| !c.pipeline.ends_with("_mono")));
        for c in &s {
            let p = pipelines::find(c.pipeline).unwrap();
            assert_eq!(c.tile.is_some(), p.uses_grid, "{}", c.pipeline);
            assert_eq!(
                c.setting(Assign::FLAG).is_some(),
                p.assign,
                "{}",
                c.pipeline
            );
        }
    }

    #[test]
    fn ranking_puts_the_fastest_correct_frames_first() {
        let mut wrong = measured(lightgrid::pipelines::ids::TILED_FORWARD, Some(16), 1.0, 10);
        wrong.outcome = Outcome::Measured {
            frame_ms: 1.0,
            gpu_ms: None,
            wrong_frames: 2,
        };
        let mut skipped = measured(lightgrid::pipelines::ids::FORWARD, None, 0.5, 1);
        skipped.outcome = Outcome::Skipped {
            reason: "slow".into(),
        };
        let r = rank(vec![
            skipped,
            measured(lightgrid::pipelines::ids::DEFERRED, None, 30.0, 50),
            wrong,
            measured(
                lightgrid::pipelines::ids::TILED_DEFERRED,
                Some(16),
                20.0,
                40,
            ),
            measured(
                lightgrid::pipelines::ids::CLUSTERED_FORWARD,
                Some(16),
                20.0,
                30,
            ),
        ]);
        let order: Vec<&str> = r.iter().map(|m| m.candidate.pipeline).collect();
        // Equal times: less memory first; wrong frames and skipped ones after the measured.
        assert_eq!(
            order,
            vec![
                lightgrid::pipelines::ids::CLUSTERED_FORWARD,
                lightgrid::pipelines::ids::TILED_DEFERRED,
                lightgrid::pipelines::ids::DEFERRED,
                lightgrid::pipelines::ids::FORWARD,
                lightgrid::pipelines::ids::TILED_FORWARD
            ]
        );
    }

    #[test]
    fn refinement_tries_tiles_then_strategies_of_the_top_grid_pipelines() {
        let done = vec![
            measured(lightgrid::pipelines::ids::TILED_DEFERRED, Some(16), 10.0, 1),
            measured(
                lightgrid::pipelines::ids::CLUSTERED_FORWARD,
                Some(16),
                12.0,
                1,
            ),
            measured(lightgrid::pipelines::ids::DEFERRED, None, 11.0, 1),
            measured(lightgrid::pipelines::ids::TILED_FORWARD, Some(16), 13.0, 1),
            measured(
                lightgrid::pipelines::ids::TILED_FORWARD_PREZ,
                Some(16),
                14.0,
                1,
            ),
        ];
        let r = refine(&done);
        let pipelines: std::collections::BTreeSet<&str> = r.iter().map(|c| c.pipeline).collect();
        // The top three grid pipelines; `deferred` has no grid to refine.
        assert_eq!(
            pipelines,
            [
                lightgrid::pipelines::ids::CLUSTERED_FORWARD,
                lightgrid::pipelines::ids::TILED_DEFERRED,
                lightgrid::pipelines::ids::TILED_FORWARD
            ]
            .into()
        );
        assert!(r.iter().all(|c| !done.iter().any(|d| d.candidate == *c)));
        let deferred = |tile, assign| {
            Candidate {
                pipeline: lightgrid::pipelines::ids::TILED_DEFERRED,
                tile: Some(tile),
                settings: BTreeMap::new(),
            }
            .with(Assign::FLAG, assign)
        };
        assert!(r.contains(&deferred(32, "cpu")));
        assert!(r.contains(&deferred(16, "gather")));
        assert!(!r.iter().any(|c| c.setting(Assign::FLAG) == Some("auto")));
        // z-binning builds no per-cell lists: never with a mask or a box (the settings refuse
        // it).
        assert!(!r.iter().any(|c| c.setting(Assign::FLAG) == Some("zbin")
            && (c.setting(DepthMask::FLAG).is_some() || c.setting(CellBox::FLAG).is_some())));
        // 2.5D culling for the top grid pipelines whose grids come from the depth buffer
        // (the settings table's rule), not for tiled_forward (no depth bounds).
        let masked: std::collections::BTreeSet<&str> = r
            .iter()
            .filter(|c| c.setting(DepthMask::FLAG) == Some("on"))
            .map(|c| c.pipeline)
            .collect();
        assert_eq!(
            masked,
            [
                lightgrid::pipelines::ids::CLUSTERED_FORWARD,
                lightgrid::pipelines::ids::TILED_DEFERRED,
            ]
            .into()
        );
        let c = r
            .iter()
            .find(|c| c.setting(DepthMask::FLAG) == Some("on"))
            .unwrap();
        assert!(options(c).ends_with("--depth-mask on"), "{}", options(c));
        // Tight cells likewise.
        let boxed: std::collections::BTreeSet<&str> = r
            .iter()
            .filter(|c| c.setting(CellBox::FLAG) == Some("on"))
            .map(|c| c.pipeline)
            .collect();
        assert_eq!(boxed, masked);
        let c = r
            .iter()
            .find(|c| c.setting(CellBox::FLAG) == Some("on"))
            .unwrap();
        assert!(options(c).ends_with("--cell-box on"), "{}", options(c));
    }

    #[test]
    fn the_recommendation_gives_its_reasons_against_the_runner_up() {
        let r = rank(vec![
            measured(lightgrid::pipelines::ids::FORWARD, None, 400.0, 10 << 20),
            measured(
                lightgrid::pipelines::ids::TILED_DEFERRED,
                Some(16),
                20.0,
                40 << 20,
            ),
            measured(
                lightgrid::pipelines::ids::CLUSTERED_FORWARD,
                Some(32),
                10.0,
                20 << 20,
            ),
        ]);
        let rec = recommend(&r).unwrap();
        assert_eq!(
            rec.candidate.pipeline,
            lightgrid::pipelines::ids::CLUSTERED_FORWARD
        );
        assert_eq!(
            rec.options,
            "--pipeline clustered_forward --tile 32 --assign cpu"
        );
        let text = rec.reasons.join("\n");
        assert!(
            text.contains("2.00x the speed of the runner-up, tiled_deferred"),
            "{text}"
        );
        assert!(
            text.contains("40.0x faster than brute-force forward"),
            "{text}"
        );
        assert!(text.contains("20.0 MiB"), "{text}");
        assert!(text.contains("50% efficient"), "{text}");
        // A tie is called a tie.
        let r = rank(vec![
            measured(lightgrid::pipelines::ids::TILED_DEFERRED, Some(16), 10.2, 1),
            measured(
                lightgrid::pipelines::ids::CLUSTERED_FORWARD,
                Some(16),
                10.0,
                1,
            ),
        ]);
        assert!(recommend(&r).unwrap().reasons[1].contains("a tie"));
        // Nothing measured: no recommendation.
        let mut s = measured(lightgrid::pipelines::ids::FORWARD, None, 1.0, 1);
        s.outcome = Outcome::Failed { reason: "x".into() };
        assert!(recommend(&[s]).is_none());
    }

    /// Driven by the settings table: each refined row is a row with a value besides its
    /// default, and every refined candidate's settings read back, row by row, what it names.
    #[test]
    fn the_refined_settings_are_rows_of_the_table_and_read_back() {
        for flag in REFINED {
            let axis = pipelines::find_axis(flag).expect("a row of the table");
            assert!((axis.values)().len() >= 2, "{flag}");
        }
        let done = vec![measured(
            lightgrid::pipelines::ids::TILED_DEFERRED,
            Some(16),
            10.0,
            1,
        )];
        let r = refine(&done);
        assert!(!r.is_empty());
        for c in &r {
            let s = settings_of(&RenderSettings::default(), c);
            assert_eq!(Some(s.grid.tile_size), c.tile);
            for (axis, value) in c.rows() {
                assert_eq!((axis.get)(&s), value, "{}", c.label());
                assert!(options(c).contains(&format!("{} {value}", axis.option())));
            }
        }
        for flag in REFINED {
            assert!(
                r.iter().any(|c| c.setting(flag).is_some()),
                "{flag} never tried"
            );
        }
    }
}
