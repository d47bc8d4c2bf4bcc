//! `lightgrid bench` and `lightgrid report`: the papers' evaluations and their report.

use crate::args::{
    check_applies, format_duration, parse_fraction, parse_size, progress_bar, run_outcome,
    stop_on_ctrl_c, AxisListArgs, OnOff, Size, MAX_COUNT,
};
use crate::files::Files;
use anyhow::Result;
use clap::Args;
use lightgrid::frame::{
    Assign, Brdf, CellBox, DepthBounds, DepthMask, GridLists, GridStorage, MsaaResolve, Shadows,
};
use lightgrid::gpu::GpuContext;
use lightgrid::passes::GBufferFormat;
use lightgrid::pipelines::ids;
use lightgrid::pipelines::PIPELINES;
use lightgrid::pipelines::{Axis, SettingValue, SpotCull};
use lightgrid_bench::{check_out_dir, AxisValues, BenchConfig, FrameRange, OutDir};
use std::path::PathBuf;

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub(crate) enum Preset {
    /// CI-sized smoke run: robots-many at 160x90, 4 frames, every pipeline.
    Quick,
    /// The papers' configurations: robots-many and robots-few without the robots' glass (the
    /// papers' scenes have none), frames 0..259 every 5, 16- and 32-bit G-buffers, the papers'
    /// tile count (32-pixel tiles at 1920x1080 on a hardware GPU; 11-pixel tiles at 640x360
    /// on a software one).
    Paper,
    /// A scene dominated by spot lights (tiled-deferred-tricks' case): robots-many with every
    /// light a spot, frames 0..259 every 20, grid pipelines culling by sphere and by cone,
    /// with forward and deferred beside them.
    Spots,
    /// Transparency (tiled-forward-shading §4.5): robots-many with its glass, frames 0..259
    /// every 20, grid pipelines with separate and with shared opaque/transparent lists, with
    /// forward and deferred beside them.
    Transparency,
    /// MSAA (tiled-forward-shading Fig. 4.4 and 4.1(c)): random-fps (the paper's 1,024
    /// random lights) with and without its translucent blocks, frames 0..259 every 20,
    /// tiled and clustered forward and deferred at every sample count the adapter offers,
    /// the papers' tile count (as the paper preset).
    Msaa,
    /// Tiled against clustered forward shading (tiled-forward-shading Fig. 4.6): random-top
    /// and random-fps (1,024 random lights, top-down and first-person) without their
    /// translucent blocks, the paper's tile count (32-pixel tiles at 1920x1080, 11 at
    /// 640x360), frames 0..119 every 10: the top-down view favours
    /// tiles, the first-person view clusters, and clusters depend less on the view.
    Clustered,
    /// The Forward+ demo (forward-plus §5): `scattered` with its 3,072 moving lights at
    /// 1280x720 (640x360 on a software adapter), the paper's 14,400 tiles (8x8 pixels at
    /// 1280x720, 4x4 at 640x360), Forward+ (tiled forward with
    /// pre-Z) beside its baseline, compute-based deferred lighting (`tiled_light_prepass`),
    /// and tiled deferred, deferred and deferred lighting, frames 0..259 every 20,
    /// the lights-per-tile heatmap on Fig. 2(b)'s fixed 0 to 50 scale.
    ForwardPlus,
    /// Light ranges (tiled-forward-shading Fig. 4.2(a)): robots-many without its glass, every
    /// light's range scaled by 0.5 to 16, `forward`, `tiled_forward_prez` and `tiled_deferred`, frames
    /// 0..259 every 65, at 320x180 on a software adapter, the papers' tile count (5-pixel
    /// tiles there): where tiling stops paying.
    LightRange,
    /// Depth bounds (tiled-forward-shading §4.4, 22.4 → 15.6 → 10.9 ms): tiled forward
    /// without pre-Z, then tiled and clustered forward with pre-Z culling by no bounds, the
    /// minimum only, the maximum only and both, on robots-many without its glass, frames
    /// 0..259 every 20, the paper's tile count (as the paper preset).
    DepthBounds,
    /// Culling past the papers: the grids built from the depth buffer (tiled and clustered,
    /// forward and deferred) with and without 2.5D depth masks (`--depth-mask`; Harada et al.
    /// 2012) and tight cell boxes (`--cell-box`), and z-binning (`--assign zbin`, Drobot 2017;
    /// its bins are the clustered pipelines' slices, one bin on tiled ones), 16-pixel tiles,
    /// on robots-many, robots-few, scattered (without glass) and stress (10,000 lights; also
    /// 100,000 on a hardware GPU), each as it is and with every light a spot (`--spot-fraction
    /// 0,1`; robots-many's is the spots preset's scene), frames 0..259 every 20, at the papers'
    /// size (640x360 on a software adapter): lighting computations against the ideal,
    /// assignment time and grid memory per grid.
    Culling,
    /// The BRDFs (`--brdf phong,ggx`): forward, tiled and clustered forward and deferred, and
    /// the light pre-pass (its irradiance split) on robots-many without its glass, frames
    /// 0..259 every 20, at the papers' size (640x360 on a software adapter): the cost of one
    /// light evaluation in each, and the frame times side by side.
    Brdf,
    /// Shadows (tiled-shading Table 1's "Re-use shadow maps" row; forward-plus §6): robots-many
    /// without its glass, 8, 64, 256 and all 924 shadowed lights, without shadows, with ray
    /// casting and with shadow maps at one face size (64 texels, a 1 GiB budget): the
    /// light-volume pipelines re-use one light's maps (`deferred`, `light_prepass`), the
    /// others keep every map in flight in an atlas (`forward`, `tiled_deferred`,
    /// `clustered_forward`); frames 0..259 every 130 at the papers' size (640x360 on a
    /// software adapter): frame time, shadow-map memory, shadow rays.
    Shadows,
    /// The texture grid against the storage grid (tiled-forward-shading §4.2; `--grid-storage
    /// buffers,textures`), and with storage buffers CPU against GPU assignment (`--assign
    /// cpu,gather`; the texture grid is always assigned on the CPU): tiled forward with and
    /// without pre-Z on robots-many and scattered (without glass), frames 0..259 every 20, at
    /// the papers' size (640x360 on a software adapter), 16-pixel tiles: frame time, grid
    /// memory, and the grid's indices and cells (what the CPU grids upload per frame).
    GridStorage,
}

