//! `lightgrid render`: one frame of a scene with one pipeline (an analysis run: image,
//! statistics, heatmap).

use crate::args::{check_applies, timing_label, SceneArgs, Size};
use crate::files::{Files, Kind};
use anyhow::Result;
use clap::Args;
use lightgrid::debug_view::{self, DebugView};
use lightgrid::gpu::GpuContext;
use lightgrid::image_io::{encode_png, write_atomic};
use lightgrid::pipelines::{self, REFERENCE};
use lightgrid::Renderer;
use std::path::PathBuf;

#[derive(Args)]
pub(crate) struct RenderArgs {
    #[command(flatten)]
    pub(crate) scene: SceneArgs,
    /// Pipeline id (see `lightgrid list`).
    #[arg(long, default_value = REFERENCE)]
    pub(crate) pipeline: String,
    /// Image to write (a *.png file).
    #[arg(long)]
    pub(crate) out: Option<PathBuf>,
    /// What --out shows: the shaded frame, or a debug view of it (the viewer's): lights
    /// (lights per cell), bounds (cell depth-bound spans) or wasted (lighting computations
    /// above the ideal, per pixel).
    #[arg(long, default_value = "shaded", value_parser = crate::args::parse_view)]
    pub(crate) view: DebugView,
    /// Statistics to write (JSON).
    #[arg(long)]
    pub(crate) stats: Option<PathBuf>,
    /// Lights-per-tile heatmap to write (a *.png file): the pipeline's own grid, or for pipelines
    /// without a CPU grid the depth-bounded grid used for the ideal count.
    #[arg(long)]
    pub(crate) heatmap: Option<PathBuf>,
    /// The heatmap's colour scale: 0 to N lights per cell, 1 to 1000000 (default: the
    /// frame's own maximum); Forward+ Fig. 2(b) uses 50.
    #[arg(long, allow_hyphen_values = true, requires = "heatmap", value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub(crate) heatmap_max: Option<u32>,
    /// With --shadows maps: the shadow-map texture the frame rendered to write (a *.png file):
    /// the atlas of every shadowed light's faces (each texel's distance to its light, near
    /// white), or a light-volume pipeline's one re-used cube.
    #[arg(long)]
    pub(crate) shadow_maps_image: Option<PathBuf>,
}

pub(crate) fn render(adapter: Option<&str>, a: &RenderArgs) -> Result<()> {
    let info = pipelines::find(&a.pipeline)?;
    let settings = a.scene.renderer.settings()?;
    check_applies(&a.scene.renderer.given(), &[info], &settings)?;
    let mut files = Files::default();
    files.output("--out", a.out.as_deref(), Kind::Png)?;
    files.output("--stats", a.stats.as_deref(), Kind::Data)?;
    files.output("--heatmap", a.heatmap.as_deref(), Kind::Png)?;
    files.output(
        "--shadow-maps-image",
        a.shadow_maps_image.as_deref(),
        Kind::Png,
    )?;
    if a.shadow_maps_image.is_some() && settings.shadows != lightgrid::scene::Shadows::Maps {
        anyhow::bail!("--shadow-maps-image needs --shadows maps");
    }
    a.scene.options.claim(&mut files)?;
    let scene = a.scene.options.build()?;
    let ctx = GpuContext::new(adapter)?;
    let (w, h) = Size::or_scene(a.scene.size, &scene);
    let mut renderer = Renderer::new(&ctx, w, h, settings)?;
    for _ in 0..a.scene.warmup {
        renderer.render(&scene, a.scene.frame, &a.pipeline)?;
    }
    let out = renderer.render(&scene, a.scene.frame, &a.pipeline)?;
    // Every output is made before any is written, so a failure leaves all of them untouched.
    let mut writes: Vec<(&PathBuf, Vec<u8>)> = Vec::new();
    if let Some(path) = &a.out {
        match debug_view::draw(a.view, &out) {
            None => writes.push((path, encode_png(&out.image, path)?)),
            Some(d) => {
                outln!(
                    "{}: 0 to {} {}{}{}",
                    a.view.name(),
                    d.max,
                    d.unit,
                    d.total.map_or(String::new(), |t| format!(", {t} in all")),
                    d.note.map_or(String::new(), |n| format!(" ({n})"))
                );
                writes.push((path, encode_png(&d.image, path)?));
            }
        }
    }
    if let Some(path) = &a.heatmap {
        let view_distance = out.view_distances();
        let map = lightgrid::heatmap::heatmap_scaled(
            &out.image,
            &out.grid,
            Some(&view_distance),
            a.heatmap_max,
        );
        writes.push((path, encode_png(&map, path)?));
    }
    if let Some(path) = &a.stats {
        let mut stats = serde_json::to_value(&out.stats)?;
        // The ranges lightgrid gave a file's lights that had none (README "glTF scenes").
        if !scene.derived_ranges.is_empty() {
            stats["lights_without_range"] = (scene.derived_ranges.iter())
                .map(|&(light, range)| serde_json::json!({"light": light, "range": range}))
                .collect();
        }
        writes.push((path, serde_json::to_vec_pretty(&stats)?));
    }
    if let Some(path) = &a.shadow_maps_image {
        let atlas = renderer
            .shadow_maps_image()?
            .ok_or_else(|| anyhow::anyhow!("--shadow-maps-image: no light cast shadows"))?;
        writes.push((path, encode_png(&atlas, path)?));
    }
    for (path, bytes) in writes {
        write_atomic(path, &bytes)?;
    }
    print_stats(&out.stats)
}

