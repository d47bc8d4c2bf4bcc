//! Running the benchmark: the measurement loop, warm-up, repeats, cancellation.

use crate::invalid;
use crate::outdir::{Outcome, STOPPED_BY_SIGNAL};
use image::RgbaImage;
use lightgrid::error::Result;
use lightgrid::frame::MsaaResolve;
use lightgrid::gpu::{GpuContext, PassTiming};
use lightgrid::passes::GBufferFormat;
use lightgrid::pipelines::{self, Axis, RenderSettings, SettingValue, AXES};
use lightgrid::realtime::{play, PlayPlan, PlayedFrame};
use lightgrid::scene::catalog::{self, SceneParams};
use lightgrid::scene::{gltf, source, AddLights, SceneRequest};
use lightgrid::stats::{Distribution, TimingSource};
use lightgrid::Renderer;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicBool, Ordering};

/// Frames `start..=end` every `step` (clipped to the scene's animation).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct FrameRange {
    pub start: u32,
    pub end: u32,
    pub step: u32,
}

impl FrameRange {
    /// Parse `A..B:STEP`, `A..B` or `N`.
    pub fn parse(s: &str) -> Result<Self> {
        let bad = || {
            invalid(
                "--frames",
                format!("'{s}' is not A..B:STEP, A..B or N (e.g. 0..259:5)"),
            )
        };
        let num = |t: &str| t.trim().parse::<u32>().map_err(|_| bad());
        let (range, step) = match s.split_once(':') {
            Some((r, st)) => (r, num(st)?),
            None => (s, 1),
        };
        let (start, end) = match range.split_once("..") {
            Some((a, b)) => (num(a)?, num(b)?),
            None => {
                let n = num(range)?;
                (n, n)
            }
        };
        if step == 0 {
            return Err(invalid(
                "--frames",
                format!("'{s}': the step must be at least 1"),
            ));
        }
        if end < start {
            return Err(invalid(
                "--frames",
                format!("'{s}': the range ends ({end}) before it starts ({start})"),
            ));
        }
        Ok(FrameRange { start, end, step })
    }

    pub fn frames(&self, frame_count: u32) -> Vec<u32> {
        (self.start..=self.end.min(frame_count.saturating_sub(1)))
            .step_by(self.step as usize)
            .collect()
    }
}

/// What to measure.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BenchConfig {
    pub scenes: Vec<String>,
    pub pipelines: Vec<String>,
    pub frames: FrameRange,
    /// None: each scene's own size.
    pub size: Option<(u32, u32)>,
    pub tile_size: u32,
    /// The values each setting of the library's table (`lightgrid::pipelines::AXES`) is
    /// measured at; a setting not listed is measured at its default. Every pipeline is
    /// measured once per combination of the values of the settings that apply to it.
    #[serde(default)]
    pub settings: Vec<AxisValues>,
    /// Measurements per frame (the spread is kept).
    pub repeat: u32,
    /// Discarded renders of the first frame before each pipeline's series.
    pub warmup: u32,
    pub seed: u64,
    /// For scenes with a variable light count: each such scene is measured once per count
    /// (as `<scene>-<n>-lights` when there are several); empty: the scene's own.
    pub lights: Vec<u32>,
    /// Frame whose lights-per-tile heatmap goes into the report (None: the middle one).
    pub heatmap_frame: Option<u32>,
    /// The heatmap's scale: 0 to this many lights (None: the frame's own maximum).
    #[serde(default)]
    pub heatmap_max: Option<u32>,
    /// Every scene measured once per factor with all its lights' ranges scaled by it, as
    /// `<scene>-range-x<factor>` (`--range-scale`; tiled-forward-shading Fig. 4.2(a): lights
    /// too large leave nothing for tiling to cull). Empty: the scenes as they are.
    #[serde(default)]
    pub range_scales: Vec<f32>,
    /// Fractions of each scene's lights made spots (`--spot-fraction`, each 0 to 1). With
    /// several, every scene is measured once per fraction, as `<scene>-spots-<f>` for those
    /// above 0 (the culling preset's `0,1`: each scene as it is and all-spot). Empty: 0.
    /// Results written before it was a list hold one number (`spot_fraction`), read as one.
    #[serde(default, alias = "spot_fraction", deserialize_with = "one_or_many")]
    pub spot_fractions: Vec<f32>,
    /// Headlights on the robots of the scenes that have them (`--headlights`).
    #[serde(default)]
    pub headlights: bool,
    /// The scenes' transparent objects (`--transparency on|off`).
    #[serde(default = "default_on")]
    pub transparency: bool,
    /// Also measure every scene that has transparent objects without them, as the scene
    /// `<name>-opaque` (`--transparency on,off`; tiled-forward-shading Fig. 4.4 compares
    /// tiled forward with and without transparency).
    #[serde(default)]
    pub opaque_variants: bool,
    /// The materials' own shaders (`--material-shaders on|off`).
    #[serde(default = "default_on")]
    pub material_shaders: bool,
    /// Lights scattered over every scene's bounds (`--add-lights`).
    #[serde(default)]
    pub add_lights: Option<AddLights>,
}

/// The values one setting of the library's table is measured at (`--spot-cull sphere,cone`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AxisValues {
    /// The option without its dashes (`spot-cull`), a row of `lightgrid::pipelines::AXES`.
    pub flag: String,
    /// Value names, as the option takes them.
    pub values: Vec<String>,
}

fn default_on() -> bool {
    true
}

/// A number or a list of them, as a list (`spot_fractions`, written as one number before).
fn one_or_many<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<f32>, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum OneOrMany {
        One(f32),
        Many(Vec<f32>),
    }
    Ok(match OneOrMany::deserialize(d)? {
        OneOrMany::One(f) => vec![f],
        OneOrMany::Many(v) => v,
    })
}

/// The suffix of a scene measured with some of its lights spots when several fractions are
/// (`<scene>-spots-<fraction>`).
pub const SPOTS_SUFFIX: &str = "-spots-";

