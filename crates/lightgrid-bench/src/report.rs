//! Writing a benchmark's results: results.json, results.csv, plots (PNG + SVG) and
//! summary.md. Every file is written whole or not at all.

use super::{evaluate_claims, BenchResults, RunRecord, Verdict};
use crate::claims::Basis;
use crate::invalid;
use crate::plot::{LineChart, Series, StackedBars};
use lightgrid::culling::GridLists;
use lightgrid::error::{Error, Result};
use lightgrid::frame::MaterialDraws;
use lightgrid::image_io::{save_png, write_atomic};
use lightgrid::passes::GBufferFormat;
use lightgrid::pipelines::{ids, SpotCull};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Files every report has (plots and heatmaps are added per scene and G-buffer setting).
pub const REPORT_FILES: &[&str] = &["results.json", "results.csv", "summary.md"];

/// Version of the results.json layout (documented in README).
pub const SCHEMA_VERSION: u32 = 4;

/// A run's mean lighting computations as a multiple of the ideal, two decimals; `missing`
/// where the run counted none.
fn times_ideal(m: &super::RunSummary, missing: &str) -> String {
    m.lighting_computations.map_or(missing.into(), |x| {
        format!(
            "{:.2}",
            x.mean / m.ideal_lighting_computations.mean.max(1.0)
        )
    })
}

/// MSAA (tiled-forward-shading Fig. 4.4): time, memory and the edge-aware kernels' work at
/// every sample count the run measured, when it measured more than one.
fn msaa_section(s: &mut String, results: &BenchResults, scene: &str) {
    let runs: Vec<&RunRecord> = results
        .runs
        .iter()
        .filter(|r| r.scene == scene && r.summary.is_some())
        .collect();
    if !runs.iter().any(|r| r.msaa() > 1) {
        return;
    }
    s.push_str("\n### MSAA (tiled-forward-shading Fig. 4.4)\n\nEvery target holds each sample; forward pipelines shade once per pixel and surface (hardware MSAA), the deferred kernels once per pixel plus every other covered sample of an edge pixel (tiled-deferred-tricks), and the tonemap resolves after the tone curve. *Cell bounds* is the Z-reduction over every sample (§4.6); with MSAA, *fragment bounds* adds every fragment's pixel-centre distance to its cell first (`fragment_bounds.wgsl`).\n\n| pipeline | samples | avg ms | × ideal | render targets MiB | cell bounds ms | fragment bounds ms | edge pixels | samples shaded / with geometry |\n|---|---|---|---|---|---|---|---|---|\n");
    for r in runs {
        let m = r.summary.as_ref().expect("filtered");
        let ratio = times_ideal(m, "n/a");
        let pass_ms = |label: &str| {
            m.passes
                .iter()
                .find(|p| p.label == label)
                .map_or("-".into(), |p| format!("{:.2}", p.ms))
        };
        let bounds = pass_ms(lightgrid::culling::labels::CELL_BOUNDS);
        let fragments = pass_ms(lightgrid::culling::labels::FRAGMENT_BOUNDS);
        let shading: Vec<_> = r
            .frames
            .iter()
            .filter_map(|f| f.stats.msaa_shading)
            .collect();
        let (edges, shaded) = if shading.is_empty() {
            ("-".to_string(), "-".to_string())
        } else {
            let sum = |f: fn(&lightgrid::frame::MsaaShading) -> u64| {
                shading.iter().map(f).sum::<u64>() as f64
            };
            let pixels = f64::from(r.width) * f64::from(r.height) * shading.len() as f64;
            (
                format!("{:.1}%", 100.0 * sum(|m| m.edge_pixels) / pixels),
                format!(
                    "{:.1}%",
                    100.0 * sum(|m| m.shaded_samples) / sum(|m| m.geometry_samples).max(1.0)
                ),
            )
        };
        let mut pipeline = match r.gbuffer_bits() {
            Some(b) => format!("{} (g{b})", r.pipeline),
            None => r.pipeline.clone(),
        };
        if let Some(m) = r.msaa_resolve() {
            pipeline += &format!(" [{} resolve]", m.name());
        }
        let _ = writeln!(
            s,
            "| {pipeline} | {} | {:.2} | {ratio} | {:.1} | {bounds} | {fragments} | {edges} | {shaded} |",
            r.msaa(),
            m.gpu_ms.mean,
            m.target_bytes as f64 / (1024.0 * 1024.0),
        );
    }
}

