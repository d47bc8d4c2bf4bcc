//! The render settings that only some pipelines read, one row each ([`AXES`]): the option,
//! its values, which pipelines it applies to (from their capabilities in [`PIPELINES`]), and
//! how to read and set it on a [`RenderSettings`]. Every place that asks "does this option
//! apply" asks the row: the CLI's refusal of an option given for pipelines that ignore it and
//! its `--help`, and the benchmark's product of variants (a setting that changes nothing for
//! a pipeline is measured once).
//!
//! [`PIPELINES`]: super::PIPELINES

use super::PipelineInfo;
use crate::frame::CullConfig;
use crate::frame::{
    Assign, Brdf, CellBox, DepthBounds, DepthMask, DepthReduction, GBufferFormat, GridLists,
    GridStorage, LightLoop, MaterialDraws, MsaaResolve, RenderSettings, Shadows, SpotCull,
};

/// A setting's values by name (the option's values, the results' columns).
pub trait SettingValue: Copy + PartialEq + Sized + 'static {
    /// The option (its row in [`AXES`], without dashes).
    const FLAG: &'static str;
    /// Every value the option accepts, the default first.
    const VALUES: &'static [Self];
    /// The value's name: what the option takes on the command line and results show.
    fn name(self) -> &'static str;
    /// One line for `--help`.
    fn help(self) -> &'static str;

    /// The value called `name`, or the accepted names.
    fn parse(name: &str) -> Result<Self, String> {
        Self::VALUES
            .iter()
            .copied()
            .find(|v| v.name() == name)
            .ok_or_else(|| {
                let names: Vec<&str> = Self::VALUES.iter().map(|v| v.name()).collect();
                format!("'{name}' is not one of {}", names.join(", "))
            })
    }
}

impl SettingValue for Assign {
    const FLAG: &'static str = "assign";
    const VALUES: &'static [Self] = &crate::culling::ASSIGN_VALUES;
    fn name(self) -> &'static str {
        Assign::name(self)
    }
    fn help(self) -> &'static str {
        self.description()
    }
}

impl SettingValue for SpotCull {
    const FLAG: &'static str = "spot-cull";
    const VALUES: &'static [Self] = &[SpotCull::Cone, SpotCull::Sphere];
    fn name(self) -> &'static str {
        match self {
            SpotCull::Sphere => "sphere",
            SpotCull::Cone => "cone",
        }
    }
    fn help(self) -> &'static str {
        match self {
            SpotCull::Sphere => "the tightest sphere around each spot's cone",
            SpotCull::Cone => "the sphere, then the cone against each cell's bounding sphere (never misses a lit sample, and tighter)",
        }
    }
}

impl SettingValue for GridLists {
    const FLAG: &'static str = "lists";
    // `Opaque` is what a frame without transparent objects builds, not an option.
    const VALUES: &'static [Self] = &[GridLists::Separate, GridLists::Shared];
    fn name(self) -> &'static str {
        GridLists::name(self)
    }
    fn help(self) -> &'static str {
        match self {
            GridLists::Separate => "an opaque list pruned by the cell's depth bounds and a transparent list over near..opaque max (tiled-forward-shading §4.5)",
            GridLists::Shared => "one list over near..opaque max for both",
            GridLists::Opaque => "opaque lists only (frames without transparent objects)",
        }
    }
}

impl SettingValue for MaterialDraws {
    const FLAG: &'static str = "material-draws";
    const VALUES: &'static [Self] = &[MaterialDraws::PerMaterial, MaterialDraws::Uber];
    fn name(self) -> &'static str {
        MaterialDraws::name(self)
    }
    fn help(self) -> &'static str {
        match self {
            MaterialDraws::PerMaterial => {
                "a pipeline per material shader, switched between runs of geometry"
            }
            MaterialDraws::Uber => {
                "one pipeline branching on the material, as deferred shading does"
            }
        }
    }
}

