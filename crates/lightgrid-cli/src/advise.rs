//! `lightgrid advise`: time the candidate configurations of one scene on this adapter within
//! a budget and print them ranked, with the recommendation and its reasons
//! (`lightgrid_bench::advise`).

use crate::args::{parse_positive, parse_size, progress_bar, stop_on_ctrl_c, SceneOptions, Size};
use crate::files::{Files, Kind};
use anyhow::{bail, Result};
use clap::Args;
use lightgrid::gpu::GpuContext;
use lightgrid::image_io::write_atomic;
use lightgrid_bench::advise::{advise as run_advice, Advice, AdvisePlan, Outcome};
use std::path::PathBuf;
use std::time::Duration;

/// Longest budget `advise` takes (a day).
const MAX_BUDGET_S: f64 = 86_400.0;

#[derive(Args)]
pub(crate) struct AdviseArgs {
    #[command(flatten)]
    pub(crate) scene: SceneOptions,
    /// Frame size WIDTHxHEIGHT (default: the scene's own size).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_size)]
    pub(crate) size: Option<Size>,
    /// Wall-clock seconds to spend measuring (candidates that would not fit are skipped,
    /// saying so), more than 0 and at most a day.
    #[arg(long, allow_hyphen_values = true, default_value_t = 60.0, value_parser = parse_positive)]
    pub(crate) budget: f64,
    /// Write the ranking and the recommendation as JSON to this file, or with `-` to
    /// stdout instead of the table (for scripts).
    #[arg(long)]
    pub(crate) json: Option<PathBuf>,
}

pub(crate) fn advise(adapter: Option<&str>, a: &AdviseArgs) -> Result<()> {
    if a.budget > MAX_BUDGET_S {
        bail!("--budget {}: at most {MAX_BUDGET_S} seconds", a.budget);
    }
    let to_stdout = a.json.as_deref() == Some(std::path::Path::new("-"));
    let mut files = Files::default();
    if !to_stdout {
        files.output("--json", a.json.as_deref(), Kind::Data)?;
    }
    a.scene.claim(&mut files)?;
    let scene = a.scene.build()?;
    let ctx = GpuContext::new(adapter)?;
    let size = Size::or_scene(a.size, &scene);
    lightgrid::validate_size(&ctx, size.0, size.1)?;
    let stop = stop_on_ctrl_c()?;
    eprintln!(
        "advising on {} at {}x{} on {} within {:.0} s",
        scene.name,
        size.0,
        size.1,
        ctx.adapter_label(),
        a.budget
    );
    let mut bar = progress_bar();
    let advice = run_advice(
        &ctx,
        &AdvisePlan {
            scene: &scene,
            size,
            budget: Duration::from_secs_f64(a.budget),
            base: lightgrid::RenderSettings::default(),
        },
        &stop,
        &mut |p| bar(p),
    )?;
    eprintln!();
    let json = serde_json::to_vec_pretty(&advice)?;
    if let Some(path) = a.json.as_ref().filter(|_| !to_stdout) {
        write_atomic(path, &json)?;
    }
    if to_stdout {
        outln!("{}", String::from_utf8_lossy(&json));
    } else {
        print_table(&advice)?;
    }
    if advice.interrupted {
        bail!(
            "interrupted by a signal (Ctrl-C or SIGTERM): only the candidates measured before it are ranked, so the recommendation is not the advice a full run gives"
        );
    }
    if advice.recommendation.is_none() {
        bail!("no configuration was measured within the budget; give a larger --budget or a smaller --size");
    }
    Ok(())
}

fn print_table(advice: &Advice) -> Result<()> {
    // The configuration column as wide as its longest label.
    let width = (advice.ranking.iter())
        .map(|m| m.candidate.label().len())
        .max()
        .unwrap_or(0)
        .max(44);
    outln!(
        "{:<4} {:<width$} {:>10} {:>9} {:>10} {:>10}  note",
        "rank",
        "configuration",
        "frame ms",
        "GPU ms",
        "memory",
        "efficiency"
    );
    for (i, m) in advice.ranking.iter().enumerate() {
        let (ms, gpu, note) = match &m.outcome {
            Outcome::Measured {
                frame_ms,
                gpu_ms,
                wrong_frames,
            } => (
                format!("{frame_ms:.2}"),
                gpu_ms.map_or("n/a".into(), |g| format!("{g:.2}")),
                if *wrong_frames > 0 {
                    format!("{wrong_frames} frames wrong (not ranked)")
                } else {
                    String::new()
                },
            ),
            Outcome::Skipped { reason } => ("-".into(), "-".into(), format!("skipped: {reason}")),
            Outcome::Failed { reason } => ("-".into(), "-".into(), format!("failed: {reason}")),
        };
        outln!(
            "{:<4} {:<width$} {:>10} {:>9} {:>10} {:>10}  {}{}",
            i + 1,
            m.candidate.label(),
            ms,
            gpu,
            match m.outcome {
                Outcome::Measured { .. } => {
                    format!("{:.1} MiB", m.memory_bytes as f64 / f64::from(1u32 << 20))
                }
                _ => "-".into(),
            },
            m.efficiency
                .map_or("-".into(), |e| format!("{:.0}%", e * 100.0)),
            note,
            if m.msaa { "" } else { " (no MSAA)" }
        );
    }
    outln!(
        "\n{} candidates in {:.1} s of a {:.0} s budget",
        advice.ranking.len(),
        advice.elapsed_s,
        advice.budget_s
    );
    if let Some(r) = &advice.recommendation {
        outln!("recommended: {}", r.options);
        for reason in &r.reasons {
            outln!("  - {reason}");
        }
    }
    Ok(())
}
