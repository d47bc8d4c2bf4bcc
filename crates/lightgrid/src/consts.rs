//! The only home of numeric constants shared between Rust and WGSL.
//!
//! `wgsl_prelude` writes every entry of [`WGSL_CONSTS`] as a WGSL `const`, and the shader
//! composer puts that prelude in front of every shader, so no shader types a number that Rust
//! also uses.

/// Most lights one frame can hold. 2^20 covers the million-light stress test; at 32 bytes a
/// light this is 32 MiB, well under the 128 MiB storage binding limit seen on lavapipe.
pub const MAX_LIGHTS: u32 = 1 << 20;

/// Default screen tile edge in pixels (tiled-shading §5 discusses 16 and 32).
pub const DEFAULT_TILE_SIZE: u32 = 16;

/// View-depth slices of the clustered grid (tiled-forward-shading §4.8), exponentially spaced
/// between the camera's near and far planes.
pub const DEFAULT_SLICES: u32 = 32;
/// Index entries a new grid's lists start with (`--index-capacity`); they grow (never
/// shrink) to fit.
pub const INITIAL_INDEX_CAPACITY: u32 = 1 << 14;
/// The most index entries `--index-capacity` may start with: what one storage binding holds
/// within WebGPU's default limits (128 MiB of u32).
pub(crate) const MAX_INDEX_CAPACITY: u32 = 1 << 25;
/// Most slices accepted by `--slices`.
pub(crate) const MAX_SLICES: u32 = 256;

/// Tile edges accepted by `--tile`. The single-kernel tiled deferred pipeline runs
/// (tile / TILE_THREADS)^2 workgroups per tile, each reducing the tile's depth and culling its
/// lights again, so large tiles repeat that work (16 times at 64).
pub const MIN_TILE_SIZE: u32 = 4;
/// Largest tile edge `--tile` accepts, in pixels.
pub const MAX_TILE_SIZE: u32 = 64;

/// Texels of a light in the texture grid's light texture (`Rgba32Float`, 16 bytes each:
/// `GpuLight`'s 48 bytes, asserted in `gpu_types.rs`; `culling/texture_grid.rs`).
pub const LIGHT_TEXELS: u32 = 3;

/// Threads along one edge of a per-tile workgroup (depth bounds, single-kernel tiled deferred):
/// 16×16 = 256 invocations stride over the tile's pixels, so any tile size works.
pub(crate) const TILE_THREADS: u32 = 16;

/// Light indices the single-kernel tiled deferred pipeline culls into workgroup memory at a
/// time. More lights per tile are handled in further batches, never dropped.
pub(crate) const TILE_LIGHT_BATCH: u32 = 1024;

/// Relative slack of every depth comparison in light assignment (CPU and GPU): a light is
/// kept when its view-depth interval misses a cell's by less than this fraction, so f32
/// round-off can never drop a light that reaches a sample.
pub const ASSIGN_DEPTH_SLACK: f32 = 1e-4;

/// The largest finite binary16 value: what a shader clamps to before `pack2x16float`, whose
/// result for a value beyond binary16's range WGSL leaves indeterminate.
pub(crate) const HALF_MAX: f32 = 65504.0;

/// The narrowest slicing range a clustered grid takes (`hi / lo`, `culling/bounds/depth_range.rs`):
/// a frame whose samples all lie at one view distance (a wall facing the camera) still gets
/// slices of a finite scale.
pub(crate) const SLICING_MIN_RATIO: f32 = 1.01;

/// Relative and absolute widening of a cell's bounding sphere in the spot-cone test (CPU and
/// GPU), so f32 round-off can never drop a spot that reaches a sample.
pub(crate) const CONE_SLACK: f32 = 1e-3;

/// Spots with an outer cosine at least this (half-angle up to 45°) are drawn as cone light
/// volumes by the classic deferred family; wider ones as their bounding sphere.
pub(crate) const CONE_VOLUME_MIN_COS: f32 = std::f32::consts::FRAC_1_SQRT_2;
/// Segments of the cone light volume's rings.
pub(crate) const CONE_VOLUME_SEGMENTS: u32 = 16;
/// How far a cone light volume reaches past its cone, as a fraction of the range: the apex is
/// pulled back by it, the rings widened and the far ring pushed out by it.
pub(crate) const CONE_VOLUME_MARGIN: f32 = 0.01;