#[derive(Args)]
pub(crate) struct BenchArgs {
    /// Start from a preset; flags given explicitly override it.
    #[arg(long, value_enum)]
    pub(crate) preset: Option<Preset>,
    /// Scenes: catalog names or glTF files (repeat the flag or separate with commas).
    /// Default: robots-many.
    #[arg(long = "scene", value_delimiter = ',')]
    pub(crate) scenes: Vec<String>,
    /// `all` or a comma-separated list of pipeline ids.
    #[arg(long)]
    pub(crate) pipelines: Option<String>,
    /// Frames A..B:STEP (inclusive). Default: 0..259:5, the paper's 5 fps sampling.
    #[arg(long)]
    pub(crate) frames: Option<String>,
    /// Frame size WIDTHxHEIGHT (default: the scene's own size).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_size)]
    pub(crate) size: Option<Size>,
    /// Screen tile edge in pixels.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) tile: Option<u32>,
    /// Every setting of the library's table, each a value or a comma list to measure.
    #[command(flatten)]
    pub(crate) axes: AxisListArgs,
    /// Scatter N point lights over every scene's bounds (catalog scenes and glTF files).
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) add_lights: Option<u32>,
    /// Range of the lights --add-lights scatters (default: about 8 reach each point).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::args::parse_positive)]
    pub(crate) light_range: Option<f64>,
    /// Measurements per frame, 1 to 1000; the median is kept and the spread recorded.
    #[arg(long, allow_hyphen_values = true, value_parser = clap::value_parser!(u32).range(1..=MAX_COUNT))]
    pub(crate) repeat: Option<u32>,
    /// Discarded renders before each pipeline's series, 0 to 1000 [default: 1].
    #[arg(long, allow_hyphen_values = true, value_parser = clap::value_parser!(u32).range(0..=MAX_COUNT))]
    pub(crate) warmup: Option<u32>,
    /// Light count for scenes that take one (refused when no chosen scene does); a list
    /// measures each such scene once per count (as `<scene>-<n>-lights`).
    #[arg(long, allow_hyphen_values = true, value_delimiter = ',')]
    pub(crate) lights: Vec<u32>,
    #[arg(long, allow_hyphen_values = true, default_value_t = 1)]
    pub(crate) seed: u64,
    /// Fraction of each scene's lights (0 to 1) turned into spot lights; a list measures
    /// every scene once per fraction (as `<scene>-spots-<f>` for those above 0).
    #[arg(long, allow_hyphen_values = true, value_delimiter = ',', value_parser = parse_fraction)]
    pub(crate) spot_fraction: Vec<f64>,
    /// Give every robot two headlights (spot lights), in the scenes that have robots.
    #[arg(long)]
    pub(crate) headlights: bool,
    /// The scenes' transparent objects (robots and random scenes): on, off, or on,off to
    /// also measure each scene with glass without it (as `<scene>-opaque`) [default: on].
    #[arg(long, value_enum, value_delimiter = ',')]
    pub(crate) transparency: Vec<OnOff>,
    /// The materials' own shaders (car paint, rim); off renders every material standard.
    #[arg(long, value_enum)]
    pub(crate) material_shaders: Option<OnOff>,
    /// Frame of the lights-per-tile heatmap (default: the middle measured frame).
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) heatmap_frame: Option<u32>,
    /// The heatmap's colour scale: 0 to N lights per tile, 1 to 1000000, counts above N
    /// shown as N (default: each frame's own maximum; the forward-plus preset: 50, as
    /// Forward+ Fig. 2(b)).
    #[arg(long, allow_hyphen_values = true, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub(crate) heatmap_max: Option<u32>,
    /// Measure every scene once per factor with all its lights' ranges scaled by it
    /// (a list, e.g. 0.5,1,2,4; each above 0 and at most 1000), as `<scene>-range-x<factor>`.
    #[arg(long, allow_hyphen_values = true, value_delimiter = ',', value_parser = crate::args::parse_range_scale)]
    pub(crate) range_scale: Vec<f64>,
    /// Output directory (created; files an earlier bench run wrote there and this one does not
    /// are removed, other commands' files are kept; an existing directory lightgrid did not
    /// make must be empty; two runs into one directory at once are refused).
    #[arg(long, default_value = "bench")]
    pub(crate) out: PathBuf,
    /// Write into an existing directory that lightgrid did not make and that is not empty,
    /// and over files there that lightgrid (or another command of it) did not write.
    #[arg(long)]
    pub(crate) force: bool,
}

