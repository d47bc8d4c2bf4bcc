//! `lightgrid`: render catalog scenes with any registry pipeline, compare images, list what
//! exists. With no arguments it runs the default job: every pipeline on `robots-many`, with
//! each image's difference from the `forward` reference.

use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand};
use lightgrid::bench::{BenchConfig, FrameRange};
use lightgrid::gpu::{list_adapters, GpuContext};
use lightgrid::image_io::{check_writable, diff, load_image, save_png, write_atomic};
use lightgrid::passes::GBufferFormat;
use lightgrid::pipelines::{self, PIPELINES, REFERENCE};
use lightgrid::scene::catalog::{self, SceneParams, SCENES};
use lightgrid::{RenderSettings, Renderer};
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "lightgrid",
    version,
    about = "Many-lights renderer: forward, deferred, tiled and clustered shading side by side.\n\nWith no command, runs the default job (`lightgrid compare`): robots-many at 640x360 with every pipeline, images in out/."
)]
struct Cli {
    /// Adapter to use: an index from `lightgrid list`, a backend (vulkan, gl), or part of
    /// the adapter's name (e.g. llvmpipe). Default: the best one (hardware first).
    #[arg(long, global = true)]
    adapter: Option<String>,
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Render one frame of a scene with one pipeline.
    Render(RenderArgs),
    /// Render a frame with every pipeline and compare each with the forward reference.
    Compare(CompareArgs),
    /// Per-pixel difference of two images, in 8-bit sRGB levels.
    Diff(DiffArgs),
    /// Render-target memory and the traffic model of every pipeline at a frame size.
    Memory(MemoryArgs),
    /// Reproduce the papers' evaluations: frame times, lighting computations and memory over
    /// scene animations, written as results.json/.csv, plots and summary.md.
    Bench(BenchArgs),
    /// Rewrite a benchmark's summary.md and plots from its results.json.
    Report(ReportArgs),
    /// Light-assignment scaling: assignment time, index-list size and lighting computations
    /// per strategy (cpu, gather, scatter, bvh, bvh-gpu) on `stress` from 1k to 1M lights.
    Scaling(ScalingArgs),
    /// List adapters, scenes and pipelines.
    List,
}

/// `--assign` values.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum AssignArg {
    /// On a software adapter (lavapipe) cpu at every light count (measured fastest there from
    /// 1k to 1M lights); on a hardware GPU gather up to 8192 lights, bvh-gpu above.
    Auto,
    /// On the CPU: projected sphere rectangles, per-cell depth test; grid uploaded.
    Cpu,
    /// GPU: one workgroup per cell tests every light.
    Gather,
    /// GPU: one thread per light emits (cell, light) pairs, radix-sorted by cell.
    Scatter,
    /// Light hierarchy built on the CPU each frame, walked per cell on the GPU.
    Bvh,
    /// Light hierarchy built on the GPU each frame (Morton codes, radix sort), walked as bvh.
    BvhGpu,
}

impl From<AssignArg> for lightgrid::pipelines::Assign {
    fn from(a: AssignArg) -> Self {
        use lightgrid::pipelines::Assign;
        match a {
            AssignArg::Auto => Assign::Auto,
            AssignArg::Cpu => Assign::Cpu,
            AssignArg::Gather => Assign::Gather,
            AssignArg::Scatter => Assign::Scatter,
            AssignArg::Bvh => Assign::Bvh,
            AssignArg::BvhGpu => Assign::BvhGpu,
        }
    }
}

/// Frame size as WIDTHxHEIGHT.
#[derive(Clone, Copy, Debug)]
struct Size(u32, u32);

fn parse_size(s: &str) -> Result<Size, String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("'{s}' is not WIDTHxHEIGHT (e.g. 640x360)"))?;
    let edge = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|_| format!("'{v}' in '{s}' is not a positive whole number"))
    };
    let (w, h) = (edge(w)?, edge(h)?);
    if w == 0 || h == 0 {
        return Err(format!("{w}x{h}: both edges must be at least 1"));
    }
    Ok(Size(w, h))
}

