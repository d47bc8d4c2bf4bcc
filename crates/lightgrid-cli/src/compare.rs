//! `lightgrid compare` (and the default job): every pipeline on one frame, each image
//! compared with the `forward` reference.

use crate::args::{run_outcome, stop_on_ctrl_c, SceneArgs, Size};
use crate::files::Files;
use anyhow::{bail, Result};
use clap::Args;
use lightgrid::gpu::GpuContext;
use lightgrid::image_io::{diff, encode_png, write_atomic, DiffSummary};
use lightgrid::pipelines::{PIPELINES, REFERENCE};
use lightgrid::Renderer;
use lightgrid_bench::{check_out_dir, Earlier, OutDir, Outcome, STOPPED_BY_SIGNAL};
use serde::Serialize;
use std::collections::HashMap;
use std::path::PathBuf;

#[derive(Args)]
pub(crate) struct CompareArgs {
    #[command(flatten)]
    pub(crate) scene: SceneArgs,
    /// Directory for the images and statistics.
    #[arg(long, default_value = "out")]
    pub(crate) out_dir: PathBuf,
    /// Write into an existing directory that lightgrid did not make and that is not empty,
    /// and over files there that lightgrid (or another command of it) did not write.
    #[arg(long)]
    pub(crate) force: bool,
}

/// Frame of `robots-many` the default job renders: street level, looking down the street.
pub(crate) const DEFAULT_JOB_FRAME: u32 = 200;

/// One row of the table and of compare.json.
#[derive(Serialize)]
struct Row {
    pipeline: &'static str,
    /// Why the pipeline produced no image.
    failed: Option<String>,
    gpu_ms: Option<f64>,
    /// Difference from `forward`; null when there is none to compare with (`diff_note`).
    diff: Option<DiffSummary>,
    diff_note: Option<String>,
    lighting_computations: Option<u64>,
    ideal_lighting_computations: Option<u64>,
}

/// compare.json: the table, and how the run ended.
#[derive(Serialize)]
struct CompareJson<'a> {
    command: String,
    adapter: String,
    scene: &'a str,
    frame: u32,
    width: u32,
    height: u32,
    outcome: &'a Outcome,
    rows: &'a [Row],
    notes: &'a [String],
}

/// What the difference column says for a pipeline whose image exists, given the rows so far
/// (the reference's among them, failed or not).
fn diff_cell(
    id: &str,
    image: &image::RgbaImage,
    references: &HashMap<&str, image::RgbaImage>,
    rows: &[Row],
) -> Result<(Option<DiffSummary>, Option<String>)> {
    if id == REFERENCE {
        return Ok((None, Some("reference".into())));
    }
    let reference_failed = rows
        .iter()
        .any(|r| r.pipeline == REFERENCE && r.failed.is_some());
    match references.get(REFERENCE) {
        Some(r) => Ok((Some(diff(r, image)?.0), None)),
        None if reference_failed => Ok((None, Some(format!("not computed: {REFERENCE} failed")))),
        None => Ok((None, Some(format!("not computed: no {REFERENCE} image")))),
    }
}

impl Row {
    /// A pipeline's image: its time, difference and counts.
    fn measured(
        pipeline: &'static str,
        s: &lightgrid::FrameStats,
        diff: Option<DiffSummary>,
        note: Option<String>,
    ) -> Row {
        Row {
            pipeline,
            failed: None,
            gpu_ms: Some(s.gpu_ms),
            diff,
            diff_note: note,
            lighting_computations: s.lighting_computations,
            ideal_lighting_computations: Some(s.ideal_lighting_computations),
        }
    }

    /// A pipeline that produced no image: it `failed`, or was skipped with `note`.
    fn without_image(pipeline: &'static str, failed: Option<String>, note: Option<String>) -> Row {
        Row {
            pipeline,
            failed,
            gpu_ms: None,
            diff: None,
            diff_note: note,
            lighting_computations: None,
            ideal_lighting_computations: None,
        }
    }
}

/// The run's first line and the table's head.
fn print_header(
    scene: &lightgrid::scene::Scene,
    frame: u32,
    (w, h): (u32, u32),
    adapter: &str,
) -> Result<()> {
    outln!(
        "{} frame {} at {w}x{h}, {} lights, on {}",
        scene.name,
        frame,
        scene.lights.len(),
        adapter
    );
    outln!(
        "{:<22} {:>9}  {:>9} {:>5} {:>5}  {:>14} {:>7}  {:>11}",
        "pipeline",
        "time ms",
        "diff mean",
        "p99",
        "max",
        "lighting comp",
        "x ideal",
        "lights/tile"
    );
    Ok(())
}