impl SettingValue for MsaaResolve {
    const FLAG: &'static str = "msaa-resolve";
    const VALUES: &'static [Self] = &[MsaaResolve::Separate, MsaaResolve::Kernel];
    fn name(self) -> &'static str {
        MsaaResolve::name(self)
    }
    fn help(self) -> &'static str {
        match self {
            MsaaResolve::Separate => "per-sample colours, then the tonemap",
            MsaaResolve::Kernel => "inside the shading kernel (tiled-deferred-tricks Trick 1; frames with transparent objects resolve separately)",
        }
    }
}

impl SettingValue for DepthBounds {
    const FLAG: &'static str = "depth-bounds";
    const VALUES: &'static [Self] = &DepthBounds::ALL;
    fn name(self) -> &'static str {
        DepthBounds::name(self)
    }
    fn help(self) -> &'static str {
        match self {
            DepthBounds::Both => "the cell's samples' [min, max]",
            DepthBounds::Min => "far side open: [min, slice far]",
            DepthBounds::Max => "near side open: [slice near, max]",
            DepthBounds::None => "every cell spans its slice",
        }
    }
}

impl SettingValue for DepthMask {
    const FLAG: &'static str = "depth-mask";
    const VALUES: &'static [Self] = &DepthMask::ALL;
    fn name(self) -> &'static str {
        DepthMask::name(self)
    }
    fn help(self) -> &'static str {
        match self {
            DepthMask::Off => "the cell's depth bounds only",
            DepthMask::On => "2.5D culling: a 32-bit mask of the bounds' bins that hold samples (Harada et al. 2012)",
        }
    }
}

impl SettingValue for LightLoop {
    const FLAG: &'static str = "light-loop";
    const VALUES: &'static [Self] = &LightLoop::ALL;
    fn name(self) -> &'static str {
        LightLoop::name(self)
    }
    fn help(self) -> &'static str {
        match self {
            LightLoop::Lane => "each lane walks its own cell's lights",
            LightLoop::Subgroup => "the subgroup takes its lanes' lights one at a time for all of them (needs subgroups)",
        }
    }
}

impl SettingValue for GridStorage {
    const FLAG: &'static str = "grid-storage";
    const VALUES: &'static [Self] = &GridStorage::ALL;
    fn name(self) -> &'static str {
        GridStorage::name(self)
    }
    fn help(self) -> &'static str {
        match self {
            GridStorage::Auto => "textures where the adapter cannot run the compute grid (no compute or fragment storage buffers, or GL), else buffers",
            GridStorage::Buffers => "storage buffers built by the --assign strategy",
            GridStorage::Textures => "textures read with textureLoad, assigned on the CPU, no compute pass (tiled-forward-shading 4.2)",
        }
    }
}

impl SettingValue for CellBox {
    const FLAG: &'static str = "cell-box";
    const VALUES: &'static [Self] = &CellBox::ALL;
    fn name(self) -> &'static str {
        CellBox::name(self)
    }
    fn help(self) -> &'static str {
        match self {
            CellBox::Off => "the cell's frustum piece only",
            CellBox::On => "tight cells: the view-space box of the cell's samples, tested against each light's sphere exactly",
        }
    }
}

impl SettingValue for DepthReduction {
    const FLAG: &'static str = "depth-reduction";
    const VALUES: &'static [Self] = &DepthReduction::ALL;
    fn name(self) -> &'static str {
        DepthReduction::name(self)
    }
    fn help(self) -> &'static str {
        match self {
            DepthReduction::Atomics => "every sample into workgroup memory with atomics",
            DepthReduction::Subgroup => {
                "registers, then one subgroup min/max (adapters with subgroups; tiled-shading §8)"
            }
        }
    }
}

/// `--brdf`: `auto` (`None`) renders each scene with the BRDF its materials were made for.
impl SettingValue for Option<Brdf> {
    const FLAG: &'static str = "brdf";
    const VALUES: &'static [Self] = &[None, Some(Brdf::Phong), Some(Brdf::Ggx)];
    fn name(self) -> &'static str {
        self.map_or("auto", Brdf::name)
    }
    fn help(self) -> &'static str {
        match self {
            None => "the scene's own: phong for the catalog's scenes (the papers' model), ggx for glTF files",
            Some(Brdf::Phong) => "Blinn-Phong, as the papers shade",
            Some(Brdf::Ggx) => "glTF's metallic-roughness BRDF: GGX, Smith height-correlated visibility, Schlick Fresnel, Lambert diffuse",
        }
    }
}

