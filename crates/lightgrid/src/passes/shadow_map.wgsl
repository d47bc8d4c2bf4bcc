// The shadow atlas's faces (`--shadows maps`; passes/shadow_atlas.rs): the opaque geometry
// drawn once per tile, the instance index naming the tile whose view-projection
// (shading/shadows.wgsl's layout) takes camera-relative positions to its clip space. Depth
// only, reversed (near / w, nearer is greater).
@group(0) @binding(0) var<uniform> frame: FrameUniforms;
@group(0) @binding(1) var<storage, read> shadow_data: array<vec4<f32>>;

@vertex
fn vs_shadow(@location(0) position: vec3<f32>, @builtin(instance_index) tile: u32) -> @builtin(position) vec4<f32> {
    let at = bitcast<u32>(shadow_data[1].x) + 4u * tile;
    let m = mat4x4<f32>(shadow_data[at], shadow_data[at + 1u], shadow_data[at + 2u], shadow_data[at + 3u]);
    return m * vec4<f32>(position - frame.eye, 1.0);
}