#[derive(Args, Clone)]
struct SceneArgs {
    /// Scene from the catalog (see `lightgrid list`).
    #[arg(long, default_value = "robots-many")]
    scene: String,
    /// Animation frame to render.
    #[arg(long, default_value_t = 0)]
    frame: u32,
    /// Frame size WIDTHxHEIGHT (default: the scene's own size).
    #[arg(long, value_parser = parse_size)]
    size: Option<Size>,
    /// Light count, for scenes that take one (stress: 1 to 1000000).
    #[arg(long)]
    lights: Option<u32>,
    /// Seed of the scene's random placement.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Screen tile edge in pixels for grid pipelines (4 to 64).
    #[arg(long, default_value_t = lightgrid::consts::DEFAULT_TILE_SIZE)]
    tile: u32,
    /// View-depth slices of clustered pipelines (exponential spacing, 1 to 256).
    #[arg(long, default_value_t = lightgrid::consts::DEFAULT_SLICES)]
    slices: u32,
    /// Who builds the light grid of grid pipelines (tiled_deferred_single culls inside its
    /// kernel and ignores this).
    #[arg(long, value_enum, default_value = "auto")]
    assign: AssignArg,
    /// G-buffer channel precision in bits for deferred pipelines.
    #[arg(long, default_value = "16", value_parser = parse_gbuffer)]
    gbuffer: GBufferFormat,
    /// Frames rendered and discarded before the measured one (drivers such as lavapipe compile
    /// shaders at first use, inside the first frame's GPU time).
    #[arg(long, default_value_t = 1)]
    warmup: u32,
}

#[derive(Args)]
struct ScalingArgs {
    /// Light counts to measure.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "1000,4000,16000,64000,256000,1000000"
    )]
    lights: Vec<u32>,
    /// Strategies to measure.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "cpu,gather,scatter,bvh,bvh-gpu"
    )]
    assign: Vec<AssignArg>,
    /// Grid pipeline to render with.
    #[arg(long, default_value = "clustered_deferred")]
    pipeline: String,
    /// Scene with a variable light count.
    #[arg(long, default_value = "stress")]
    scene: String,
    /// Frame size WIDTHxHEIGHT.
    #[arg(long, default_value = "640x360", value_parser = parse_size)]
    size: Size,
    /// Screen tile edge in pixels.
    #[arg(long, default_value_t = lightgrid::consts::DEFAULT_TILE_SIZE)]
    tile: u32,
    /// View-depth slices of clustered pipelines.
    #[arg(long, default_value_t = lightgrid::consts::DEFAULT_SLICES)]
    slices: u32,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Measured renders per point (the median assignment time is kept).
    #[arg(long, default_value_t = 1)]
    runs: u32,
    /// Discarded renders before each point (shader compilation, buffer growth).
    #[arg(long, default_value_t = 1)]
    warmup: u32,
    /// A strategy whose assignment takes longer than this many seconds is not run at larger
    /// light counts.
    #[arg(long = "budget", default_value_t = 5.0)]
    budget_s: f64,
    /// Output directory.
    #[arg(long, default_value = "scaling")]
    out: PathBuf,
}

fn parse_gbuffer(s: &str) -> Result<GBufferFormat, String> {
    match s {
        "16" => Ok(GBufferFormat::F16),
        "32" => Ok(GBufferFormat::F32),
        _ => Err(format!("'{s}': the G-buffer is 16 or 32 bits per channel")),
    }
}

impl SceneArgs {
    fn settings(&self) -> RenderSettings {
        RenderSettings {
            tile_size: self.tile,
            gbuffer: self.gbuffer,
            slices: self.slices,
            assign: self.assign.into(),
        }
    }
}

#[derive(Args)]
struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Pipeline id (see `lightgrid list`).
    #[arg(long, default_value = REFERENCE)]
    pipeline: String,
    /// Image to write (PNG).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Statistics to write (JSON).
    #[arg(long)]
    stats: Option<PathBuf>,
    /// Lights-per-tile heatmap to write (PNG): the pipeline's own grid, or for pipelines
    /// without a CPU grid the depth-bounded grid used for the ideal count.
    #[arg(long)]
    heatmap: Option<PathBuf>,
}