/// `GpuLight::cos_outer` of a point light (no cone: below every cosine).
pub const POINT_LIGHT_COS: f32 = -2.0;

/// Invocations per workgroup of the one-thread-per-item assignment kernels (scatter per light,
/// radix sort blocks, prefix sums).
pub(crate) const ASSIGN_THREADS: u32 = 256;

/// Loop iterations llvmpipe (lavapipe) lets one shader invocation run: its infinite-loop guard
/// is one counter per invocation across all loops, and when it runs out the loops simply end,
/// without an error (measured: `forward` with 65,536 lights is exact, with 66,000 it misses
/// light; splitting the loop into chunks does not help). Every data-dependent shader loop
/// checks after it ends that it reached its bound and counts a miss in
/// [`COUNTER_TRUNCATED_LOOPS`]; this number only sizes kernels and tests.
pub const SOFTWARE_LOOP_BUDGET: u64 = 65_536;

/// Slots of the frame counters (group 0, binding 3: `frame_counters` in
/// `shading/scene_bindings.wgsl`), cleared at the start of every frame and read back after it
/// (asynchronously in real-time frames, `gpu/counters.rs`).
/// Data-dependent shader loops that ended before their bound (llvmpipe's loop guard).
pub const COUNTER_TRUNCATED_LOOPS: u32 = 0;
/// Index-list entries the per-cell assignment kernels reserved: what the grid needs.
pub(crate) const COUNTER_INDEX_NEEDED: u32 = 1;
/// Of those, entries that did not fit the index buffer (sized from earlier frames).
pub(crate) const COUNTER_INDEX_OUT_OF_ROOM: u32 = 2;
/// Cells queued for the spill pass (more than CELL_LIST_CAPACITY lights).
pub(crate) const COUNTER_SPILLS: u32 = 3;
/// Hits beyond a counted length (spill pass): count and write passes disagree; must stay 0.
pub(crate) const COUNTER_WRITE_OVERFLOW: u32 = 4;
/// (cell, light) pairs the scatter strategy emitted: what its pair buffer needs.
pub(crate) const COUNTER_PAIRS_NEEDED: u32 = 5;
/// Of those, pairs that did not fit the pair buffer (sized from earlier frames).
pub(crate) const COUNTER_PAIRS_OUT_OF_ROOM: u32 = 6;
/// Lights a `LightCuller` refused (not finite, range not positive: `cull_lights.wgsl`).
pub(crate) const COUNTER_INVALID_LIGHTS: u32 = 7;
/// Three slots: the spill pass's indirect dispatch arguments (x, y, z).
pub(crate) const COUNTER_SPILL_ARGS: u32 = 8;
/// Three slots: the scatter emit pass's indirect dispatch arguments (x, y, z); the fourth
/// holds the number of items they cover (`scatter.wgsl`'s `items_args_main`).
pub(crate) const COUNTER_ITEM_ARGS: u32 = 12;
/// Pixels the edge-aware MSAA shading kernels shaded per sample (samples differing in depth,
/// normal or material: `EDGE_*`).
pub(crate) const COUNTER_EDGE_PIXELS: u32 = 16;
/// Samples the MSAA shading kernels shaded: one per pixel with geometry, plus every other
/// covered sample of an edge pixel.
pub(crate) const COUNTER_SHADED_SAMPLES: u32 = 17;
/// Samples with geometry the MSAA shading kernels saw (what per-sample shading would shade).
pub(crate) const COUNTER_GEOMETRY_SAMPLES: u32 = 18;
/// MSAA forward fragments whose shading point lay outside their cell's bounds, so their list
/// may miss lights (`light_grid_shade_fragment` in `light_grid.wgsl`): the frame is wrong when
/// non-zero (the fragment-bounds pass keeps it zero).
pub(crate) const COUNTER_OFF_BOUNDS_FRAGMENTS: u32 = 19;
/// Shadow rays the light function cast (`--shadows rays`: one per shadow-casting light that
/// would light a shaded sample).
pub(crate) const COUNTER_SHADOW_RAYS: u32 = 20;
/// Number of slots.
pub(crate) const COUNTER_SLOTS: u32 = 21;