/// What the frame cost and counted, for the terminal.
fn print_stats(s: &lightgrid::FrameStats) -> Result<()> {
    outln!(
        "{} / {} frame {} at {}x{}: {} lights, {:.2} ms ({}) on {}",
        s.scene,
        s.pipeline,
        s.frame,
        s.width,
        s.height,
        s.lights,
        s.gpu_ms,
        timing_label(s.timing),
        s.adapter
    );
    outln!(
        "lighting computations {} (ideal {}, efficiency {}){}",
        s.lighting_computations
            .map_or("n/a".into(), |n| n.to_string()),
        s.ideal_lighting_computations,
        s.efficiency
            .map_or("n/a".into(), |e| format!("{:.1}%", e * 100.0)),
        match (s.lights_per_tile_avg, s.lights_per_tile_max) {
            (Some(avg), Some(max)) =>
                format!(", lights per {}px cell avg {avg:.1} max {max}", s.tile_size),
            _ => String::new(),
        }
    );
    if let (Some(assign), Some(indices)) = (&s.assign, s.grid_indices) {
        outln!(
            "light assignment {assign}: {} ms ({} ms GPU timestamps{}), {indices} index entries in {} cells ({} with samples)",
            s.assign_ms.map_or("n/a".into(), |ms| format!("{ms:.2}")),
            s.assign_gpu_ms.map_or("n/a".into(), |ms| format!("{ms:.2}")),
            s.assign_cpu_ms
                .filter(|&ms| ms > 0.0)
                .map_or(String::new(), |ms| format!(", {ms:.2} ms on the CPU")),
            s.grid_cells.unwrap_or(0),
            s.grid_cells_occupied.unwrap_or(0),
        );
    }
    if s.msaa > 1 {
        let edges = match s.msaa_shading {
            Some(m) => format!(
                ": {} edge pixels ({:.1}%) shaded per sample, {} samples shaded of {} with geometry ({:.1}%)",
                m.edge_pixels,
                100.0 * m.edge_pixels as f64 / (f64::from(s.width) * f64::from(s.height)),
                m.shaded_samples,
                m.geometry_samples,
                100.0 * m.shaded_samples as f64 / m.geometry_samples.max(1) as f64
            ),
            None => String::new(),
        };
        outln!("msaa {}x{edges}", s.msaa);
    }
    outln!(
        "frame: {} queue submission(s), {} bytes read back and {:.2} ms waited inside the frame{}",
        s.submits,
        s.readback_bytes,
        s.cpu_wait_ms,
        if s.submits > 1 {
            " (--assign cpu reads the cell bounds back)"
        } else {
            ""
        }
    );
    Ok(())
}
