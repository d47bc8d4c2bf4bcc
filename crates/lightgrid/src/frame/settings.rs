//! The settings every pipeline of a renderer shares (`--tile`, `--gbuffer`, `--slices`,
//! `--assign`): plain values, below everything that reads them.

/// Settings every pipeline of a renderer shares: the light grid's description
/// ([`CullConfig`], its fields flattened into the same records) and the rest.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct RenderSettings {
    /// The light grid every grid pipeline builds, and the frame's MSAA samples
    /// (`--tile`, `--slices`, `--assign`, `--spot-cull`, `--lists`, `--msaa`,
    /// `--depth-bounds`, `--depth-reduction`, `--depth-mask`, `--cell-box`).
    #[serde(flatten)]
    pub grid: CullConfig,
    /// G-buffer channel precision (`--gbuffer 16|32`).
    pub gbuffer: GBufferFormat,
    /// How forward pipelines draw the material shaders (`--material-draws`).
    pub material_draws: MaterialDraws,
    /// Where the MSAA deferred kernels resolve (`--msaa-resolve`).
    pub msaa_resolve: MsaaResolve,
    /// The light loop of grid pipelines (`--light-loop`).
    #[serde(default)]
    pub light_loop: LightLoop,
    /// Where tiled forward keeps its grid (`--grid-storage`): storage buffers built by a
    /// `LightCuller`, or textures built on the CPU (no compute; `culling/texture_grid.rs`).
    #[serde(default)]
    pub grid_storage: GridStorage,
    /// The light function's BRDF (`--brdf`); `None` (`auto`): the scene's own
    /// (`scene::Lighting::brdf`: Blinn-Phong for the catalog, GGX for glTF files).
    #[serde(default)]
    pub brdf: Option<Brdf>,
    /// How lights cast shadows (`--shadows`), in every pipeline.
    #[serde(default)]
    pub shadows: Shadows,
    /// How many lights cast shadows (`--shadow-lights`): the most important this frame
    /// (`crate::shadows`); `None`: every light.
    #[serde(default)]
    pub shadow_lights: Option<u32>,
    /// The shadow atlas's budget in MiB (`--shadow-atlas`, `--shadows maps`).
    #[serde(default = "default_shadow_atlas")]
    pub shadow_atlas: u32,
    /// The largest shadow-map face in texels (`--shadow-map-size`, `--shadows maps`).
    #[serde(default = "default_shadow_map_size")]
    pub shadow_map_size: u32,
}

/// **The light grid's description**: every grid lightgrid builds is made from one, its own
/// renderer's ([`RenderSettings::grid`]) and any other renderer's
/// [`LightCuller`](crate::LightCuller).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct CullConfig {
    /// Screen tile edge in pixels, 4 to 64 (`--tile`).
    pub tile_size: u32,
    /// View-depth slices per tile: 1 builds tiles (tiled shading), 2 to 256 clusters spread
    /// exponentially over the frame's samples' depth range (clustered shading). `--slices`;
    /// lightgrid's tiled pipelines build their grids with 1.
    pub slices: u32,
    /// Who assigns lights to cells (`--assign`; a row of `culling::STRATEGIES`, or `Auto`).
    #[serde(rename = "assign")]
    pub strategy: Assign,
    /// What spot lights are culled by (`--spot-cull`), in every strategy.
    pub spot_cull: SpotCull,
    /// Lists for frames with transparent surfaces (`--lists`): separate opaque and
    /// transparent lists, or one shared list; a frame without any builds opaque lists only.
    pub lists: GridLists,
    /// Samples per pixel of the depth the grid is built over (`--msaa`: every target of a
    /// lightgrid frame): 1, or an MSAA count. With MSAA the bounds cover every sample.
    #[serde(rename = "msaa")]
    pub samples: u32,
    /// Which side of each cell's depth range culls lights (`--depth-bounds`;
    /// [`DepthBounds::Both`]: a light must reach between the cell's nearest and farthest
    /// sample).
    pub depth_bounds: DepthBounds,
    /// How the cell-bounds kernel reduces a tile's depths (`--depth-reduction`).
    pub depth_reduction: DepthReduction,
    /// 2.5D culling (`--depth-mask on`): each cell also keeps a mask of which of 32 bins of
    /// its depth bounds hold samples; needs [`DepthBounds::Both`].
    #[serde(default)]
    pub depth_mask: DepthMask,
    /// Tight cells (`--cell-box on`): each occupied cell also keeps the view-space box of its
    /// samples, and lights are kept by the closest-point test against it; needs
    /// [`DepthBounds::Both`].
    #[serde(default)]
    pub cell_box: CellBox,
    /// The most lights one frame may have; more is an error. Not a setting of the records.
    #[serde(skip, default = "default_max_lights")]
    pub max_lights: u32,
    /// Index entries the lists start with, 1 to `MAX_INDEX_CAPACITY` (`--index-capacity`);
    /// they grow from the frames' counters, so a frame whose lists did not fit is counted
    /// and the next ones fit. A scene known to need long lists starts with them.
    #[serde(default = "default_index_capacity")]
    pub index_capacity: u32,
}