impl BenchConfig {
    /// The spot fractions measured (`[0]` when none is given).
    pub fn spot_fractions(&self) -> Vec<f32> {
        match self.spot_fractions.is_empty() {
            true => vec![0.0],
            false => self.spot_fractions.clone(),
        }
    }

    /// Are some of the scenes' lights made spots?
    pub fn has_spots(&self) -> bool {
        self.spot_fractions.iter().any(|&f| f > 0.0)
    }

    /// The values `axis` is measured at: those listed, else its default.
    pub fn values(&self, axis: &Axis) -> Vec<String> {
        match self.settings.iter().find(|a| a.flag == axis.flag) {
            Some(a) => a.values.clone(),
            None => vec![(axis.get)(&RenderSettings::default())],
        }
    }

    /// Is `axis` measured at more than one value?
    pub fn varies(&self, axis: &Axis) -> bool {
        self.values(axis).len() > 1
    }

    /// The values of the setting `T` is the type of.
    pub fn values_of<T: SettingValue>(&self) -> Vec<T> {
        let axis = pipelines::find_axis(T::FLAG).expect("every setting type has a row");
        (self.values(axis).iter())
            .map(|v| T::parse(v).expect("validated"))
            .collect()
    }

    /// The MSAA sample counts measured.
    pub fn msaa_counts(&self) -> Vec<u32> {
        let axis = pipelines::find_axis("msaa").expect("the msaa row");
        (self.values(axis).iter())
            .map(|v| v.parse().expect("validated"))
            .collect()
    }

    /// Set `flag`'s values (replacing any listed).
    pub fn set(&mut self, flag: &str, values: Vec<String>) {
        self.settings.retain(|a| a.flag != flag);
        self.settings.push(AxisValues {
            flag: flag.into(),
            values,
        });
    }

    /// Every list names series: a value given twice, or two values that are one, would
    /// measure one series twice under one name.
    fn check_distinct_lists(&self) -> Result<()> {
        crate::check_distinct("--scene", &self.scenes, |s| scene_key(s))?;
        crate::check_distinct("--pipelines", &self.pipelines, |p| {
            pipelines::find(p).map_or(p.trim().to_string(), |i| i.id.to_string())
        })?;
        crate::check_distinct("--lights", &self.lights, |&n| n)?;
        crate::check_distinct("--spot-fraction", &self.spot_fractions(), |&f| f)?;
        crate::check_distinct("--range-scale", &self.range_scales, |&f| f)?;
        for a in &self.settings {
            let canonical = |v: &String| match pipelines::find_axis(&a.flag) {
                Some(axis) => {
                    let mut s = RenderSettings::default();
                    match (axis.set)(&mut s, v) {
                        Ok(()) => (axis.get)(&s),
                        Err(_) => v.clone(),
                    }
                }
                None => v.clone(),
            };
            crate::check_distinct(&format!("--{}", a.flag), &a.values, canonical)?;
        }
        Ok(())
    }

    pub fn validate(&self) -> Result<()> {
        check_range_scales(&self.range_scales)?;
        self.check_distinct_lists()?;
        if self.scenes.is_empty() || self.pipelines.is_empty() {
            return Err(invalid("bench", "needs at least one scene and pipeline"));
        }
        for a in &self.settings {
            let axis = pipelines::find_axis(&a.flag)
                .ok_or_else(|| invalid("bench", format!("no setting --{}", a.flag)))?;
            if a.values.is_empty() {
                return Err(invalid("bench", format!("--{} needs a value", a.flag)));
            }
            for v in &a.values {
                (axis.set)(&mut RenderSettings::default(), v)
                    .map_err(|e| invalid("bench", format!("--{}: {e}", a.flag)))?;
            }
        }
        for p in &self.pipelines {
            pipelines::find(p)?;
        }
        for s in &self.scenes {
            if !gltf::is_gltf_path(s) {
                catalog::find(s)?;
            }
        }
        // Scene options are checked the way `render` checks them (files included).
        let check = |spec: &str, params: SceneParams| {
            source::check(&SceneRequest {
                params,
                add_lights: self.add_lights,
                ..SceneRequest::new(spec)
            })
        };
        // One rule for every command: an option that applies to nothing chosen is refused.
        // --lights goes to the scenes that take a light count; with none, the first scene's
        // check says which scenes do.
        for &n in &self.lights {
            let taker = self
                .scenes
                .iter()
                .find(|s| catalog::find(s).is_ok_and(|i| i.variable_lights))
                .unwrap_or(&self.scenes[0]);
            let params = SceneParams {
                seed: self.seed,
                lights: Some(n),
                ..Default::default()
            };
            check(taker, params)?;
        }
        for (flag, v, min) in [("--repeat", self.repeat, 1), ("--warmup", self.warmup, 0)] {
            if !(min..=crate::MAX_REPEATS).contains(&v) {
                return Err(invalid(
                    flag,
                    format!("{v} is out of range {min} to {}", crate::MAX_REPEATS),
                ));
            }
        }
        lightgrid::RenderSettings {
            grid: lightgrid::CullConfig {
                tile_size: self.tile_size,
                ..lightgrid::CullConfig::default()
            },
            ..Default::default()
        }
        .validate()?;
        for spot_fraction in self.spot_fractions() {
            let params = SceneParams {
                spot_fraction,
                ..Default::default()
            };
            check(&self.scenes[0], params)?;
        }
        if self.headlights {
            // As --lights: refused only when no chosen scene has robots.
            let taker = self
                .scenes
                .iter()
                .find(|s| catalog::find(s).is_ok_and(|i| i.robots))
                .unwrap_or(&self.scenes[0]);
            let params = SceneParams {
                headlights: true,
                ..Default::default()
            };
            check(taker, params)?;
        }
        Ok(())
    }
}