/// Write compare.json beside the images and move the run's files into place (an
/// interrupted run is set aside rather than replacing an earlier whole one); the run's
/// outcome as the command's.
fn commit_table(
    a: &CompareArgs,
    files: &mut Files,
    dir: OutDir,
    mut written: Vec<std::path::PathBuf>,
    summary: &CompareJson,
    outcome: Outcome,
) -> Result<()> {
    let path = dir.staging().join(COMPARE_JSON);
    write_atomic(&path, &serde_json::to_vec_pretty(summary)?)?;
    written.push(path);
    // Images of pipelines that failed this time must not stay from an earlier run. A table
    // with failed pipelines is a whole answer (every pipeline was tried); an interrupted one
    // is not, and does not replace an earlier run's.
    files.placed("--out-dir", &a.out_dir, &written)?;
    let whole = !matches!(outcome, Outcome::Interrupted(_));
    let committed = dir.commit(&written, Earlier::Remove, whole)?;
    let place = committed.set_aside.as_deref().unwrap_or(&a.out_dir);
    outln!(
        "images and stats in {} ({COMPARE_JSON}: the table)",
        place.display()
    );
    match outcome {
        Outcome::Complete => Ok(()),
        Outcome::Failed(reason) => match committed.note(&a.out_dir) {
            Some(note) => bail!("{reason}\n{note}"),
            None => bail!("{reason}"),
        },
        o => run_outcome(&o, &a.out_dir, &committed),
    }
}

/// The pipeline's image and its stats, written into the staging directory.
fn write_outputs(
    staging: &std::path::Path,
    id: &str,
    out: &lightgrid::FrameOutput,
) -> Result<Vec<std::path::PathBuf>> {
    let png = staging.join(format!("{id}.png"));
    let stats = staging.join(format!("{id}.json"));
    let mut written = Vec::new();
    for (path, bytes) in [
        (png.clone(), encode_png(&out.image, &png)?),
        (stats, serde_json::to_vec_pretty(&out.stats)?),
    ] {
        write_atomic(&path, &bytes)?;
        written.push(path);
    }
    Ok(written)
}

/// How a pipeline compared with its own reference, where that is not `forward` (the
/// mono-specular variants).
fn own_reference_note(
    p: &lightgrid::pipelines::PipelineInfo,
    references: &HashMap<&str, image::RgbaImage>,
    image: &image::RgbaImage,
) -> Result<Option<String>> {
    if p.reference == REFERENCE || p.reference == p.id {
        return Ok(None);
    }
    let Some(r) = references.get(p.reference) else {
        return Ok(None);
    };
    let own = diff(r, image)?.0;
    Ok(Some(format!(
        "{} vs its own reference {}: mean {:.3}, p99 {}, max {}",
        p.id, p.reference, own.mean, own.p99, own.max
    )))
}

/// One pipeline's line of the printed table: time, difference (or why there is none),
/// lighting computations against the ideal, lights per cell.
fn table_line(
    id: &str,
    s: &lightgrid::FrameStats,
    d: Option<&DiffSummary>,
    note: Option<&str>,
) -> String {
    let time = format!(
        "{:.2}{}",
        s.gpu_ms,
        if s.timing == lightgrid::TimingSource::WallClock {
            "*"
        } else {
            ""
        }
    );
    let (mean, p99, max) = match (d, note) {
        (Some(d), _) => (
            format!("{:.3}", d.mean),
            d.p99.to_string(),
            d.max.to_string(),
        ),
        (None, n) => (
            n.unwrap_or_default().to_string(),
            String::new(),
            String::new(),
        ),
    };
    let comps = s
        .lighting_computations
        .map_or("n/a".into(), |n| n.to_string());
    let ratio = s
        .lighting_computations
        .filter(|_| s.ideal_lighting_computations > 0)
        .map_or("n/a".into(), |n| {
            format!("{:.2}", n as f64 / s.ideal_lighting_computations as f64)
        });
    let per_tile = match (s.lights_per_tile_avg, s.lights_per_tile_max) {
        (Some(avg), Some(max)) => format!("{avg:.1}/{max}"),
        _ => "-".into(),
    };
    format!(
        "{:<22} {:>9}  {:>9} {:>5} {:>5}  {:>14} {:>7}  {:>11}",
        id, time, mean, p99, max, comps, ratio, per_tile
    )
}

