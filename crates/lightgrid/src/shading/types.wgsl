// Structs shared by every shader. Their Rust twins are in gpu_types.rs; the layout test
// compares the two field by field.

struct Light {
    position: vec3<f32>,
    range: f32,
    color: vec3<f32>,
    intensity: f32,
}

struct Material {
    diffuse: vec3<f32>,
    alpha: f32,
    specular: vec3<f32>,
    shininess: f32,
    emissive: vec3<f32>,
    flags: u32,
    ambient: vec3<f32>,
    _pad: f32,
}

struct FrameUniforms {
    view: mat4x4<f32>,
    proj: mat4x4<f32>,
    view_proj: mat4x4<f32>,
    inv_view_proj: mat4x4<f32>,
    camera_pos: vec3<f32>,
    light_count: u32,
    viewport: vec2<f32>,
    near: f32,
    far: f32,
}

struct GridParams {
    tile_size: u32,
    tiles_x: u32,
    tiles_y: u32,
    slices: u32,
    slice_scale: f32,
    slice_bias: f32,
    _pad0: u32,
    _pad1: u32,
}
