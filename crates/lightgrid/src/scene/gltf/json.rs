//! The part of the glTF 2.0 JSON document lightgrid reads (glTF 2.0 specification, §5
//! "Properties Reference"). Unknown properties are ignored, as the specification asks; every
//! index and count read here is untrusted and checked where it is used (`read.rs`,
//! `import.rs`).

use serde::Deserialize;
use std::collections::BTreeMap;

#[derive(Deserialize, Default)]
#[serde(default, rename_all = "camelCase")]
pub(super) struct Root {
    pub asset: Option<Asset>,
    pub extensions_used: Vec<String>,
    pub extensions_required: Vec<String>,
    pub scene: Option<usize>,
    pub scenes: Vec<SceneDef>,
    pub nodes: Vec<Node>,
    pub meshes: Vec<MeshDef>,
    pub accessors: Vec<Accessor>,
    pub buffer_views: Vec<BufferView>,
    pub buffers: Vec<BufferDef>,
    pub materials: Vec<MaterialDef>,
    pub textures: Vec<TextureDef>,
    pub images: Vec<ImageDef>,
    pub samplers: Vec<SamplerDef>,
    pub cameras: Vec<CameraDef>,
    /// Read only to say they are not applied (`unread.rs`).
    pub skins: Vec<serde_json::Value>,
    pub animations: Vec<serde_json::Value>,
    pub extensions: Option<RootExtensions>,
    /// `extras.lightgrid.lighting`: a scene lightgrid exported keeps its lighting
    /// conventions (`scene::Lighting`).
    pub extras: Option<serde_json::Value>,
}

#[derive(Deserialize, Default)]
#[serde(default)]
pub(super) struct Asset {
    pub version: String,
}

#[derive(Deserialize, Default)]
#[serde(default)]
pub(super) struct SceneDef {
    pub nodes: Vec<usize>,
}

#[derive(Deserialize, Default)]
#[serde(default)]
pub(super) struct Node {
    pub children: Vec<usize>,
    pub matrix: Option<[f32; 16]>,
    pub translation: Option<[f32; 3]>,
    pub rotation: Option<[f32; 4]>,
    pub scale: Option<[f32; 3]>,
    pub mesh: Option<usize>,
    pub camera: Option<usize>,
    pub extensions: Option<NodeExtensions>,
    pub skin: Option<usize>,
    /// Morph target weights of the node's mesh (read to say they are not applied).
    pub weights: Option<Vec<f32>>,
}

#[derive(Deserialize, Default)]
#[serde(default)]
pub(super) struct NodeExtensions {
    #[serde(rename = "KHR_lights_punctual")]
    pub lights: Option<NodeLight>,
}

#[derive(Deserialize)]
pub(super) struct NodeLight {
    pub light: usize,
}

#[derive(Deserialize, Default)]
#[serde(default)]
pub(super) struct MeshDef {
    pub primitives: Vec<Primitive>,
    /// Default morph target weights (read to say they are not applied).
    pub weights: Option<Vec<f32>>,
}

#[derive(Deserialize, Default)]
#[serde(default)]
pub(super) struct Primitive {
    pub attributes: BTreeMap<String, usize>,
    pub indices: Option<usize>,
    pub material: Option<usize>,
    /// 0 points, 1 lines, 2 line loop, 3 line strip, 4 triangles (the default), 5 triangle
    /// strip, 6 triangle fan.
    pub mode: Option<u32>,
    /// Morph targets (read to say they are not applied).
    pub targets: Vec<serde_json::Value>,
}

#[derive(Deserialize, Default)]
#[serde(default, rename_all = "camelCase")]
pub(super) struct Accessor {
    pub buffer_view: Option<usize>,
    pub byte_offset: u64,
    pub component_type: u32,
    pub normalized: bool,
    pub count: u64,
    #[serde(rename = "type")]
    pub kind: String,
    pub sparse: Option<Sparse>,
}

#[derive(Deserialize, Default)]
#[serde(default)]
pub(super) struct Sparse {
    pub count: u64,
    pub indices: SparseIndices,
    pub values: SparseValues,
}

#[derive(Deserialize, Default)]
#[serde(default, rename_all = "camelCase")]
pub(super) struct SparseIndices {
    pub buffer_view: usize,
    pub byte_offset: u64,
    pub component_type: u32,
}

#[derive(Deserialize, Default)]
#[serde(default, rename_all = "camelCase")]
pub(super) struct SparseValues {
    pub buffer_view: usize,
    pub byte_offset: u64,
}

#[derive(Deserialize, Default)]
#[serde(default, rename_all = "camelCase")]
pub(super) struct BufferView {
    pub buffer: usize,
    pub byte_offset: u64,
    pub byte_length: u64,
    pub byte_stride: Option<u64>,
}

#[derive(Deserialize, Default)]
#[serde(default, rename_all = "camelCase")]
pub(super) struct BufferDef {
    pub uri: Option<String>,
    pub byte_length: u64,
}