/// MSAA sample counts lightgrid knows (`--msaa`); the adapter decides which it offers
/// (`frame::msaa_counts`).
pub const MSAA_COUNTS: [u32; 5] = [1, 2, 4, 8, 16];
/// The standard sample positions (Vulkan `standardSampleLocations`, D3D's standard
/// patterns) within a pixel, for `samples` samples: where a per-sample shading kernel
/// reconstructs a sample's position from its depth.
pub(crate) fn msaa_sample_positions(samples: u32) -> &'static [[f32; 2]] {
    match samples {
        2 => &[[0.75, 0.75], [0.25, 0.25]],
        4 => &[
            [0.375, 0.125],
            [0.875, 0.375],
            [0.125, 0.625],
            [0.625, 0.875],
        ],
        8 => &[
            [0.5625, 0.3125],
            [0.4375, 0.6875],
            [0.8125, 0.5625],
            [0.3125, 0.1875],
            [0.1875, 0.8125],
            [0.0625, 0.4375],
            [0.6875, 0.9375],
            [0.9375, 0.0625],
        ],
        16 => &[
            [0.5625, 0.5625],
            [0.4375, 0.3125],
            [0.3125, 0.625],
            [0.75, 0.4375],
            [0.1875, 0.375],
            [0.625, 0.8125],
            [0.8125, 0.6875],
            [0.6875, 0.1875],
            [0.375, 0.875],
            [0.5, 0.0625],
            [0.25, 0.125],
            [0.125, 0.75],
            [0.0, 0.5],
            [0.9375, 0.25],
            [0.875, 0.9375],
            [0.0625, 0.0],
        ],
        _ => &[[0.5, 0.5]],
    }
}

/// Edge detection of the MSAA deferred kernels (tiled-deferred-tricks, edge detection): two
/// samples of a pixel belong to different surfaces when their materials differ, their
/// normals differ by more than about 8 degrees (cosine below `EDGE_NORMAL_COS`), or the
/// second lies off the first's tangent plane: the offset between them leaves the plane by
/// more than `EDGE_PLANE_SIN` of its length (about 11.5 degrees).
pub(crate) const EDGE_NORMAL_COS: f32 = 0.99;
pub(crate) const EDGE_PLANE_SIN: f32 = 0.2;

/// Light indices one per-cell assignment workgroup (gather, BVH walk) collects in workgroup
/// memory before flushing them to the global index list. A cell with more lights "spills": a
/// second pass writes its whole list straight to global memory (nothing is ever dropped).
pub(crate) const CELL_LIST_CAPACITY: u32 = 512;

/// Branching factor of the light BVH (tiled-forward-shading §4.4 uses 32): a leaf holds up to
/// 32 lights, an inner node up to 32 children, and one traversal workgroup has 32 invocations,
/// one per child.
pub(crate) const BVH_WIDTH: u32 = 32;
/// Flag in `BvhNode::count` marking a leaf (its children are lights).
pub(crate) const BVH_LEAF: u32 = 1 << 31;
/// Traversal stack entries per workgroup: a depth-first walk holds at most 31 siblings per
/// level plus one; 2^20 lights make at most 4 inner levels, so 160 is ample.
pub(crate) const BVH_STACK: u32 = 160;

/// Largest accepted frame edge, before the adapter's own texture limit is applied.
pub const MAX_FRAME_EDGE: u32 = 16384;

/// Global ambient light intensity that multiplies every material's ambient colour.
pub const SCENE_AMBIENT: f32 = 0.04;

/// Exposure applied before tonemapping the HDR target. A scene's own exposure
/// (`scene::Lighting::exposure`, `--exposure`) scales its lights as they are uploaded; this
/// one stays 1.
pub const EXPOSURE: f32 = 1.0;