fn default_max_lights() -> u32 {
    crate::consts::MAX_LIGHTS
}

fn default_index_capacity() -> u32 {
    crate::consts::INITIAL_INDEX_CAPACITY
}

impl Default for CullConfig {
    /// 16-pixel tiles cut into 32 slices, `auto` assignment, both depth bounds, separate
    /// transparent lists, no MSAA, up to `MAX_LIGHTS` lights.
    fn default() -> Self {
        CullConfig {
            tile_size: crate::consts::DEFAULT_TILE_SIZE,
            slices: crate::consts::DEFAULT_SLICES,
            strategy: Assign::default(),
            spot_cull: SpotCull::default(),
            lists: GridLists::Separate,
            samples: 1,
            depth_bounds: DepthBounds::Both,
            depth_reduction: DepthReduction::Atomics,
            depth_mask: DepthMask::Off,
            cell_box: CellBox::Off,
            max_lights: default_max_lights(),
            index_capacity: default_index_capacity(),
        }
    }
}

impl CullConfig {
    /// Refuse a description no grid can be built from, naming the setting and the accepted
    /// range.
    pub fn validate(&self) -> crate::error::Result<()> {
        validate_tile_size(self.tile_size)?;
        validate_slices(self.slices)?;
        validate_msaa(self.samples)?;
        validate_sample_culling(self.depth_mask, self.cell_box, self.depth_bounds)?;
        validate_zbin_culling(self.strategy, self.depth_mask, self.cell_box)?;
        if self.max_lights == 0 {
            return Err(crate::error::Error::invalid(
                "max_lights",
                "must be at least 1",
            ));
        }
        validate_index_capacity(self.index_capacity)?;
        Ok(())
    }

    /// The same grid as tiles (one slice).
    pub fn tiled(self) -> Self {
        CullConfig { slices: 1, ..self }
    }
}

fn default_shadow_map_size() -> u32 {
    crate::shadows::maps::MAX_TILE
}

fn default_shadow_atlas() -> u32 {
    crate::consts::DEFAULT_SHADOW_ATLAS_MIB
}

/// How grid pipelines loop over a sample's lights (`--light-loop`; `culling/grid/light_loop_*.wgsl`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LightLoop {
    /// Each lane walks its own cell's lights.
    #[default]
    Lane,
    /// The subgroup takes its lanes' lights one at a time for all of them (the same light's
    /// data for every lane that lists it); needs an adapter with subgroups.
    Subgroup,
}

impl LightLoop {
    /// Every value `--light-loop` accepts, the default first.
    pub const ALL: [LightLoop; 2] = [LightLoop::Lane, LightLoop::Subgroup];

    /// The value's name, as `--light-loop` takes it and results show it.
    pub fn name(self) -> &'static str {
        match self {
            LightLoop::Lane => "lane",
            LightLoop::Subgroup => "subgroup",
        }
    }
}

/// Where `tiled_forward` and `tiled_forward_prez` keep their light grid (`--grid-storage`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GridStorage {
    /// Textures where the adapter cannot run the compute grid (no compute shaders or no
    /// storage buffers in fragment shaders, or wgpu's GL backend, whose compute cannot read
    /// depth), else buffers.
    #[default]
    Auto,
    /// Storage buffers, built by the `--assign` strategy (a `LightCuller`).
    Buffers,
    /// Textures read with `textureLoad`, built on the CPU, with no compute pass
    /// (tiled-forward-shading §4.2; `culling/texture_grid.rs`).
    Textures,
}

