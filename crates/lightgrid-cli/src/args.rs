//! Arguments and helpers every command shares: frame size, scene and renderer settings,
//! `--assign` values, Ctrl-C handling and the progress bar.

use crate::files::Files;
use anyhow::{Context, Result};
use clap::Args;
use lightgrid::passes::GBufferFormat;
use lightgrid::scene::catalog::SceneParams;
use lightgrid::scene::{AddLights, SceneRequest};
use lightgrid::RenderSettings;
use std::path::Path;

/// `--assign` values.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub(crate) enum AssignArg {
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
pub(crate) struct Size(pub(crate) u32, pub(crate) u32);

impl Size {
    /// `size`, or the scene's own frame size when none was given.
    pub(crate) fn or_scene(size: Option<Size>, scene: &lightgrid::scene::Scene) -> (u32, u32) {
        let Size(w, h) = size.unwrap_or(Size(scene.default_size.0, scene.default_size.1));
        (w, h)
    }
}

pub(crate) fn parse_size(s: &str) -> Result<Size, String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("'{s}' is not WIDTHxHEIGHT (e.g. 640x360)"))?;
    let edge = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|_| format!("'{v}' in '{s}' is not a positive whole number"))
    };
    let (w, h) = (edge(w)?, edge(h)?);
    let max = lightgrid::consts::MAX_FRAME_EDGE;
    if w == 0 || h == 0 || w > max || h > max {
        return Err(format!("{w}x{h}: both edges must be 1 to {max}"));
    }
    Ok(Size(w, h))
}

/// Most `--warmup`, `--repeat`, `--runs` and `--loops` a command takes (more would render
/// for hours on a software adapter without a better figure).
pub(crate) const MAX_COUNT: i64 = lightgrid_bench::MAX_REPEATS as i64;

/// A fraction: a finite number from 0 to 1.
pub(crate) fn parse_fraction(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if (0.0..=1.0).contains(&v) => Ok(v),
        _ => Err(format!("'{s}' is not a number from 0 to 1")),
    }
}

/// `--add-lights N [--light-range R]` (`render`, `compare`, `play`, `export`, `bench`):
/// `--light-range` alone is refused.
pub(crate) fn added_lights(count: Option<u32>, range: Option<f64>) -> Result<Option<AddLights>> {
    if range.is_some() && count.is_none() {
        anyhow::bail!(
            "--light-range sets the range of the lights --add-lights scatters; give --add-lights N"
        );
    }
    Ok(count.map(|count| AddLights {
        count,
        range: range.map(|r| r as f32),
    }))
}

/// A length: a finite number above 0 (and below 10^9, past which f32 arithmetic breaks).
pub(crate) fn parse_positive(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v > 0.0 && v < 1e9 => Ok(v),
        _ => Err(format!("'{s}' is not a positive number below 1e9")),
    }
}

/// `--spot-cull` values.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub(crate) enum SpotCullArg {
    /// The tightest sphere around each spot's cone.
    Sphere,
    /// The sphere, then the cone against each cell's bounding sphere (never misses a lit
    /// sample, and tighter).
    Cone,
}

impl From<SpotCullArg> for lightgrid::pipelines::SpotCull {
    fn from(a: SpotCullArg) -> Self {
        match a {
            SpotCullArg::Sphere => Self::Sphere,
            SpotCullArg::Cone => Self::Cone,
        }
    }
}

/// `--lists`: the light lists of frames with transparent geometry.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum ListsArg {
    /// An opaque list pruned by the tile's depth bounds and a transparent list over
    /// near..opaque max (tiled-forward-shading §4.5).
    Separate,
    /// One list over near..opaque max for both.
    Shared,
}

impl From<ListsArg> for lightgrid::culling::GridLists {
    fn from(a: ListsArg) -> Self {
        match a {
            ListsArg::Separate => Self::Separate,
            ListsArg::Shared => Self::Shared,
        }
    }
}

/// `--material-draws`: how forward pipelines draw the material shaders.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum MaterialDrawsArg {
    /// A pipeline per material shader, switched between runs of geometry.
    PerMaterial,
    /// One pipeline branching on the material, as deferred shading does.
    Uber,
}