/// One measured frame. Times come from the real-time path (`realtime::play`: the frames
/// rendered back to back, one submission each, no analysis), counts from an analysis render
/// of the same frame ([`SOURCES`] in results.json says so).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameRecord {
    /// The analysis render's statistics, flattened into the record, with `gpu_ms`, `passes`
    /// and `timing` the real-time path's once it has measured the frame: `gpu_ms` its
    /// timestamp span (each submission's, summed; the wall frame time without timestamps),
    /// median over the repeats, `passes` the median repeat's.
    #[serde(flatten)]
    pub stats: lightgrid::FrameStats,
    pub gpu_ms_repeats: Vec<f64>,
    /// Wall time from this frame's start to the next one's on the real-time path (median).
    #[serde(default)]
    pub frame_ms: f64,
    /// GPU time of the analysis render of the frame (for comparison; not what a game sees).
    #[serde(default)]
    pub analysis_gpu_ms: f64,
}

/// Summaries of a run's per-frame series.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunSummary {
    pub gpu_ms: Distribution,
    pub lighting_computations: Option<Distribution>,
    pub ideal_lighting_computations: Distribution,
    /// Σ ideal ÷ Σ actual over the frames.
    pub efficiency: Option<f64>,
    pub lights_per_tile_avg: Option<f64>,
    pub lights_per_tile_max: Option<u32>,
    /// Average GPU time per pass label.
    pub passes: Vec<PassTiming>,
    pub bytes_per_pixel: u32,
    pub target_bytes: u64,
}

impl RunSummary {
    pub fn from_frames(
        frames: &[FrameRecord],
        bytes_per_pixel: u32,
        target_bytes: u64,
    ) -> Option<Self> {
        let counts: Option<Vec<u64>> = frames
            .iter()
            .map(|f| f.stats.lighting_computations)
            .collect();
        let ideal: u64 = frames
            .iter()
            .map(|f| f.stats.ideal_lighting_computations)
            .sum();
        let mut passes: Vec<PassTiming> = Vec::new();
        for f in frames {
            for p in &f.stats.passes {
                match passes.iter_mut().find(|q| q.label == p.label) {
                    Some(q) => q.ms += p.ms,
                    None => passes.push(p.clone()),
                }
            }
        }
        for p in &mut passes {
            p.ms /= frames.len() as f64;
        }
        let per_tile: Vec<f64> = frames
            .iter()
            .filter_map(|f| f.stats.lights_per_tile_avg)
            .collect();
        Some(RunSummary {
            gpu_ms: Distribution::of(frames.iter().map(|f| f.stats.gpu_ms))?,
            lighting_computations: counts
                .as_ref()
                .and_then(|c| Distribution::of(c.iter().map(|&n| n as f64))),
            ideal_lighting_computations: Distribution::of(
                frames
                    .iter()
                    .map(|f| f.stats.ideal_lighting_computations as f64),
            )?,
            efficiency: counts
                .map(|c| c.iter().sum::<u64>())
                .filter(|&n| n > 0)
                .map(|n| ideal as f64 / n as f64),
            lights_per_tile_avg: (!per_tile.is_empty())
                .then(|| per_tile.iter().sum::<f64>() / per_tile.len() as f64),
            lights_per_tile_max: frames
                .iter()
                .filter_map(|f| f.stats.lights_per_tile_max)
                .max(),
            passes,
            bytes_per_pixel,
            target_bytes,
        })
    }
}

/// Which renders a run's times were measured on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TimesFrom {
    /// `realtime::play`: frames back to back, one submission each (what a game sees).
    #[default]
    RealTime,
    /// The analysis renders (only a run stopped before its real-time pass).
    Analysis,
}

/// One scene × pipeline × setting.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunRecord {
    pub scene: String,
    pub pipeline: String,
    /// The settings the pipeline rendered with.
    pub settings: RenderSettings,
    /// The settings the pipeline reads that the run measured at more than one value or away
    /// from their default (their flags): what names this series among its siblings.
    #[serde(default)]
    pub varied: Vec<String>,
    pub width: u32,
    pub height: u32,
    pub tile_size: u32,
    /// The scene's light count (from the analysis renders).
    #[serde(default)]
    pub lights: Option<u32>,
    pub timing: TimingSource,
    /// False when the run was interrupted before its last frame.
    pub complete: bool,
    /// Real-time frames whose light lists did not fit (sized from earlier frames).
    #[serde(default)]
    pub overflow_frames: u32,
    /// Where the run's `gpu_ms` come from: the real-time path, or (a run interrupted before
    /// its real-time pass) its analysis renders.
    #[serde(default)]
    pub times_from: TimesFrom,
    pub frames: Vec<FrameRecord>,
    pub summary: Option<RunSummary>,
}

/// Everything a bench run measured.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BenchResults {
    /// The command line that produced these results.
    pub command: String,
    pub adapter: String,
    pub software_adapter: bool,
    pub config: BenchConfig,
    /// Complete, interrupted (Ctrl-C, SIGTERM) or failed, with the reason.
    #[serde(default)]
    pub outcome: Outcome,
    /// Where each figure comes from (figure, source), [`SOURCES`].
    #[serde(default)]
    pub sources: Vec<(String, String)>,
    pub runs: Vec<RunRecord>,
    /// With spots: per (scene, frame), what test (b), the post's ray against a thickened cone,
    /// would list on the depth-bounded tile grid and how many lit (tile, spot) pairs it
    /// would miss (`culling::ray_test_count`; measured, not shipped).
    #[serde(default)]
    pub spot_ray_tests: Vec<SpotRayTest>,
    /// Lights-per-tile heatmaps: (scene, pipeline, frame, image).
    #[serde(skip)]
    pub heatmaps: Vec<(String, String, u32, RgbaImage)>,
    /// Per scene, the frames of [`THUMBNAIL_FRAMES`] side by side (tiled-shading Fig. 2's
    /// views along the animation), as rendered by the heatmap's pipeline (else the first one).
    #[serde(skip)]
    pub thumbnails: Vec<(String, RgbaImage)>,
}