impl GridStorage {
    /// Every value `--grid-storage` accepts, the default first.
    pub const ALL: [GridStorage; 3] = [
        GridStorage::Auto,
        GridStorage::Buffers,
        GridStorage::Textures,
    ];

    /// The value's name, as `--grid-storage` takes it and results show it.
    pub fn name(self) -> &'static str {
        match self {
            GridStorage::Auto => "auto",
            GridStorage::Buffers => "buffers",
            GridStorage::Textures => "textures",
        }
    }

    /// `Buffers` or `Textures`: `Auto` resolved for an adapter that runs the compute grid
    /// (`compute_grid`) or not.
    pub fn resolve(self, compute_grid: bool) -> GridStorage {
        match (self, compute_grid) {
            (GridStorage::Auto, true) => GridStorage::Buffers,
            (GridStorage::Auto, false) => GridStorage::Textures,
            (s, _) => s,
        }
    }
}

/// Tight cells: each occupied cell of a grid built from the depth buffer keeps the view-space
/// box of its samples' pixel footprints, and a light is listed only where its sphere reaches
/// the box (the closest-point test; `culling/bounds/cell_box.rs`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CellBox {
    /// The cell's frustum piece (its tile's planes and depth bounds) only.
    #[default]
    Off,
    /// The frustum piece and the samples' box.
    On,
}

impl CellBox {
    /// Every value `--cell-box` accepts, the default first.
    pub const ALL: [CellBox; 2] = [CellBox::Off, CellBox::On];

    /// The value's name, as `--cell-box` takes it and results show it.
    pub fn name(self) -> &'static str {
        match self {
            CellBox::Off => "off",
            CellBox::On => "on",
        }
    }
}

/// 2.5D culling (Harada et al. 2012, "A 2.5D culling for Forward+"): each cell of a grid built
/// from the depth buffer keeps a 32-bit mask of which of 32 equal bins of its depth bounds hold
/// samples, and a light is listed only where the bins its view-depth span covers meet the
/// mask (`culling/bounds/depth_mask.rs`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DepthMask {
    /// The cell's depth bounds only.
    #[default]
    Off,
    /// The bounds and the mask.
    On,
}

impl DepthMask {
    /// Every value `--depth-mask` accepts, the default first.
    pub const ALL: [DepthMask; 2] = [DepthMask::Off, DepthMask::On];

    /// The value's name, as `--depth-mask` takes it and results show it.
    pub fn name(self) -> &'static str {
        match self {
            DepthMask::Off => "off",
            DepthMask::On => "on",
        }
    }
}

/// How the cell-bounds kernel reduces a tile's samples to its `[min, max]` (tiled-shading
/// §8: a warp-level reduction was 6x faster than shared-memory atomics at 16x16 tiles).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DepthReduction {
    /// Every sample's distance into workgroup memory with atomics (min and max).
    #[default]
    Atomics,
    /// Each invocation's samples in registers, then one subgroup min/max and one atomic per
    /// subgroup; tiled grids only (a clustered grid's samples go to different slices, so its
    /// cells reduce with atomics either way). Needs an adapter with subgroups.
    Subgroup,
}

impl DepthReduction {
    /// Every value `--depth-reduction` accepts, the default first.
    pub const ALL: [DepthReduction; 2] = [DepthReduction::Atomics, DepthReduction::Subgroup];

    /// The value's name, as `--depth-reduction` takes it and results show it.
    pub fn name(self) -> &'static str {
        match self {
            DepthReduction::Atomics => "atomics",
            DepthReduction::Subgroup => "subgroup",
        }
    }
}

/// The cell depth bounds light assignment culls by, for grids built from a depth buffer
/// (tiled-forward-shading §4.4 measures no pre-Z → pre-Z → pre-Z + bounds as 22.4 → 15.6 →
/// 10.9 ms; §4.4 and §4.8 note that one side of the bounds can be enough).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DepthBounds {
    /// `[min, max]` of the cell's samples (Forward+'s tile depth bounds).
    #[default]
    Both,
    /// `[min, slice far]`: lights behind every sample are culled, those in front are not.
    Min,
    /// `[slice near, max]`: lights in front of every sample are culled (the far side only
    /// bounds what the depth buffer hides).
    Max,
    /// Every cell spans its slice (`[near, far]` for a tile), occupied or not: the grid a
    /// pre-Z pass would build without reading depth.
    None,
}

