//! Every `#[repr(C)]` struct shared with WGSL. Sizes are asserted at compile time here; the
//! `layout` test parses the WGSL with naga and compares every field offset with these.
//! Not an API (public only as `lightgrid::testing::gpu_types`): each field is the WGSL
//! struct's field of the same name, documented there.
#![cfg_attr(feature = "testing", allow(missing_docs))]

use bytemuck::{Pod, Zeroable};

/// A light with a finite range (tiled-shading §1.1): a point light, or a spot light whose
/// cone (`direction`, `cos_outer` < `cos_inner`) limits it further. `radiance` is linear RGB
/// (the colour times the intensity); the light contributes nothing at or beyond `range`, nor
/// outside the outer cone. `cos_outer` = `consts::POINT_LIGHT_COS` marks a point light. 48
/// bytes, what shading reads per light; culling also reads the light's bounding sphere, kept
/// in a buffer of its own (group 0 binding 4, `[centre, radius]` per light,
/// `Light::bounding_sphere`) so shading does not load it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuLight {
    pub position: [f32; 3],
    pub range: f32,
    pub radiance: [f32; 3],
    pub cos_inner: f32,
    pub direction: [f32; 3],
    pub cos_outer: f32,
}

pub use crate::consts::POINT_LIGHT_COS;

/// A Blinn-Phong material. `flags` holds `MATERIAL_FLAG_*` bits.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuMaterial {
    pub diffuse: [f32; 3],
    pub alpha: f32,
    pub specular: [f32; 3],
    pub shininess: f32,
    pub emissive: [f32; 3],
    pub flags: u32,
    pub ambient: [f32; 3],
    /// Exponent of the material shader's view-angle blend (car paint, rim).
    pub paint_power: f32,
    /// The material shader's second colour: car paint's flip colour, the rim colour.
    pub paint: [f32; 3],
    /// `consts::MATERIAL_SHADER_*`.
    pub shader: u32,
    /// Base-colour texture: its layer in the texture array + 1; 0 for none.
    pub texture: u32,
    /// Alpha test: fragments with alpha below are discarded; 0 for none.
    pub alpha_cutoff: f32,
    /// Emissive texture: its layer in the texture array + 1; 0 for none.
    pub emissive_texture: u32,
    /// Bit `slot` set: that texture is magnified nearest-texel (glTF's `magFilter` NEAREST).
    pub nearest: u32,
    /// glTF's metallic-roughness inputs, applied per sample where `flags` has
    /// `MATERIAL_FLAG_METALLIC_ROUGHNESS` (a file's material): the base colour factor, the
    /// metallic and roughness factors; the colours above are what they give untextured.
    pub base: [f32; 3],
    pub metallic: f32,
    pub roughness: f32,
    /// The normal texture's scale (x and y of its tangent-space normal).
    pub normal_scale: f32,
    /// The occlusion texture's strength on the ambient term (0: none, 1: all).
    pub occlusion_strength: f32,
    /// Metallic-roughness texture (B metallic, G roughness): layer + 1; 0 for none.
    pub metal_rough_texture: u32,
    /// Normal texture (tangent space): layer + 1; 0 for none.
    pub normal_texture: u32,
    /// Occlusion texture (R): layer + 1; 0 for none.
    pub occlusion_texture: u32,
    /// Bit `slot` set: that texture reads texture coordinate set 1 (`TEXTURE_SLOT_*`).
    pub uv_sets: u32,
    /// 4 bits per texture slot (bit `4·slot`): wrap along u (2 bits), then v; `WRAP_*`.
    pub wraps: u32,
    /// Per texture slot, the 2×3 matrix of its `KHR_texture_transform`, row-major (u' is
    /// a·u plus b·v plus c, v' is d·u plus e·v plus f), six floats a slot from float
    /// `6·slot`; the identity without one.
    pub uv_transforms: [[f32; 4]; 8],
}

/// One vertex in world space (the CPU bakes object transforms each frame).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuVertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub uv: [f32; 2],
    pub material: u32,
    /// Tangent (xyz, world space) and bitangent sign (w) as signed normalized 16-bit
    /// integers, for normal textures; zero where the mesh has none (and no normal texture
    /// reads it).
    pub tangent: [i16; 4],
    /// Vertex colour (glTF's `COLOR_0`, 0 to 1) as normalized bytes, multiplying the base
    /// colour; white without one.
    pub color: [u8; 4],
    /// Texture coordinate set 1 (set 0 where the mesh has none).
    pub uv1: [f32; 2],
}