impl From<MaterialDrawsArg> for lightgrid::frame::MaterialDraws {
    fn from(a: MaterialDrawsArg) -> Self {
        match a {
            MaterialDrawsArg::PerMaterial => Self::PerMaterial,
            MaterialDrawsArg::Uber => Self::Uber,
        }
    }
}

/// `--transparency on|off`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum OnOff {
    On,
    Off,
}

impl OnOff {
    pub(crate) fn on(self) -> bool {
        self == OnOff::On
    }
}

/// A finite number at least 0 (thresholds, budgets).
pub(crate) fn parse_non_negative(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("'{s}' is not a finite number at least 0")),
    }
}

/// Which of the options that only some pipelines read were given on the command line.
#[derive(Clone, Copy, Default)]
pub(crate) struct Given {
    pub(crate) slices: bool,
    pub(crate) gbuffer: bool,
    pub(crate) assign: bool,
    pub(crate) spot_cull: bool,
    pub(crate) lists: bool,
    pub(crate) material_draws: bool,
    /// `--msaa` above 1.
    pub(crate) msaa: bool,
    pub(crate) msaa_resolve: bool,
    pub(crate) depth_bounds: bool,
    pub(crate) depth_reduction: bool,
}

/// One rule for every command: an option given explicitly that applies to none of the chosen
/// pipelines is refused rather than silently ignored.
pub(crate) fn check_applies(
    given: Given,
    chosen: &[&'static lightgrid::pipelines::PipelineInfo],
) -> Result<()> {
    use lightgrid::pipelines::{PipelineInfo, PIPELINES};
    type Applies = fn(&PipelineInfo) -> bool;
    let rules: [(&str, bool, Applies); 10] = [
        ("--slices", given.slices, |p| p.clustered),
        ("--gbuffer", given.gbuffer, |p| p.uses_gbuffer()),
        ("--assign", given.assign, |p| p.assign),
        ("--spot-cull", given.spot_cull, |p| p.uses_grid),
        ("--lists", given.lists, |p| p.assign),
        ("--material-draws", given.material_draws, |p| {
            p.forward_shading
        }),
        ("--msaa", given.msaa, |p| {
            p.msaa == lightgrid::pipelines::Msaa::Supported
        }),
        ("--msaa-resolve", given.msaa_resolve, |p| {
            p.msaa == lightgrid::pipelines::Msaa::Supported && !p.forward_shading
        }),
        ("--depth-bounds", given.depth_bounds, |p| p.depth_bounds),
        ("--depth-reduction", given.depth_reduction, |p| {
            p.depth_bounds
        }),
    ];
    for (flag, given, applies) in rules {
        if given && !chosen.iter().any(|p| applies(p)) {
            let takers: Vec<&str> = PIPELINES
                .iter()
                .filter(|p| applies(p))
                .map(|p| p.id)
                .collect();
            // A pipeline that refuses MSAA says why.
            let why: Vec<String> = chosen
                .iter()
                .filter_map(|p| match p.msaa {
                    lightgrid::pipelines::Msaa::Refused(why) if flag == "--msaa" => {
                        Some(format!(" ({}: {why})", p.id))
                    }
                    _ => None,
                })
                .collect();
            let chosen: Vec<&str> = chosen.iter().map(|p| p.id).collect();
            anyhow::bail!(
                "{flag} does not apply to {}{}; it applies to: {}",
                chosen.join(", "),
                why.concat(),
                takers.join(", ")
            );
        }
    }
    Ok(())
}

/// The renderer's settings as options (`render`, `compare`, `play`).
#[derive(Args, Clone)]
pub(crate) struct RendererArgs {
    /// Screen tile edge in pixels for grid pipelines (4 to 64).
    #[arg(long, allow_hyphen_values = true, default_value_t = lightgrid::consts::DEFAULT_TILE_SIZE)]
    pub(crate) tile: u32,
    /// View-depth slices of clustered pipelines (exponential spacing, 1 to 256) [default: 32].
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) slices: Option<u32>,
    /// Who builds the light grid of grid pipelines (not tiled_deferred_single, which culls
    /// inside its kernel) [default: auto].
    #[arg(long, value_enum)]
    pub(crate) assign: Option<AssignArg>,
    /// G-buffer channel precision in bits for deferred pipelines [default: 16].
    #[arg(long, value_parser = parse_gbuffer)]
    pub(crate) gbuffer: Option<GBufferFormat>,
    /// What grid pipelines cull spot lights by [default: cone].
    #[arg(long, value_enum)]
    pub(crate) spot_cull: Option<SpotCullArg>,
    /// The light lists of grid pipelines with an --assign grid, for frames with transparent
    /// objects [default: separate].
    #[arg(long, value_enum)]
    pub(crate) lists: Option<ListsArg>,
    /// How forward-shading pipelines draw the material shaders: a pipeline per shader, or
    /// one branching übershader [default: per-material].
    #[arg(long, value_enum)]
    pub(crate) material_draws: Option<MaterialDrawsArg>,
    /// MSAA samples per pixel: 1 (off) or a count the adapter supports for every target
    /// (lavapipe: 4; real GPUs also 2 and 8); every pipeline renders with it.
    #[arg(long, allow_hyphen_values = true, default_value_t = 1)]
    pub(crate) msaa: u32,
    /// Where tiled and clustered deferred and tiled_deferred_single resolve MSAA: separate
    /// (per-sample colours, then the tonemap) or kernel (inside the shading kernel,
    /// tiled-deferred-tricks Trick 1; frames with transparent objects resolve separately)
    /// [default: separate].
    #[arg(long, value_enum)]
    pub(crate) msaa_resolve: Option<MsaaResolveArg>,
    /// Which cell depth bounds grids built from the depth buffer cull lights by: both, min
    /// (far side open), max (near side open) or none (every cell spans its slice)
    /// (tiled-forward-shading §4.4) [default: both].
    #[arg(long, value_enum)]
    pub(crate) depth_bounds: Option<DepthBoundsArg>,
    /// How the cell-bounds kernel of grids built from depth reduces a tile's samples:
    /// atomics (every sample into workgroup memory) or subgroup (registers, then one subgroup
    /// min/max; tiled grids, adapters with subgroups; tiled-shading §8) [default: atomics].
    #[arg(long, value_enum)]
    pub(crate) depth_reduction: Option<DepthReductionArg>,
}