impl DepthBounds {
    /// Every value `--depth-bounds` accepts, the default first.
    pub const ALL: [DepthBounds; 4] = [
        DepthBounds::Both,
        DepthBounds::Min,
        DepthBounds::Max,
        DepthBounds::None,
    ];

    /// The value's name, as `--depth-bounds` takes it and results show it.
    pub fn name(self) -> &'static str {
        match self {
            DepthBounds::Both => "both",
            DepthBounds::Min => "min",
            DepthBounds::Max => "max",
            DepthBounds::None => "none",
        }
    }

    /// The WGSL constant (`consts::DEPTH_BOUNDS_*`).
    pub fn id(self) -> u32 {
        use crate::consts::*;
        match self {
            DepthBounds::Both => DEPTH_BOUNDS_BOTH,
            DepthBounds::Min => DEPTH_BOUNDS_MIN,
            DepthBounds::Max => DEPTH_BOUNDS_MAX,
            DepthBounds::None => DEPTH_BOUNDS_NONE,
        }
    }
}

/// Where the edge-aware MSAA kernels of tiled and clustered deferred resolve their samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MsaaResolve {
    /// Every sample's colour into a per-sample buffer, written into the multisampled HDR
    /// target by a sample-rate pass, resolved by the tonemap (Lauritzen's flat buffer).
    #[default]
    Separate,
    /// Inside the kernel (tiled-deferred-tricks, Trick 1): each pixel's tone-mapped samples
    /// summed in workgroup memory as packed 16-bit integers with atomics, the display colour
    /// written directly. A frame with transparent objects resolves separately (they blend
    /// over every sample after the kernel).
    Kernel,
}

impl MsaaResolve {
    /// The value's name, as `--msaa-resolve` takes it and results show it.
    pub fn name(self) -> &'static str {
        match self {
            MsaaResolve::Separate => "separate",
            MsaaResolve::Kernel => "kernel",
        }
    }
}

/// How forward pipelines draw materials with different shaders (tiled-forward-shading §4.7).
/// Deferred pipelines always branch on the material stored in the G-buffer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum MaterialDraws {
    /// A pipeline per material shader, switched between the runs of geometry.
    #[default]
    PerMaterial,
    /// One pipeline for all, branching on the material (as deferred shading does).
    Uber,
}

impl MaterialDraws {
    /// The value's name, as `--material-draws` takes it and results show it.
    pub fn name(self) -> &'static str {
        match self {
            MaterialDraws::PerMaterial => "per-material",
            MaterialDraws::Uber => "uber",
        }
    }
}

pub use crate::scene::{Brdf, Shadows, SpotCull};

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            grid: CullConfig::default(),
            gbuffer: GBufferFormat::F16,
            material_draws: MaterialDraws::PerMaterial,
            msaa_resolve: MsaaResolve::Separate,
            light_loop: LightLoop::Lane,
            grid_storage: GridStorage::Auto,
            brdf: None,
            shadows: Shadows::Off,
            shadow_lights: None,
            shadow_atlas: crate::consts::DEFAULT_SHADOW_ATLAS_MIB,
            shadow_map_size: crate::shadows::maps::MAX_TILE,
        }
    }
}

impl RenderSettings {
    /// Refuse settings no renderer can use, with the accepted range (`--slices 0` would
    /// otherwise silently build a tiled grid for the clustered pipelines).
    pub fn validate(&self) -> crate::error::Result<()> {
        self.grid.validate()?;
        if self.grid.lists == GridLists::Opaque {
            return Err(crate::error::Error::invalid(
                "lists",
                "frames with transparent objects need transparent lists: separate or shared",
            ));
        }
        validate_shadow_lights(self.shadow_lights)?;
        validate_shadow_atlas(self.shadow_atlas)?;
        validate_shadow_map_size(self.shadow_map_size)
    }
}