pub(crate) fn compare(adapter: Option<&str>, a: &CompareArgs) -> Result<()> {
    let settings = a.scene.renderer.settings()?;
    // Only whether it can be written, here: what the directory holds is checked by the claim
    // below, after the options (which a user fixes first) and before anything is rendered.
    check_out_dir(&a.out_dir, true)?;
    let mut files = Files::default();
    a.scene.options.claim(&mut files)?;
    let scene = a.scene.options.build()?;
    let ctx = GpuContext::new(adapter)?;
    let (w, h) = Size::or_scene(a.scene.size, &scene);
    let mut renderer = Renderer::new(&ctx, w, h, settings)?;
    let dir = OutDir::claim(&a.out_dir, "compare", a.force)?;
    let stop = stop_on_ctrl_c()?;
    print_header(&scene, a.scene.frame, (w, h), &ctx.adapter_label())?;
    // Reference images by id; `forward` is rendered first (registry order).
    let mut references: HashMap<&str, image::RgbaImage> = Default::default();
    let mut notes = Vec::new();
    let mut assigned_by: Option<String> = None;
    let mut rows: Vec<Row> = Vec::new();
    let mut written = Vec::new();
    let mut outcome = Outcome::Complete;
    for p in PIPELINES {
        if stop.load(std::sync::atomic::Ordering::Relaxed) {
            outcome = Outcome::Interrupted(STOPPED_BY_SIGNAL.into());
            break;
        }
        if let (true, lightgrid::pipelines::Msaa::Refused(why)) =
            (settings.grid.samples > 1, p.msaa)
        {
            outln!("{:<24} skipped: refuses MSAA ({why})", p.id);
            rows.push(Row::without_image(
                p.id,
                None,
                Some(format!("skipped: refuses MSAA ({why})")),
            ));
            continue;
        }
        let warm = (0..a.scene.warmup)
            .try_for_each(|_| renderer.render(&scene, a.scene.frame, p.id).map(drop));
        let out = match warm.and_then(|_| renderer.render(&scene, a.scene.frame, p.id)) {
            Ok(o) => o,
            Err(e) => {
                outln!("{:<24} failed: {e}", p.id);
                rows.push(Row::without_image(p.id, Some(e.to_string()), None));
                continue;
            }
        };
        written.extend(write_outputs(dir.staging(), p.id, &out)?);
        let (d, note) = diff_cell(p.id, &out.image, &references, &rows)?;
        notes.extend(own_reference_note(p, &references, &out.image)?);
        let s = &out.stats;
        if let Some(assign) = &s.assign {
            assigned_by.get_or_insert_with(|| assign.clone());
        }
        outln!("{}", table_line(p.id, s, d.as_ref(), note.as_deref()));
        rows.push(Row::measured(p.id, s, d, note));
        if p.reference == p.id {
            references.insert(p.id, out.image);
        }
    }
    for n in &notes {
        outln!("{n}");
    }
    if !ctx.timestamps {
        outln!("* wall clock: this adapter has no timestamp queries");
    }
    outln!(
        "diff in 8-bit sRGB levels vs {REFERENCE}; 'x ideal' = lighting computations / ideal (one per light reaching a visible sample); lights/tile = avg/max per cell of the pipeline's grid ({}px tiles; clusters for clustered_*), built by --assign {}",
        a.scene.renderer.tile,
        assigned_by.as_deref().unwrap_or("-")
    );
    let failed: Vec<&str> = rows
        .iter()
        .filter(|r| r.failed.is_some())
        .map(|r| r.pipeline)
        .collect();
    if outcome.is_complete() && !failed.is_empty() {
        outcome = Outcome::Failed(format!("pipelines failed: {}", failed.join(", ")));
    }
    let summary = CompareJson {
        command: std::env::args().collect::<Vec<_>>().join(" "),
        adapter: ctx.adapter_label(),
        scene: &scene.name,
        frame: a.scene.frame,
        width: w,
        height: h,
        outcome: &outcome,
        rows: &rows,
        notes: &notes,
    };
    let outcome = outcome.clone();
    commit_table(a, &mut files, dir, written, &summary, outcome)
}

/// The table's file in the output directory.
pub(crate) const COMPARE_JSON: &str = "compare.json";