/// The animation frames tiled-shading Fig. 2 shows (those past a scene's end are left out).
pub const THUMBNAIL_FRAMES: [u32; 4] = [0, 86, 186, 259];
/// Width of one thumbnail, pixels.
pub const THUMBNAIL_WIDTH: u32 = 200;

/// The frames of [`THUMBNAIL_FRAMES`] a scene has, rendered by `pipeline` and scaled to
/// [`THUMBNAIL_WIDTH`], side by side with a 2-pixel gap.
fn thumbnails(
    renderer: &mut Renderer,
    scene: &lightgrid::scene::Scene,
    pipeline: &str,
) -> Result<RgbaImage> {
    let mut shots = Vec::new();
    for f in THUMBNAIL_FRAMES
        .into_iter()
        .filter(|&f| f < scene.frame_count())
    {
        let out = renderer.render(scene, f, pipeline)?;
        let (w, h) = out.image.dimensions();
        let th = (h * THUMBNAIL_WIDTH / w.max(1)).max(1);
        shots.push(image::imageops::resize(
            &out.image,
            THUMBNAIL_WIDTH,
            th,
            image::imageops::FilterType::Triangle,
        ));
    }
    let h = shots.iter().map(|s| s.height()).max().unwrap_or(1);
    let n = shots.len() as u32;
    let mut strip = RgbaImage::from_pixel(
        (n * (THUMBNAIL_WIDTH + 2)).saturating_sub(2).max(1),
        h,
        image::Rgba([0, 0, 0, 255]),
    );
    for (i, s) in shots.iter().enumerate() {
        image::imageops::replace(&mut strip, s, i as i64 * i64::from(THUMBNAIL_WIDTH + 2), 0);
    }
    Ok(strip)
}

/// Test (b) on one frame (see [`BenchResults::spot_ray_tests`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpotRayTest {
    pub scene: String,
    pub frame: u32,
    pub tile_size: u32,
    pub ideal_lighting_computations: u64,
    #[serde(flatten)]
    pub count: lightgrid::culling::RayTestCount,
}

/// Where the figures of results.json come from.
pub const SOURCES: &[(&str, &str)] = &[
    ("gpu_ms", "real-time path (lightgrid play): the frame's timestamp span (first pass start to last pass end, per submission, summed), median over --repeat passes over the frames"),
    ("frame_ms", "real-time path: wall time from one frame's start to the next's, median over the passes"),
    ("passes", "real-time path: pass timestamps of the median pass"),
    ("analysis_gpu_ms", "analysis render of the same frame (readbacks recorded in the frame)"),
    ("lighting_computations", "analysis render: the GPU's count target"),
    ("ideal_lighting_computations", "analysis render: depth read back, every visible sample against the lights reaching it"),
    ("lights_per_tile_avg, lights_per_tile_max, memory.grid_bytes", "analysis render: the grid downloaded"),
    ("memory.modelled_write_bytes, memory.modelled_read_bytes, memory.forward_plus_table1", "analysis render: the memory model applied to its counts"),
    ("the frame's other fields (lightgrid::FrameStats)", "analysis render of the frame"),
];

/// Progress of a run, for a progress bar.
#[derive(Clone, Debug)]
pub struct Progress {
    pub done: u64,
    pub total: u64,
    pub label: String,
}

/// One series of the plan: a scene and a pipeline with one combination of the settings
/// that apply to it, over its frames.
struct Series {
    scene: usize,
    info: &'static pipelines::PipelineInfo,
    settings: RenderSettings,
    frames: Vec<u32>,
}

/// The settings one pipeline is measured under: every combination of the values of the
/// settings that apply to it (the library's table decides which, as it does for the CLI's
/// refusals); a setting that changes nothing for it stays at its default. The product runs
/// in the table's order, last setting fastest.
fn variants(config: &BenchConfig, info: &pipelines::PipelineInfo) -> Vec<RenderSettings> {
    let mut out = vec![RenderSettings {
        grid: lightgrid::CullConfig {
            tile_size: config.tile_size,
            ..lightgrid::CullConfig::default()
        },
        ..RenderSettings::default()
    }];
    for axis in AXES {
        let values = config.values(axis);
        out = out
            .into_iter()
            .flat_map(|s| match (axis.applies)(info, &s) {
                true => values
                    .iter()
                    .map(|v| {
                        let mut s = s;
                        (axis.set)(&mut s, v).expect("validated");
                        s
                    })
                    .collect(),
                false => vec![s],
            })
            .collect();
    }
    out
}

/// What names `settings` among its siblings: the flags of the settings `info` reads that
/// the run measured at more than one value or at a value other than the default.
fn varied(
    config: &BenchConfig,
    info: &pipelines::PipelineInfo,
    settings: &RenderSettings,
) -> Vec<String> {
    let default = RenderSettings::default();
    AXES.iter()
        .filter(|a| (a.applies)(info, settings))
        .filter(|a| config.varies(a) || (a.get)(settings) != (a.get)(&default))
        .map(|a| a.flag.to_string())
        .collect()
}

/// The suffix of a scene measured without its transparent objects (`opaque_variants`).
pub const OPAQUE_SUFFIX: &str = "-opaque";

/// A scene variant's name in the results: the scene's, with its light count and spot
/// fraction where the run measures several.
fn variant_name(
    scene: &str,
    config: &BenchConfig,
    lights: Option<u32>,
    spot_fraction: f32,
) -> String {
    let mut base = match lights {
        Some(n) if config.lights.len() > 1 => format!("{scene}-{n}-lights"),
        _ => scene.to_string(),
    };
    if config.spot_fractions().len() > 1 && spot_fraction > 0.0 {
        base = format!("{base}{SPOTS_SUFFIX}{spot_fraction}");
    }
    base
}

/// Where a scene variant came from, in the options' words.
fn variant_source(
    name: &str,
    config: &BenchConfig,
    lights: Option<u32>,
    spot_fraction: f32,
) -> String {
    match (lights, config.spot_fractions().len() > 1) {
        (Some(n), _) if config.lights.len() > 1 => format!("--scene {name} with {n} lights"),
        (_, true) => format!("--scene {name} at spot fraction {spot_fraction}"),
        _ => format!("--scene {name}"),
    }
}