impl SettingValue for Shadows {
    const FLAG: &'static str = "shadows";
    const VALUES: &'static [Self] = &Shadows::ALL;
    fn name(self) -> &'static str {
        Shadows::name(self)
    }
    fn help(self) -> &'static str {
        match self {
            Shadows::Off => "no shadows: every light reaches everything in its range",
            Shadows::Rays => "one ray from each lit sample to each shadow-casting light through a BVH over the opaque triangles (Forward+ §6)",
            Shadows::Maps => "shadow maps (a cube per point light, a face per spot) in one atlas of --shadow-atlas MiB, 2x2 PCF",
        }
    }
}

impl SettingValue for GBufferFormat {
    const FLAG: &'static str = "gbuffer";
    const VALUES: &'static [Self] = &[GBufferFormat::F16, GBufferFormat::F32];
    fn name(self) -> &'static str {
        match self {
            GBufferFormat::F16 => "16",
            GBufferFormat::F32 => "32",
        }
    }
    fn help(self) -> &'static str {
        match self {
            GBufferFormat::F16 => "16-bit float channels",
            GBufferFormat::F32 => "32-bit float channels",
        }
    }
}

/// A named value of an axis, for `--help`.
#[derive(Clone, Copy, Debug)]
pub struct AxisValue {
    /// The value as the option takes it ([`SettingValue::name`]).
    pub name: &'static str,
    /// One line describing it ([`SettingValue::help`]).
    pub help: &'static str,
}

/// One setting that only some pipelines read.
pub struct Axis {
    /// The option, without its dashes (`spot-cull`).
    pub flag: &'static str,
    /// The results column and key (`spot_cull`).
    pub column: &'static str,
    /// What the option sets (`--help`), and which pipelines read it.
    pub help: &'static str,
    /// Every value by name, the default first; empty for a number ([`Axis::set`] checks it).
    pub values: fn() -> Vec<AxisValue>,
    /// Does `pipeline`, rendering with `settings`, read this setting?
    pub applies: fn(&PipelineInfo, &RenderSettings) -> bool,
    /// The setting's value in `settings`, by name.
    pub get: fn(&RenderSettings) -> String,
    /// Set the value called `value` (an error names the accepted values).
    pub set: fn(&mut RenderSettings, &str) -> Result<(), String>,
    /// How a series measured at `value` is named in reports (`[bounds min]`).
    pub label: fn(&str) -> String,
}

impl Axis {
    /// `--flag`.
    pub fn option(&self) -> String {
        format!("--{}", self.flag)
    }

    /// The pipelines this applies to with `settings`, by id.
    pub fn takers(&self, settings: &RenderSettings) -> Vec<&'static str> {
        super::PIPELINES
            .iter()
            .filter(|p| (self.applies)(p, settings))
            .map(|p| p.id)
            .collect()
    }
}

/// Is `p`'s grid in storage buffers, built by a `LightCuller` (what the grid's options are
/// about)? Not where `--grid-storage textures` puts a texture-grid pipeline's in textures,
/// assigned on the CPU (`culling/texture_grid.rs`).
fn buffer_grid(p: &PipelineInfo, s: &RenderSettings) -> bool {
    !(p.texture_grid && s.grid_storage == GridStorage::Textures)
}

fn values<T: SettingValue>() -> Vec<AxisValue> {
    T::VALUES
        .iter()
        .map(|v| AxisValue {
            name: v.name(),
            help: v.help(),
        })
        .collect()
}

fn number(value: &str) -> Result<u32, String> {
    value
        .trim()
        .parse()
        .map_err(|_| format!("'{value}' is not a whole number from 0 to {}", u32::MAX))
}