/// A unit vector's component as a signed normalized 16-bit integer (`Snorm16`).
pub(crate) fn snorm16(v: f32) -> i16 {
    (v.clamp(-1.0, 1.0) * 32767.0).round() as i16
}

/// A 0-to-1 value as a normalized byte (`Unorm8`).
pub(crate) fn unorm8(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// Per-frame uniforms: camera matrices, viewport and light count. Positions on the GPU are
/// camera-relative (world minus `eye`, world-aligned): `view` is a rotation, and the
/// projection is reversed-Z (`crate::depth`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct FrameUniforms {
    /// Camera-relative space to view space (a rotation).
    pub view: [[f32; 4]; 4],
    pub proj: [[f32; 4]; 4],
    pub view_proj: [[f32; 4]; 4],
    /// View space to camera-relative space (the inverse of `view`, a rotation).
    pub inv_view: [[f32; 4]; 4],
    /// The camera's world position: the vertex stage subtracts it (camera-relative space).
    pub eye: [f32; 3],
    pub light_count: u32,
    pub viewport: [f32; 2],
    pub near: f32,
    pub far: f32,
    /// 1: spot lights are culled by their cone as well as their bounding sphere
    /// (`SpotCull::Cone`); 0: by the sphere only.
    pub spot_cull: u32,
    /// 1: standard depth (0 at the near plane, cleared to 1), as a caller of
    /// `culling::LightCuller` may have; 0: lightgrid's reversed-Z (`depth.rs`).
    pub standard_depth: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

/// The light grid's shape (`culling/grid/light_grid.wgsl`). A tiled grid has one slice.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GridParams {
    pub tile_size: u32,
    pub tiles_x: u32,
    pub tiles_y: u32,
    pub slices: u32,
    /// slice = floor(ln(view distance) * slice_scale + slice_bias), clamped (clusters only).
    pub slice_scale: f32,
    pub slice_bias: f32,
    /// `GridLists::gpu`: 0 opaque, 1 shared, 2 separate (a second layer of cells).
    pub lists: u32,
    /// Cells of one layer (tiles × slices).
    pub layer_cells: u32,
    /// A z-binned grid (`culling/strategies/zbin.rs`): 32-bit words of each tile's light mask; 0 for a
    /// grid of per-cell lists.
    pub zbin_words: u32,
    /// A z-binned grid: where the tile masks start in the index buffer (after the sorted
    /// light indices).
    pub zbin_masks: u32,
    /// Padding (named without a trailing digit or leading underscore: naga_oil imports the
    /// WGSL struct by these names, `LightCuller::naga_oil_module`).
    pub pad_a: u32,
    /// Padding.
    pub pad_b: u32,
}

const _: () = assert!(std::mem::size_of::<GridParams>() == 48);
const _: () = assert!(std::mem::size_of::<GpuLight>() == 48);
// The texture grid stores a light as `LIGHT_TEXELS` Rgba32Float texels.
const _: () = assert!(std::mem::size_of::<GpuLight>() == crate::consts::LIGHT_TEXELS as usize * 16);
const _: () = assert!(std::mem::size_of::<GpuMaterial>() == 272);
const _: () = assert!(std::mem::size_of::<GpuVertex>() == 56);
const _: () = assert!(std::mem::size_of::<FrameUniforms>() == 304);

/// One node of the light BVH: 32 bytes (`BvhNode` in `shading/types.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct BvhNode {
    pub lo: [f32; 3],
    /// First child node, or for a leaf the first slot of `order`.
    pub first: u32,
    pub hi: [f32; 3],
    /// Number of children, `| BVH_LEAF` for a leaf.
    pub count: u32,
}

/// One pass of the radix sort (`SortParams`, `culling/strategies/radix_sort.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SortParams {
    /// Pairs sorted.
    pub n: u32,
    /// Lowest key bit of this pass's 4-bit digit.
    pub shift: u32,
    /// Blocks of ASSIGN_THREADS pairs.
    pub blocks: u32,
    pub _pad: u32,
}

/// One level of the GPU BVH build (`LevelParams`, `culling/strategies/bvh_build.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LevelParams {
    /// This level's first node and its number of nodes.
    pub first: u32,
    pub count: u32,
    /// The level below's first node and its number of nodes (lights for the leaves).
    pub child_first: u32,
    pub child_count: u32,
}

const _: () = assert!(std::mem::size_of::<BvhNode>() == 32);
const _: () = assert!(std::mem::size_of::<SortParams>() == 16);
const _: () = assert!(std::mem::size_of::<LevelParams>() == 16);