fn build_scenes(config: &BenchConfig) -> Result<Vec<lightgrid::scene::Scene>> {
    let mut scenes = Vec::new();
    // Scene ids: two files with one file name (a/model.glb, b/model.glb) would be one scene
    // in the results and the report's files; the later ones get a number ("model-2").
    let mut ids: Vec<String> = Vec::new();
    let mut sources: Vec<String> = Vec::new();
    for name in &config.scenes {
        // What applies to this scene: a light count and headlights only where the catalog
        // scene takes them, transparency off only where there is some.
        let (variable_lights, robots) = match gltf::is_gltf_path(name) {
            true => (false, false),
            false => {
                let info = catalog::find(name)?;
                (info.variable_lights, info.robots)
            }
        };
        // One scene per light count for the scenes that take one (named by the count when
        // there are several), the scene's own count otherwise.
        let counts: Vec<Option<u32>> = match variable_lights && !config.lights.is_empty() {
            true => config.lights.iter().map(|&n| Some(n)).collect(),
            false => vec![None],
        };
        let fractions = config.spot_fractions();
        let variants = counts
            .iter()
            .flat_map(|&n| fractions.iter().map(move |&f| (n, f)));
        for (lights, spot_fraction) in variants {
            let params = SceneParams {
                seed: config.seed,
                lights,
                spot_fraction,
                headlights: config.headlights && robots,
                transparency: true,
                material_shaders: config.material_shaders,
            };
            let open = |transparency| {
                source::open(&SceneRequest {
                    params: SceneParams {
                        transparency,
                        ..params
                    },
                    add_lights: config.add_lights,
                    ..SceneRequest::new(name)
                })
            };
            let mut opened = open(true)?;
            for w in &opened.warnings {
                eprintln!("warning: {name}: {w}");
            }
            let base = variant_name(&opened.scene.name, config, lights, spot_fraction);
            let id = unique_id(&base, &ids);
            if id != base {
                eprintln!(
                    "warning: {name}: another scene is named {base}; this one is {id} in the results"
                );
            }
            ids.push(id.clone());
            opened.scene.name = id.clone();
            let open = |transparency| {
                open(transparency).map(|mut o| {
                    o.scene.name = id.clone();
                    o
                })
            };
            let has_glass = opened.scene.has_transparency();
            // Without its glass when asked (then measured at every range factor too).
            let scene = match !config.transparency && has_glass {
                true => open(false)?.scene,
                false => opened.scene,
            };
            let source = variant_source(name, config, lights, spot_fraction);
            if !config.range_scales.is_empty() {
                for &f in &config.range_scales {
                    scenes.push(range_scaled(&scene, f));
                    sources.push(format!("{source} at --range-scale {f}"));
                }
                continue;
            }
            scenes.push(scene);
            sources.push(source.clone());
            if config.opaque_variants && config.transparency && has_glass {
                let mut opaque = open(false)?.scene;
                opaque.name = format!("{}{OPAQUE_SUFFIX}", opaque.name);
                scenes.push(opaque);
                sources.push(format!(
                    "{source} without its glass (--transparency on,off)"
                ));
            }
        }
    }
    check_scene_names(&scenes, &sources)?;
    Ok(scenes)
}

/// What a `--scene` value is: a catalog scene by name, a file by what it is on disk (two
/// spellings or links of one file are one scene).
fn scene_key(spec: &str) -> String {
    match gltf::is_gltf_path(spec) {
        true => format!(
            "file {:?}",
            lightgrid::image_io::file_identity(std::path::Path::new(spec))
        ),
        false => spec.to_string(),
    }
}

/// Refuse scenes of one run that would be measured under one name (a file named like a
/// catalog scene's variant, `robots-few-opaque.glb` beside `robots-few` measured without its
/// glass): their series, rows and files would be one. `sources` says where each came from.
fn check_scene_names(scenes: &[lightgrid::scene::Scene], sources: &[String]) -> Result<()> {
    for (i, s) in scenes.iter().enumerate() {
        if let Some(j) = scenes[..i].iter().position(|o| o.name == s.name) {
            return Err(invalid(
                "--scene",
                format!(
                    "{} and {} would both be measured as {}; rename the file or leave one out",
                    sources[j], sources[i], s.name
                ),
            ));
        }
    }
    Ok(())
}

/// `name`, or `name-2`, `name-3`, ... when an earlier scene of the run took it.
fn unique_id(name: &str, taken: &[String]) -> String {
    (1..)
        .map(|k| match k {
            1 => name.to_string(),
            k => format!("{name}-{k}"),
        })
        .find(|id| !taken.contains(id))
        .expect("an unbounded range has a free number")
}

/// The name suffix of a scene measured with its light ranges scaled (`range_scales`).
pub const RANGE_SUFFIX: &str = "-range-x";

/// `scene` with every light's range multiplied by `factor`, named for it.
fn range_scaled(scene: &lightgrid::scene::Scene, factor: f32) -> lightgrid::scene::Scene {
    let mut s = scene.clone();
    s.name = format!("{}{RANGE_SUFFIX}{factor}", scene.name);
    for l in &mut s.lights {
        l.light.range *= factor;
    }
    s
}

/// The largest `--range-scale` factor.
pub const MAX_RANGE_SCALE: f32 = 1000.0;

/// Refuse range factors that are not finite and positive (or absurd).
fn check_range_scales(scales: &[f32]) -> Result<()> {
    for &f in scales {
        if !(f.is_finite() && f > 0.0 && f <= MAX_RANGE_SCALE) {
            return Err(invalid(
                "--range-scale",
                format!("{f} is not a factor above 0 and at most {MAX_RANGE_SCALE}"),
            ));
        }
    }
    Ok(())
}