/// `FrameUniforms::brdf` (`scene::Brdf`): Blinn-Phong or glTF's GGX metallic-roughness.
pub(crate) const BRDF_PHONG: u32 = 0;
pub(crate) const BRDF_GGX: u32 = 1;

/// A spot's angular window between its cones (`scene::SpotCone`): the papers' smoothstep, or
/// KHR_lights_punctual's squared linear ramp.
pub(crate) const SPOT_CONE_SMOOTHSTEP: u32 = 0;
pub(crate) const SPOT_CONE_SQUARED: u32 = 1;
/// `FrameUniforms::falloff` (`scene::LightUnits`): the papers' window `(1 − (d/r)²)²`, or
/// KHR_lights_punctual's inverse square windowed by `clamp(1 − (d/r)⁴, 0, 1)²`.
pub(crate) const FALLOFF_WINDOW: u32 = 0;
pub(crate) const FALLOFF_INVERSE_SQUARE: u32 = 1;
/// The smallest squared distance the inverse-square falloff divides by (1 cm² in a glTF
/// file's metres, as Filament clamps it): a light touching a surface stays finite there.
pub(crate) const MIN_LIGHT_DISTANCE_SQ: f32 = 1e-4;

/// The Blinn-Phong exponents a glTF material's roughness maps to (`2/α² − 2`, α =
/// roughness²): from just above 0 (roughness 1, α = 1: GGX reads α back as 0.99975; 0 itself
/// would make Blinn-Phong's `pow(0, 0)` undefined) to 2048 (roughness 0.18, the sharpest lobe
/// a 16-bit G-buffer's exponent holds).
pub(crate) const MIN_SHININESS: f32 = 1e-3;
pub(crate) const MAX_SHININESS: f32 = 2048.0;

/// `--shadow-atlas`'s default budget in MiB: a 4096² depth atlas.
pub(crate) const DEFAULT_SHADOW_ATLAS_MIB: u32 = 64;
/// `scene::Shadows` as the light function's `SHADING_SHADOWS` (`shading/shadows.wgsl`).
pub(crate) const SHADOWS_OFF: u32 = 0;
pub(crate) const SHADOWS_RAYS: u32 = 1;
pub(crate) const SHADOWS_MAPS: u32 = 2;
/// Shadow maps re-used light by light (the light-volume pipelines): a face's tile is its cube
/// face's.
pub(crate) const SHADOWS_MAPS_REUSED: u32 = 3;
/// A shadow map's slope-scaled normal offset, in texels of the map at the sample's distance
/// (`shadows/maps.rs`): the sample moves along its normal by `SHADOW_NORMAL_OFFSET` +
/// `SHADOW_SLOPE_OFFSET` × tan θ (θ between normal and light), tan θ capped at
/// `SHADOW_MAX_SLOPE`.
pub(crate) const SHADOW_NORMAL_OFFSET: f32 = 1.0;
pub(crate) const SHADOW_SLOPE_OFFSET: f32 = 1.0;
pub(crate) const SHADOW_MAX_SLOPE: f32 = 4.0;
/// Entries of a shadow ray's traversal stack: a balanced tree of 2^31 triangles needs 30
/// (`shadows/bvh.rs`); the renderer refuses a deeper one.
pub(crate) const SHADOW_STACK_DEPTH: u32 = 32;
/// Most nodes one shadow ray's walk of one tree visits before it is counted as truncated.
pub(crate) const SHADOW_MAX_STEPS: u32 = 1 << 20;
/// Most triangles in a leaf (`shadows::bvh::LEAF_TRIANGLES`).
pub(crate) const SHADOW_LEAF_TRIANGLES: u32 = 4;
/// The root of an empty tree in the shadow buffer.
pub(crate) const SHADOW_NO_TREE: u32 = u32::MAX;

/// Workgroup edge of the full-screen compute passes (8×8 = 64 invocations).
pub(crate) const SCREEN_WORKGROUP: u32 = 8;

/// `GridParams::lists` values (`frame::GridLists`): lists over opaque samples only, one list
/// shared by opaque and transparent fragments, or separate lists (a second layer of cells).
pub(crate) const GRID_LISTS_OPAQUE: u32 = 0;
pub(crate) const GRID_LISTS_SHARED: u32 = 1;
pub(crate) const GRID_LISTS_SEPARATE: u32 = 2;