/// `--assign zbin` keeps no per-cell lists: its tile masks and depth bins are the culling, so
/// the per-cell 2.5D masks and boxes have nothing to cut.
pub(crate) fn validate_zbin_culling(
    assign: Assign,
    depth_mask: DepthMask,
    cell_box: CellBox,
) -> crate::error::Result<()> {
    if assign != Assign::ZBin {
        return Ok(());
    }
    let flag = match (depth_mask, cell_box) {
        (DepthMask::On, _) => "depth-mask",
        (_, CellBox::On) => "cell-box",
        _ => return Ok(()),
    };
    Err(crate::error::Error::invalid(
        flag,
        "on cuts per-cell lists, which --assign zbin does not build (its tile masks and depth bins are its culling)",
    ))
}

/// Refuse a sample count no adapter offers (the adapter's own list is checked by the renderer).
pub fn validate_msaa(samples: u32) -> crate::error::Result<()> {
    use crate::consts::MSAA_COUNTS;
    if !MSAA_COUNTS.contains(&samples) {
        let list: Vec<String> = MSAA_COUNTS.iter().map(u32::to_string).collect();
        return Err(crate::error::Error::invalid(
            "msaa",
            format!("{samples}: must be one of {}", list.join(", ")),
        ));
    }
    Ok(())
}

/// Refuse a tile edge outside `MIN_TILE_SIZE..=MAX_TILE_SIZE`.
pub fn validate_tile_size(tile_size: u32) -> crate::error::Result<()> {
    use crate::consts::{MAX_TILE_SIZE, MIN_TILE_SIZE};
    if !(MIN_TILE_SIZE..=MAX_TILE_SIZE).contains(&tile_size) {
        return Err(crate::error::Error::invalid(
            "tile size",
            format!("{tile_size}: must be between {MIN_TILE_SIZE} and {MAX_TILE_SIZE} pixels"),
        ));
    }
    Ok(())
}

/// Refuse 2.5D culling or tight cells over bounds opened on a side: the mask's bins cut the
/// samples' own bounds and the box is the samples' own (the renderer's settings and
/// `LightCuller`'s config both ask this).
pub(crate) fn validate_sample_culling(
    depth_mask: DepthMask,
    cell_box: CellBox,
    depth_bounds: DepthBounds,
) -> crate::error::Result<()> {
    if depth_bounds == DepthBounds::Both {
        return Ok(());
    }
    let refuse = |flag: &'static str, why: &str| {
        Err(crate::error::Error::invalid(
            flag,
            format!(
                "on needs both depth bounds ({why}), not {}",
                depth_bounds.name()
            ),
        ))
    };
    if depth_mask == DepthMask::On {
        return refuse("depth-mask", "the mask's bins cut the samples' own bounds");
    }
    if cell_box == CellBox::On {
        return refuse(
            "cell-box",
            "the box is the samples' own, as both bounds are",
        );
    }
    Ok(())
}

/// Refuse a starting list capacity outside `1..=MAX_INDEX_CAPACITY` entries.
fn validate_index_capacity(entries: u32) -> crate::error::Result<()> {
    use crate::consts::MAX_INDEX_CAPACITY;
    if !(1..=MAX_INDEX_CAPACITY).contains(&entries) {
        return Err(crate::error::Error::invalid(
            "index-capacity",
            format!("{entries}: must be between 1 and {MAX_INDEX_CAPACITY} index entries"),
        ));
    }
    Ok(())
}

/// Refuse a view-depth slice count outside `1..=MAX_SLICES`.
pub(crate) fn validate_slices(slices: u32) -> crate::error::Result<()> {
    use crate::consts::MAX_SLICES;
    if !(1..=MAX_SLICES).contains(&slices) {
        return Err(crate::error::Error::invalid(
            "slices",
            format!("{slices}: must be between 1 and {MAX_SLICES}"),
        ));
    }
    Ok(())
}

/// `--shadow-lights`: 1 to `MAX_LIGHTS` lights, or every light (`None`). Zero is refused:
/// `--shadows off` says no light casts.
pub(crate) fn validate_shadow_lights(n: Option<u32>) -> crate::error::Result<()> {
    use crate::consts::MAX_LIGHTS;
    match n {
        Some(n) if !(1..=MAX_LIGHTS).contains(&n) => Err(crate::error::Error::invalid(
            "shadow-lights",
            format!("{n}: must be between 1 and {MAX_LIGHTS}, or all (--shadows off for none)"),
        )),
        _ => Ok(()),
    }
}

