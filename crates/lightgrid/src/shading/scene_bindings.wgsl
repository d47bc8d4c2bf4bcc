// Group 0, identical for every pipeline: the frame uniforms, the global light list
// (tiled-shading §6.2) and the material table.

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
@group(0) @binding(1) var<storage, read> lights: array<Light>;
@group(0) @binding(2) var<storage, read> materials: array<Material>;

// Unit vector from a world-space point to the eye.
fn view_dir_to(world: vec3<f32>) -> vec3<f32> {
    return normalize(frame.camera_pos - world);
}