#[derive(Args)]
struct CompareArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Directory for the images and statistics.
    #[arg(long, default_value = "out")]
    out_dir: PathBuf,
}

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum Preset {
    /// CI-sized smoke run: robots-many at 160x90, 4 frames, every pipeline.
    Quick,
    /// The papers' configurations: robots-many and robots-few, frames 0..259 every 5, 16- and
    /// 32-bit G-buffers, at 1920x1080 on a hardware GPU or 640x360 on a software one.
    Paper,
}

#[derive(Args)]
struct BenchArgs {
    /// Start from a preset; flags given explicitly override it.
    #[arg(long, value_enum)]
    preset: Option<Preset>,
    /// Scenes (repeat the flag or separate with commas). Default: robots-many.
    #[arg(long = "scene", value_delimiter = ',')]
    scenes: Vec<String>,
    /// `all` or a comma-separated list of pipeline ids.
    #[arg(long)]
    pipelines: Option<String>,
    /// Frames A..B:STEP (inclusive). Default: 0..259:5, the paper's 5 fps sampling.
    #[arg(long)]
    frames: Option<String>,
    /// Frame size WIDTHxHEIGHT (default: the scene's own size).
    #[arg(long, value_parser = parse_size)]
    size: Option<Size>,
    /// Screen tile edge in pixels.
    #[arg(long)]
    tile: Option<u32>,
    /// View-depth slices of clustered pipelines.
    #[arg(long, default_value_t = lightgrid::consts::DEFAULT_SLICES)]
    slices: u32,
    /// Who builds the light grid of grid pipelines.
    #[arg(long, value_enum, default_value = "auto")]
    assign: AssignArg,
    /// MSAA sample count. Only 1 is supported until MSAA lands.
    #[arg(long, default_value_t = 1)]
    msaa: u32,
    /// G-buffer precisions to measure: 16, 32 or 16,32.
    #[arg(long, value_delimiter = ',', value_parser = parse_gbuffer)]
    gbuffer: Vec<GBufferFormat>,
    /// Measurements per frame; the median is kept and the spread recorded.
    #[arg(long)]
    repeat: Option<u32>,
    /// Discarded renders before each pipeline's series.
    #[arg(long)]
    warmup: Option<u32>,
    /// Light count for scenes that take one.
    #[arg(long)]
    lights: Option<u32>,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Frame of the lights-per-tile heatmap (default: the middle measured frame).
    #[arg(long)]
    heatmap_frame: Option<u32>,
    /// Output directory.
    #[arg(long, default_value = "bench")]
    out: PathBuf,
}

#[derive(Args)]
struct ReportArgs {
    /// The benchmark directory (reads results.json, writes the report files next to it).
    dir: PathBuf,
}

#[derive(Args)]
struct MemoryArgs {
    /// Frame size WIDTHxHEIGHT.
    #[arg(long, value_parser = parse_size, default_value = "1920x1080")]
    size: Size,
    /// G-buffer channel precision in bits for deferred pipelines.
    #[arg(long, default_value = "16", value_parser = parse_gbuffer)]
    gbuffer: GBufferFormat,
}

