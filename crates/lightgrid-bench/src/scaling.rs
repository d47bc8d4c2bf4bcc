//! The light-assignment scaling benchmark (tiled-forward-shading §4.4: brute force is fine to
//! ~10k lights, a light hierarchy scales to a million): one grid pipeline on the `stress`
//! scene at increasing light counts, once per assignment strategy, recording per point the
//! assignment time (`assign_ms`: the GPU timestamp span of its passes + its CPU time), the index-list
//! size, occupied cells and lighting computations. `write_scaling` writes scaling.json,
//! scaling.csv, scaling.md (the table and how each strategy's time grows) and scaling.svg/.png
//! (assignment time against lights).

use super::run::Progress;
use crate::invalid;
use crate::outdir::{Outcome, STOPPED_BY_SIGNAL};
use crate::plot::{LineChart, Series};
use crate::report::csv_bytes;
use lightgrid::error::{Error, Result};
use lightgrid::gpu::GpuContext;
use lightgrid::image_io::write_atomic;
use lightgrid::pipelines::ids;
use lightgrid::pipelines::{self, Assign, RenderSettings};
use lightgrid::scene::catalog::{self, SceneParams};
use lightgrid::{Distribution, Renderer};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

/// What to measure.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ScalingConfig {
    pub scene: String,
    pub pipeline: String,
    pub lights: Vec<u32>,
    pub strategies: Vec<Assign>,
    pub size: (u32, u32),
    pub tile_size: u32,
    pub slices: u32,
    pub seed: u64,
    /// Measured renders per point (the median assignment time is kept).
    pub runs: u32,
    /// Discarded renders before each point (shader compilation, buffer growth).
    pub warmup: u32,
    /// A strategy whose assignment took longer than this at one light count is not run at
    /// larger ones (recorded as skipped).
    pub budget_ms: f64,
}

impl Default for ScalingConfig {
    fn default() -> Self {
        ScalingConfig {
            scene: "stress".into(),
            pipeline: ids::CLUSTERED_DEFERRED.into(),
            lights: vec![1_000, 4_000, 16_000, 64_000, 256_000, 1_000_000],
            strategies: vec![
                Assign::Cpu,
                Assign::Gather,
                Assign::Scatter,
                Assign::Bvh,
                Assign::BvhGpu,
            ],
            size: (640, 360),
            tile_size: lightgrid::consts::DEFAULT_TILE_SIZE,
            slices: lightgrid::consts::DEFAULT_SLICES,
            seed: 1,
            runs: 1,
            warmup: 1,
            budget_ms: 5_000.0,
        }
    }
}

/// One (light count, strategy) point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ScalingPoint {
    pub lights: u32,
    pub assign: String,
    /// Why the point was not measured (the strategy exceeded the budget or failed at a
    /// smaller count).
    pub skipped: Option<String>,
    /// The error that stopped this point (the strategy is not run at larger counts).
    #[serde(default)]
    pub failed: Option<String>,
    /// Median assignment time (`FrameStats::assign_ms`: GPU timestamp span of the assignment
    /// passes + CPU time of the assignment).
    pub assign_ms: Option<f64>,
    pub assign_ms_runs: Vec<f64>,
    /// GPU timestamps of the assignment passes (cell bounds included).
    pub assign_gpu_ms: Option<f64>,
    /// CPU share: `assign_cpu`, or the BVH build.
    pub assign_cpu_ms: Option<f64>,
    /// The whole frame's GPU time (timestamps, first pass start to last pass end).
    pub frame_gpu_ms: Option<f64>,
    pub grid_indices: Option<u64>,
    pub grid_bytes: Option<u64>,
    pub grid_cells: Option<u64>,
    pub grid_cells_occupied: Option<u64>,
    pub lights_per_cell_max: Option<u32>,
    pub lighting_computations: Option<u64>,
    pub ideal_lighting_computations: Option<u64>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ScalingResults {
    pub command: String,
    pub adapter: String,
    pub software_adapter: bool,
    pub config: ScalingConfig,
    /// Complete, interrupted (Ctrl-C, SIGTERM) or failed, with the reason.
    #[serde(default)]
    pub outcome: Outcome,
    pub points: Vec<ScalingPoint>,
}