/// The tiled grids whose cell bounds the depth buffer gives: the cell-bounds kernel reduces
/// a tiled grid's samples in subgroups; a clustered grid's samples go to different slices,
/// so its cells reduce with atomics either way (`cell_bounds.wgsl`: `SUBGROUP_REDUCTION &&
/// grid.slices == 1u`).
fn reduces_tile_depth(p: &PipelineInfo) -> bool {
    p.depth_bounds && !p.clustered
}

/// The table: every setting only some pipelines read.
pub const AXES: &[Axis] = &[
    Axis {
        flag: "slices",
        column: "slices",
        help: "view-depth slices of clustered pipelines (exponential spacing, 1 to 256)",
        values: Vec::new,
        applies: |p, _| p.clustered,
        get: |s| s.grid.slices.to_string(),
        set: |s, v| {
            s.grid.slices = number(v)?;
            crate::frame::validate_slices(s.grid.slices).map_err(|e| e.to_string())
        },
        label: |v| format!("{v} slices"),
    },
    Axis {
        flag: "gbuffer",
        column: "gbuffer",
        help: "G-buffer channel precision in bits of deferred pipelines",
        values: values::<GBufferFormat>,
        applies: |p, _| p.uses_gbuffer(),
        get: |s| s.gbuffer.name().to_string(),
        set: |s, v| {
            s.gbuffer = GBufferFormat::parse(v)?;
            Ok(())
        },
        label: |v| format!("g{v}"),
    },
    Axis {
        flag: "grid-storage",
        column: "grid_storage",
        help: "where tiled forward keeps its light grid: storage buffers from a LightCuller, or textures built on the CPU that need no compute shaders or storage buffers (WebGL2, GL)",
        values: values::<GridStorage>,
        applies: |p, _| p.texture_grid,
        get: |s| s.grid_storage.name().to_string(),
        set: |s, v| {
            s.grid_storage = GridStorage::parse(v)?;
            Ok(())
        },
        label: |v| format!("{v} grid"),
    },
    Axis {
        flag: "assign",
        column: "assign",
        help: "who builds the light grid of grid pipelines (not tiled_deferred_single, which culls inside its kernel)",
        values: values::<Assign>,
        applies: |p, s| p.assign && buffer_grid(p, s),
        get: |s| s.grid.strategy.name().to_string(),
        set: |s, v| {
            s.grid.strategy = Assign::parse(v)?;
            Ok(())
        },
        label: |v| v.to_string(),
    },
    Axis {
        flag: "index-capacity",
        column: "index_capacity",
        help: "index entries the light lists of --assign grids start with (1 to 33554432; they grow from the frames' counters, a frame whose lists did not fit is counted)",
        values: Vec::new,
        applies: |p, s| p.assign && buffer_grid(p, s),
        get: |s| s.grid.index_capacity.to_string(),
        set: |s, v| {
            s.grid.index_capacity = number(v)?;
            s.grid.validate().map_err(|e| e.to_string())
        },
        label: |v| format!("{v} entries"),
    },
    Axis {
        flag: "spot-cull",
        column: "spot_cull",
        help: "what grid pipelines cull spot lights by",
        values: values::<SpotCull>,
        applies: |p, _| p.uses_grid,
        get: |s| s.grid.spot_cull.name().to_string(),
        set: |s, v| {
            s.grid.spot_cull = SpotCull::parse(v)?;
            Ok(())
        },
        label: |v| v.to_string(),
    },
    Axis {
        flag: "lists",
        column: "lists",
        help: "the light lists of grid pipelines with an --assign grid, for frames with transparent objects",
        values: values::<GridLists>,
        applies: |p, s| p.assign && buffer_grid(p, s),
        get: |s| SettingValue::name(s.grid.lists).to_string(),
        set: |s, v| {
            s.grid.lists = GridLists::parse(v)?;
            Ok(())
        },
        label: |v| format!("{v} lists"),
    },
    Axis {
        flag: "material-draws",
        column: "material_draws",
        help: "how forward-shading pipelines draw the material shaders",
        values: values::<MaterialDraws>,
        applies: |p, _| p.forward_shading,
        get: |s| s.material_draws.name().to_string(),
        set: |s, v| {
            s.material_draws = MaterialDraws::parse(v)?;
            Ok(())
        },
        label: |v| format!("{v} draws"),
    },
    Axis {
        flag: "msaa",
        column: "msaa",
        help: "MSAA samples per pixel: 1 (off) or a count the adapter supports for every target (lavapipe: 4; real GPUs also 2 and 8)",
        values: Vec::new,
        applies: |p, _| p.msaa == super::Msaa::Supported,
        get: |s| s.grid.samples.to_string(),
        set: |s, v| {
            s.grid.samples = number(v)?;
            crate::frame::validate_msaa(s.grid.samples).map_err(|e| e.to_string())
        },
        label: |v| format!("{v}x msaa"),
    },
    Axis {
        flag: "msaa-resolve",
        column: "msaa_resolve",
        help: "where tiled and clustered deferred and tiled_deferred_single resolve MSAA (with --msaa above 1)",
        values: values::<MsaaResolve>,
        applies: |p, s| p.kernel_resolve && s.grid.samples > 1,
        get: |s| s.msaa_resolve.name().to_string(),
        set: |s, v| {
            s.msaa_resolve = MsaaResolve::parse(v)?;
            Ok(())
        },
        label: |v| format!("{v} resolve"),
    },
    Axis {
        flag: "depth-bounds",
        column: "depth_bounds",
        help: "which cell depth bounds grids built from the depth buffer cull lights by (tiled-forward-shading §4.4)",
        values: values::<DepthBounds>,
        applies: |p, _| p.depth_bounds,
        get: |s| s.grid.depth_bounds.name().to_string(),
        set: |s, v| {
            s.grid.depth_bounds = DepthBounds::parse(v)?;
            Ok(())
        },
        label: |v| format!("bounds {v}"),
    },
    Axis {
        flag: "depth-reduction",
        column: "depth_reduction",
        help: "how the cell-bounds kernel of tiled grids built from depth reduces a tile's samples (clustered grids always use atomics)",
        values: values::<DepthReduction>,
        applies: |p, s| reduces_tile_depth(p) && buffer_grid(p, s),
        get: |s| s.grid.depth_reduction.name().to_string(),
        set: |s, v| {
            s.grid.depth_reduction = DepthReduction::parse(v)?;
            Ok(())
        },
        label: |v| format!("{v} reduction"),
    },
    Axis {
        flag: "depth-mask",
        column: "depth_mask",
        help: "2.5D culling of the grids --assign builds from the depth buffer (needs --depth-bounds both)",
        values: values::<DepthMask>,
        applies: |p, s| p.depth_bounds && p.assign && s.grid.strategy != Assign::ZBin && buffer_grid(p, s),
        get: |s| s.grid.depth_mask.name().to_string(),
        set: |s, v| {
            s.grid.depth_mask = DepthMask::parse(v)?;
            Ok(())
        },
        label: |v| format!("mask {v}"),
    },
    Axis {
        flag: "cell-box",
        column: "cell_box",
        help: "tight cells of the grids --assign builds from the depth buffer: each cell's samples' view-space box (needs --depth-bounds both)",
        values: values::<CellBox>,
        applies: |p, s| p.depth_bounds && p.assign && s.grid.strategy != Assign::ZBin && buffer_grid(p, s),
        get: |s| s.grid.cell_box.name().to_string(),
        set: |s, v| {
            s.grid.cell_box = CellBox::parse(v)?;
            Ok(())
        },
        label: |v| format!("box {v}"),
    },
    Axis {
        flag: "light-loop",
        column: "light_loop",
        help: "the light loop of the pipelines that shade from a LightCuller grid: per lane, or scalarized over the subgroup (one light at a time for all lanes; adapters with subgroups)",
        values: values::<LightLoop>,
        applies: |p, s| p.assign && buffer_grid(p, s),
        get: |s| s.light_loop.name().to_string(),
        set: |s, v| {
            s.light_loop = LightLoop::parse(v)?;
            Ok(())
        },
        label: |v| format!("{v} loop"),
    },
    Axis {
        flag: "brdf",
        column: "brdf",
        help: "the BRDF of the one light function, in every pipeline",
        values: values::<Option<Brdf>>,
        applies: |_, _| true,
        get: |s| SettingValue::name(s.brdf).to_string(),
        set: |s, v| {
            s.brdf = <Option<Brdf>>::parse(v)?;
            Ok(())
        },
        label: |v| v.to_string(),
    },
    Axis {
        flag: "shadows",
        column: "shadows",
        help: "how lights cast shadows, in every pipeline",
        values: values::<Shadows>,
        applies: |_, _| true,
        get: |s| s.shadows.name().to_string(),
        set: |s, v| {
            s.shadows = Shadows::parse(v)?;
            Ok(())
        },
        label: |v| format!("shadows {v}"),
    },
    Axis {
        flag: "shadow-lights",
        column: "shadow_lights",
        help: "how many lights cast shadows with --shadows rays or maps: the most important this frame (brightness × screen coverage), 1 to 1048576, or all",
        values: Vec::new,
        applies: |_, s| s.shadows != Shadows::Off,
        get: |s| s.shadow_lights.map_or("all".to_string(), |n| n.to_string()),
        set: |s, v| {
            s.shadow_lights = if v == "all" { None } else { Some(number(v)?) };
            crate::frame::validate_shadow_lights(s.shadow_lights).map_err(|e| e.to_string())
        },
        label: |v| format!("{v} shadowed"),
    },
    Axis {
        flag: "shadow-atlas",
        column: "shadow_atlas",
        help: "the shadow atlas's budget in MiB with --shadows maps (1 to 4096): every shadowed light's maps share it, more lights getting smaller maps",
        values: Vec::new,
        applies: |_, s| s.shadows == Shadows::Maps,
        get: |s| s.shadow_atlas.to_string(),
        set: |s, v| {
            s.shadow_atlas = number(v)?;
            crate::frame::validate_shadow_atlas(s.shadow_atlas).map_err(|e| e.to_string())
        },
        label: |v| format!("{v} MiB atlas"),
    },
    Axis {
        flag: "shadow-map-size",
        column: "shadow_map_size",
        help: "the largest shadow-map face in texels with --shadows maps (a power of two, 16 to 1024); faces get smaller when the atlas cannot hold them at this size",
        values: Vec::new,
        applies: |_, s| s.shadows == Shadows::Maps,
        get: |s| s.shadow_map_size.to_string(),
        set: |s, v| {
            s.shadow_map_size = number(v)?;
            crate::frame::validate_shadow_map_size(s.shadow_map_size).map_err(|e| e.to_string())
        },
        label: |v| format!("{v}px maps"),
    },
];