/// Which cell depth bounds light assignment uses (`--depth-bounds`; `DepthBounds` in
/// `frame/settings.rs`): both, the minimum only (far side open), the maximum only (near side
/// open), or none (every cell spans its slice).
pub(crate) const DEPTH_BOUNDS_BOTH: u32 = 0;
pub(crate) const DEPTH_BOUNDS_MIN: u32 = 1;
pub(crate) const DEPTH_BOUNDS_MAX: u32 = 2;
pub(crate) const DEPTH_BOUNDS_NONE: u32 = 3;

/// 2.5D culling (`--depth-mask on`; Harada et al. 2012, "A 2.5D culling for Forward+"): each
/// cell's depth bounds are cut into this many equal bins, one bit each of a 32-bit mask that
/// says which bins hold samples (`culling/bounds/depth_mask.rs`).
pub(crate) const DEPTH_MASK_BINS: u32 = 32;
/// A cell mask's bits when the cell has no mask (`--depth-mask off`, cells without depth
/// bounds, transparent lists): every light that passes the other tests is listed.
pub(crate) const DEPTH_MASK_ALL: u32 = u32::MAX;

/// Material shaders (`scene::MaterialShader`, tiled-forward-shading §4.7): the id each
/// material carries, and the value of the WGSL override `MATERIAL_SHADER` that makes a
/// pipeline branch on the material instead of being specialised to one shader.
pub(crate) const MATERIAL_SHADER_STANDARD: u32 = 0;
/// `MaterialShader::CarPaint`: the diffuse colour turns toward a flip colour at grazing angles.
pub const MATERIAL_SHADER_CAR_PAINT: u32 = 1;
/// `MaterialShader::Rim`: a rim colour times `(1 − n·v)^power` added to the diffuse colour.
pub const MATERIAL_SHADER_RIM: u32 = 2;
/// Number of material shaders (forward pipelines create one pipeline each).
pub(crate) const MATERIAL_SHADERS: u32 = 3;
pub(crate) const MATERIAL_SHADER_ANY: u32 = 0xffff_ffff;
/// Most materials a scene may have (the G-buffer stores the index in a 16-bit float, exact
/// up to 2048).
pub(crate) const MAX_MATERIALS: usize = 2048;
/// Most base-colour textures a scene may have: the layers of one texture array (WebGPU's
/// default `max_texture_array_layers`).
pub(crate) const MAX_TEXTURES: usize = 256;
/// Largest edge a base-colour texture keeps: larger images are scaled down when loaded (the
/// GPU array's layers are at most this), so 256 textures stay within 1 GiB of texels.
pub(crate) const MAX_TEXTURE_EDGE: u32 = 1024;

/// Material flag bit: the material is transparent (blended, drawn after opaque geometry).
pub(crate) const MATERIAL_FLAG_TRANSPARENT: u32 = 1;
/// The material is glTF's metallic-roughness: diffuse, specular and exponent are derived per
/// sample from `base`, `metallic`, `roughness`, the textures and the vertex colour (by
/// `gltf::import::map_material`'s rule, which gives the stored colours untextured).
pub(crate) const MATERIAL_FLAG_METALLIC_ROUGHNESS: u32 = 2;
/// A material's texture slots (`GpuMaterial::uv_sets`, `wraps`).
pub const TEXTURE_SLOT_BASE: u32 = 0;
/// Emissive texture slot: its RGB scales the material's emissive colour.
pub const TEXTURE_SLOT_EMISSIVE: u32 = 1;
/// glTF metallic-roughness texture slot: B scales metallic, G scales roughness.
pub const TEXTURE_SLOT_METAL_ROUGH: u32 = 2;
/// Tangent-space normal map slot (glTF §3.9.3), its x and y scaled by the normal scale.
pub const TEXTURE_SLOT_NORMAL: u32 = 3;
/// Occlusion texture slot: its R darkens the ambient term only, by the occlusion strength.
pub const TEXTURE_SLOT_OCCLUSION: u32 = 4;
/// Texture wrapping (glTF samplers' `wrapS`/`wrapT`): the GPU sampler repeats, clamping and
/// mirroring are applied to the coordinates.
pub(crate) const WRAP_REPEAT: u32 = 0;
/// glTF `CLAMP_TO_EDGE` (33071): the coordinate is clamped to within half a texel of the edges.
pub const WRAP_CLAMP: u32 = 1;
/// glTF `MIRRORED_REPEAT` (33648): every other repeat is folded back, then clamped like
/// [`WRAP_CLAMP`].
pub const WRAP_MIRROR: u32 = 2;