#[derive(Deserialize, Default)]
#[serde(default, rename_all = "camelCase")]
pub(super) struct MaterialDef {
    pub pbr_metallic_roughness: Option<Pbr>,
    pub emissive_factor: Option<[f32; 3]>,
    pub emissive_texture: Option<TextureRef>,
    /// Read only to say they are not applied (`unread.rs`).
    pub normal_texture: Option<TextureRef>,
    pub occlusion_texture: Option<TextureRef>,
    pub extensions: Option<MaterialExtensions>,
    pub alpha_mode: Option<String>,
    pub alpha_cutoff: Option<f32>,
    pub extras: Option<serde_json::Value>,
}

#[derive(Deserialize, Default)]
#[serde(default, rename_all = "camelCase")]
pub(super) struct Pbr {
    pub base_color_factor: Option<[f32; 4]>,
    pub base_color_texture: Option<TextureRef>,
    pub metallic_factor: Option<f32>,
    pub roughness_factor: Option<f32>,
    /// Read only to say it is not applied (`unread.rs`).
    pub metallic_roughness_texture: Option<TextureRef>,
}

#[derive(Deserialize, Default)]
#[serde(default)]
pub(super) struct MaterialExtensions {
    #[serde(rename = "KHR_materials_emissive_strength")]
    pub emissive_strength: Option<EmissiveStrength>,
}

#[derive(Deserialize, Default)]
#[serde(default, rename_all = "camelCase")]
pub(super) struct EmissiveStrength {
    pub emissive_strength: Option<f32>,
}

#[derive(Deserialize, Default)]
#[serde(default, rename_all = "camelCase")]
pub(super) struct TextureRef {
    pub index: usize,
    pub tex_coord: u32,
    /// `normalTexture.scale`.
    pub scale: Option<f32>,
    /// `occlusionTexture.strength`.
    pub strength: Option<f32>,
    pub extensions: Option<TextureRefExtensions>,
}

impl TextureRef {
    /// The texture coordinate set read: KHR_texture_transform's `texCoord` overrides the
    /// reference's own.
    pub fn set(&self) -> u32 {
        (self.extensions.as_ref())
            .and_then(|e| e.transform.as_ref())
            .and_then(|t| t.tex_coord)
            .unwrap_or(self.tex_coord)
    }
}

#[derive(Deserialize, Default)]
#[serde(default)]
pub(super) struct TextureRefExtensions {
    #[serde(rename = "KHR_texture_transform")]
    pub transform: Option<TextureTransform>,
}

#[derive(Deserialize, Default)]
#[serde(default, rename_all = "camelCase")]
pub(super) struct TextureTransform {
    pub offset: Option<[f32; 2]>,
    pub rotation: Option<f32>,
    pub scale: Option<[f32; 2]>,
    pub tex_coord: Option<u32>,
}

#[derive(Deserialize, Default)]
#[serde(default)]
pub(super) struct TextureDef {
    pub source: Option<usize>,
    pub sampler: Option<usize>,
}

#[derive(Deserialize, Default)]
#[serde(default, rename_all = "camelCase")]
pub(super) struct SamplerDef {
    /// 10497 repeat (the default), 33071 clamp, 33648 mirrored repeat.
    pub wrap_s: Option<u32>,
    pub wrap_t: Option<u32>,
    /// 9728 NEAREST, 9729 LINEAR; the minification filter's NEAREST_MIPMAP_* too.
    pub mag_filter: Option<u32>,
    pub min_filter: Option<u32>,
}

#[derive(Deserialize, Default)]
#[serde(default, rename_all = "camelCase")]
pub(super) struct ImageDef {
    pub uri: Option<String>,
    pub buffer_view: Option<usize>,
    pub mime_type: Option<String>,
}

#[derive(Deserialize, Default)]
#[serde(default)]
pub(super) struct CameraDef {
    #[serde(rename = "type")]
    pub kind: String,
    pub perspective: Option<Perspective>,
}

#[derive(Deserialize, Default)]
#[serde(default, rename_all = "camelCase")]
pub(super) struct Perspective {
    pub yfov: f32,
    pub znear: f32,
    pub zfar: Option<f32>,
    pub aspect_ratio: Option<f32>,
}

#[derive(Deserialize, Default)]
#[serde(default)]
pub(super) struct RootExtensions {
    #[serde(rename = "KHR_lights_punctual")]
    pub lights: Option<LightsExt>,
}

#[derive(Deserialize, Default)]
#[serde(default)]
pub(super) struct LightsExt {
    pub lights: Vec<LightDef>,
}

#[derive(Deserialize, Default)]
#[serde(default)]
pub(super) struct LightDef {
    pub color: Option<[f32; 3]>,
    pub intensity: Option<f32>,
    #[serde(rename = "type")]
    pub kind: String,
    pub range: Option<f32>,
    pub spot: Option<SpotDef>,
    pub extras: Option<serde_json::Value>,
}

#[derive(Deserialize, Default)]
#[serde(default, rename_all = "camelCase")]
pub(super) struct SpotDef {
    pub inner_cone_angle: Option<f32>,
    pub outer_cone_angle: Option<f32>,
}
