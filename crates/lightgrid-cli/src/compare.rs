//! `lightgrid compare` (and the default job): every pipeline on one frame, each image
//! compared with the `forward` reference.

use crate::args::{build_scene, SceneArgs, Size};
use anyhow::{bail, Context, Result};
use clap::Args;
use lightgrid::gpu::GpuContext;
use lightgrid::image_io::{diff, save_png, write_atomic};
use lightgrid::pipelines::{PIPELINES, REFERENCE};
use lightgrid::Renderer;
use std::path::PathBuf;

#[derive(Args)]
pub(crate) struct CompareArgs {
    #[command(flatten)]
    pub(crate) scene: SceneArgs,
    /// Directory for the images and statistics.
    #[arg(long, default_value = "out")]
    pub(crate) out_dir: PathBuf,
}

/// Frame of `robots-many` the default job renders: street level, looking down the street.
pub(crate) const DEFAULT_JOB_FRAME: u32 = 200;

pub(crate) fn compare(adapter: Option<&str>, a: &CompareArgs) -> Result<()> {
    std::fs::create_dir_all(&a.out_dir)
        .with_context(|| format!("cannot create {}", a.out_dir.display()))?;
    let scene = build_scene(&a.scene)?;
    let ctx = GpuContext::new(adapter)?;
    let (w, h) = Size::or_scene(a.scene.size, &scene);
    let mut renderer = Renderer::new(&ctx, w, h, a.scene.settings())?;
    println!(
        "{} frame {} at {w}x{h}, {} lights, on {}",
        scene.name,
        a.scene.frame,
        scene.lights.len(),
        ctx.adapter_label()
    );
    println!(
        "{:<22} {:>9}  {:>9} {:>5} {:>5}  {:>14} {:>7}  {:>11}",
        "pipeline", "time ms", "diff mean", "p99", "max", "lighting comp", "x ideal", "lights/tile"
    );
    // Reference images by id; `forward` is rendered first (registry order).
    let mut references: std::collections::HashMap<&str, image::RgbaImage> = Default::default();
    let mut notes = Vec::new();
    let mut assigned_by: Option<String> = None;
    let mut failed = Vec::new();
    for p in PIPELINES {
        let warm = (0..a.scene.warmup)
            .try_for_each(|_| renderer.render(&scene, a.scene.frame, p.id).map(drop));
        let out = match warm.and_then(|_| renderer.render(&scene, a.scene.frame, p.id)) {
            Ok(o) => o,
            Err(e) => {
                println!("{:<24} failed: {e}", p.id);
                failed.push(p.id);
                continue;
            }
        };
        let png = a.out_dir.join(format!("{}.png", p.id));
        save_png(&out.image, &png)?;
        write_atomic(
            &a.out_dir.join(format!("{}.json", p.id)),
            &serde_json::to_vec_pretty(&out.stats)?,
        )?;
        let d = match references.get(REFERENCE) {
            None => None,
            Some(r) => Some(diff(r, &out.image)?.0),
        };
        if p.reference != REFERENCE && p.reference != p.id {
            if let Some(r) = references.get(p.reference) {
                let own = diff(r, &out.image)?.0;
                notes.push(format!(
                    "{} vs its own reference {}: mean {:.3}, p99 {}, max {}",
                    p.id, p.reference, own.mean, own.p99, own.max
                ));
            }
        }
        let time = format!(
            "{:.2}{}",
            out.stats.gpu_ms,
            if out.stats.timing == lightgrid::TimingSource::WallClock {
                "*"
            } else {
                ""
            }
        );
        let s = &out.stats;
        let (mean, p99, max) = match d {
            None => ("reference".to_string(), String::new(), String::new()),
            Some(d) => (
                format!("{:.3}", d.mean),
                d.p99.to_string(),
                d.max.to_string(),
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
        if let Some(assign) = &s.assign {
            assigned_by.get_or_insert_with(|| assign.clone());
        }
        println!(
            "{:<22} {:>9}  {:>9} {:>5} {:>5}  {:>14} {:>7}  {:>11}",
            p.id, time, mean, p99, max, comps, ratio, per_tile
        );
        if p.reference == p.id {
            references.insert(p.id, out.image);
        }
    }
    for n in &notes {
        println!("{n}");
    }
    if !ctx.timestamps {
        println!("* wall clock: this adapter has no timestamp queries");
    }
    println!(
        "diff in 8-bit sRGB levels vs {REFERENCE}; 'x ideal' = lighting computations / ideal (one per light reaching a visible sample); lights/tile = avg/max per cell of the pipeline's grid ({}px tiles; clusters for clustered_*), built by --assign {}",
        a.scene.tile,
        assigned_by.as_deref().unwrap_or("-")
    );
    println!("images and stats in {}", a.out_dir.display());
    if !failed.is_empty() {
        bail!("pipelines failed: {}", failed.join(", "));
    }
    Ok(())
}
