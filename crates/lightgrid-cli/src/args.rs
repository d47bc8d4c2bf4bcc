//! Arguments and helpers every command shares: frame size, scene and renderer settings,
//! `--assign` values, Ctrl-C handling and the progress bar.

use crate::files::Files;
use anyhow::{Context, Result};
use clap::Args;
use lightgrid::pipelines::{Axis, SettingValue, AXES};
use lightgrid::scene::catalog::SceneParams;
use lightgrid::scene::{AddLights, SceneRequest};
use lightgrid::RenderSettings;

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

/// A number above 0 and at most `max` (the bounds the message states are the ones enforced).
fn parse_up_to(s: &str, min: f64, max: f64) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v >= min && v <= max => Ok(v),
        _ => Err(format!("'{s}' is not a number from {min:e} to {max:e}")),
    }
}

/// `--exposure`: from [`MIN_EXPOSURE`] (tinier factors are 0 in f32, so nothing would show)
/// to the library's largest ([`lightgrid::scene::source::MAX_EXPOSURE`]).
pub(crate) fn parse_exposure(s: &str) -> Result<f64, String> {
    parse_up_to(
        s,
        MIN_EXPOSURE,
        f64::from(lightgrid::scene::source::MAX_EXPOSURE),
    )
}

/// The smallest `--exposure`: an f32 keeps it (and its products with a light) above 0.
pub(crate) const MIN_EXPOSURE: f64 = 1e-30;