#[derive(Args)]
pub(crate) struct ReportArgs {
    /// The benchmark directory (reads results.json, writes the report files next to it; a
    /// report that cannot write one of them changes none).
    pub(crate) dir: PathBuf,
}

/// The light-range preset's factors: half the scene's ranges to sixteen times (robots-many's
/// 12.5 to 200, the length of its street).
const LIGHT_RANGE_SCALES: [f32; 6] = [0.5, 1.0, 2.0, 4.0, 8.0, 16.0];

/// The papers' tile edge at 1920x1080 (tiled-shading §8, tiled-forward-shading §4): 2,040
/// tiles of 32 pixels.
const PAPER_TILE: u32 = 32;

/// The tile edge that gives a frame `width` wide the papers' tile count: 32 pixels at 1920,
/// 11 at 640 (1,947 tiles at 640x360 against their 2,040), so lights per tile and culling
/// ratios compare with theirs.
pub(crate) fn paper_tile(width: u32) -> u32 {
    ((f64::from(PAPER_TILE) * f64::from(width) / 1920.0).round() as u32).max(1)
}

/// The tile edge that gives a frame `width` wide Forward+'s tile count (forward-plus §5: 8x8
/// tiles at 1280x720, 14,400 tiles): 8 pixels at 1280, 4 at 640.
fn forward_plus_tile(width: u32) -> u32 {
    (8 * width / 1280).max(1)
}