/// `--depth-reduction` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum DepthReductionArg {
    Atomics,
    Subgroup,
}

impl From<DepthReductionArg> for lightgrid::frame::DepthReduction {
    fn from(a: DepthReductionArg) -> Self {
        match a {
            DepthReductionArg::Atomics => lightgrid::frame::DepthReduction::Atomics,
            DepthReductionArg::Subgroup => lightgrid::frame::DepthReduction::Subgroup,
        }
    }
}

/// `--depth-bounds` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum DepthBoundsArg {
    Both,
    Min,
    Max,
    None,
}

impl From<DepthBoundsArg> for lightgrid::frame::DepthBounds {
    fn from(a: DepthBoundsArg) -> Self {
        use lightgrid::frame::DepthBounds as D;
        match a {
            DepthBoundsArg::Both => D::Both,
            DepthBoundsArg::Min => D::Min,
            DepthBoundsArg::Max => D::Max,
            DepthBoundsArg::None => D::None,
        }
    }
}

/// `--msaa-resolve` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum MsaaResolveArg {
    Separate,
    Kernel,
}

impl From<MsaaResolveArg> for lightgrid::frame::MsaaResolve {
    fn from(a: MsaaResolveArg) -> Self {
        match a {
            MsaaResolveArg::Separate => lightgrid::frame::MsaaResolve::Separate,
            MsaaResolveArg::Kernel => lightgrid::frame::MsaaResolve::Kernel,
        }
    }
}