#[derive(Args)]
struct DiffArgs {
    a: PathBuf,
    b: PathBuf,
    /// Print a JSON object {"mean", "p99", "max"} instead of text.
    #[arg(long)]
    json: bool,
    /// Exit with status 1 when the mean difference is above this.
    #[arg(long)]
    max_mean: Option<f64>,
    /// Exit with status 1 when the 99th-percentile difference is above this.
    #[arg(long)]
    max_p99: Option<f64>,
    /// Write a visual diff image (PNG) here.
    #[arg(long)]
    diff_image: Option<PathBuf>,
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        None => compare(
            cli.adapter.as_deref(),
            &CompareArgs {
                scene: SceneArgs {
                    scene: "robots-many".into(),
                    frame: DEFAULT_JOB_FRAME,
                    size: Some(Size(640, 360)),
                    lights: None,
                    seed: 1,
                    tile: lightgrid::consts::DEFAULT_TILE_SIZE,
                    slices: lightgrid::consts::DEFAULT_SLICES,
                    assign: AssignArg::Auto,
                    gbuffer: GBufferFormat::F16,
                    warmup: 1,
                },
                out_dir: PathBuf::from("out"),
            },
        ),
        Some(Command::Render(a)) => render(cli.adapter.as_deref(), &a),
        Some(Command::Compare(a)) => compare(cli.adapter.as_deref(), &a),
        Some(Command::Diff(a)) => diff_cmd(&a),
        Some(Command::Memory(a)) => memory(&a),
        Some(Command::Bench(a)) => bench(cli.adapter.as_deref(), &a),
        Some(Command::Report(a)) => report(&a),
        Some(Command::Scaling(a)) => scaling(cli.adapter.as_deref(), &a),
        Some(Command::List) => list(),
    };
    if let Err(e) = result {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

/// Frame of `robots-many` the default job renders: street level, looking down the street.
const DEFAULT_JOB_FRAME: u32 = 200;

fn build_scene(a: &SceneArgs) -> Result<lightgrid::scene::Scene> {
    let params = SceneParams {
        seed: a.seed,
        lights: a.lights,
    };
    Ok(catalog::build(&a.scene, &params)?)
}

fn render(adapter: Option<&str>, a: &RenderArgs) -> Result<()> {
    pipelines::find(&a.pipeline)?;
    for path in a.out.iter().chain(a.stats.iter()).chain(a.heatmap.iter()) {
        check_writable(path).context("output is not writable")?;
    }
    let scene = build_scene(&a.scene)?;
    let ctx = GpuContext::new(adapter)?;
    let Size(w, h) = a
        .scene
        .size
        .unwrap_or(Size(scene.default_size.0, scene.default_size.1));
    let mut renderer = Renderer::new(&ctx, w, h, a.scene.settings())?;
    for _ in 0..a.scene.warmup {
        renderer.render(&scene, a.scene.frame, &a.pipeline)?;
    }
    let out = renderer.render(&scene, a.scene.frame, &a.pipeline)?;
    if let Some(path) = &a.out {
        save_png(&out.image, path)?;
    }
    if let Some(path) = &a.heatmap {
        save_png(&lightgrid::heatmap::heatmap(&out.image, &out.grid), path)?;
    }
    if let Some(path) = &a.stats {
        let json = serde_json::to_vec_pretty(&out.stats)?;
        write_atomic(path, &json)?;
    }
    let s = &out.stats;
    println!(
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
    println!(
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
        println!(
            "light assignment {assign}: {} ms wall ({} ms GPU timestamps{}), {indices} index entries in {} cells ({} with samples)",
            s.assign_ms.map_or("n/a".into(), |ms| format!("{ms:.2}")),
            s.assign_gpu_ms.map_or("n/a".into(), |ms| format!("{ms:.2}")),
            s.assign_cpu_ms
                .filter(|&ms| ms > 0.0)
                .map_or(String::new(), |ms| format!(", {ms:.2} ms on the CPU")),
            s.grid_cells.unwrap_or(0),
            s.grid_cells_occupied.unwrap_or(0),
        );
    }
    Ok(())
}

fn timing_label(t: lightgrid::TimingSource) -> &'static str {
    match t {
        lightgrid::TimingSource::GpuTimestamps => "GPU timestamps",
        lightgrid::TimingSource::WallClock => "wall clock",
    }
}

fn compare(adapter: Option<&str>, a: &CompareArgs) -> Result<()> {
    std::fs::create_dir_all(&a.out_dir)
        .with_context(|| format!("cannot create {}", a.out_dir.display()))?;
    let scene = build_scene(&a.scene)?;
    let ctx = GpuContext::new(adapter)?;
    let Size(w, h) = a
        .scene
        .size
        .unwrap_or(Size(scene.default_size.0, scene.default_size.1));
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

fn diff_cmd(a: &DiffArgs) -> Result<()> {
    let img_a = load_image(&a.a)?;
    let img_b = load_image(&a.b)?;
    let (d, vis) = diff(&img_a, &img_b)?;
    if let Some(p) = &a.diff_image {
        save_png(&vis, p)?;
    }
    if a.json {
        println!("{}", serde_json::to_string(&d)?);
    } else {
        println!(
            "mean {:.4}  p99 {}  max {}  (8-bit sRGB levels, largest channel per pixel)",
            d.mean, d.p99, d.max
        );
    }
    let mut over = Vec::new();
    if let Some(m) = a.max_mean.filter(|&m| d.mean > m) {
        over.push(format!("mean {:.4} > {m}", d.mean));
    }
    if let Some(m) = a.max_p99.filter(|&m| d.p99 > m) {
        over.push(format!("p99 {} > {m}", d.p99));
    }
    if !over.is_empty() {
        bail!("images differ: {}", over.join(", "));
    }
    Ok(())
}

/// What a preset (or no preset) sets before explicit flags override it.
struct BenchDefaults {
    scenes: Vec<&'static str>,
    frames: &'static str,
    size: Option<(u32, u32)>,
    gbuffers: Vec<GBufferFormat>,
    repeat: u32,
    pipelines: Vec<String>,
}

fn bench_config(a: &BenchArgs, hardware: bool) -> Result<BenchConfig> {
    if a.msaa != 1 {
        bail!(
            "--msaa {}: MSAA is not implemented yet; only --msaa 1 can be measured",
            a.msaa
        );
    }
    let all: Vec<String> = PIPELINES.iter().map(|p| p.id.to_string()).collect();
    let d = match a.preset {
        None => BenchDefaults {
            scenes: vec!["robots-many"],
            frames: "0..259:5",
            size: None,
            gbuffers: vec![GBufferFormat::F16],
            repeat: 1,
            pipelines: all.clone(),
        },
        Some(Preset::Quick) => BenchDefaults {
            scenes: vec!["robots-many"],
            frames: "0..259:86",
            size: Some((160, 90)),
            gbuffers: vec![GBufferFormat::F16],
            repeat: 1,
            pipelines: all.clone(),
        },
        Some(Preset::Paper) => BenchDefaults {
            scenes: vec!["robots-many", "robots-few"],
            frames: "0..259:5",
            size: Some(if hardware { (1920, 1080) } else { (640, 360) }),
            gbuffers: vec![GBufferFormat::F16, GBufferFormat::F32],
            repeat: if hardware { 3 } else { 1 },
            // forward_mono only exists as light_prepass_mono's test reference.
            pipelines: all
                .iter()
                .filter(|p| *p != "forward_mono")
                .cloned()
                .collect(),
        },
    };
    let (scenes, frames, size, gbuffers, repeat, pipelines) = (
        d.scenes,
        d.frames,
        d.size,
        d.gbuffers,
        d.repeat,
        d.pipelines,
    );
    let pipelines = match a.pipelines.as_deref() {
        None => pipelines,
        Some("all") => all,
        Some(list) => list
            .split(',')
            .map(|p| p.trim().to_string())
            .filter(|p| !p.is_empty())
            .collect(),
    };
    let config = BenchConfig {
        scenes: if a.scenes.is_empty() {
            scenes.iter().map(|s| s.to_string()).collect()
        } else {
            a.scenes.clone()
        },
        pipelines,
        frames: FrameRange::parse(a.frames.as_deref().unwrap_or(frames))?,
        size: a.size.map(|Size(w, h)| (w, h)).or(size),
        tile_size: a.tile.unwrap_or(lightgrid::consts::DEFAULT_TILE_SIZE),
        slices: a.slices,
        assign: a.assign.into(),
        gbuffers: if a.gbuffer.is_empty() {
            gbuffers
        } else {
            a.gbuffer.clone()
        },
        repeat: a.repeat.unwrap_or(repeat),
        warmup: a.warmup.unwrap_or(1),
        seed: a.seed,
        lights: a.lights,
        heatmap_frame: a.heatmap_frame,
    };
    config.validate()?;
    Ok(config)
}

fn format_duration(secs: f64) -> String {
    let s = secs.max(0.0).round() as u64;
    if s >= 3600 {
        format!("{}h{:02}m", s / 3600, (s % 3600) / 60)
    } else if s >= 60 {
        format!("{}m{:02}s", s / 60, s % 60)
    } else {
        format!("{s}s")
    }
}

fn bench(adapter: Option<&str>, a: &BenchArgs) -> Result<()> {
    check_writable(&a.out.join("results.json")).or_else(|_| {
        std::fs::create_dir_all(&a.out)
            .with_context(|| format!("cannot create {}", a.out.display()))
    })?;
    let ctx = GpuContext::new(adapter)?;
    let config = bench_config(a, !ctx.is_software())?;
    let stop = stop_on_ctrl_c()?;
    eprintln!(
        "benchmark on {}: {} scene(s), {} pipeline(s), frames {}..{} every {}, writing to {}",
        ctx.adapter_label(),
        config.scenes.len(),
        config.pipelines.len(),
        config.frames.start,
        config.frames.end,
        config.frames.step,
        a.out.display()
    );
    let start = std::time::Instant::now();
    let mut progress = progress_bar();
    let mut results = lightgrid::bench::run(&ctx, &config, &stop, &mut progress)?;
    eprintln!();
    results.command = std::env::args().collect::<Vec<_>>().join(" ");
    let written = lightgrid::bench::write_report(&a.out, &results)?;
    let claims = lightgrid::bench::evaluate_claims(&results);
    let held = claims
        .iter()
        .filter(|c| c.verdict == lightgrid::bench::Verdict::Held)
        .count();
    let measured = claims
        .iter()
        .filter(|c| c.verdict != lightgrid::bench::Verdict::NotMeasured)
        .count();
    println!(
        "{} runs in {}; {held} of {measured} measured claims held; {} files in {} (start with summary.md)",
        results.runs.len(),
        format_duration(start.elapsed().as_secs_f64()),
        written.len(),
        a.out.display()
    );
    if results.interrupted {
        bail!(
            "interrupted: partial results written to {}",
            a.out.display()
        );
    }
    Ok(())
}

/// A flag set by the first Ctrl-C (long runs stop after the current frame and keep their
/// results); a second Ctrl-C exits at once.
fn stop_on_ctrl_c() -> Result<std::sync::Arc<std::sync::atomic::AtomicBool>> {
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let flag = stop.clone();
    ctrlc::set_handler(move || {
        if flag.swap(true, std::sync::atomic::Ordering::SeqCst) {
            std::process::exit(130);
        }
        eprintln!("\nstopping after the current frame (Ctrl-C again to abort without writing)...");
    })
    .context("cannot install the Ctrl-C handler")?;
    Ok(stop)
}

/// A progress bar with an ETA on stderr, redrawn at most every 200 ms.
fn progress_bar() -> impl FnMut(&lightgrid::bench::Progress) {
    let start = std::time::Instant::now();
    let mut last = std::time::Instant::now() - std::time::Duration::from_secs(1);
    move |p: &lightgrid::bench::Progress| {
        if last.elapsed().as_millis() < 200 && p.done < p.total {
            return;
        }
        last = std::time::Instant::now();
        let frac = p.done as f64 / p.total.max(1) as f64;
        let elapsed = start.elapsed().as_secs_f64();
        let eta = if p.done > 0 {
            format_duration(elapsed / frac - elapsed)
        } else {
            "?".into()
        };
        let filled = (frac * 30.0) as usize;
        eprint!(
            "\r[{}{}] {:>3.0}% {}/{} ETA {:<7} {:<48}",
            "#".repeat(filled),
            " ".repeat(30 - filled),
            frac * 100.0,
            p.done,
            p.total,
            eta,
            p.label.chars().take(48).collect::<String>()
        );
    }
}

fn scaling(adapter: Option<&str>, a: &ScalingArgs) -> Result<()> {
    std::fs::create_dir_all(&a.out)
        .with_context(|| format!("cannot create {}", a.out.display()))?;
    check_writable(&a.out.join("scaling.json"))?;
    let config = lightgrid::bench::ScalingConfig {
        scene: a.scene.clone(),
        pipeline: a.pipeline.clone(),
        lights: a.lights.clone(),
        strategies: a.assign.iter().map(|&s| s.into()).collect(),
        size: (a.size.0, a.size.1),
        tile_size: a.tile,
        slices: a.slices,
        seed: a.seed,
        runs: a.runs,
        warmup: a.warmup,
        budget_ms: a.budget_s * 1e3,
    };
    config.validate()?;
    let ctx = GpuContext::new(adapter)?;
    let stop = stop_on_ctrl_c()?;
    eprintln!(
        "light assignment scaling on {}: {} at {}x{}, {} light counts x {} strategies, writing to {}",
        ctx.adapter_label(),
        config.pipeline,
        a.size.0,
        a.size.1,
        config.lights.len(),
        config.strategies.len(),
        a.out.display()
    );
    let start = std::time::Instant::now();
    let mut progress = progress_bar();
    let mut results = lightgrid::bench::run_scaling(&ctx, &config, &stop, &mut progress)?;
    eprintln!();
    results.command = std::env::args().collect::<Vec<_>>().join(" ");
    lightgrid::bench::write_scaling(&results, &a.out)?;
    println!("{}", lightgrid::bench::scaling_table(&results));
    println!("{}", lightgrid::bench::scaling_growth(&results));
    println!(
        "{} points in {}; {} in {}",
        results.points.len(),
        format_duration(start.elapsed().as_secs_f64()),
        lightgrid::bench::SCALING_FILES.join(", "),
        a.out.display()
    );
    if results.interrupted {
        bail!(
            "interrupted: partial results written to {}",
            a.out.display()
        );
    }
    Ok(())
}

fn report(a: &ReportArgs) -> Result<()> {
    let results = lightgrid::bench::read_results(&a.dir.join("results.json"))?;
    let written = lightgrid::bench::write_report(&a.dir, &results)?;
    println!(
        "{} files rewritten in {} (heatmaps are kept from the run)",
        written.len(),
        a.dir.display()
    );
    Ok(())
}

fn memory(a: &MemoryArgs) -> Result<()> {
    let Size(w, h) = a.size;
    let settings = RenderSettings {
        gbuffer: a.gbuffer,
        ..Default::default()
    };
    println!("render targets at {w}x{h}, {}-bit G-buffer (the lighting-count target is a statistics aid, not counted)", a.gbuffer.bits());
    println!(
        "{:<22} {:>6} {:>10}   {:>9} {:>9} {:>9} {:>9}   targets",
        "pipeline", "B/px", "total MiB", "wr B/px", "rd B/px", "wr B/lit", "rd B/lit"
    );
    for p in PIPELINES {
        let m = (p.memory)(&settings);
        let t = m.traffic;
        let targets: Vec<String> = m
            .targets
            .iter()
            .map(|t| format!("{} {}", t.name, t.bytes_per_pixel))
            .collect();
        println!(
            "{:<22} {:>6} {:>10.2}   {:>9} {:>9} {:>9} {:>9}   {}",
            p.id,
            m.bytes_per_pixel(),
            m.target_bytes(w, h) as f64 / (1024.0 * 1024.0),
            t.write_per_pixel,
            t.read_per_pixel,
            t.write_per_lit,
            t.read_per_lit,
            targets.join(", ")
        );
    }
    println!(
        "traffic model (deferred-shading-vs-deferred-lighting): render-target bytes per pixel and per lit pixel \
         (one lighting computation); blending counts as read + write; light data {} B per light, grid indices {} B; \
         tiled pipelines also upload their grid each frame (see --stats memory.grid_bytes)",
        lightgrid::memory::LIGHT_BYTES,
        lightgrid::memory::INDEX_BYTES
    );
    Ok(())
}

fn list() -> Result<()> {
    println!("adapters (in order of preference):");
    let adapters = list_adapters();
    if adapters.is_empty() {
        println!("  none found: install mesa-vulkan-drivers for a software Vulkan adapter");
    }
    for a in adapters {
        println!(
            "  {}: {} [{}, {}] {}",
            a.index, a.name, a.backend, a.device_type, a.driver
        );
    }
    println!("scenes:");
    for s in SCENES {
        println!("  {:<12} {}", s.name, s.description);
    }
    println!("pipelines:");
    for p in PIPELINES {
        println!("  {:<24} {} ({})", p.id, p.description, p.paper);
    }
    println!("light assignment (--assign, for grid pipelines):");
    for a in lightgrid::culling::Assign::ALL {
        println!("  {:<10} {}", a.name(), a.description());
    }
    Ok(())
}