/// Forward+ Fig. 2(b)'s lights-per-tile scale (the forward-plus preset's heatmap).
const FORWARD_PLUS_HEATMAP_MAX: u32 = 50;

/// What a preset (or no preset) sets before explicit flags override it.
pub(crate) struct BenchDefaults {
    pub(crate) scenes: Vec<&'static str>,
    pub(crate) frames: &'static str,
    pub(crate) size: Option<(u32, u32)>,
    pub(crate) repeat: u32,
    pub(crate) pipelines: Vec<String>,
    /// Spot fractions, each scene measured once per fraction (unless `--spot-fraction` says).
    pub(crate) spot_fractions: Vec<f32>,
    /// The values settings of the library's table are measured at (unless their options
    /// say): `--flag` without dashes and the values.
    pub(crate) settings: Vec<(&'static str, Vec<String>)>,
    /// The scenes' transparent objects (unless `--transparency` says).
    pub(crate) transparency: bool,
    /// The paper's tile edge (unless `--tile` says; None: the renderer's default).
    pub(crate) tile: Option<u32>,
    /// Light-range factors to measure each scene with (empty: the scene's own ranges).
    pub(crate) range_scales: Vec<f32>,
    /// The lights-per-tile heatmap's fixed scale (None: each frame's own maximum).
    pub(crate) heatmap_max: Option<u32>,
    /// Each scene also without its transparent objects (unless `--transparency` says).
    pub(crate) opaque_variants: bool,
    /// Light counts of the scenes that take one (unless `--lights` says; empty: their own).
    pub(crate) lights: Vec<u32>,
}

/// Without a preset: robots-many's animation every 5 frames (the paper's 5 fps sampling) at
/// the scene's size, every pipeline, the renderer's default settings.
fn everything() -> BenchDefaults {
    BenchDefaults {
        scenes: vec!["robots-many"],
        frames: "0..259:5",
        size: None,
        repeat: 1,
        pipelines: PIPELINES.iter().map(|p| p.id.to_string()).collect(),
        spot_fractions: Vec::new(),
        settings: Vec::new(),
        transparency: true,
        tile: None,
        range_scales: Vec::new(),
        heatmap_max: None,
        opaque_variants: false,
        lights: Vec::new(),
    }
}

/// A study of one dimension over robots-many's animation (frames every 20, the papers' size
/// on a hardware GPU): the pipelines `studied` picks, with `forward` and `deferred` beside
/// them.
fn study(
    hardware: bool,
    studied: fn(&lightgrid::pipelines::PipelineInfo) -> bool,
) -> BenchDefaults {
    BenchDefaults {
        frames: "0..259:20",
        size: Some(if hardware { (1920, 1080) } else { (640, 360) }),
        repeat: if hardware { 3 } else { 1 },
        pipelines: PIPELINES
            .iter()
            .filter(|p| studied(p) || p.id == ids::FORWARD || p.id == ids::DEFERRED)
            .map(|p| p.id.to_string())
            .collect(),
        ..everything()
    }
}

/// The papers' frame size on a hardware GPU, a third of it on a software one.
fn papers_size(hardware: bool) -> (u32, u32) {
    if hardware {
        (1920, 1080)
    } else {
        (640, 360)
    }
}

/// A preset's values of the setting `T` is the type of.
fn measure<T: SettingValue>(values: &[T]) -> (&'static str, Vec<String>) {
    (
        T::FLAG,
        values.iter().map(|v| v.name().to_string()).collect(),
    )
}

/// `supported`: the MSAA sample counts the adapter offers (the msaa preset measures them all).
/// What a preset measures: the papers' figures at their conditions, or one setting studied.
fn preset_defaults(preset: Preset, hardware: bool, supported: &[u32]) -> BenchDefaults {
    match preset {
        Preset::Msaa
        | Preset::Paper
        | Preset::ForwardPlus
        | Preset::LightRange
        | Preset::DepthBounds
        | Preset::Clustered => paper_preset(preset, hardware, supported),
        _ => study_preset(preset, hardware),
    }
}

/// `--preset grid-storage` (see [`Preset::GridStorage`]).
fn grid_storage_preset(hardware: bool) -> BenchDefaults {
    BenchDefaults {
        scenes: vec!["robots-many", "scattered"],
        pipelines: [ids::TILED_FORWARD, ids::TILED_FORWARD_PREZ]
            .map(String::from)
            .to_vec(),
        settings: vec![
            measure(&[GridStorage::Buffers, GridStorage::Textures]),
            measure(&[Assign::Cpu, Assign::Gather]),
        ],
        size: Some(papers_size(hardware)),
        tile: Some(16),
        transparency: false,
        ..study(hardware, |_| false)
    }
}

/// The presets that reproduce a paper's figure at its conditions (its tile count, size and
/// scenes).
fn paper_preset(preset: Preset, hardware: bool, supported: &[u32]) -> BenchDefaults {
    match preset {
        Preset::Msaa => BenchDefaults {
            scenes: vec!["random-fps"],
            pipelines: [
                ids::TILED_FORWARD_PREZ,
                ids::CLUSTERED_FORWARD,
                ids::TILED_DEFERRED,
                ids::CLUSTERED_DEFERRED,
            ]
            .map(String::from)
            .to_vec(),
            settings: vec![
                ("msaa", supported.iter().map(u32::to_string).collect()),
                measure(&[MsaaResolve::Separate, MsaaResolve::Kernel]),
            ],
            // Fig. 4.4 measures the scene with and without its translucent blocks, with the
            // papers' tile count.
            opaque_variants: true,
            tile: Some(paper_tile(papers_size(hardware).0)),
            ..study(hardware, |_| false)
        },
        Preset::Paper => BenchDefaults {
            scenes: vec!["robots-many", "robots-few"],
            size: Some(papers_size(hardware)),
            settings: vec![measure(&[GBufferFormat::F16, GBufferFormat::F32])],
            repeat: if hardware { 3 } else { 1 },
            // The references of the mono-specular pipelines only exist to test their images.
            pipelines: PIPELINES
                .iter()
                .filter(|p| p.reference != p.id || p.id == lightgrid::pipelines::REFERENCE)
                .map(|p| p.id.to_string())
                .collect(),
            // tiled-shading §8 and tiled-forward-shading: 32x32 tiles at 1920x1080, and
            // scenes without transparent objects (the transparency preset measures the glass).
            tile: Some(paper_tile(papers_size(hardware).0)),
            transparency: false,
            ..everything()
        },
        Preset::ForwardPlus => BenchDefaults {
            scenes: vec!["scattered"],
            size: Some(if hardware { (1280, 720) } else { (640, 360) }),
            pipelines: [
                ids::TILED_FORWARD_PREZ,
                ids::TILED_LIGHT_PREPASS,
                ids::TILED_DEFERRED,
                ids::DEFERRED,
                ids::LIGHT_PREPASS,
            ]
            .map(String::from)
            .to_vec(),
            // forward-plus §5: 8x8 tiles at 1280x720 (their count: 4x4 at 640x360), Fig. 2(b)'s
            // fixed lights-per-tile scale.
            tile: Some(forward_plus_tile(if hardware { 1280 } else { 640 })),
            heatmap_max: Some(FORWARD_PLUS_HEATMAP_MAX),
            ..study(hardware, |_| false)
        },
        Preset::LightRange => BenchDefaults {
            pipelines: [ids::FORWARD, ids::TILED_FORWARD_PREZ, ids::TILED_DEFERRED]
                .map(String::from)
                .to_vec(),
            frames: "0..259:65",
            size: Some(if hardware { (1280, 720) } else { (320, 180) }),
            // Fig. 4.2(a)'s 32-px tiles at 1920x1080: their count at this size.
            tile: Some(paper_tile(if hardware { 1280 } else { 320 })),
            range_scales: LIGHT_RANGE_SCALES.to_vec(),
            transparency: false,
            ..study(hardware, |_| false)
        },
        Preset::DepthBounds => BenchDefaults {
            pipelines: [
                ids::TILED_FORWARD,
                ids::TILED_FORWARD_PREZ,
                ids::CLUSTERED_FORWARD,
            ]
            .map(String::from)
            .to_vec(),
            settings: vec![measure(&DepthBounds::ALL)],
            // tiled-forward-shading measures 32x32 tiles at 1920x1080, without glass.
            tile: Some(paper_tile(papers_size(hardware).0)),
            transparency: false,
            ..study(hardware, |_| false)
        },
        Preset::Clustered => BenchDefaults {
            scenes: vec!["random-top", "random-fps"],
            frames: "0..119:10",
            pipelines: [ids::TILED_FORWARD_PREZ, ids::CLUSTERED_FORWARD]
                .map(String::from)
                .to_vec(),
            transparency: false,
            // Fig. 4.6's 32-px tiles at 1920x1080: their count at this size.
            tile: Some(paper_tile(papers_size(hardware).0)),
            ..study(hardware, |_| false)
        },
        _ => unreachable!("not a paper's preset"),
    }
}

/// The presets that study one setting (or a quick look at everything).
fn study_preset(preset: Preset, hardware: bool) -> BenchDefaults {
    match preset {
        Preset::Quick => BenchDefaults {
            frames: "0..259:86",
            size: Some((160, 90)),
            ..everything()
        },
        Preset::Spots => BenchDefaults {
            spot_fractions: vec![1.0],
            settings: vec![measure(&[SpotCull::Sphere, SpotCull::Cone])],
            ..study(hardware, |p| p.uses_grid)
        },
        Preset::Transparency => BenchDefaults {
            settings: vec![measure(&[GridLists::Separate, GridLists::Shared])],
            ..study(hardware, |p| p.assign)
        },
        Preset::Culling => BenchDefaults {
            scenes: vec!["robots-many", "robots-few", "scattered", "stress"],
            // Each scene as it is and with every light a spot (the spots preset's scene is
            // `robots-many-spots-1`).
            spot_fractions: vec![0.0, 1.0],
            // stress at 10,000 lights, and 100,000 on a hardware GPU (on lavapipe a z-binned
            // frame of 100,000 lights takes 2 s: `--lights 10000,100000` asks for it).
            lights: if hardware {
                vec![10_000, 100_000]
            } else {
                vec![10_000]
            },
            pipelines: [
                ids::TILED_FORWARD_PREZ,
                ids::TILED_DEFERRED,
                ids::CLUSTERED_FORWARD,
                ids::CLUSTERED_DEFERRED,
            ]
            .map(String::from)
            .to_vec(),
            settings: vec![
                measure(&[Assign::Auto, Assign::ZBin]),
                measure(&DepthMask::ALL),
                measure(&CellBox::ALL),
            ],
            size: Some(papers_size(hardware)),
            tile: Some(16),
            transparency: false,
            ..study(hardware, |_| false)
        },
        Preset::GridStorage => grid_storage_preset(hardware),
        Preset::Brdf => BenchDefaults {
            pipelines: [
                ids::FORWARD,
                ids::TILED_FORWARD_PREZ,
                ids::TILED_DEFERRED,
                ids::CLUSTERED_FORWARD,
                ids::LIGHT_PREPASS,
            ]
            .map(String::from)
            .to_vec(),
            settings: vec![measure(&[Some(Brdf::Phong), Some(Brdf::Ggx)])],
            size: Some(papers_size(hardware)),
            tile: Some(16),
            transparency: false,
            ..study(hardware, |_| false)
        },
        Preset::Shadows => BenchDefaults {
            pipelines: [
                ids::FORWARD,
                ids::TILED_DEFERRED,
                ids::CLUSTERED_FORWARD,
                ids::DEFERRED,
                ids::LIGHT_PREPASS,
            ]
            .map(String::from)
            .to_vec(),
            settings: vec![
                measure(&[Shadows::Off, Shadows::Rays, Shadows::Maps]),
                (
                    "shadow-lights",
                    ["8", "64", "256", "all"].map(String::from).to_vec(),
                ),
                ("shadow-map-size", vec!["64".to_string()]),
                ("shadow-atlas", vec!["1024".to_string()]),
            ],
            frames: "0..259:130",
            size: Some(papers_size(hardware)),
            tile: Some(16),
            transparency: false,
            ..study(hardware, |_| false)
        },
        _ => unreachable!("not a study preset"),
    }
}

pub(crate) fn bench_config(
    a: &BenchArgs,
    hardware: bool,
    supported: &[u32],
) -> Result<BenchConfig> {
    let all: Vec<String> = PIPELINES.iter().map(|p| p.id.to_string()).collect();
    let d = match a.preset {
        None => everything(),
        Some(p) => preset_defaults(p, hardware, supported),
    };
    let (scenes, frames, size, repeat, pipelines) =
        (d.scenes, d.frames, d.size, d.repeat, d.pipelines);
    // The preset's settings, then the options given.
    let mut settings: Vec<AxisValues> = (d.settings.iter())
        .map(|(flag, values)| AxisValues {
            flag: flag.to_string(),
            values: values.clone(),
        })
        .collect();
    for (axis, values) in &a.axes.given {
        settings.retain(|s| s.flag != axis.flag);
        settings.push(AxisValues {
            flag: axis.flag.to_string(),
            values: values.clone(),
        });
    }
    let pipelines = match a.pipelines.as_deref() {
        None => pipelines,
        Some("all") => all,
        Some(list) => list
            .split(',')
            .map(|p| p.trim().to_string())
            .filter(|p| !p.is_empty())
            .collect(),
    };
    let transparency: Vec<&str> = (a.transparency.iter())
        .map(|t| if t.on() { "on" } else { "off" })
        .collect();
    lightgrid_bench::check_distinct("--transparency", &transparency, |&t| t)?;
    let config = BenchConfig {
        scenes: if a.scenes.is_empty() {
            scenes.iter().map(|s| s.to_string()).collect()
        } else {
            a.scenes.clone()
        },
        pipelines,
        frames: FrameRange::parse(a.frames.as_deref().unwrap_or(frames))?,
        size: a.size.map(|Size(w, h)| (w, h)).or(size),
        tile_size: a
            .tile
            .or(d.tile)
            .unwrap_or(lightgrid::consts::DEFAULT_TILE_SIZE),
        settings,
        repeat: a.repeat.unwrap_or(repeat),
        warmup: a.warmup.unwrap_or(1),
        seed: a.seed,
        lights: if a.lights.is_empty() {
            d.lights.clone()
        } else {
            a.lights.clone()
        },
        heatmap_frame: a.heatmap_frame,
        range_scales: if a.range_scale.is_empty() {
            d.range_scales.clone()
        } else {
            a.range_scale.iter().map(|&f| f as f32).collect()
        },
        heatmap_max: a.heatmap_max.or(d.heatmap_max),
        spot_fractions: match a.spot_fraction.is_empty() {
            true => d.spot_fractions.clone(),
            false => a.spot_fraction.iter().map(|&f| f as f32).collect(),
        },
        headlights: a.headlights,
        transparency: if a.transparency.is_empty() {
            d.transparency
        } else {
            a.transparency.iter().any(|t| t.on())
        },
        opaque_variants: d.opaque_variants && a.transparency.is_empty()
            || a.transparency.iter().any(|t| !t.on()) && a.transparency.iter().any(|t| t.on()),
        material_shaders: a.material_shaders.is_none_or(OnOff::on),
        add_lights: crate::args::added_lights(a.add_lights, a.light_range)?,
    };
    check_config(a, &config)?;
    Ok(config)
}

/// Refuse a configuration no run can measure: its own checks, `--msaa-resolve` without
/// MSAA, and an option given for pipelines that do not read it.
fn check_config(a: &BenchArgs, config: &BenchConfig) -> Result<()> {
    let resolve_given = a
        .axes
        .given
        .iter()
        .any(|(axis, _)| axis.flag == MsaaResolve::FLAG);
    config.validate()?;
    crate::args::check_msaa_resolve(resolve_given, &config.msaa_counts())?;
    let chosen: Vec<_> = config
        .pipelines
        .iter()
        .map(|p| lightgrid::pipelines::find(p))
        .collect::<Result<_, _>>()?;
    let given: Vec<&'static Axis> = a.axes.given.iter().map(|(axis, _)| *axis).collect();
    // The MSAA-dependent options apply at the largest sample count measured.
    let settings = lightgrid::RenderSettings {
        grid: lightgrid::CullConfig {
            samples: config.msaa_counts().into_iter().max().unwrap_or(1),
            ..lightgrid::CullConfig::default()
        },
        ..Default::default()
    };
    check_applies(&given, &chosen, &settings)
}

pub(crate) fn bench(adapter: Option<&str>, a: &BenchArgs) -> Result<()> {
    // Only whether it can be written, here: what the directory holds is checked by the claim
    // below, after the options (which a user fixes first) and before anything is rendered.
    check_out_dir(&a.out, true)?;
    let ctx = GpuContext::new(adapter)?;
    let config = bench_config(
        a,
        !ctx.is_software(),
        &lightgrid::frame::msaa_counts(&ctx, GBufferFormat::F16),
    )?;
    for n in config.msaa_counts() {
        for g in config.values_of::<GBufferFormat>() {
            lightgrid::frame::check_msaa(&ctx, n, g)?;
        }
    }
    let mut files = Files::default();
    for scene in &config.scenes {
        files.scene("--scene", scene)?;
    }
    let prepared = lightgrid_bench::prepare(&config)?;
    let dir = OutDir::claim(&a.out, "bench", a.force)?;
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
    let mut results = prepared.run(&ctx, &stop, &mut progress)?;
    eprintln!();
    results.command = std::env::args().collect::<Vec<_>>().join(" ");
    let written = lightgrid_bench::write_report(dir.staging(), &results)?;
    files.placed("--out", &a.out, &written)?;
    let complete = results.outcome.is_complete();
    let committed = dir.commit(&written, lightgrid_bench::Earlier::Remove, complete)?;
    let claims = lightgrid_bench::evaluate_claims(&results);
    let held = claims
        .iter()
        .filter(|c| c.verdict == lightgrid_bench::Verdict::Held)
        .count();
    let measured = claims
        .iter()
        .filter(|c| c.verdict != lightgrid_bench::Verdict::NotMeasured)
        .count();
    let place = committed.set_aside.as_deref().unwrap_or(&a.out);
    outln!(
        "{} runs in {}; {held} of {measured} measured claims held; {} files in {} (start with summary.md)",
        results.runs.len(),
        format_duration(start.elapsed().as_secs_f64()),
        written.len(),
        place.display()
    );
    run_outcome(&results.outcome, &a.out, &committed)
}

pub(crate) fn report(a: &ReportArgs) -> Result<()> {
    let results_json = a.dir.join("results.json");
    let results = lightgrid_bench::read_results(&results_json)?;
    // The bench's files are the report's: the derived ones are rewritten under the bench's
    // manifest; results.json (which the report only reads), the heatmaps and anything else
    // the run wrote are kept. Written aside first and checked before anything moves, so a
    // report that fails changes nothing.
    let dir = OutDir::claim(&a.dir, "bench", false)?;
    let written = lightgrid_bench::write_derived(dir.staging(), &results)?;
    let mut files = Files::default();
    files.input("DIR/results.json", &results_json)?;
    files.placed("DIR", &a.dir, &written)?;
    let committed = dir.commit(&written, lightgrid_bench::Earlier::Keep, true)?;
    outln!(
        "{} files rewritten in {} (results.json, read, and the heatmaps are kept from the run)",
        committed.placed.len(),
        a.dir.display()
    );
    Ok(())
}