/// `--shadow-atlas`: 1 to `shadows::maps::MAX_ATLAS_MIB` MiB.
pub(crate) fn validate_shadow_atlas(mib: u32) -> crate::error::Result<()> {
    use crate::shadows::maps::MAX_ATLAS_MIB;
    if !(1..=MAX_ATLAS_MIB).contains(&mib) {
        return Err(crate::error::Error::invalid(
            "shadow-atlas",
            format!("{mib}: must be between 1 and {MAX_ATLAS_MIB} MiB"),
        ));
    }
    Ok(())
}

/// `--shadow-map-size`: a power of two from `MIN_TILE` to `MAX_TILE` texels.
pub(crate) fn validate_shadow_map_size(texels: u32) -> crate::error::Result<()> {
    use crate::shadows::maps::{MAX_TILE, MIN_TILE};
    if !(MIN_TILE..=MAX_TILE).contains(&texels) || !texels.is_power_of_two() {
        return Err(crate::error::Error::invalid(
            "shadow-map-size",
            format!("{texels}: must be a power of two from {MIN_TILE} to {MAX_TILE}"),
        ));
    }
    Ok(())
}

/// Bits per G-buffer channel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum GBufferFormat {
    /// 16-bit float channels (`--gbuffer 16`), the default.
    #[default]
    F16,
    /// 32-bit float channels (`--gbuffer 32`).
    F32,
}

impl GBufferFormat {
    /// The texture format of each four-channel G-buffer target (`Rgba16Float` or `Rgba32Float`).
    pub fn texture_format(self) -> wgpu::TextureFormat {
        match self {
            GBufferFormat::F16 => wgpu::TextureFormat::Rgba16Float,
            GBufferFormat::F32 => wgpu::TextureFormat::Rgba32Float,
        }
    }

    /// Bytes per pixel of one four-channel G-buffer target.
    pub fn bytes_per_target(self) -> u32 {
        4 * self.bits() / 8
    }

    /// Bits per channel: 16 or 32, as `--gbuffer` takes it.
    pub fn bits(self) -> u32 {
        match self {
            GBufferFormat::F16 => 16,
            GBufferFormat::F32 => 32,
        }
    }
}

/// Who builds the light grid (`--assign`): the typed id of a row of the strategy registry
/// (`culling::STRATEGIES`, which also holds each one's name and description), or `Auto`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Assign {
    /// On the CPU (`assign_cpu.rs`): projected sphere rectangles, per-cell depth test.
    Cpu,
    /// GPU gather: one workgroup per cell tests every light against the cell's frustum.
    Gather,
    /// GPU scatter: one invocation per light emits (cell, light) pairs, radix-sorted by cell.
    Scatter,
    /// Light BVH rebuilt each frame on the CPU, traversed on the GPU per cell.
    Bvh,
    /// Light BVH rebuilt each frame on the GPU (Morton codes, radix sort, node boxes),
    /// traversed as `Bvh`.
    #[serde(rename = "bvh-gpu")]
    BvhGpu,
    /// GPU z-binning (Drobot 2017): lights sorted by view depth, per depth bin (slice) the
    /// range of sorted lights meeting it, per tile a bit mask of the lights reaching it.
    ZBin,
    /// By light count: see [`Assign::resolve`].
    #[default]
    Auto,
}

/// On a hardware GPU, `auto` gathers up to this many lights and walks a GPU-built BVH above
/// (tiled-forward-shading §4.4: brute force holds to about 10k lights).
pub const AUTO_GATHER_MAX_LIGHTS: usize = 8192;

impl Assign {
    /// The strategy used for a frame with `lights` lights. `auto` on a software adapter
    /// (lavapipe, which shares the CPU's cores) is `cpu` at every count: measured fastest from
    /// 1k to 1M lights (README, "Light assignment scaling"). On a hardware GPU it is `gather`
    /// up to [`AUTO_GATHER_MAX_LIGHTS`] and `bvh-gpu` above, which keeps the grid on the GPU
    /// (the paper's crossover; no hardware GPU was available to measure it).
    pub fn resolve(self, lights: usize, software_adapter: bool) -> Assign {
        match self {
            Assign::Auto if software_adapter => Assign::Cpu,
            Assign::Auto if lights <= AUTO_GATHER_MAX_LIGHTS => Assign::Gather,
            Assign::Auto => Assign::BvhGpu,
            other => other,
        }
    }
}

