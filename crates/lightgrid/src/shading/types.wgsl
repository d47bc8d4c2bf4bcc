// Structs shared by every shader. Their Rust twins are in gpu_types.rs; the layout test
// compares the two field by field.

// A point light, or a spot (cos_outer > POINT_LIGHT_COS) whose cone limits it further;
// culling uses its bounding sphere, `light_bounds[i]` (scene_bindings.wgsl).
struct Light {
    position: vec3<f32>,
    range: f32,
    radiance: vec3<f32>,
    cos_inner: f32,
    direction: vec3<f32>,
    cos_outer: f32,
}

// What culling reads of a light: the sphere around everything it reaches (centre, radius)
// and its reach (a spot's cone). LightCuller's kernels read one record per light
// (`culling/embed/light_records.wgsl`, written by `cull_lights.wgsl`); the renderer's
// single-kernel tiled deferred pass builds it from its lights and bounds
// (`light_cull_scene.wgsl`).
struct CullRecord {
    sphere: vec4<f32>,
    position: vec3<f32>,
    range: f32,
    direction: vec3<f32>,
    cos_outer: f32,
}

struct Material {
    diffuse: vec3<f32>,
    alpha: f32,
    specular: vec3<f32>,
    shininess: f32,
    emissive: vec3<f32>,
    flags: u32,
    ambient: vec3<f32>,
    paint_power: f32,
    paint: vec3<f32>,
    shader: u32,
    texture: u32,          // layer + 1 in `base_textures`; 0: none
    alpha_cutoff: f32,     // alpha test (glTF MASK); 0: none
    emissive_texture: u32, // layer + 1 in `base_textures`; 0: none
    nearest: u32,          // bit TEXTURE_SLOT_*: the slot is magnified nearest-texel
    // glTF metallic-roughness, per sample where flags has MATERIAL_FLAG_METALLIC_ROUGHNESS
    base: vec3<f32>,
    metallic: f32,
    roughness: f32,
    normal_scale: f32,
    occlusion_strength: f32,
    metal_rough_texture: u32, // layer + 1 (B metallic, G roughness); 0: none
    normal_texture: u32,      // layer + 1 (tangent space); 0: none
    occlusion_texture: u32,   // layer + 1 (R); 0: none
    uv_sets: u32,             // bit TEXTURE_SLOT_*: the slot reads coordinate set 1
    wraps: u32,               // 4 bits per slot: u then v, WRAP_*
    uv_transforms: array<vec4<f32>, 8>, // per slot a 2x3 matrix, 6 floats from 6 * slot
}

struct FrameUniforms {
    view: mat4x4<f32>,
    proj: mat4x4<f32>,
    view_proj: mat4x4<f32>,
    inv_view: mat4x4<f32>,   // view space -> camera-relative space (a rotation)
    eye: vec3<f32>,          // the camera's world position (camera-relative space's origin)
    light_count: u32,
    viewport: vec2<f32>,
    near: f32,
    far: f32,
    spot_cull: u32,
    standard_depth: u32,     // 1: depth 0 at the near plane, 1 (the clear) at the far; 0: reversed-Z
    _pad1: u32,
    _pad2: u32,
}

// The light BVH (culling/strategies/bvh.rs): built by bvh_build.wgsl, walked by bvh.wgsl.
struct BvhNode {
    lo: vec3<f32>,
    first: u32,   // first child node, or for a leaf the first slot of the light order
    hi: vec3<f32>,
    count: u32,   // number of children | BVH_LEAF for a leaf
}

// One pass of the radix sort (radix_sort.wgsl).
struct SortParams {
    n: u32,
    shift: u32,
    blocks: u32,
    _pad: u32,
}

// One level of the GPU BVH build (bvh_build.wgsl).
struct LevelParams {
    first: u32,        // this level's first node
    count: u32,        // its nodes
    child_first: u32,  // the level below's first node
    child_count: u32,  // its nodes (lights, for the leaves)
}