/// `--range-scale`: a factor above 0 and at most [`lightgrid_bench::MAX_RANGE_SCALE`].
pub(crate) fn parse_range_scale(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v > 0.0 && v <= f64::from(lightgrid_bench::MAX_RANGE_SCALE) => Ok(v),
        _ => Err(format!(
            "'{s}' is not a factor above 0 and at most {}",
            lightgrid_bench::MAX_RANGE_SCALE
        )),
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

/// A clap value parser for any setting the library names ([`SettingValue`]): the one adapter
/// between the library's enums and the command line (their names and one line of help each).
pub(crate) fn setting<T: SettingValue + Send + Sync>(
) -> impl clap::builder::TypedValueParser<Value = T> {
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
    let values = T::VALUES
        .iter()
        .map(|v| PossibleValue::new(v.name()).help(v.help()));
    PossibleValuesParser::new(values).map(|name| T::parse(&name).expect("a possible value"))
}

/// One rule for every command: an option given explicitly that applies to none of the chosen
/// pipelines (with `settings`) is refused rather than silently ignored; which pipelines an
/// option applies to is the library's table ([`AXES`]).
pub(crate) fn check_applies(
    given: &[&'static Axis],
    chosen: &[&'static lightgrid::pipelines::PipelineInfo],
    settings: &RenderSettings,
) -> Result<()> {
    lightgrid::pipelines::check_axes_apply(given, chosen, settings).map_err(anyhow::Error::msg)
}

/// The options of the library's table of settings ([`AXES`]), one value each, made from the
/// table: a setting added there is an option here, with its values and help, and refused
/// where it does not apply.
#[derive(Clone, Default)]
pub(crate) struct AxisArgs {
    /// The options given, with their value.
    pub(crate) given: Vec<(&'static Axis, String)>,
}

impl AxisArgs {
    /// The table's options, for `augment_args`: one value each (`list`: a comma list).
    pub(crate) fn options(cmd: clap::Command, list: bool) -> clap::Command {
        use clap::builder::PossibleValue;
        AXES.iter().fold(cmd, |cmd, axis| {
            let default = (axis.get)(&RenderSettings::default());
            let mut arg = clap::Arg::new(axis.column)
                .long(axis.flag)
                .allow_hyphen_values(true)
                .help(match list {
                    false => format!("{} [default: {default}]", capitalized(axis.help)),
                    true => format!(
                        "{}: a value, or a comma list to measure each (a preset may set it) [default: {default}]",
                        capitalized(axis.help)
                    ),
                });
            let values = (axis.values)();
            arg = if values.is_empty() {
                // A number: the table's `set` checks it.
                arg.value_parser(move |v: &str| -> Result<String, String> {
                    (axis.set)(&mut RenderSettings::default(), v)?;
                    Ok(v.to_string())
                })
            } else {
                arg.value_parser(clap::builder::PossibleValuesParser::new(
                    values
                        .iter()
                        .map(|v| PossibleValue::new(v.name).help(v.help)),
                ))
            };
            if list {
                arg = arg.value_delimiter(',').action(clap::ArgAction::Append);
            }
            cmd.arg(arg)
        })
    }

    /// The given options' values, from `matches`.
    pub(crate) fn given_in(matches: &clap::ArgMatches) -> Vec<(&'static Axis, Vec<String>)> {
        AXES.iter()
            .filter_map(|axis| {
                let values = matches.get_many::<String>(axis.column)?;
                Some((axis, values.cloned().collect()))
            })
            .collect()
    }

    /// The options given.
    pub(crate) fn axes(&self) -> Vec<&'static Axis> {
        self.given.iter().map(|(a, _)| *a).collect()
    }

    /// `settings` with the given options set.
    pub(crate) fn apply(&self, settings: &mut RenderSettings) -> Result<()> {
        for (axis, value) in &self.given {
            (axis.set)(settings, value).map_err(|e| anyhow::anyhow!("{}: {e}", axis.option()))?;
        }
        Ok(())
    }
}

fn capitalized(s: &str) -> String {
    let mut c = s.chars();
    c.next()
        .map(|f| f.to_uppercase().chain(c).collect())
        .unwrap_or_default()
}

/// The options of the library's table of settings as comma lists of values to measure
/// (`bench`): made from the table as [`AxisArgs`] is.
#[derive(Clone, Default)]
pub(crate) struct AxisListArgs {
    /// The options given, with their values.
    pub(crate) given: Vec<(&'static Axis, Vec<String>)>,
}

impl clap::FromArgMatches for AxisListArgs {
    fn from_arg_matches(matches: &clap::ArgMatches) -> Result<Self, clap::Error> {
        Ok(AxisListArgs {
            given: AxisArgs::given_in(matches),
        })
    }

    fn update_from_arg_matches(&mut self, matches: &clap::ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(matches)?;
        Ok(())
    }
}

impl clap::Args for AxisListArgs {
    fn augment_args(cmd: clap::Command) -> clap::Command {
        AxisArgs::options(cmd, true)
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        Self::augment_args(cmd)
    }
}

impl clap::FromArgMatches for AxisArgs {
    fn from_arg_matches(matches: &clap::ArgMatches) -> Result<Self, clap::Error> {
        let given = AxisArgs::given_in(matches)
            .into_iter()
            .map(|(axis, mut values)| (axis, values.pop().unwrap_or_default()))
            .collect();
        Ok(AxisArgs { given })
    }

    fn update_from_arg_matches(&mut self, matches: &clap::ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(matches)?;
        Ok(())
    }
}

impl clap::Args for AxisArgs {
    fn augment_args(cmd: clap::Command) -> clap::Command {
        AxisArgs::options(cmd, false)
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        Self::augment_args(cmd)
    }
}

/// The renderer's settings as options (`render`, `compare`, `play`, `view`): `--tile`, and
/// every setting of the library's table ([`AXES`]).
#[derive(Args, Clone)]
pub(crate) struct RendererArgs {
    /// Screen tile edge in pixels for grid pipelines (4 to 64).
    #[arg(long, allow_hyphen_values = true, default_value_t = lightgrid::consts::DEFAULT_TILE_SIZE)]
    pub(crate) tile: u32,
    #[command(flatten)]
    pub(crate) axes: AxisArgs,
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
        let mut settings = RenderSettings {
            grid: lightgrid::CullConfig {
                tile_size: self.tile,
                ..lightgrid::CullConfig::default()
            },
            ..RenderSettings::default()
        };
        self.axes.apply(&mut settings)?;
        let resolve_given =
            (self.axes.axes().iter()).any(|a| a.flag == lightgrid::frame::MsaaResolve::FLAG);
        check_msaa_resolve(resolve_given, &[settings.grid.samples])?;
        settings.validate()?;
        Ok(settings)
    }

    /// The options given that only some pipelines read, for [`check_applies`].
    pub(crate) fn given(&self) -> Vec<&'static Axis> {
        self.axes.axes()
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
    /// Multiplies every light before shading (default: 1 for the catalog; for a glTF file's
    /// photometric lights, the exposure at which the median light shows mid-grey on a white
    /// surface at half its range). 1e-30 to 1e6.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_exposure)]
    pub(crate) exposure: Option<f64>,
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
            exposure: None,
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
            exposure: self.exposure.map(|e| e as f32),
            contents: None,
        };
        lightgrid::scene::source::check(&req)?;
        Ok(req)
    }

    /// A glTF scene file, and the files it reads, are inputs no output may replace.
    pub(crate) fn claim(&self, files: &mut Files) -> Result<()> {
        files.scene("--scene", &self.scene)
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
/// it ended and where the partial results are (set aside beside an earlier run's files,
/// which stay as they were, or in `out` when there was none).
pub(crate) fn run_outcome(
    outcome: &lightgrid_bench::Outcome,
    out: &std::path::Path,
    committed: &lightgrid_bench::Committed,
) -> Result<()> {
    if !outcome.is_complete() {
        let marked = match outcome {
            lightgrid_bench::Outcome::Failed(_) => "failed",
            _ => "interrupted",
        };
        let place = match &committed.set_aside {
            Some(aside) => format!(
                "{} (marked {marked}); the earlier run's files in {} are kept as they were",
                aside.display(),
                out.display()
            ),
            None => format!("{} (marked {marked})", out.display()),
        };
        anyhow::bail!("{}\nwhat was measured is in {place}", outcome.describe());
    }
    Ok(())
}