/// `--msaa-resolve` only means something with MSAA.
pub(crate) fn check_msaa_resolve(resolve_given: bool, msaa: &[u32]) -> Result<()> {
    if resolve_given && msaa.iter().all(|&n| n <= 1) {
        anyhow::bail!(
            "--msaa-resolve needs --msaa above 1 (it says where MSAA samples are resolved)"
        );
    }
    Ok(())
}

impl RendererArgs {
    /// The renderer settings, validated (the message gives each option's range).
    pub(crate) fn settings(&self) -> Result<RenderSettings> {
        let settings = RenderSettings {
            tile_size: self.tile,
            gbuffer: self.gbuffer.unwrap_or_default(),
            slices: self.slices.unwrap_or(lightgrid::consts::DEFAULT_SLICES),
            assign: self.assign.unwrap_or(AssignArg::Auto).into(),
            spot_cull: self.spot_cull.map(Into::into).unwrap_or_default(),
            lists: self
                .lists
                .map_or(RenderSettings::default().lists, Into::into),
            material_draws: self.material_draws.map(Into::into).unwrap_or_default(),
            msaa: self.msaa,
            msaa_resolve: self.msaa_resolve.map(Into::into).unwrap_or_default(),
            depth_bounds: self.depth_bounds.map(Into::into).unwrap_or_default(),
            depth_reduction: self.depth_reduction.map(Into::into).unwrap_or_default(),
        };
        check_msaa_resolve(self.msaa_resolve.is_some(), &[self.msaa])?;
        settings.validate()?;
        Ok(settings)
    }

    /// Which options were given, for [`check_applies`].
    pub(crate) fn given(&self) -> Given {
        Given {
            slices: self.slices.is_some(),
            gbuffer: self.gbuffer.is_some(),
            assign: self.assign.is_some(),
            spot_cull: self.spot_cull.is_some(),
            lists: self.lists.is_some(),
            material_draws: self.material_draws.is_some(),
            msaa: self.msaa > 1,
            msaa_resolve: self.msaa_resolve.is_some(),
            depth_bounds: self.depth_bounds.is_some(),
            depth_reduction: self.depth_reduction.is_some(),
        }
    }
}

/// The options that build a catalog scene (`render`, `compare`, `play`).
#[derive(Args, Clone)]
pub(crate) struct SceneOptions {
    /// Scene from the catalog (see `lightgrid list`), or a glTF 2.0 file (*.gltf or *.glb)
    /// with its meshes, materials, cameras and KHR_lights_punctual lights.
    #[arg(long, default_value = "robots-many")]
    pub(crate) scene: String,
    /// A glTF file's camera, by its index in the file's `cameras` (default: the first
    /// perspective camera placed, else one fitted to the scene); the animation orbits the
    /// scene from there.
    #[arg(long, allow_hyphen_values = true, value_parser = clap::value_parser!(u32).range(0..=1_000_000))]
    pub(crate) camera: Option<u32>,
    /// Scatter N point lights over the scene's bounds (any scene; 1 to 1048576).
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) add_lights: Option<u32>,
    /// Range of the lights --add-lights scatters (default: about 8 of them reach each point).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_positive)]
    pub(crate) light_range: Option<f64>,
    /// Light count, for scenes that take one (stress: 1 to 1000000).
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) lights: Option<u32>,
    /// Seed of the scene's random placement.
    #[arg(long, allow_hyphen_values = true, default_value_t = 1)]
    pub(crate) seed: u64,
    /// Fraction of the scene's lights (0 to 1) turned into spot lights with seeded random
    /// directions and cones.
    #[arg(long, allow_hyphen_values = true, default_value_t = 0.0, value_parser = parse_fraction)]
    pub(crate) spot_fraction: f64,
    /// Give every robot two headlights (spot lights that turn with it); robots scenes only.
    #[arg(long)]
    pub(crate) headlights: bool,
    /// The scene's transparent objects (glass panes and bubbles, translucent blocks), drawn
    /// blended after the opaque geometry; robots and random scenes.
    #[arg(long, value_enum, default_value_t = OnOff::On)]
    pub(crate) transparency: OnOff,
    /// The materials' own shaders (car paint, rim); off renders every material standard.
    #[arg(long, value_enum, default_value_t = OnOff::On)]
    pub(crate) material_shaders: OnOff,
}