/// A WGSL constant value: unsigned integer or float.
#[derive(Clone, Copy, Debug)]
pub enum WgslConst {
    /// Written as a WGSL `u32` literal (`{v}u`).
    U32(u32),
    /// Written as a WGSL `f32` literal (Rust's `{v:?}` form, so whole numbers keep their `.0`).
    F32(f32),
}

/// Every constant the shaders see, by its WGSL name.
pub const WGSL_CONSTS: &[(&str, WgslConst)] = &[
    ("MAX_LIGHTS", WgslConst::U32(MAX_LIGHTS)),
    ("SCENE_AMBIENT", WgslConst::F32(SCENE_AMBIENT)),
    ("EXPOSURE", WgslConst::F32(EXPOSURE)),
    ("BRDF_PHONG", WgslConst::U32(BRDF_PHONG)),
    ("BRDF_GGX", WgslConst::U32(BRDF_GGX)),
    ("SPOT_CONE_SMOOTHSTEP", WgslConst::U32(SPOT_CONE_SMOOTHSTEP)),
    ("SPOT_CONE_SQUARED", WgslConst::U32(SPOT_CONE_SQUARED)),
    ("FALLOFF_WINDOW", WgslConst::U32(FALLOFF_WINDOW)),
    (
        "FALLOFF_INVERSE_SQUARE",
        WgslConst::U32(FALLOFF_INVERSE_SQUARE),
    ),
    (
        "MIN_LIGHT_DISTANCE_SQ",
        WgslConst::F32(MIN_LIGHT_DISTANCE_SQ),
    ),
    ("MIN_SHININESS", WgslConst::F32(MIN_SHININESS)),
    ("MAX_SHININESS", WgslConst::F32(MAX_SHININESS)),
    ("SCREEN_WORKGROUP", WgslConst::U32(SCREEN_WORKGROUP)),
    ("SHADOWS_OFF", WgslConst::U32(SHADOWS_OFF)),
    ("SHADOWS_RAYS", WgslConst::U32(SHADOWS_RAYS)),
    ("SHADOWS_MAPS", WgslConst::U32(SHADOWS_MAPS)),
    ("SHADOWS_MAPS_REUSED", WgslConst::U32(SHADOWS_MAPS_REUSED)),
    ("SHADOW_NORMAL_OFFSET", WgslConst::F32(SHADOW_NORMAL_OFFSET)),
    ("SHADOW_SLOPE_OFFSET", WgslConst::F32(SHADOW_SLOPE_OFFSET)),
    ("SHADOW_MAX_SLOPE", WgslConst::F32(SHADOW_MAX_SLOPE)),
    ("SHADOW_STACK_DEPTH", WgslConst::U32(SHADOW_STACK_DEPTH)),
    ("SHADOW_MAX_STEPS", WgslConst::U32(SHADOW_MAX_STEPS)),
    (
        "SHADOW_LEAF_TRIANGLES",
        WgslConst::U32(SHADOW_LEAF_TRIANGLES),
    ),
    ("SHADOW_NO_TREE", WgslConst::U32(SHADOW_NO_TREE)),
    ("MAX_TILE_SIZE", WgslConst::U32(MAX_TILE_SIZE)),
    ("LIGHT_TEXELS", WgslConst::U32(LIGHT_TEXELS)),
    ("TILE_THREADS", WgslConst::U32(TILE_THREADS)),
    ("TILE_LIGHT_BATCH", WgslConst::U32(TILE_LIGHT_BATCH)),
    ("ASSIGN_DEPTH_SLACK", WgslConst::F32(ASSIGN_DEPTH_SLACK)),
    ("SLICING_MIN_RATIO", WgslConst::F32(SLICING_MIN_RATIO)),
    ("HALF_MAX", WgslConst::F32(HALF_MAX)),
    ("CONE_SLACK", WgslConst::F32(CONE_SLACK)),
    ("CONE_VOLUME_MIN_COS", WgslConst::F32(CONE_VOLUME_MIN_COS)),
    ("CONE_VOLUME_SEGMENTS", WgslConst::U32(CONE_VOLUME_SEGMENTS)),
    ("CONE_VOLUME_MARGIN", WgslConst::F32(CONE_VOLUME_MARGIN)),
    ("POINT_LIGHT_COS", WgslConst::F32(POINT_LIGHT_COS)),
    ("ASSIGN_THREADS", WgslConst::U32(ASSIGN_THREADS)),
    ("CELL_LIST_CAPACITY", WgslConst::U32(CELL_LIST_CAPACITY)),
    ("MAX_SLICES", WgslConst::U32(MAX_SLICES)),
    ("DEPTH_MASK_BINS", WgslConst::U32(DEPTH_MASK_BINS)),
    ("DEPTH_MASK_ALL", WgslConst::U32(DEPTH_MASK_ALL)),
    ("BVH_WIDTH", WgslConst::U32(BVH_WIDTH)),
    ("BVH_LEAF", WgslConst::U32(BVH_LEAF)),
    ("BVH_STACK", WgslConst::U32(BVH_STACK)),
    (
        "COUNTER_TRUNCATED_LOOPS",
        WgslConst::U32(COUNTER_TRUNCATED_LOOPS),
    ),
    ("COUNTER_INDEX_NEEDED", WgslConst::U32(COUNTER_INDEX_NEEDED)),
    (
        "COUNTER_INDEX_OUT_OF_ROOM",
        WgslConst::U32(COUNTER_INDEX_OUT_OF_ROOM),
    ),
    ("COUNTER_SPILLS", WgslConst::U32(COUNTER_SPILLS)),
    (
        "COUNTER_WRITE_OVERFLOW",
        WgslConst::U32(COUNTER_WRITE_OVERFLOW),
    ),
    ("COUNTER_PAIRS_NEEDED", WgslConst::U32(COUNTER_PAIRS_NEEDED)),
    (
        "COUNTER_PAIRS_OUT_OF_ROOM",
        WgslConst::U32(COUNTER_PAIRS_OUT_OF_ROOM),
    ),
    (
        "COUNTER_INVALID_LIGHTS",
        WgslConst::U32(COUNTER_INVALID_LIGHTS),
    ),
    ("COUNTER_SPILL_ARGS", WgslConst::U32(COUNTER_SPILL_ARGS)),
    ("COUNTER_ITEM_ARGS", WgslConst::U32(COUNTER_ITEM_ARGS)),
    ("COUNTER_SLOTS", WgslConst::U32(COUNTER_SLOTS)),
    ("COUNTER_SHADOW_RAYS", WgslConst::U32(COUNTER_SHADOW_RAYS)),
    ("COUNTER_EDGE_PIXELS", WgslConst::U32(COUNTER_EDGE_PIXELS)),
    (
        "COUNTER_SHADED_SAMPLES",
        WgslConst::U32(COUNTER_SHADED_SAMPLES),
    ),
    (
        "COUNTER_GEOMETRY_SAMPLES",
        WgslConst::U32(COUNTER_GEOMETRY_SAMPLES),
    ),
    (
        "COUNTER_OFF_BOUNDS_FRAGMENTS",
        WgslConst::U32(COUNTER_OFF_BOUNDS_FRAGMENTS),
    ),
    ("EDGE_NORMAL_COS", WgslConst::F32(EDGE_NORMAL_COS)),
    ("EDGE_PLANE_SIN", WgslConst::F32(EDGE_PLANE_SIN)),
    ("LIGHT_GRID_LISTS_OPAQUE", WgslConst::U32(GRID_LISTS_OPAQUE)),
    ("DEPTH_BOUNDS_BOTH", WgslConst::U32(DEPTH_BOUNDS_BOTH)),
    ("DEPTH_BOUNDS_MIN", WgslConst::U32(DEPTH_BOUNDS_MIN)),
    ("DEPTH_BOUNDS_MAX", WgslConst::U32(DEPTH_BOUNDS_MAX)),
    ("DEPTH_BOUNDS_NONE", WgslConst::U32(DEPTH_BOUNDS_NONE)),
    (
        "MATERIAL_SHADER_STANDARD",
        WgslConst::U32(MATERIAL_SHADER_STANDARD),
    ),
    (
        "MATERIAL_SHADER_CAR_PAINT",
        WgslConst::U32(MATERIAL_SHADER_CAR_PAINT),
    ),
    ("MATERIAL_SHADER_RIM", WgslConst::U32(MATERIAL_SHADER_RIM)),
    ("MATERIAL_SHADER_ANY", WgslConst::U32(MATERIAL_SHADER_ANY)),
    ("LIGHT_GRID_LISTS_SHARED", WgslConst::U32(GRID_LISTS_SHARED)),
    (
        "LIGHT_GRID_LISTS_SEPARATE",
        WgslConst::U32(GRID_LISTS_SEPARATE),
    ),
    (
        "MATERIAL_FLAG_TRANSPARENT",
        WgslConst::U32(MATERIAL_FLAG_TRANSPARENT),
    ),
    (
        "MATERIAL_FLAG_METALLIC_ROUGHNESS",
        WgslConst::U32(MATERIAL_FLAG_METALLIC_ROUGHNESS),
    ),
    ("TEXTURE_SLOT_BASE", WgslConst::U32(TEXTURE_SLOT_BASE)),
    (
        "TEXTURE_SLOT_EMISSIVE",
        WgslConst::U32(TEXTURE_SLOT_EMISSIVE),
    ),
    (
        "TEXTURE_SLOT_METAL_ROUGH",
        WgslConst::U32(TEXTURE_SLOT_METAL_ROUGH),
    ),
    ("TEXTURE_SLOT_NORMAL", WgslConst::U32(TEXTURE_SLOT_NORMAL)),
    (
        "TEXTURE_SLOT_OCCLUSION",
        WgslConst::U32(TEXTURE_SLOT_OCCLUSION),
    ),
    ("WRAP_CLAMP", WgslConst::U32(WRAP_CLAMP)),
    ("WRAP_MIRROR", WgslConst::U32(WRAP_MIRROR)),
];