/// Which samples a grid's lists cover (tiled-forward-shading §4.5, Listing 4.2). A
/// transparent fragment lies in front of the opaque depth at its pixel, so anywhere between
/// the near plane and the tile's opaque *maximum*; an opaque sample lies inside the tile's
/// `[min, max]`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum GridLists {
    /// One list per cell over its opaque samples (no transparent geometry in the frame).
    #[default]
    Opaque,
    /// One list per cell covering near..opaque max: opaque and transparent fragments share it.
    Shared,
    /// Two layers of cells: layer 0 over the opaque samples (pruned by the minimum too),
    /// layer 1 over near..opaque max for transparent fragments.
    Separate,
}

impl GridLists {
    /// The value's name in results and messages (`--lists` takes `separate` and `shared`).
    pub fn name(self) -> &'static str {
        match self {
            GridLists::Opaque => "opaque",
            GridLists::Shared => "shared",
            GridLists::Separate => "separate",
        }
    }

    /// Layers of cells: 2 for separate lists.
    pub fn layers(self) -> u32 {
        if self == GridLists::Separate {
            2
        } else {
            1
        }
    }

    /// The layer transparent fragments read.
    pub fn transparent_layer(self) -> u32 {
        self.layers() - 1
    }

    /// The value of `GridParams::lists` (`culling/grid/grid_cell.wgsl`).
    pub fn gpu(self) -> u32 {
        use crate::consts::{GRID_LISTS_OPAQUE, GRID_LISTS_SEPARATE, GRID_LISTS_SHARED};
        match self {
            GridLists::Opaque => GRID_LISTS_OPAQUE,
            GridLists::Shared => GRID_LISTS_SHARED,
            GridLists::Separate => GRID_LISTS_SEPARATE,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The records (the benchmark's results.json, the viewer's scripts) keep one flat object
    /// per run: the grid's description is flattened into it under the settings' own names,
    /// and the culler's limits are not records at all.
    #[test]
    fn the_grid_description_is_recorded_flat_under_the_settings_names() {
        let s = RenderSettings {
            grid: CullConfig {
                tile_size: 8,
                strategy: Assign::ZBin,
                samples: 4,
                max_lights: 7,
                ..CullConfig::default()
            },
            ..RenderSettings::default()
        };
        let json = serde_json::to_value(s).unwrap();
        let object = json.as_object().unwrap();
        for key in [
            "tile_size",
            "slices",
            "assign",
            "spot_cull",
            "lists",
            "msaa",
            "depth_bounds",
            "depth_reduction",
            "depth_mask",
            "cell_box",
            "gbuffer",
        ] {
            assert!(object.contains_key(key), "{key} missing: {json}");
        }
        assert!(!object.contains_key("grid") && !object.contains_key("max_lights"));
        assert_eq!(
            json["index_capacity"],
            crate::consts::INITIAL_INDEX_CAPACITY
        );
        assert_eq!(json["assign"], "zbin");
        assert_eq!(json["msaa"], 4);
        // Read back: the limits come back as their defaults, everything else as written.
        let back: RenderSettings = serde_json::from_value(json).unwrap();
        assert_eq!(back.grid.max_lights, CullConfig::default().max_lights);
        assert_eq!(
            back,
            RenderSettings {
                grid: CullConfig {
                    max_lights: CullConfig::default().max_lights,
                    ..s.grid
                },
                ..s
            }
        );
        // A record written before 2.5D culling and tight cells existed.
        let mut old = serde_json::to_value(RenderSettings::default()).unwrap();
        let o = old.as_object_mut().unwrap();
        o.remove("depth_mask");
        o.remove("cell_box");
        o.remove("index_capacity");
        let back: RenderSettings = serde_json::from_value(old).unwrap();
        assert_eq!(back, RenderSettings::default());
    }
}