impl SceneOptions {
    /// The default job's scene: a catalog scene with every option at its default.
    pub(crate) fn catalog(name: &str) -> SceneOptions {
        SceneOptions {
            scene: name.into(),
            camera: None,
            add_lights: None,
            light_range: None,
            lights: None,
            seed: 1,
            spot_fraction: 0.0,
            headlights: false,
            transparency: OnOff::On,
            material_shaders: OnOff::On,
        }
    }

    /// What these options ask for, checked.
    pub(crate) fn request(&self) -> Result<SceneRequest> {
        let req = SceneRequest {
            spec: self.scene.clone(),
            params: SceneParams {
                seed: self.seed,
                lights: self.lights,
                spot_fraction: self.spot_fraction as f32,
                headlights: self.headlights,
                transparency: self.transparency.on(),
                material_shaders: self.material_shaders.on(),
            },
            camera: self.camera.map(|c| c as usize),
            add_lights: added_lights(self.add_lights, self.light_range)?,
        };
        lightgrid::scene::source::check(&req)?;
        Ok(req)
    }

    /// A glTF scene file is an input no output may replace.
    pub(crate) fn claim(&self, files: &mut Files) -> Result<()> {
        if lightgrid::scene::gltf::is_gltf_path(&self.scene) {
            files.input("--scene", Path::new(&self.scene))?;
        }
        Ok(())
    }

    /// The scene these options name, built or loaded (warnings about skipped parts of a file
    /// go to stderr).
    pub(crate) fn build(&self) -> Result<lightgrid::scene::Scene> {
        let opened = lightgrid::scene::open(&self.request()?)?;
        for w in &opened.warnings {
            eprintln!("warning: {}: {w}", self.scene);
        }
        Ok(opened.scene)
    }
}

#[derive(Args, Clone)]
pub(crate) struct SceneArgs {
    #[command(flatten)]
    pub(crate) options: SceneOptions,
    /// Animation frame to render.
    #[arg(long, allow_hyphen_values = true, default_value_t = 0)]
    pub(crate) frame: u32,
    /// Frame size WIDTHxHEIGHT (default: the scene's own size).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_size)]
    pub(crate) size: Option<Size>,
    #[command(flatten)]
    pub(crate) renderer: RendererArgs,
    /// Frames rendered and discarded before the measured one (drivers such as lavapipe compile
    /// shaders at first use, inside the first frame's GPU time); 0 to 1000.
    #[arg(long, allow_hyphen_values = true, default_value_t = 1, value_parser = clap::value_parser!(u32).range(0..=MAX_COUNT))]
    pub(crate) warmup: u32,
}

/// `--view`: a debug view's name.
pub(crate) fn parse_view(s: &str) -> Result<lightgrid::debug_view::DebugView, String> {
    lightgrid::debug_view::DebugView::parse(s)
        .ok_or_else(|| format!("'{s}': one of shaded, lights, bounds, wasted"))
}

pub(crate) fn parse_gbuffer(s: &str) -> Result<GBufferFormat, String> {
    match s {
        "16" => Ok(GBufferFormat::F16),
        "32" => Ok(GBufferFormat::F32),
        _ => Err(format!("'{s}': the G-buffer is 16 or 32 bits per channel")),
    }
}

pub(crate) fn timing_label(t: lightgrid::TimingSource) -> &'static str {
    match t {
        lightgrid::TimingSource::GpuTimestamps => "GPU timestamps",
        lightgrid::TimingSource::WallClock => "wall clock",
    }
}

pub(crate) fn format_duration(secs: f64) -> String {
    let s = secs.max(0.0).round() as u64;
    if s >= 3600 {
        format!("{}h{:02}m", s / 3600, (s % 3600) / 60)
    } else if s >= 60 {
        format!("{}m{:02}s", s / 60, s % 60)
    } else {
        format!("{s}s")
    }
}