fn plan(config: &BenchConfig, scenes: &[lightgrid::scene::Scene]) -> Result<Vec<Series>> {
    if let Some(f) = config.heatmap_frame {
        let measured = scenes
            .iter()
            .any(|s| config.frames.frames(s.frame_count()).contains(&f));
        if !measured {
            return Err(invalid(
                "--heatmap-frame",
                format!(
                    "frame {f} is not one of the measured frames ({}..{} every {})",
                    config.frames.start, config.frames.end, config.frames.step
                ),
            ));
        }
    }
    let mut plan = Vec::new();
    for (si, scene) in scenes.iter().enumerate() {
        let frames = config.frames.frames(scene.frame_count());
        if frames.is_empty() {
            return Err(invalid(
                "--frames",
                format!(
                    "no frame of {} is in range (it has frames 0..{})",
                    scene.name,
                    scene.frame_count().saturating_sub(1)
                ),
            ));
        }
        for id in &config.pipelines {
            let info = pipelines::find(id)?;
            for settings in variants(config, info) {
                plan.push(Series {
                    scene: si,
                    info,
                    settings,
                    frames: frames.clone(),
                });
            }
        }
    }
    Ok(plan)
}

/// What the series loop shares: the stop flag, progress and the renderers by settings.
struct Measuring<'a> {
    ctx: &'a GpuContext,
    config: &'a BenchConfig,
    stop: &'a AtomicBool,
    progress: &'a mut dyn FnMut(&Progress),
    done: u64,
    total: u64,
    /// The pipeline whose grid the report's heatmap shows (a depth-bounded grid when one is
    /// measured).
    heatmap_pipeline: Option<String>,
    /// Renderers by (scene, settings); pipelines without a grid builder ignore `assign`.
    renderers: Vec<(usize, RenderSettings, Renderer)>,
}

/// How a series ended when it did not fail.
#[derive(PartialEq)]
enum SeriesEnd {
    Complete,
    Stopped,
}

impl<'a> Measuring<'a> {
    fn stopped(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    fn tick(&mut self, label: String) {
        (self.progress)(&Progress {
            done: self.done,
            total: self.total,
            label,
        });
    }

    fn renderer(&mut self, series: &Series, size: (u32, u32)) -> Result<&mut Renderer> {
        let settings = series.settings;
        let si = series.scene;
        if !self.renderers.iter().any(|r| r.0 == si && r.1 == settings) {
            self.renderers.retain(|r| r.0 == si);
            let r = Renderer::new(self.ctx, size.0, size.1, settings)?;
            self.renderers.push((si, settings, r));
        }
        Ok(&mut self
            .renderers
            .iter_mut()
            .find(|r| r.0 == si && r.1 == settings)
            .expect("created above")
            .2)
    }

    /// Once per scene and frame with spots: how many lights the spot test's rays take per
    /// tile (`culling::ray_test_count`) against the frame's ideal.
    fn spot_ray_test(
        &self,
        scene: &lightgrid::scene::Scene,
        f: u32,
        record: &RunRecord,
        out: &lightgrid::FrameOutput,
        results: &mut BenchResults,
    ) -> Result<()> {
        let tested = |t: &SpotRayTest| t.scene == scene.name && t.frame == f;
        let spots = self.config.has_spots() && scene.lights.iter().any(|l| l.light.spot.is_some());
        if spots && !results.spot_ray_tests.iter().any(tested) {
            let state = scene.frame(f);
            let setup =
                lightgrid::scene::ViewSetup::new(&state.camera, record.width, record.height);
            let count = lightgrid::culling::ray_test_count(
                &setup,
                self.config.tile_size,
                &state.lights,
                &out.depth,
            )?;
            results.spot_ray_tests.push(SpotRayTest {
                scene: scene.name.clone(),
                frame: f,
                tile_size: self.config.tile_size,
                ideal_lighting_computations: out.stats.ideal_lighting_computations,
                count,
            });
        }
        Ok(())
    }

    /// Measure one series into `record` (and the render-target bytes per pixel and in all
    /// into `bytes`): warm-up, one analysis render per frame (counts), then `repeat` real-time
    /// passes (times). What it measured stays in `record` whatever the outcome.
    fn series(
        &mut self,
        scene: &lightgrid::scene::Scene,
        series: &Series,
        record: &mut RunRecord,
        bytes: &mut (u32, u64),
        results: &mut BenchResults,
    ) -> Result<SeriesEnd> {
        let info = series.info;
        let frames = &series.frames;
        // The settings the record names (those measured at more than one value).
        let named = record.describe();
        let label = |what: &str| format!("{} {}{named} {what}", scene.name, info.id);
        for _ in 0..self.config.warmup {
            self.tick(label("warm-up"));
            self.renderer(series, (record.width, record.height))?
                .render(scene, frames[0], info.id)?;
            self.done += 1;
            if self.stopped() {
                return Ok(SeriesEnd::Stopped);
            }
        }
        let heatmap_frame = self
            .config
            .heatmap_frame
            .unwrap_or(frames[frames.len() / 2]);
        let wants_heatmap = self.heatmap_pipeline.as_deref() == Some(info.id);
        // 1. Counts: one analysis render per frame.
        for &f in frames {
            self.tick(label(&format!("frame {f}")));
            let out = self
                .renderer(series, (record.width, record.height))?
                .render(scene, f, info.id)?;
            self.done += 1;
            let s = &out.stats;
            record.timing = s.timing;
            record.lights = Some(s.lights);
            *bytes = (s.memory.bytes_per_pixel, s.memory.target_bytes);
            let heatmaps = &mut results.heatmaps;
            if f == heatmap_frame && wants_heatmap && !heatmaps.iter().any(|h| h.0 == scene.name) {
                let view_distance = out.view_distances();
                let map = lightgrid::heatmap::heatmap_scaled(
                    &out.image,
                    &out.grid,
                    Some(&view_distance),
                    self.config.heatmap_max,
                );
                heatmaps.push((scene.name.clone(), info.id.to_string(), f, map));
            }
            self.spot_ray_test(scene, f, record, &out, results)?;
            record.frames.push(FrameRecord::from_analysis(f, s));
            if self.stopped() {
                return Ok(SeriesEnd::Stopped);
            }
        }
        // 2. Times: the frames back to back on the real-time path, `repeat` times.
        let plan = PlayPlan {
            scene,
            pipeline: info.id,
            frames,
            passes: self.config.repeat,
            // The analysis renders already compiled and sized everything: these only fill
            // the queue of frames in flight.
            warmup: crate::PLAY_QUEUE_FILL,
        };
        let (base, total, stop) = (self.done, self.total, self.stop);
        let settings = series.settings;
        let progress = &mut *self.progress;
        let renderer = &mut self
            .renderers
            .iter_mut()
            .find(|r| r.0 == series.scene && r.1 == settings)
            .expect("the analysis renders created it")
            .2;
        let run = play(renderer, &plan, stop, &mut |n, _| {
            progress(&Progress {
                done: base + n,
                total,
                label: label("real-time"),
            })
        })?;
        self.done = base + run.frames.len() as u64;
        record.take_play_times(&run.frames, frames.len());
        record.overflow_frames = run.overflow_frames() as u32;
        Ok(if run.interrupted {
            SeriesEnd::Stopped
        } else {
            SeriesEnd::Complete
        })
    }
}

impl FrameRecord {
    /// A frame's counts (and, until the real-time pass replaces them, times) from its
    /// analysis render.
    fn from_analysis(frame: u32, s: &lightgrid::FrameStats) -> FrameRecord {
        FrameRecord {
            stats: lightgrid::FrameStats { frame, ..s.clone() },
            gpu_ms_repeats: Vec::new(),
            frame_ms: 0.0,
            analysis_gpu_ms: s.gpu_ms,
        }
    }
}

impl RunRecord {
    /// The value of the setting `T` is the type of, when it names the run (measured at more
    /// than one value or away from its default, and read by the pipeline).
    pub fn varied<T: SettingValue>(&self) -> Option<T> {
        self.varied
            .iter()
            .any(|f| f == T::FLAG)
            .then(|| pipelines::value_of::<T>(&self.settings))
    }