/// The BRDFs side by side (`--brdf phong,ggx`): for each run measured with both, the cost of
/// one light evaluation, as the slope of a least-squares line of GPU frame time against
/// lighting computations over the frames (tiled-shading §8.2's fit, `claims::fit_cost`) and
/// as the mean frame time per mean computation, and the frames' mean times.
fn brdf_section(s: &mut String, results: &BenchResults, scene: &str) {
    use lightgrid::scene::Brdf;
    let runs: Vec<&RunRecord> = results
        .runs
        .iter()
        .filter(|r| r.scene == scene && r.summary.is_some() && r.settings.brdf.is_some())
        .collect();
    let twin = |r: &RunRecord, brdf: Brdf| {
        runs.iter().copied().find(|o| {
            o.pipeline == r.pipeline
                && o.settings.brdf == Some(brdf)
                && lightgrid::RenderSettings {
                    brdf: r.settings.brdf,
                    ..o.settings
                } == r.settings
        })
    };
    let pairs: Vec<(&RunRecord, &RunRecord)> = runs
        .iter()
        .filter(|r| r.settings.brdf == Some(Brdf::Phong))
        .filter_map(|r| Some((*r, twin(r, Brdf::Ggx)?)))
        .collect();
    if pairs.is_empty() {
        return;
    }
    s.push_str("
### The BRDFs: one light evaluation, Blinn-Phong against GGX

ns per lighting computation: the slope of GPU frame time against lighting computations over the frames (least squares), and the mean frame time over the mean count (constant work included).

| pipeline | Blinn-Phong ns (fit) | GGX ns (fit) | fit ratio | Blinn-Phong ns (mean) | GGX ns (mean) | avg ms Blinn-Phong / GGX |
|---|---|---|---|---|---|---|
");
    let cost = |r: &RunRecord| {
        let fit = crate::claims::frame_costs(r)
            .as_deref()
            .and_then(crate::claims::fit_cost);
        let m = r.summary.as_ref().expect("filtered");
        let mean = m
            .lighting_computations
            .map(|c| m.gpu_ms.mean * 1e6 / c.mean.max(1.0));
        (fit.map(|(_, b)| b * 1e6), mean, m.gpu_ms.mean)
    };
    let show = |v: Option<f64>| v.map_or("n/a".to_string(), |v| format!("{v:.1}"));
    for (phong, ggx) in pairs {
        let (pf, pm, pms) = cost(phong);
        let (gf, gm, gms) = cost(ggx);
        let ratio = match (pf, gf) {
            (Some(p), Some(g)) if p > 0.0 => format!("{:.2}x", g / p),
            _ => "n/a".into(),
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {ratio} | {} | {} | {pms:.2} / {gms:.2} |",
            phong.name().replace(" [phong]", ""),
            show(pf),
            show(gf),
            show(pm),
            show(gm)
        );
    }
}

/// Shadows (`--shadows`): per run with shadows, the frame time, the shadow-map texture's
/// memory and face size (re-used or all in flight), and the shadow rays per frame.
fn shadows_section(s: &mut String, results: &BenchResults, scene: &str) {
    use lightgrid::scene::Shadows;
    let runs: Vec<&RunRecord> = results
        .runs
        .iter()
        .filter(|r| r.scene == scene && r.summary.is_some())
        .filter(|r| r.settings.shadows != Shadows::Off)
        .collect();
    if runs.is_empty() {
        return;
    }
    s.push_str("
### Shadows: time, shadow-map memory, rays

Means over the frames. Maps: the depth texture the frame's maps were rendered into (all in flight in an atlas, or one light's re-used by the light-volume pipelines), a face's side, and the atlas pass's GPU time (the re-used maps are rendered between the light volumes, untimed); rays: shadow rays cast per frame.

| run | avg ms | unshadowed lights | maps MiB | face | maps | maps ms | rays per frame |
|---|---|---|---|---|---|---|---|
");
    for r in runs {
        let n = r.frames.len().max(1) as f64;
        let mean = |f: &dyn Fn(&crate::FrameRecord) -> Option<f64>| {
            let v: Vec<f64> = r.frames.iter().filter_map(f).collect();
            (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
        };
        let bytes = mean(&|f| f.stats.shadow_maps.map(|m| m.bytes as f64));
        let maps = r.frames.iter().find_map(|f| f.stats.shadow_maps);
        let rays = mean(&|f| f.stats.shadow_rays.map(|x| x as f64));
        let maps_ms = mean(&|f| {
            f.stats
                .passes
                .iter()
                .find(|p| p.label == lightgrid::shadows::maps::PASS_LABEL)
                .map(|p| p.ms)
        });
        let unshadowed: f64 = r
            .frames
            .iter()
            .filter_map(|f| f.stats.unshadowed_lights)
            .map(f64::from)
            .sum::<f64>()
            / n;
        let _ = writeln!(
            s,
            "| {} | {:.2} | {unshadowed:.0} | {} | {} | {} | {} | {} |",
            r.name(),
            r.summary.as_ref().expect("filtered").gpu_ms.mean,
            bytes.map_or("-".into(), |b| format!("{:.2}", b / (1024.0 * 1024.0))),
            maps.map_or("-".into(), |m| format!("{}²", m.face)),
            maps.map_or("-".into(), |m| {
                if m.reused {
                    "re-used".to_string()
                } else {
                    "atlas".to_string()
                }
            }),
            maps_ms.map_or("-".into(), |x| format!("{x:.2}")),
            rays.map_or("-".into(), |x| format!("{x:.0}")),
        );
    }
}

/// Culling past the papers (`--preset culling`; a run that measures 2.5D masks, tight cells
/// or z-binning): per grid, the lighting computations against the ideal, the GPU frame time,
/// what the assignment costs in it (its GPU passes, and the `cpu` strategy's own time beside
/// it) and the grid's memory, all means over the frames. Issue 31's goal is the best grid
/// near 1× the ideal with assignment at most 15% of its frame.
fn culling_section(s: &mut String, results: &BenchResults, scene: &str) {
    use lightgrid::frame::{Assign, CellBox, DepthMask};
    let c = &results.config;
    let studied = c.values_of::<DepthMask>().len() > 1
        || c.values_of::<CellBox>().len() > 1
        || c.values_of::<Assign>().contains(&Assign::ZBin);
    let runs: Vec<&RunRecord> = (results.runs.iter())
        .filter(|r| r.scene == scene && r.summary.is_some())
        .filter(|r| r.frames.iter().any(|f| f.stats.memory.grid_bytes.is_some()))
        .collect();
    if !studied || runs.is_empty() {
        return;
    }
    s.push_str("
### Culling: the grids' computations, assignment cost and memory

Means over the frames. Assignment: the GPU passes labelled `assign: ...` in the real-time frame (depth range, cell bounds with their masks and boxes, and a GPU strategy's kernels) and their share of its GPU time; `--assign cpu` (what `auto` is on a software adapter) also spends the CPU time beside it, measured in the analysis render. Memory: cells, lists (or z-bins and their masks) and, with masks or boxes, the cells' records.

| grid | × ideal | avg ms | assignment GPU ms (share) | assignment CPU ms | grid KiB |
|---|---|---|---|---|---|
");
    for r in runs {
        let m = r.summary.as_ref().expect("filtered");
        let ratio = times_ideal(m, "-");
        let assign: f64 = (m.passes.iter())
            .filter(|p| {
                p.label
                    .starts_with(lightgrid::culling::labels::ASSIGN_PREFIX)
            })
            .map(|p| p.ms)
            .sum();
        let mean = |f: &dyn Fn(&crate::FrameRecord) -> Option<f64>| {
            let v: Vec<f64> = r.frames.iter().filter_map(f).collect();
            (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
        };
        let cpu = mean(&|f| f.stats.assign_cpu_ms);
        let bytes = mean(&|f| f.stats.memory.grid_bytes.map(|b| b as f64));
        let _ = writeln!(
            s,
            "| {} | {ratio} | {:.2} | {assign:.2} ({:.0}%) | {} | {} |",
            r.name(),
            m.gpu_ms.mean,
            100.0 * assign / m.gpu_ms.mean.max(1e-9),
            cpu.map_or("-".into(), |x| format!("{x:.2}")),
            bytes.map_or("-".into(), |b| format!("{:.1}", b / 1024.0)),
        );
    }
}

/// Test (b) of the spot culling over the scene's frames, when it was measured.
fn spot_ray_section(s: &mut String, results: &BenchResults, scene: &str) {
    let tests: Vec<_> = results
        .spot_ray_tests
        .iter()
        .filter(|t| t.scene == scene)
        .collect();
    if tests.is_empty() {
        return;
    }
    let sum = |f: &dyn Fn(&crate::SpotRayTest) -> u64| tests.iter().map(|t| f(t)).sum::<u64>();
    let listed = sum(&|t| t.count.lighting_computations);
    let ideal = sum(&|t| t.ideal_lighting_computations).max(1);
    let (lit, missed) = (sum(&|t| t.count.lit_pairs), sum(&|t| t.count.missed_pairs));
    let _ = writeln!(
        s,
        "\n### Spot test (b): the post's ray against a thickened cone (measured, not shipped)\n\nOn the depth-bounded {}-px tile grid of the same frames (tiled-deferred-tricks, Trick 2, with its constants): {:.2} × ideal, and it misses {missed} of {lit} lit (tile, spot) pairs ({:.1}%): light that tiled shading would lose, which is why `[cone]` ships instead.",
        tests[0].tile_size,
        listed as f64 / ideal as f64,
        100.0 * missed as f64 / lit.max(1) as f64
    );
}

/// `--spot-cull` value names, as in results.json.
fn spot_cull_name(c: lightgrid::pipelines::SpotCull) -> &'static str {
    match c {
        lightgrid::pipelines::SpotCull::Sphere => "sphere",
        lightgrid::pipelines::SpotCull::Cone => "cone",
    }
}

/// Frames per second of a run's real-time path (1000 / mean frame period).
fn fps(r: &super::run::RunRecord) -> String {
    let periods: Vec<f64> = r
        .frames
        .iter()
        .map(|f| f.frame_ms)
        .filter(|&m| m > 0.0)
        .collect();
    if periods.is_empty() {
        return "-".into();
    }
    format!(
        "{:.1}",
        1e3 * periods.len() as f64 / periods.iter().sum::<f64>()
    )
}

/// The columns of results.csv after the scene, the pipeline and one column per setting of
/// the library's table (`lightgrid::pipelines::AXES`, in its order: the value the pipeline
/// rendered with, empty where it does not read the setting).
const RESULTS_CSV_TAIL: [&str; 23] = [
    "width",
    "height",
    "tile_size",
    "timing",
    "frame",
    "gpu_ms",
    "gpu_ms_min",
    "gpu_ms_max",
    "frame_ms",
    "analysis_gpu_ms",
    "lighting_computations",
    "ideal_lighting_computations",
    "transparent_fragments",
    "ideal_transparent_computations",
    "lights_per_tile_avg",
    "lights_per_tile_max",
    "tile_area_computations",
    "grid_bytes",
    "modelled_write_bytes",
    "modelled_read_bytes",
    "edge_pixels",
    "shaded_samples",
    "passes",
];

/// Every column of results.csv, in order.
pub(crate) fn results_csv_columns() -> Vec<&'static str> {
    let mut columns = vec!["scene", "pipeline"];
    columns.extend(lightgrid::pipelines::AXES.iter().map(|a| a.column));
    columns.extend(RESULTS_CSV_TAIL);
    columns
}

/// Rows serialized after a header line of `columns` (also written when there are no rows).
pub(crate) fn csv_bytes<R: Serialize>(
    what: &'static str,
    columns: &[&str],
    rows: impl IntoIterator<Item = R>,
) -> Result<Vec<u8>> {
    let err = |e: csv::Error| invalid(what, e.to_string());
    let mut w = csv::WriterBuilder::new()
        .has_headers(false)
        .from_writer(Vec::new());
    w.write_record(columns).map_err(err)?;
    for row in rows {
        w.serialize(row).map_err(err)?;
    }
    w.into_inner().map_err(|e| invalid(what, e.to_string()))
}

/// One row of results.csv per frame of each run: empty fields are `None`; times keep four
/// decimals, the average lights per tile three.
fn csv(results: &BenchResults) -> Result<Vec<u8>> {
    fn opt<T: std::fmt::Display>(v: Option<T>) -> String {
        v.map_or(String::new(), |v| v.to_string())
    }
    let rows = results.runs.iter().flat_map(|r| {
        let pipeline = lightgrid::pipelines::find(&r.pipeline).ok();
        let settings: Vec<String> = (lightgrid::pipelines::AXES.iter())
            .map(
                |a| match pipeline.is_some_and(|p| (a.applies)(p, &r.settings)) {
                    true => (a.get)(&r.settings),
                    false => String::new(),
                },
            )
            .collect();
        r.frames.iter().map(move |f| {
            let repeats = || f.gpu_ms_repeats.iter().copied();
            let mut row = vec![r.scene.clone(), r.pipeline.clone()];
            row.extend(settings.iter().cloned());
            row.extend([
                r.width.to_string(),
                r.height.to_string(),
                r.tile_size.to_string(),
                r.timing.label().to_string(),
                f.stats.frame.to_string(),
                format!("{:.4}", f.stats.gpu_ms),
                format!("{:.4}", repeats().fold(f64::INFINITY, f64::min)),
                format!("{:.4}", repeats().fold(f64::NEG_INFINITY, f64::max)),
                format!("{:.4}", f.frame_ms),
                format!("{:.4}", f.analysis_gpu_ms),
                opt(f.stats.lighting_computations),
                f.stats.ideal_lighting_computations.to_string(),
                f.stats.transparent_fragments.to_string(),
                f.stats.ideal_transparent_computations.to_string(),
                opt(f.stats.lights_per_tile_avg.map(|v| format!("{v:.3}"))),
                opt(f.stats.lights_per_tile_max),
                opt(f.stats.tile_area_computations),
                opt(f.stats.memory.grid_bytes),
                opt(f.stats.memory.modelled_write_bytes),
                opt(f.stats.memory.modelled_read_bytes),
                opt(f.stats.msaa_shading.map(|m| m.edge_pixels)),
                opt(f.stats.msaa_shading.map(|m| m.shaded_samples)),
                f.stats
                    .passes
                    .iter()
                    .map(|p| format!("{}={:.4}", p.label, p.ms))
                    .collect::<Vec<_>>()
                    .join(";"),
            ]);
            row
        })
    });
    csv_bytes("results", &results_csv_columns(), rows)
}

fn write_chart(
    dir: &Path,
    stem: &str,
    svg: String,
    png: image::RgbaImage,
    written: &mut Vec<PathBuf>,
) -> Result<()> {
    let svg_path = dir.join(format!("{stem}.svg"));
    write_atomic(&svg_path, svg.as_bytes())?;
    let png_path = dir.join(format!("{stem}.png"));
    save_png(&png, &png_path)?;
    written.push(png_path);
    written.push(svg_path);
    Ok(())
}

/// Scenes in run order, and the G-buffer settings measured.
fn scenes_and_bits(results: &BenchResults) -> (Vec<String>, Vec<u32>) {
    let mut scenes: Vec<String> = Vec::new();
    for r in &results.runs {
        if !scenes.contains(&r.scene) {
            scenes.push(r.scene.clone());
        }
    }
    let bits = (results.config.values_of::<GBufferFormat>().iter())
        .map(|g| g.bits())
        .collect();
    (scenes, bits)
}

/// A scene's frame time over the animation and its average GPU time per pass, at G-buffer
/// precision `b`.
fn time_charts(
    dir: &Path,
    results: &BenchResults,
    scene: &str,
    b: u32,
    written: &mut Vec<PathBuf>,
) -> Result<()> {
    let (w, h) = results.runs.first().map_or((0, 0), |r| (r.width, r.height));
    let runs: Vec<&RunRecord> = results
        .runs
        .iter()
        .filter(|r| r.scene == scene && r.gbuffer_bits().unwrap_or(b) == b)
        .collect();
    let timing = if runs
        .iter()
        .all(|r| r.timing == lightgrid::TimingSource::GpuTimestamps)
    {
        "GPU timestamps"
    } else {
        "wall clock"
    };
    let chart = LineChart {
        title: format!("{scene}: frame time over the animation ({w}x{h}, {b}-bit G-buffer)"),
        x_label: "frame".into(),
        y_label: format!("ms ({timing}, log scale)"),
        log_x: false,
        log_y: true,
        series: runs
            .iter()
            .map(|r| Series {
                name: r.label(),
                points: r
                    .frames
                    .iter()
                    .map(|f| (f.stats.frame as f64, f.stats.gpu_ms))
                    .collect(),
                emphasis: false,
            })
            .collect(),
    };
    write_chart(
        dir,
        &format!("frame_time_{scene}_g{b}"),
        chart.svg(),
        chart.png(),
        written,
    )?;
    // The brute-force references would flatten every other bar; their time is in the
    // frame-time chart.
    let bars = StackedBars {
        title: format!(
            "{scene}: average GPU time per pass ({b}-bit G-buffer; brute-force forward omitted)"
        ),
        y_label: "ms".into(),
        bars: runs
            .iter()
            .filter(|r| !lightgrid::pipelines::find(&r.pipeline).is_ok_and(|p| p.reference == p.id))
            .filter_map(|r| {
                let s = r.summary.as_ref()?;
                Some((
                    r.label(),
                    s.passes.iter().map(|p| (p.label.clone(), p.ms)).collect(),
                ))
            })
            .collect(),
    };
    write_chart(
        dir,
        &format!("passes_{scene}_g{b}"),
        bars.svg(),
        bars.png(),
        written,
    )?;
    Ok(())
}

/// A scene's lighting computations per frame and the ideal (they do not depend on the
/// G-buffer precision: the runs at precision `first`).
fn lighting_chart(
    dir: &Path,
    results: &BenchResults,
    scene: &str,
    first: u32,
    written: &mut Vec<PathBuf>,
) -> Result<()> {
    let (w, h) = results.runs.first().map_or((0, 0), |r| (r.width, r.height));
    let runs: Vec<&RunRecord> = results
        .runs
        .iter()
        .filter(|r| r.scene == scene && r.gbuffer_bits().unwrap_or(first) == first)
        .collect();
    let mut series: Vec<Series> = runs
        .iter()
        .filter(|r| {
            r.frames
                .iter()
                .all(|f| f.stats.lighting_computations.is_some())
        })
        .map(|r| Series {
            name: r.label(),
            points: r
                .frames
                .iter()
                .map(|f| {
                    (
                        f.stats.frame as f64,
                        f.stats.lighting_computations.unwrap_or(0) as f64,
                    )
                })
                .collect(),
            emphasis: false,
        })
        .collect();
    if let Some(r) = runs.first() {
        series.push(Series {
            name: "ideal".into(),
            points: r
                .frames
                .iter()
                .map(|f| {
                    (
                        f.stats.frame as f64,
                        f.stats.ideal_lighting_computations as f64,
                    )
                })
                .collect(),
            emphasis: true,
        });
    }
    let chart = LineChart {
        title: format!("{scene}: lighting computations per frame ({w}x{h})"),
        x_label: "frame".into(),
        y_label: "lighting computations (log scale)".into(),
        log_x: false,
        log_y: true,
        series,
    };
    write_chart(
        dir,
        &format!("lighting_{scene}"),
        chart.svg(),
        chart.png(),
        written,
    )?;
    Ok(())
}

fn plots(dir: &Path, results: &BenchResults, written: &mut Vec<PathBuf>) -> Result<()> {
    let (scenes, bits) = scenes_and_bits(results);
    for scene in &scenes {
        for &b in &bits {
            time_charts(dir, results, scene, b, written)?;
        }
        lighting_chart(
            dir,
            results,
            scene,
            bits.first().copied().unwrap_or(16),
            written,
        )?;
    }
    msaa_charts(dir, results, written)?;
    for (scene, pipeline, frame, img) in &results.heatmaps {
        let p = dir.join(format!("heatmap_{scene}_{pipeline}_f{frame}.png"));
        save_png(img, &p)?;
        written.push(p);
    }
    for (scene, img) in &results.thumbnails {
        let p = dir.join(format!("thumbnails_{scene}.png"));
        save_png(img, &p)?;
        written.push(p);
    }
    Ok(())
}

/// Tiled-forward-shading Fig. 4.4: (a) average frame time and (b) render-target memory
/// against the MSAA sample count, one line per pipeline and scene (a scene and its
/// `-opaque` variant side by side: forward with and without transparency), when the run
/// measured more than one sample count.
fn msaa_charts(dir: &Path, results: &BenchResults, written: &mut Vec<PathBuf>) -> Result<()> {
    let runs: Vec<&RunRecord> = results
        .runs
        .iter()
        .filter(|r| r.summary.is_some() && r.gbuffer_bits().unwrap_or(16) == 16)
        .collect();
    let mut counts: Vec<u32> = runs.iter().map(|r| r.msaa()).collect();
    counts.sort_unstable();
    counts.dedup();
    if counts.len() < 2 {
        return Ok(());
    }
    // One line per scene, pipeline and resolve (a run at one sample has no resolve: it
    // starts every line of its pipeline).
    let resolve = |r: &RunRecord| r.msaa_resolve().map_or("", |m| m.name());
    let mut lines: Vec<(String, String, &str)> = runs
        .iter()
        .filter(|r| r.msaa() > 1)
        .map(|r| (r.scene.clone(), r.pipeline.clone(), resolve(r)))
        .collect();
    lines.sort();
    lines.dedup();
    let series = |value: &dyn Fn(&RunRecord) -> f64| -> Vec<Series> {
        lines
            .iter()
            .map(|(scene, pipeline, how)| Series {
                // Short enough for the legend: [k]ernel / [s]eparate resolve, the scene's
                // opaque variant marked.
                name: format!(
                    "{pipeline}{}{}",
                    match how.chars().next() {
                        Some(c) => format!(" [{c}]"),
                        None => String::new(),
                    },
                    if scene.ends_with(crate::run::OPAQUE_SUFFIX) {
                        " opaque"
                    } else {
                        ""
                    }
                ),
                points: runs
                    .iter()
                    .filter(|r| &r.scene == scene && &r.pipeline == pipeline)
                    .filter(|r| r.msaa() == 1 || resolve(r) == *how)
                    .map(|r| (f64::from(r.msaa()), value(r)))
                    .collect(),
                emphasis: false,
            })
            .filter(|s| s.points.len() > 1)
            .collect()
    };
    let (w, h) = runs.first().map_or((0, 0), |r| (r.width, r.height));
    let time = LineChart {
        title: format!(
            "MSAA: average frame time ({w}x{h}; [k]/[s]: kernel/separate resolve; Fig. 4.4a)"
        ),
        x_label: "samples per pixel".into(),
        y_label: "ms (log scale)".into(),
        log_x: false,
        log_y: true,
        series: series(&|r| r.summary.as_ref().map_or(0.0, |m| m.gpu_ms.mean)),
    };
    write_chart(dir, "msaa_time", time.svg(), time.png(), written)?;
    let memory = LineChart {
        title: format!("MSAA: render-target memory ({w}x{h}; tiled-forward-shading Fig. 4.4b)"),
        x_label: "samples per pixel".into(),
        y_label: "MiB".into(),
        log_x: false,
        log_y: false,
        series: series(&|r| {
            r.summary
                .as_ref()
                .map_or(0.0, |m| mib(m.target_bytes as f64))
        }),
    };
    write_chart(dir, "msaa_memory", memory.svg(), memory.png(), written)
}

fn mib(b: f64) -> f64 {
    b / (1024.0 * 1024.0)
}

fn summary(results: &BenchResults) -> String {
    let mut s = header(results);
    let (scenes, _) = scenes_and_bits(results);
    for scene in &scenes {
        scene_section(&mut s, results, scene);
        model_section(&mut s, results, scene);
    }
    claims_section(&mut s, results);
    s
}

/// The run: its command, adapter, size, lights, settings and how it ended, and how to read
/// the times and counts.
fn header(results: &BenchResults) -> String {
    let c = &results.config;
    let mut s = String::from("# lightgrid benchmark\n\n");
    let (w, h) = results.runs.first().map_or((0, 0), |r| (r.width, r.height));
    let _ = writeln!(s, "- command: `{}`", results.command);
    let _ = writeln!(
        s,
        "- adapter: **{}**{}",
        results.adapter,
        if results.software_adapter {
            " (software rasterizer: compare shapes and ratios, not absolute times, with the papers' GPUs)"
        } else {
            ""
        }
    );
    let tiles = w.div_ceil(c.tile_size.max(1)) * h.div_ceil(c.tile_size.max(1));
    let _ = writeln!(
        s,
        "- {w}x{h}, tile {} ({tiles} tiles; the papers': 2040 for 32-px tiles at 1920x1080, Forward+'s 14,400 for 8-px tiles at 1280x720), frames {}..{} every {}, {} repeat(s) per frame (median kept), {} warm-up render(s) per series",
        c.tile_size, c.frames.start, c.frames.end, c.frames.step, c.repeat, c.warmup
    );
    if !c.transparency {
        let _ = writeln!(
            s,
            "- transparent objects off (`--transparency off`): the papers' scenes have none; `--preset transparency` measures the glass"
        );
    }
    if c.has_spots() {
        let culls: Vec<&str> = (c.values_of::<SpotCull>().iter())
            .map(|&x| spot_cull_name(x))
            .collect();
        let fractions = c.spot_fractions();
        let listed: Vec<String> = fractions.iter().map(|f| f.to_string()).collect();
        let shares: Vec<String> = fractions
            .iter()
            .map(|f| format!("{:.0}%", f * 100.0))
            .collect();
        let named = match fractions.len() {
            1 => String::new(),
            _ => format!(
                ", each scene once per fraction (`<scene>{}<fraction>` above 0)",
                crate::run::SPOTS_SUFFIX
            ),
        };
        let _ = writeln!(
            s,
            "- spot lights: {} of each scene's lights (`--spot-fraction {}`){named}; grid pipelines cull them by {} (`[sphere]`: the cone's bounding sphere; `[cone]`: the sphere, then the cone against each cell's bounding sphere)",
            shares.join(" and "),
            listed.join(","),
            culls.join(" and by ")
        );
    }
    if c.values_of::<GridLists>().len() > 1 {
        let _ = writeln!(
            s,
            "- transparent objects {}; grid pipelines measured with `[separate lists]` (an opaque list pruned by each tile's depth bounds and a transparent list over near..opaque max, tiled-forward-shading §4.5) and `[shared lists]` (one list over near..max for both)",
            if c.transparency { "on" } else { "off" }
        );
    }
    if c.values_of::<MaterialDraws>().len() > 1 {
        let _ = writeln!(
            s,
            "- forward-shading pipelines measured with `[per-material draws]` (a pipeline per material shader) and `[uber draws]` (one pipeline branching on the material)"
        );
    }
    if !results.outcome.is_complete() {
        let _ = writeln!(
            s,
            "- **{}**; incomplete series are marked",
            results.outcome.describe()
        );
    }
    s.push_str("\nTimes come from the real-time path (`lightgrid play`: the frames rendered back to back, one queue submission each, no analysis): each frame's GPU time from timestamp queries where the adapter has them (first pass start to last pass end per submission, summed), else the wall time from one frame to the next (column `timing`); *real-time fps* is frames per second of that path. Counts come from an analysis render of each frame (results.json `sources`). *× ideal* = lighting computations ÷ the ideal (every light reaching every visible sample once); *efficiency* = ideal ÷ actual.\n");
    s
}

/// One scene's table: per run the time, fps, lighting computations against the ideal,
/// memory and grid figures, then its sections.
fn scene_section(s: &mut String, results: &BenchResults, scene: &str) {
    let _ = writeln!(s, "\n## {scene}\n");
    if results.thumbnails.iter().any(|t| t.0 == scene) {
        let frames: Vec<String> = super::run::THUMBNAIL_FRAMES
            .iter()
            .map(u32::to_string)
            .collect();
        let _ = writeln!(
            s,
            "![{scene}: frames {} (those the animation has)](thumbnails_{scene}.png)\n\n*Frames {} of the animation, as tiled-shading Fig. 2 shows them.*\n",
            frames.join(", "),
            frames.join(", ")
        );
    }
    s.push_str("| pipeline | G-buffer | avg ms | min / max ms | real-time fps | lighting computations (avg) | × ideal | efficiency | lights/tile avg / max | target B/px | timing |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
    for r in results.runs.iter().filter(|r| r.scene == scene) {
        let Some(m) = &r.summary else { continue };
        let lc = m
            .lighting_computations
            .map_or("n/a".into(), |x| format!("{:.0}", x.mean));
        let ratio = times_ideal(m, "n/a");
        let eff = m
            .efficiency
            .map_or("n/a".into(), |e| format!("{:.1}%", e * 100.0));
        let tiles = match (m.lights_per_tile_avg, m.lights_per_tile_max) {
            (Some(a), Some(x)) => format!("{a:.1} / {x}"),
            _ => "-".into(),
        };
        let _ = writeln!(
            s,
            "| {}{} | {} | {:.2} | {:.2} / {:.2} | {} | {} | {} | {} | {} | {} | {} |",
            r.label(),
            match (r.complete, r.times_from) {
                (true, _) => "",
                (false, super::run::TimesFrom::RealTime) => " (incomplete)",
                (false, super::run::TimesFrom::Analysis) => " (incomplete; analysis times)",
            },
            r.gbuffer_bits().map_or("-".into(), |b| format!("{b}-bit")),
            m.gpu_ms.mean,
            m.gpu_ms.min,
            m.gpu_ms.max,
            fps(r),
            lc,
            ratio,
            eff,
            tiles,
            m.bytes_per_pixel,
            r.timing.label()
        );
    }
    let ideal = results
        .runs
        .iter()
        .find(|r| r.scene == scene)
        .and_then(|r| r.summary.as_ref())
        .map(|m| m.ideal_lighting_computations.mean);
    if let Some(i) = ideal {
        let _ = writeln!(s, "\nIdeal lighting computations per frame (avg): {i:.0}.");
    }
    fig3_counts(s, results, scene);
    transparent_section(s, results, scene);
    spot_ray_section(s, results, scene);
    msaa_section(s, results, scene);
    brdf_section(s, results, scene);
    shadows_section(s, results, scene);
    culling_section(s, results, scene);
}

/// The transparent overdraw: the same for every run of the scene (the analysis rasterizes
/// the frame's transparent objects), and each run's transparent pass against its ideal.
fn transparent_section(s: &mut String, results: &BenchResults, scene: &str) {
    if let Some(r) = results
        .runs
        .iter()
        .find(|r| r.scene == scene && !r.frames.is_empty())
    {
        let n = r.frames.len() as f64;
        let fragments: f64 = r
            .frames
            .iter()
            .map(|f| f.stats.transparent_fragments as f64)
            .sum();
        let ideal: f64 = r
            .frames
            .iter()
            .map(|f| f.stats.ideal_transparent_computations as f64)
            .sum();
        if fragments > 0.0 {
            let pixels = f64::from(r.width) * f64::from(r.height);
            let _ = writeln!(
                s,
                "Transparent fragments per frame (avg): {:.0} ({:.3} per pixel), lit {:.0} times in the ideal (included above). The transparent pass's lighting computations per frame (avg, × that ideal):\n",
                fragments / n,
                fragments / n / pixels,
                ideal / n
            );
            for r in results.runs.iter().filter(|r| r.scene == scene) {
                let counts: Option<Vec<u64>> = r
                    .frames
                    .iter()
                    .map(|f| f.stats.transparent_lighting_computations)
                    .collect();
                if let Some(c) = counts.filter(|c| !c.is_empty()) {
                    let avg = c.iter().sum::<u64>() as f64 / c.len() as f64;
                    let _ = writeln!(
                        s,
                        "- {}: {avg:.0} ({:.2}×)",
                        r.name(),
                        avg / (ideal / n).max(1.0)
                    );
                }
            }
        }
    }
}

/// Average measured GPU time per pass next to the traffic models.
fn model_section(s: &mut String, results: &BenchResults, scene: &str) {
    s.push_str("\n### Model vs measurement\n\nAverage measured GPU time per pass next to the traffic models: the blog's per-pixel / per-lit-pixel byte budget applied to the frame (`lightgrid memory` lists the budgets), and for grid pipelines the Forward+ paper's Table 1 evaluated with the measured lights per tile M.\n\n| pipeline | passes (avg ms) | modelled traffic per frame, MiB written / read | Forward+ Table 1: Forward+ / deferred MiB (M) |\n|---|---|---|---|\n");
    for r in results.runs.iter().filter(|r| r.scene == scene) {
        let Some(m) = &r.summary else { continue };
        let passes: Vec<String> = m
            .passes
            .iter()
            .map(|p| format!("{} {:.2}", p.label, p.ms))
            .collect();
        let n = r.frames.len().max(1) as f64;
        let avg = |f: &dyn Fn(&super::FrameRecord) -> Option<u64>| {
            let v: Vec<u64> = r.frames.iter().filter_map(f).collect();
            (v.len() == r.frames.len()).then(|| v.iter().sum::<u64>() as f64 / n)
        };
        let traffic = match (
            avg(&|f| f.stats.memory.modelled_write_bytes),
            avg(&|f| f.stats.memory.modelled_read_bytes),
        ) {
            (Some(wb), Some(rb)) => format!("{:.1} / {:.1}", mib(wb), mib(rb)),
            _ => "n/a".into(),
        };
        let t1: Vec<_> = r
            .frames
            .iter()
            .filter_map(|f| f.stats.memory.forward_plus_table1)
            .collect();
        let table1 = if t1.is_empty() {
            "-".into()
        } else {
            let k = t1.len() as f64;
            format!(
                "{:.1} / {:.1} (M {:.1})",
                mib(t1.iter().map(|t| t.forward_plus_bytes).sum::<f64>() / k),
                mib(t1.iter().map(|t| t.deferred_bytes).sum::<f64>() / k),
                t1.iter().map(|t| t.m).sum::<f64>() / k
            )
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} |",
            r.name(),
            passes.join(", "),
            traffic,
            table1
        );
    }
}

/// The papers' claims on this adapter: each checked with its evidence and verdict, the
/// conditions against the papers', and the claims these runs cannot speak to.
fn claims_section(s: &mut String, results: &BenchResults) {
    s.push_str("\n## The papers' claims on this adapter\n\n");
    let (checked, unchecked): (Vec<_>, Vec<_>) = evaluate_claims(results)
        .into_iter()
        .partition(|c| c.verdict != Verdict::NotMeasured);
    if checked.is_empty() {
        s.push_str("No claim could be checked with these runs.\n");
    } else {
        s.push_str("The threshold is what counts as the paper's words holding: where the paper gives a figure, an interval around it; verdicts marked *model* evaluate the blog's traffic model at the measured lights per pixel (no bytes are measured).\n\n| scene | claim (the paper's words) | source | threshold | measured | verdict |\n|---|---|---|---|---|---|\n");
    }
    for c in &checked {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | **{}**{} |",
            c.scene,
            c.statement,
            c.source,
            c.threshold,
            c.evidence,
            c.verdict.label(),
            match c.basis {
                Basis::Model => " (model)",
                Basis::Measured => "",
            }
        );
    }
    let mut sources: Vec<&str> = checked.iter().map(|c| c.source).collect();
    sources.dedup();
    s.push_str(&conditions_against_papers(results, &sources));
    // The claims this run's pipelines and settings cannot speak to, once each with the
    // scenes, so a focused run's table holds only what it measured.
    let mut missing: Vec<(&str, &str, &str, Vec<&str>)> = Vec::new();
    for c in &unchecked {
        match missing
            .iter_mut()
            .find(|m| m.0 == c.statement && m.2 == c.evidence)
        {
            Some(m) => m.3.push(&c.scene),
            None => missing.push((c.statement, c.source, &c.evidence, vec![&c.scene])),
        }
    }
    if !missing.is_empty() {
        s.push_str(
            "\nNot checked by this run (each needs runs or settings it did not include):\n\n",
        );
        for (statement, source, evidence, scenes) in missing {
            let _ = writeln!(
                s,
                "- {statement} ({source}), {}: {evidence}",
                scenes.join(", ")
            );
        }
    }
    s.push_str("\nFiles: `results.json` (per-frame series and summaries), `results.csv` (one row per frame), `frame_time_*` (Fig. 2 style), `lighting_*` (Fig. 3 style, ideal dashed), `passes_*` (per-pass stacked bars), `heatmap_*` (lights per tile).\n");
}

/// Where each paper measured its claims: the source's name, its GPU, frame size and tile edge
/// (tiled-shading §8 and tiled-forward-shading §4: 32x32 tiles at 1920x1080; forward-plus
/// §5: 8x8 tiles at 1280x720).
const PAPER_CONDITIONS: [(&str, &str, (u32, u32), u32); 3] = [
    (
        "tiled-shading",
        "an NVIDIA GTX 280 or GTX 480",
        (1920, 1080),
        32,
    ),
    (
        "tiled-forward-shading",
        "an NVIDIA GTX 480",
        (1920, 1080),
        32,
    ),
    ("forward-plus", "an AMD Radeon HD 6970", (1280, 720), 8),
];

/// For each paper among `sources` (the checked claims' sources), how this run's conditions
/// differ from the paper's: the adapter, the frame size, the tile count.
fn conditions_against_papers(results: &BenchResults, sources: &[&str]) -> String {
    let (w, h) = results.runs.first().map_or((0, 0), |r| (r.width, r.height));
    let tile = results.config.tile_size.max(1);
    let tiles = |(w, h): (u32, u32), t: u32| w.div_ceil(t) * h.div_ceil(t);
    let mut out = String::new();
    for (paper, gpu, size, paper_tile) in PAPER_CONDITIONS {
        if !sources.iter().any(|s| s.starts_with(paper)) {
            continue;
        }
        let (ours, theirs) = (tiles((w, h), tile), tiles(size, paper_tile));
        let mut differ = vec![format!("the adapter ({})", results.adapter)];
        if (w, h) != size {
            differ.push(format!("the frame size ({w}x{h})"));
        }
        // The tile count sets lights per tile and the culling ratios; within 10% is the
        // paper's count.
        if ours.abs_diff(theirs) * 10 > theirs {
            differ.push(format!("the tile count ({ours} tiles of {tile} px)"));
        }
        let _ = writeln!(
            out,
            "- **{paper}** measured on {gpu} at {}x{} with {paper_tile}-px tiles ({theirs} tiles); this run differs in {}{}",
            size.0,
            size.1,
            differ.join(", "),
            if results.config.transparency {
                " and draws transparent objects (the papers' opaque figures have none)"
            } else {
                ""
            }
        );
    }
    if out.is_empty() {
        out
    } else {
        format!(
            "
The conditions each paper's claims were measured under, against this run's:

{out}"
        )
    }
}

/// Read a results.json written by [`write_report`] (heatmaps are not part of it).
pub fn read_results(path: &Path) -> Result<BenchResults> {
    let bytes = std::fs::read(path).map_err(|cause| Error::Io {
        path: path.display().to_string(),
        cause,
    })?;
    let v: serde_json::Value = serde_json::from_slice(&bytes)
        .map_err(|e| invalid("results", format!("{}: {e}", path.display())))?;
    match v.get("schema_version").and_then(|x| x.as_u64()) {
        Some(n) if n == u64::from(SCHEMA_VERSION) => {}
        other => {
            return Err(invalid(
                "results",
                format!(
                    "{}: schema_version {other:?}, expected {SCHEMA_VERSION}",
                    path.display()
                ),
            ))
        }
    }
    let results: BenchResults = serde_json::from_value(v)
        .map_err(|e| invalid("results", format!("{}: {e}", path.display())))?;
    check_names(&results)
        .map_err(|reason| invalid("results", format!("{}: {reason}", path.display())))?;
    Ok(results)
}

/// Scene and pipeline names become parts of the report's file names: refuse, before anything
/// is written, a results file (edited, or from elsewhere) whose names would not be one plain
/// file name in the directory.
fn check_names(results: &BenchResults) -> std::result::Result<(), String> {
    let names = results
        .runs
        .iter()
        .flat_map(|r| [("scene", &r.scene), ("pipeline", &r.pipeline)])
        .chain(results.thumbnails.iter().map(|t| ("scene", &t.0)))
        .chain(
            results
                .heatmaps
                .iter()
                .flat_map(|h| [("scene", &h.0), ("pipeline", &h.1)]),
        );
    for (what, name) in names {
        let plain = !name.is_empty()
            && name.len() <= 128
            && !name.starts_with('.')
            && !name.contains(['/', '\\', '\0']);
        if !plain {
            return Err(format!(
                "{what} name {name:?} cannot be part of a file name (1 to 128 bytes, no '/', '\\' or leading '.')"
            ));
        }
    }
    Ok(())
}

/// Write every report file into `dir` (created if missing). Returns the paths written.
pub fn write_report(dir: &Path, results: &BenchResults) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).map_err(|cause| Error::Io {
        path: dir.display().to_string(),
        cause,
    })?;
    let mut written = Vec::new();
    #[derive(serde::Serialize)]
    struct File<'a> {
        schema_version: u32,
        #[serde(flatten)]
        results: &'a BenchResults,
    }
    let json = serde_json::to_vec_pretty(&File {
        schema_version: SCHEMA_VERSION,
        results,
    })
    .map_err(|e| invalid("results", e.to_string()))?;
    let p = dir.join("results.json");
    write_atomic(&p, &json)?;
    written.push(p);
    written.extend(write_derived(dir, results)?);
    Ok(written)
}