/// Set by the first Ctrl-C or SIGTERM while a long run is listening ([`stop_on_ctrl_c`]).
static STOP: std::sync::OnceLock<std::sync::Arc<std::sync::atomic::AtomicBool>> =
    std::sync::OnceLock::new();
/// Whether a long run is listening for [`STOP`].
static LISTENING: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

fn stop_flag() -> std::sync::Arc<std::sync::atomic::AtomicBool> {
    STOP.get_or_init(Default::default).clone()
}

/// Install the one Ctrl-C / SIGTERM handler of the process, before any command runs: a signal
/// that ends the process first removes the temporary files being written
/// (`image_io::remove_temporaries`), so an interrupted export or render leaves no partial
/// file. While a long run listens ([`stop_on_ctrl_c`]) the first signal only asks it to stop.
pub(crate) fn handle_signals() -> Result<()> {
    use std::sync::atomic::Ordering;
    let stop = stop_flag();
    ctrlc::set_handler(move || {
        if LISTENING.load(Ordering::SeqCst) && !stop.swap(true, Ordering::SeqCst) {
            eprintln!("\nstopping after the current frame and writing what was measured (again to abort without writing)...");
            return;
        }
        // Held until the exit, so no temporary is made (and left) after the removal.
        let _held = lightgrid::image_io::remove_temporaries();
        std::process::exit(130);
    })
    .context("cannot install the Ctrl-C / SIGTERM handler")
}

/// A flag set by the first Ctrl-C or SIGTERM (long runs stop after the current frame and
/// write what they measured, marked interrupted); a second one exits at once, removing the
/// temporary files ([`handle_signals`]).
pub(crate) fn stop_on_ctrl_c() -> Result<std::sync::Arc<std::sync::atomic::AtomicBool>> {
    LISTENING.store(true, std::sync::atomic::Ordering::SeqCst);
    Ok(stop_flag())
}

/// A progress bar with an ETA on stderr: redrawn in place at most every 200 ms on a terminal,
/// a plain log line every 10 s when stderr is a file or a pipe (no `\r` in logs).
pub(crate) fn progress_bar() -> impl FnMut(&lightgrid_bench::Progress) {
    use std::io::IsTerminal;
    // On a terminal one line redrawn in place; in a log, a plain line every 10 seconds.
    let terminal = std::io::stderr().is_terminal();
    let every = std::time::Duration::from_millis(if terminal { 200 } else { 10_000 });
    let start = std::time::Instant::now();
    let mut last: Option<std::time::Instant> = None;
    move |p: &lightgrid_bench::Progress| {
        let due = last.is_none_or(|t| t.elapsed() >= every);
        if !due && p.done < p.total {
            return;
        }
        last = Some(std::time::Instant::now());
        let frac = p.done as f64 / p.total.max(1) as f64;
        let elapsed = start.elapsed().as_secs_f64();
        let eta = if p.done > 0 {
            format_duration(elapsed / frac - elapsed)
        } else {
            "?".into()
        };
        let label = p.label.chars().take(48).collect::<String>();
        if terminal {
            let filled = (frac * 30.0) as usize;
            eprint!(
                "\r[{}{}] {:>3.0}% {}/{} ETA {:<7} {:<48}",
                "#".repeat(filled),
                " ".repeat(30 - filled),
                frac * 100.0,
                p.done,
                p.total,
                eta,
                label
            );
        } else {
            eprintln!(
                "{:>3.0}% {}/{} ETA {eta} {label}",
                frac * 100.0,
                p.done,
                p.total
            );
        }
    }
}

/// The exit of a long run: an error (non-zero status) when it did not complete, saying how
/// it ended and where the partial results are.
pub(crate) fn run_outcome(outcome: &lightgrid_bench::Outcome, out: &std::path::Path) -> Result<()> {
    if !outcome.is_complete() {
        anyhow::bail!(
            "{}\nwhat was measured is in {} (marked {})",
            outcome.describe(),
            out.display(),
            match outcome {
                lightgrid_bench::Outcome::Failed(_) => "failed",
                _ => "interrupted",
            }
        );
    }
    Ok(())
}