    /// Does the pipeline read the setting `flag` (with the run's settings)?
    pub fn reads(&self, flag: &str) -> bool {
        let axis = pipelines::find_axis(flag).expect("a row of the table");
        pipelines::find(&self.pipeline).is_ok_and(|p| (axis.applies)(p, &self.settings))
    }

    /// The run as the summary names it: [`Self::label`] and its G-buffer precision.
    pub(crate) fn name(&self) -> String {
        match self.gbuffer_bits() {
            Some(b) => format!("{} (g{b})", self.label()),
            None => self.label(),
        }
    }

    /// The pipeline, with each setting the run varied (in the settings table's order, as
    /// its row labels it; the G-buffer is named by [`Self::name`]), and MSAA and where it
    /// resolves whenever MSAA is on.
    pub(crate) fn label(&self) -> String {
        let mut label = self.pipeline.clone();
        for axis in AXES {
            let names = self.varied.iter().any(|f| f == axis.flag)
                || (axis.flag == MsaaResolve::FLAG && self.msaa_resolve().is_some());
            if names && axis.flag != GBufferFormat::FLAG {
                label += &format!(" [{}]", (axis.label)(&(axis.get)(&self.settings)));
            }
        }
        label
    }

    /// The G-buffer's bits per channel, for pipelines with one.
    pub fn gbuffer_bits(&self) -> Option<u32> {
        self.reads(GBufferFormat::FLAG)
            .then_some(self.settings.gbuffer.bits())
    }

    /// MSAA samples per pixel.
    pub fn msaa(&self) -> u32 {
        self.settings.grid.samples
    }

    /// Where the MSAA deferred kernel resolved (the deferred kernels above one sample).
    pub fn msaa_resolve(&self) -> Option<MsaaResolve> {
        self.reads(MsaaResolve::FLAG)
            .then_some(self.settings.msaa_resolve)
    }

    /// " flag value" for each setting the run measured at more than one value (the series'
    /// name in progress lines and errors).
    pub fn describe(&self) -> String {
        self.varied
            .iter()
            .filter_map(|f| pipelines::find_axis(f))
            .map(|a| format!(" {} {}", a.flag, (a.get)(&self.settings)))
            .collect()
    }

    fn new(scene: &lightgrid::scene::Scene, series: &Series, size: (u32, u32), tile: u32) -> Self {
        RunRecord {
            scene: scene.name.clone(),
            pipeline: series.info.id.to_string(),
            settings: series.settings,
            varied: Vec::new(),
            lights: None,
            width: size.0,
            height: size.1,
            tile_size: tile,
            timing: TimingSource::WallClock,
            complete: false,
            overflow_frames: 0,
            times_from: TimesFrom::Analysis,
            frames: Vec::new(),
            summary: None,
        }
    }