impl ScalingConfig {
    pub fn validate(&self) -> Result<()> {
        let info = pipelines::find(&self.pipeline)?;
        if !info.assign {
            return Err(invalid(
                "--pipeline",
                format!(
                    "{} builds no grid through --assign; use one of: {}",
                    info.id,
                    pipelines::PIPELINES
                        .iter()
                        .filter(|p| p.assign)
                        .map(|p| p.id)
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
        if !catalog::find(&self.scene)?.variable_lights {
            return Err(invalid(
                "--scene",
                format!("{} has a fixed light count; use stress", self.scene),
            ));
        }
        crate::check_distinct("--lights", &self.lights, |&n| n)?;
        let strategies: Vec<&str> = self.strategies.iter().map(|a| a.name()).collect();
        crate::check_distinct("--assign", &strategies, |&n| n)?;
        if self.lights.is_empty() || self.strategies.is_empty() {
            return Err(invalid(
                "scaling",
                "needs at least one light count and one strategy",
            ));
        }
        for (flag, v, min) in [("--runs", self.runs, 1), ("--warmup", self.warmup, 0)] {
            if !(min..=crate::MAX_REPEATS).contains(&v) {
                return Err(invalid(
                    flag,
                    format!("{v} is out of range {min} to {}", crate::MAX_REPEATS),
                ));
            }
        }
        if !self.budget_ms.is_finite() || self.budget_ms <= 0.0 {
            return Err(invalid(
                "--budget",
                format!(
                    "{} s: the budget is a positive number of seconds",
                    self.budget_ms / 1e3
                ),
            ));
        }
        for &n in &self.lights {
            let params = SceneParams {
                seed: self.seed,
                lights: Some(n),
                ..Default::default()
            };
            catalog::check_params(&self.scene, &params)?;
        }
        Ok(())
    }
}

impl ScalingPoint {
    fn new(lights: u32, assign: String) -> Self {
        ScalingPoint {
            lights,
            assign,
            skipped: None,
            failed: None,
            assign_ms: None,
            assign_ms_runs: Vec::new(),
            assign_gpu_ms: None,
            assign_cpu_ms: None,
            frame_gpu_ms: None,
            grid_indices: None,
            grid_bytes: None,
            grid_cells: None,
            grid_cells_occupied: None,
            lights_per_cell_max: None,
            lighting_computations: None,
            ideal_lighting_computations: None,
        }
    }

    /// Take the figures of the measured renders (the median assignment time, the last
    /// render's counts).
    fn take(&mut self, outs: &[lightgrid::FrameOutput]) {
        let Some(last) = outs.last() else { return };
        let times: Vec<f64> = outs.iter().filter_map(|o| o.stats.assign_ms).collect();
        let s = &last.stats;
        self.assign_ms = Distribution::of(times.iter().copied()).map(|d| d.median);
        self.assign_ms_runs = times;
        self.assign_gpu_ms = s.assign_gpu_ms;
        self.assign_cpu_ms = s.assign_cpu_ms;
        self.frame_gpu_ms = Some(s.gpu_ms);
        self.grid_indices = s.grid_indices;
        self.grid_bytes = s.memory.grid_bytes;
        self.grid_cells = s.grid_cells;
        self.grid_cells_occupied = s.grid_cells_occupied;
        self.lights_per_cell_max = s.lights_per_tile_max;
        self.lighting_computations = s.lighting_computations;
        self.ideal_lighting_computations = Some(s.ideal_lighting_computations);
    }
}

/// Render one point's warm-up and measured frames; the measured outputs so far and whether
/// the stop flag ended it early, or the error that did (with the outputs before it).
#[allow(clippy::too_many_arguments)]
fn measure_point(
    ctx: &GpuContext,
    config: &ScalingConfig,
    scene: &lightgrid::scene::Scene,
    assign: Assign,
    stop: &AtomicBool,
    progress: &mut dyn FnMut(&Progress),
    done: &mut u64,
    total: u64,
) -> (Vec<lightgrid::FrameOutput>, Result<bool>) {
    let settings = RenderSettings {
        grid: lightgrid::CullConfig {
            tile_size: config.tile_size,
            slices: config.slices,
            strategy: assign,
            ..lightgrid::CullConfig::default()
        },
        ..Default::default()
    };
    let mut outs = Vec::new();
    let mut renderer = match Renderer::new(ctx, config.size.0, config.size.1, settings) {
        Ok(r) => r,
        Err(e) => return (outs, Err(e)),
    };
    for i in 0..config.warmup + config.runs {
        let warm = i < config.warmup;
        progress(&Progress {
            done: *done,
            total,
            label: format!(
                "{} lights, {} ({})",
                scene.lights.len(),
                assign.name(),
                if warm { "warm-up" } else { "measuring" }
            ),
        });
        match renderer.render(scene, 0, &config.pipeline) {
            Ok(out) if !warm => outs.push(out),
            Ok(_) => {}
            Err(e) => return (outs, Err(e)),
        }
        *done += 1;
        if stop.load(Ordering::Relaxed) {
            return (outs, Ok(true));
        }
    }
    (outs, Ok(false))
}

/// Run the scaling benchmark; `stop` is polled after every render. A strategy that fails at
/// a light count has the error recorded in that point and is not run at larger counts; the
/// run goes on with the others. Results come back on every way out ([`Outcome`]).
pub fn run_scaling(
    ctx: &GpuContext,
    config: &ScalingConfig,
    stop: &AtomicBool,
    progress: &mut dyn FnMut(&Progress),
) -> Result<ScalingResults> {
    config.validate()?;
    let mut lights = config.lights.clone();
    lights.sort_unstable();
    lights.dedup();
    let per_point = u64::from(config.warmup) + u64::from(config.runs);
    let total = per_point * (lights.len() * config.strategies.len()) as u64;
    let mut done = 0;
    let mut results = ScalingResults {
        command: String::new(),
        adapter: ctx.adapter_label(),
        software_adapter: ctx.is_software(),
        config: config.clone(),
        outcome: Outcome::Complete,
        points: Vec::new(),
    };
    // Why a strategy is no longer run: over the budget or failed at a smaller count.
    let mut dropped: Vec<Option<String>> = vec![None; config.strategies.len()];
    'counts: for &n in &lights {
        let params = SceneParams {
            seed: config.seed,
            lights: Some(n),
            ..Default::default()
        };
        let scene = match catalog::build(&config.scene, &params) {
            Ok(s) => s,
            Err(e) => {
                results.outcome = Outcome::Failed(format!("{} at {n} lights: {e}", config.scene));
                break;
            }
        };
        for (si, &assign) in config.strategies.iter().enumerate() {
            let name = assign.resolve(n as usize, ctx.is_software()).name();
            let mut point = ScalingPoint::new(n, name.to_string());
            if let Some(why) = &dropped[si] {
                point.skipped = Some(why.clone());
                done += per_point;
                results.points.push(point);
                continue;
            }
            let before = done;
            let (outs, end) = measure_point(
                ctx, config, &scene, assign, stop, progress, &mut done, total,
            );
            done = before + per_point;
            point.take(&outs);
            match end {
                Ok(stopped) => {
                    if let Some(ms) = point.assign_ms.filter(|&ms| ms > config.budget_ms) {
                        dropped[si] = Some(format!(
                            "took {:.1} s at {n} lights (budget {:.1} s)",
                            ms / 1e3,
                            config.budget_ms / 1e3
                        ));
                    }
                    if !outs.is_empty() {
                        results.points.push(point);
                    }
                    if stopped {
                        results.outcome = Outcome::Interrupted(STOPPED_BY_SIGNAL.into());
                        break 'counts;
                    }
                }
                Err(e) => {
                    dropped[si] = Some(format!("failed at {n} lights"));
                    point.failed = Some(e.to_string());
                    results.points.push(point);
                }
            }
        }
    }
    if results.outcome.is_complete() {
        let failed: Vec<String> = results
            .points
            .iter()
            .filter_map(|p| {
                p.failed
                    .as_ref()
                    .map(|e| format!("{} at {} lights: {e}", p.assign, p.lights))
            })
            .collect();
        if !failed.is_empty() {
            results.outcome = Outcome::Failed(failed.join("; "));
        }
    }
    progress(&Progress {
        done: total,
        total,
        label: "done".into(),
    });
    Ok(results)
}

fn opt<T: std::fmt::Display>(v: Option<T>) -> String {
    v.map_or(String::new(), |v| v.to_string())
}

fn ms(v: Option<f64>) -> String {
    v.map_or("–".into(), |v| format!("{v:.1}"))
}

/// The table (Markdown), as README shows it.
pub fn scaling_table(r: &ScalingResults) -> String {
    let c = &r.config;
    let mut out = format!(
        "`{}` on `{}` at {}x{}, tile {}, {} slices; {}\n\n",
        c.pipeline, c.scene, c.size.0, c.size.1, c.tile_size, c.slices, r.adapter
    );
    out.push_str(
        "| lights | assign | assign ms (GPU span + CPU) | GPU ms (timestamps) | CPU ms | index entries | grid MiB | cells with samples | max lights/cell | lighting computations | × ideal |\n",
    );
    out.push_str("|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for p in &r.points {
        let not_measured = match (&p.failed, &p.skipped) {
            (Some(e), _) => Some(format!("failed: {e}")),
            (None, Some(why)) => Some(format!("skipped: {why}")),
            (None, None) => None,
        };
        if let Some(why) = not_measured {
            let _ = writeln!(
                out,
                "| {} | {} | {why} | | | | | | | | |",
                p.lights, p.assign
            );
            continue;
        }
        let ratio = match (p.lighting_computations, p.ideal_lighting_computations) {
            (Some(n), Some(i)) if i > 0 => format!("{:.1}", n as f64 / i as f64),
            _ => "–".into(),
        };
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            p.lights,
            p.assign,
            ms(p.assign_ms),
            ms(p.assign_gpu_ms),
            ms(p.assign_cpu_ms.filter(|&v| v > 0.0)),
            opt(p.grid_indices),
            p.grid_bytes
                .map_or("–".into(), |b| format!("{:.2}", b as f64 / 1048576.0)),
            opt(p.grid_cells_occupied),
            opt(p.lights_per_cell_max),
            opt(p.lighting_computations),
            ratio
        );
    }
    out
}

/// How each strategy's assignment time grows: from its smallest to its largest measured light
/// count, the factor and the log-log slope (1 = linear in the light count); then the fastest
/// strategy at each count.
pub fn scaling_growth(r: &ScalingResults) -> String {
    let mut names: Vec<&str> = Vec::new();
    for p in &r.points {
        if !names.contains(&p.assign.as_str()) {
            names.push(&p.assign);
        }
    }
    let mut out = String::from(
        "Growth of the assignment time (GPU span + CPU):

",
    );
    for name in &names {
        let measured: Vec<(u32, f64)> = r
            .points
            .iter()
            .filter(|p| p.assign == *name)
            .filter_map(|p| Some((p.lights, p.assign_ms?)))
            .filter(|&(_, ms)| ms > 0.0)
            .collect();
        if let (Some(&(n0, t0)), Some(&(n1, t1))) = (measured.first(), measured.last()) {
            if n1 > n0 {
                let slope = (t1 / t0).ln() / (f64::from(n1) / f64::from(n0)).ln();
                let _ = writeln!(
                    out,
                    "- {name}: {t0:.1} ms at {n0} lights to {t1:.1} ms at {n1} ({:.0}x for {:.0}x the lights; log-log slope {slope:.2})",
                    t1 / t0,
                    f64::from(n1) / f64::from(n0)
                );
            }
        }
    }
    out.push_str(
        "
Fastest at each light count:",
    );
    let mut counts: Vec<u32> = r.points.iter().map(|p| p.lights).collect();
    counts.dedup();
    for n in counts {
        let best = r
            .points
            .iter()
            .filter(|p| p.lights == n)
            .filter_map(|p| Some((p.assign.as_str(), p.assign_ms?)))
            .min_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((name, ms)) = best {
            let _ = write!(out, " {n}: {name} ({ms:.1} ms);");
        }
    }
    out.pop();
    out.push('\n');
    out
}

/// Files `write_scaling` produces.
pub const SCALING_FILES: [&str; 5] = [
    "scaling.json",
    "scaling.csv",
    "scaling.md",
    "scaling.svg",
    "scaling.png",
];

/// The columns of scaling.csv, in order (the header [`ScalingRow`] serializes to).
const SCALING_CSV_COLUMNS: [&str; 15] = [
    "lights",
    "assign",
    "skipped",
    "failed",
    "assign_ms",
    "assign_gpu_ms",
    "assign_cpu_ms",
    "frame_gpu_ms",
    "grid_indices",
    "grid_bytes",
    "grid_cells",
    "grid_cells_occupied",
    "lights_per_cell_max",
    "lighting_computations",
    "ideal_lighting_computations",
];

/// One row of scaling.csv: one (light count, strategy) point; what was not measured is empty.
#[derive(Default, Serialize)]
struct ScalingRow<'a> {
    lights: u32,
    assign: &'a str,
    skipped: Option<&'a str>,
    failed: Option<&'a str>,
    assign_ms: Option<f64>,
    assign_gpu_ms: Option<f64>,
    assign_cpu_ms: Option<f64>,
    frame_gpu_ms: Option<f64>,
    grid_indices: Option<u64>,
    grid_bytes: Option<u64>,
    grid_cells: Option<u64>,
    grid_cells_occupied: Option<u64>,
    lights_per_cell_max: Option<u32>,
    lighting_computations: Option<u64>,
    ideal_lighting_computations: Option<u64>,
}

/// Write scaling.json, scaling.csv, scaling.md and the chart into `dir`; returns the paths
/// written ([`SCALING_FILES`]).
pub fn write_scaling(r: &ScalingResults, dir: &Path) -> Result<Vec<std::path::PathBuf>> {
    std::fs::create_dir_all(dir).map_err(|cause| Error::Io {
        path: dir.display().to_string(),
        cause,
    })?;
    let json = serde_json::to_vec_pretty(r).map_err(|e| invalid("scaling", e.to_string()))?;
    write_atomic(&dir.join("scaling.json"), &json)?;
    let rows = r.points.iter().map(|p| ScalingRow {
        lights: p.lights,
        assign: &p.assign,
        skipped: p.skipped.as_deref(),
        failed: p.failed.as_deref(),
        assign_ms: p.assign_ms,
        assign_gpu_ms: p.assign_gpu_ms,
        assign_cpu_ms: p.assign_cpu_ms,
        frame_gpu_ms: p.frame_gpu_ms,
        grid_indices: p.grid_indices,
        grid_bytes: p.grid_bytes,
        grid_cells: p.grid_cells,
        grid_cells_occupied: p.grid_cells_occupied,
        lights_per_cell_max: p.lights_per_cell_max,
        lighting_computations: p.lighting_computations,
        ideal_lighting_computations: p.ideal_lighting_computations,
    });
    let csv = csv_bytes("scaling", &SCALING_CSV_COLUMNS, rows)?;
    write_atomic(&dir.join("scaling.csv"), &csv)?;
    let md = format!(
        "# Light assignment scaling\n\n`{}`\n\n{}{}\n{}",
        r.command,
        if r.outcome.is_complete() {
            String::new()
        } else {
            format!("**{}**\n\n", r.outcome.describe())
        },
        scaling_table(r),
        scaling_growth(r)
    );
    write_atomic(&dir.join("scaling.md"), md.as_bytes())?;
    let mut names: Vec<&str> = Vec::new();
    for p in &r.points {
        if !names.contains(&p.assign.as_str()) {
            names.push(&p.assign);
        }
    }
    let chart = LineChart {
        title: format!(
            "Light assignment time, {} at {}x{}",
            r.config.pipeline, r.config.size.0, r.config.size.1
        ),
        x_label: "lights".into(),
        y_label: "assignment ms (GPU span + CPU)".into(),
        log_x: true,
        log_y: true,
        series: names
            .iter()
            .map(|name| Series {
                name: name.to_string(),
                points: r
                    .points
                    .iter()
                    .filter(|p| p.assign == *name)
                    .filter_map(|p| Some((f64::from(p.lights), p.assign_ms?)))
                    .collect(),
                emphasis: false,
            })
            .collect(),
    };
    write_atomic(&dir.join("scaling.svg"), chart.svg().as_bytes())?;
    let mut png = Vec::new();
    chart
        .png()
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .map_err(|e| invalid("scaling", e.to_string()))?;
    write_atomic(&dir.join("scaling.png"), &png)?;
    Ok(SCALING_FILES.iter().map(|f| dir.join(f)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scaling_header_is_what_the_row_serializes_to() {
        let mut w = csv::Writer::from_writer(Vec::new());
        w.serialize(ScalingRow::default()).unwrap();
        let text = String::from_utf8(w.into_inner().unwrap()).unwrap();
        assert_eq!(
            text.lines().next(),
            Some(SCALING_CSV_COLUMNS.join(",").as_str())
        );
        let rows = [
            ScalingRow {
                lights: 1000,
                assign: "cpu",
                assign_ms: Some(1.5),
                grid_indices: Some(12),
                ..Default::default()
            },
            ScalingRow {
                lights: 4000,
                assign: "bvh",
                skipped: Some("took 6.0 s at 1000 lights, over budget"),
                ..Default::default()
            },
        ];
        let text =
            String::from_utf8(csv_bytes("scaling", &SCALING_CSV_COLUMNS, rows).unwrap()).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[1], "1000,cpu,,,1.5,,,,12,,,,,,");
        assert_eq!(
            lines[2],
            "4000,bvh,\"took 6.0 s at 1000 lights, over budget\",,,,,,,,,,,,"
        );
    }
}