/// The WGSL prelude: one `const` line per entry of [`WGSL_CONSTS`].
pub(crate) fn wgsl_prelude() -> String {
    let mut out = String::from("// generated from consts.rs; do not edit\n");
    for (name, value) in WGSL_CONSTS {
        let line = match value {
            WgslConst::U32(v) => format!("const {name}: u32 = {v}u;\n"),
            WgslConst::F32(v) => format!("const {name}: f32 = {v:?};\n"),
        };
        out.push_str(&line);
    }
    out
}

/// The timed passes' labels that code outside the pass reads (the frame's assignment span,
/// the benchmark's cell-bounds figures and claims): constants, so a renamed pass cannot
/// silently un-measure them.
pub mod pass_labels {
    /// Every light-assignment pass's label starts with this (`FinishedFrame::assign_gpu_ms`).
    pub const ASSIGN_PREFIX: &str = "assign:";
    /// The cell-bounds kernel's pass (`cell_bounds.wgsl`): each cell's sample depth range.
    pub const CELL_BOUNDS: &str = "assign: cell bounds";
    /// The MSAA fragment-bounds render pass (`fragment_bounds.wgsl`) that widens cell bounds to
    /// where forward fragments will look their cells up.
    pub const FRAGMENT_BOUNDS: &str = "assign: fragment bounds";
    /// The culler's copy of the caller's lights, camera-relative, with their bounding spheres.
    pub const CULL_LIGHTS: &str = "assign: lights";
    pub(crate) const DEPTH_RANGE: &str = "assign: depth range";
}