/// Write what is derived from `results` into `dir` (the CSV, the summary and the plots), not
/// `results.json` itself: `report` reads that file and leaves it as it is, fields it does not
/// know included. Returns the paths written.
pub fn write_derived(dir: &Path, results: &BenchResults) -> Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    for (name, bytes) in [
        ("results.csv", csv(results)?),
        ("summary.md", summary(results).into_bytes()),
    ] {
        let p = dir.join(name);
        write_atomic(&p, &bytes)?;
        written.push(p);
    }
    plots(dir, results, &mut written)?;
    Ok(written)
}

/// tiled-shading Fig. 3's count beside ours, for the tiled runs of `scene`: for
/// TiledFwd-PreZ and TiledDeferred the figure counts tile area × list length (sky and partial
/// tiles included); for TiledFwd its shaded fragments (overdraw included), as ours does.
fn fig3_counts(s: &mut String, results: &BenchResults, scene: &str) {
    let rows: Vec<String> = results
        .runs
        .iter()
        .filter(|r| r.scene == scene && r.msaa() == 1 && r.gbuffer_bits().unwrap_or(16) == 16)
        .filter(|r| r.pipeline != ids::TILED_FORWARD)
        .filter_map(|r| {
            let n = r.frames.len().max(1) as f64;
            let area: Option<Vec<u64>> = r
                .frames
                .iter()
                .map(|f| f.stats.tile_area_computations)
                .collect();
            let area = area.filter(|a| !a.is_empty())?.iter().sum::<u64>() as f64 / n;
            // Ours, opaque samples only (the figure has no transparency).
            let opaque: Option<f64> = r
                .frames
                .iter()
                .map(|f| {
                    let all = f.stats.lighting_computations? as f64;
                    Some(all - f.stats.transparent_lighting_computations.unwrap_or(0) as f64)
                })
                .sum::<Option<f64>>()
                .map(|t| t / n);
            let ours = opaque?;
            Some(format!(
                "- {}: {area:.0} (ours, per visible opaque sample: {ours:.0}; {:.2}x)",
                r.pipeline,
                area / ours.max(1.0)
            ))
        })
        .collect();
    if !rows.is_empty() {
        let _ = writeln!(
            s,
            "\ntiled-shading Fig. 3's count, tile area × list length per frame (avg; for tiled_forward the figure counts shaded fragments, as ours does):\n"
        );
        for r in rows {
            let _ = writeln!(s, "{r}");
        }
        let _ = writeln!(s);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The settings' columns come from the library's table, between the pipeline and the
    /// frame size; every column name is unique.
    #[test]
    fn the_results_header_has_a_column_per_setting_of_the_table() {
        let columns = results_csv_columns();
        assert_eq!(&columns[..2], ["scene", "pipeline"]);
        let n = lightgrid::pipelines::AXES.len();
        for (c, axis) in columns[2..2 + n].iter().zip(lightgrid::pipelines::AXES) {
            assert_eq!(*c, axis.column);
        }
        assert_eq!(columns[2 + n], "width");
        let mut unique = columns.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), columns.len());
    }
}
