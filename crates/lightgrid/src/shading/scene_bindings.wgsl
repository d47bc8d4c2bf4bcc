// Group 0, identical for every pipeline: the frame uniforms, the global light list
// (tiled-shading §6.2) and the material table.

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
@group(0) @binding(1) var<storage, read> lights: array<Light>;
@group(0) @binding(2) var<storage, read> materials: array<Material>;
// Per light, the sphere around everything it reaches (centre, radius): what culling tests.
@group(0) @binding(4) var<storage, read> light_bounds: array<vec4<f32>>;
// The frame counters (slots COUNTER_* from consts.rs), cleared at the start of every frame and
// read back after it: truncated loops, index-list and pair sizes, indirect dispatch arguments.
// With MSAA, per pixel the lighting computations of every pass follow them (row-major from
// slot COUNTER_SLOTS): a fragment shader runs once per pixel and primitive, so a per-sample
// count target cannot count it. One buffer for both keeps group 0 within WebGPU's default
// 8 storage buffers per stage (`gpu/counters.rs`).
@group(0) @binding(3) var<storage, read_write> frame_counters: array<atomic<u32>>;

// Set for pipelines drawing into multisampled targets (MSAA): the count goes to the pixel's
// count after the frame counters instead of the count target (which such a pipeline does not have),
// and a grid fragment checks that its cell holds it (`light_grid_shade_fragment`).
override MULTISAMPLED: bool = false;

// Add `count` lighting computations to pixel `p`'s count (MSAA frames).
fn count_pixel(p: vec2<u32>, count: u32) {
    if (count > 0u) {
        atomicAdd(&frame_counters[COUNTER_SLOTS + p.y * u32(frame.viewport.x) + p.x], count);
    }
}

// No loop ends silently (llvmpipe ends an invocation's loops after 65,536 iterations without a
// word): call after every data-dependent loop with the index it stopped at and its bound; a
// loop that stopped short is counted, and the frame is reported wrong, never passed off as right.
fn check_loop(stopped: u32, bound: u32) {
    if (stopped < bound) {
        atomicAdd(&frame_counters[COUNTER_TRUNCATED_LOOPS], 1u);
    }
}

// Unit vector from a point (camera-relative, as every position on the GPU) to the eye.
fn view_dir_to(position: vec3<f32>) -> vec3<f32> {
    return normalize(-position);
}

// Does a depth-buffer value hold no geometry? Reversed-Z (depth.rs): 1 at the near plane,
// 0 at the far plane and for the cleared background. A LightCuller's caller may use standard
// depth instead (`frame.standard_depth`: 0 at the near plane, 1 at the far and the clear).
fn is_background(depth: f32) -> bool {
    if (frame.standard_depth != 0u) {
        return depth >= 1.0;
    }
    return depth <= 0.0;
}

// Camera-relative position of the sample at the centre of pixel `p` with depth-buffer value
// `depth`.
fn position_from_depth(p: vec2<u32>, depth: f32) -> vec3<f32> {
    return position_from_screen(vec2<f32>(p) + vec2<f32>(0.5), depth);
}

// Camera-relative position of the sample at framebuffer position `xy` (pixels, y down) with
// depth-buffer value `depth`: its view distance from the projection's inverse, then back
// from view space by the inverse rotation. No 4x4 inverse of a projection is involved, so
// a tiny near plane costs no precision.
fn position_from_screen(xy: vec2<f32>, depth: f32) -> vec3<f32> {
    let uv = xy / frame.viewport;
    let w = view_distance_from_depth(depth);
    let ndc = vec2<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0) + vec2<f32>(frame.proj[2][0], frame.proj[2][1]);
    let v = vec3<f32>(ndc.x * w / frame.proj[0][0], ndc.y * w / frame.proj[1][1], -w);
    return (frame.inv_view * vec4<f32>(v, 0.0)).xyz;
}

// View distance (-z in view space) of a depth-buffer value: the inverse of the reversed-Z
// projection's depth = A / w - B, whose coefficients are the projection's z row
// (proj[3][2] = A, proj[2][2] = B; depth.rs computes them in f64). The background (0) maps
// to the far plane. The same inverse holds for a standard-depth perspective projection
// (A < 0 there).
fn view_distance_from_depth(depth: f32) -> f32 {
    return frame.proj[3][2] / (depth + frame.proj[2][2]);
}