/// The value of the setting `T` is the type of, in `settings`.
pub fn value_of<T: SettingValue>(settings: &RenderSettings) -> T {
    let axis = find_axis(T::FLAG).expect("every setting type has a row");
    T::parse(&(axis.get)(settings)).expect("the row reads its own values")
}

/// The row of `--flag` (without dashes).
pub fn find_axis(flag: &str) -> Option<&'static Axis> {
    AXES.iter().find(|a| a.flag == flag)
}

/// The first option given (by flag) that applies to none of `chosen` with `settings`, as an
/// error naming who it applies to.
pub fn check_axes_apply(
    given: &[&'static Axis],
    chosen: &[&'static PipelineInfo],
    settings: &RenderSettings,
) -> Result<(), String> {
    for axis in given {
        if chosen.iter().any(|p| (axis.applies)(p, settings)) {
            continue;
        }
        let ids: Vec<&str> = chosen.iter().map(|p| p.id).collect();
        let takers = axis.takers(settings);
        let takers = if takers.is_empty() {
            // A setting read only when another is on (`--msaa-resolve` with MSAA,
            // `--shadow-lights` with shadows): name the other.
            let enabling = [
                (
                    "--msaa 4",
                    RenderSettings {
                        grid: CullConfig {
                            samples: 4,
                            ..settings.grid
                        },
                        ..*settings
                    },
                ),
                (
                    "--shadows rays",
                    RenderSettings {
                        shadows: Shadows::Rays,
                        ..*settings
                    },
                ),
                (
                    "--shadows maps",
                    RenderSettings {
                        shadows: Shadows::Maps,
                        ..*settings
                    },
                ),
            ];
            enabling
                .iter()
                .find_map(|(flag, with)| {
                    let t = axis.takers(with);
                    (!t.is_empty())
                        .then(|| format!("none without {flag} (with it: {})", t.join(", ")))
                })
                .unwrap_or_else(|| "none with these settings".to_string())
        } else {
            takers.join(", ")
        };
        return Err(format!(
            "{} does not apply to {}; it applies to: {takers}",
            axis.option(),
            ids.join(", ")
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipelines::PIPELINES;

    /// Every named value round-trips; the default settings hold each axis's first value.
    #[test]
    fn every_value_sets_and_reads_back() {
        for axis in AXES {
            let all = (axis.values)();
            for v in &all {
                let mut s = RenderSettings::default();
                (axis.set)(&mut s, v.name).unwrap();
                assert_eq!((axis.get)(&s), v.name, "{}", axis.flag);
            }
            if let Some(first) = all.first() {
                assert_eq!(
                    (axis.get)(&RenderSettings::default()),
                    first.name,
                    "{}",
                    axis.flag
                );
            }
            let mut s = RenderSettings::default();
            assert!(
                (axis.set)(&mut s, "no-such-value").is_err(),
                "{}",
                axis.flag
            );
        }
    }

    /// Each value type names its own row, whose values are the type's.
    #[test]
    fn every_value_type_names_its_row() {
        fn check<T: SettingValue>() {
            let axis = find_axis(T::FLAG).unwrap();
            let names: Vec<&str> = (axis.values)().iter().map(|v| v.name).collect();
            let own: Vec<&str> = T::VALUES.iter().map(|v| v.name()).collect();
            assert_eq!(names, own, "{}", T::FLAG);
        }
        check::<Assign>();
        check::<SpotCull>();
        check::<GridLists>();
        check::<MaterialDraws>();
        check::<MsaaResolve>();
        check::<DepthBounds>();
        check::<DepthReduction>();
        check::<DepthMask>();
        check::<GBufferFormat>();
    }

    #[test]
    fn flags_and_columns_are_unique() {
        for (i, a) in AXES.iter().enumerate() {
            for b in &AXES[i + 1..] {
                assert_ne!(a.flag, b.flag);
                assert_ne!(a.column, b.column);
            }
        }
    }

    /// The two rules the old hand-written checks had wrong: the subgroup depth reduction is
    /// a tiled grid's, and only the deferred kernels resolve MSAA.
    #[test]
    fn depth_reduction_and_msaa_resolve_apply_exactly_where_read() {
        let find = |id| PIPELINES.iter().find(|p| p.id == id).unwrap();
        let reduction = find_axis("depth-reduction").unwrap();
        let s = RenderSettings::default();
        assert!((reduction.applies)(find("tiled_deferred"), &s));
        assert!((reduction.applies)(find("tiled_forward_prez"), &s));
        assert!(!(reduction.applies)(find("clustered_forward"), &s));
        assert!(!(reduction.applies)(find("clustered_deferred"), &s));
        let resolve = find_axis("msaa-resolve").unwrap();
        let msaa = RenderSettings {
            grid: CullConfig {
                samples: 4,
                ..s.grid
            },
            ..s
        };
        let takers = resolve.takers(&msaa);
        assert_eq!(
            takers,
            [
                "tiled_deferred",
                "tiled_deferred_single",
                "clustered_deferred"
            ]
        );
        assert!(resolve.takers(&s).is_empty(), "no resolve without MSAA");
        let e = check_axes_apply(&[reduction], &[find("clustered_forward")], &s).unwrap_err();
        assert!(
            e.contains("--depth-reduction does not apply to clustered_forward"),
            "{e}"
        );
        assert!(e.contains("tiled_deferred"), "{e}");
    }
}