    /// Replace the analysis times with the real-time passes' (`played` holds the passes one
    /// after another, `per_pass` frames each). Frames an interrupted pass did not reach carry
    /// no real-time figure and are dropped; with none reached the analysis times stay (and
    /// `times_from` says so).
    fn take_play_times(&mut self, played: &[PlayedFrame], per_pass: usize) {
        let timestamps = played.iter().all(|p| p.gpu_ms.is_some());
        self.timing = if timestamps {
            TimingSource::GpuTimestamps
        } else {
            TimingSource::WallClock
        };
        for (i, rec) in self.frames.iter_mut().enumerate() {
            let of_frame: Vec<&PlayedFrame> = played.iter().skip(i).step_by(per_pass).collect();
            if of_frame.is_empty() {
                continue;
            }
            let times: Vec<f64> = of_frame
                .iter()
                .map(|p| p.gpu_ms.unwrap_or(p.frame_ms))
                .collect();
            let m = Distribution::median_index(&times).expect("not empty");
            rec.stats.gpu_ms = times[m];
            rec.stats.timing = self.timing;
            rec.gpu_ms_repeats = times.clone();
            rec.stats.passes = of_frame[m].passes.clone();
            let periods: Vec<f64> = of_frame.iter().map(|p| p.frame_ms).collect();
            rec.frame_ms = periods[Distribution::median_index(&periods).expect("not empty")];
        }
        let measured = played.len().min(per_pass);
        if measured > 0 {
            self.frames.truncate(measured);
            self.times_from = TimesFrom::RealTime;
        }
    }
}

/// A benchmark checked and planned: scenes built, every series listed. Everything that can be
/// refused is refused by [`prepare`], before a directory is created or a frame rendered.
pub struct PreparedBench {
    config: BenchConfig,
    scenes: Vec<lightgrid::scene::Scene>,
    plan: Vec<Series>,
}

/// Validate `config`, build its scenes and plan its series.
pub fn prepare(config: &BenchConfig) -> Result<PreparedBench> {
    config.validate()?;
    let scenes = build_scenes(config)?;
    let plan = plan(config, &scenes)?;
    Ok(PreparedBench {
        config: config.clone(),
        scenes,
        plan,
    })
}

/// Each scene's strip of frames (`THUMBNAIL_FRAMES`) with `pipeline` at the first value of
/// every setting; a strip that fails is said, not a failed run.
fn add_thumbnails(
    ctx: &GpuContext,
    config: &BenchConfig,
    scenes: &[lightgrid::scene::Scene],
    pipeline: &str,
    results: &mut BenchResults,
) {
    for scene in scenes {
        let size = config.size.unwrap_or(scene.default_size);
        // The first value of every setting (the thumbnails show the scene).
        let mut settings = RenderSettings {
            grid: lightgrid::CullConfig {
                tile_size: config.tile_size,
                ..lightgrid::CullConfig::default()
            },
            ..Default::default()
        };
        for axis in AXES {
            (axis.set)(&mut settings, &config.values(axis)[0]).expect("validated");
        }
        let strip = Renderer::new(ctx, size.0, size.1, settings)
            .and_then(|mut r| thumbnails(&mut r, scene, pipeline));
        match strip {
            Ok(img) => results.thumbnails.push((scene.name.clone(), img)),
            // A picture is not worth failing a finished run for: the report says.
            Err(e) => eprintln!("thumbnails of {}: {e}", scene.name),
        }
    }
}

/// Run the benchmark: [`prepare`], then [`PreparedBench::run`].
pub fn run(
    ctx: &GpuContext,
    config: &BenchConfig,
    stop: &AtomicBool,
    progress: &mut dyn FnMut(&Progress),
) -> Result<BenchResults> {
    prepare(config)?.run(ctx, stop, progress)
}

impl PreparedBench {
    /// The scenes it measures, as the results name them.
    pub fn scenes(&self) -> &[lightgrid::scene::Scene] {
        &self.scenes
    }

    /// Run the prepared benchmark. `stop` is polled after every render; when set, the results
    /// so far are returned with [`Outcome::Interrupted`]. An error part-way is returned the same
    /// way, as [`Outcome::Failed`] with what was measured before it.
    pub fn run(
        &self,
        ctx: &GpuContext,
        stop: &AtomicBool,
        progress: &mut dyn FnMut(&Progress),
    ) -> Result<BenchResults> {
        let (config, scenes, plan) = (&self.config, &self.scenes, &self.plan);
        // Per frame one analysis render, then `repeat` real-time passes over the frames.
        let total: u64 = plan
            .iter()
            .map(|p| {
                u64::from(config.warmup) + p.frames.len() as u64 * u64::from(1 + config.repeat)
            })
            .sum();
        let mut results = BenchResults {
            command: String::new(),
            adapter: ctx.adapter_label(),
            software_adapter: ctx.is_software(),
            config: config.clone(),
            outcome: Outcome::Complete,
            sources: SOURCES
                .iter()
                .map(|(a, b)| (a.to_string(), b.to_string()))
                .collect(),
            runs: Vec::new(),
            spot_ray_tests: Vec::new(),
            heatmaps: Vec::new(),
            thumbnails: Vec::new(),
        };
        let heatmap_pipeline = config
            .pipelines
            .iter()
            .find(|p| p.as_str() == lightgrid::pipelines::ids::TILED_DEFERRED)
            .or_else(|| {
                config
                    .pipelines
                    .iter()
                    .find(|p| pipelines::find(p).is_ok_and(|i| i.uses_grid))
            })
            .cloned();
        let mut m = Measuring {
            ctx,
            config,
            stop,
            progress,
            done: 0,
            total,
            heatmap_pipeline,
            renderers: Vec::new(),
        };
        for series in plan {
            let scene = &scenes[series.scene];
            let size = config.size.unwrap_or(scene.default_size);
            let mut record = RunRecord::new(scene, series, size, config.tile_size);
            record.varied = varied(config, series.info, &series.settings);
            let mut bytes = (0, 0);
            let named = record.describe();
            let end = m.series(scene, series, &mut record, &mut bytes, &mut results);
            record.complete = matches!(end, Ok(SeriesEnd::Complete));
            record.summary = RunSummary::from_frames(&record.frames, bytes.0, bytes.1);
            if !record.frames.is_empty() {
                results.runs.push(record);
            }
            match end {
                Ok(SeriesEnd::Complete) => {}
                Ok(SeriesEnd::Stopped) => {
                    results.outcome = Outcome::Interrupted(STOPPED_BY_SIGNAL.into());
                    break;
                }
                Err(e) => {
                    results.outcome = Outcome::Failed(format!(
                        "{} / {}{}: {e}",
                        scene.name, series.info.id, named
                    ));
                    break;
                }
            }
        }
        if results.outcome.is_complete() {
            m.tick("thumbnails".into());
            let pipeline = m
                .heatmap_pipeline
                .clone()
                .unwrap_or_else(|| config.pipelines[0].clone());
            add_thumbnails(ctx, config, scenes, &pipeline, &mut results);
        }
        m.tick("done".into());
        Ok(results)
    }
}
