// LightCuller's first pass: a caller's lights (world space, `CullLight`'s layout, which is
// `Light`'s) into the camera-relative copy every culling kernel reads, and each light's
// bounding sphere (`Light::bounding_sphere`'s formula, in f32 as the CPU computes it). A
// light whose position, range or spot cone is not finite, or whose range is not positive, is
// counted (COUNTER_INVALID_LIGHTS) and given a sphere no cell holds: the report says the
// frame lacks it, never a silently wrong grid.

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
@group(0) @binding(1) var<storage, read> caller_lights: array<Light>;
@group(0) @binding(2) var<storage, read_write> lights_out: array<Light>;
@group(0) @binding(3) var<storage, read_write> bounds_out: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> frame_counters: array<atomic<u32>, COUNTER_SLOTS>;

// Infinity or NaN, by the exponent bits (comparisons with NaN may be folded away).
fn not_finite(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) == 0x7f800000u;
}

fn light_is_valid(l: Light) -> bool {
    let p = l.position;
    let d = l.direction;
    if (not_finite(p.x) || not_finite(p.y) || not_finite(p.z) || not_finite(l.range) || !(l.range > 0.0)) {
        return false;
    }
    if (l.cos_outer == POINT_LIGHT_COS) {
        return true;
    }
    let unit = abs(dot(d, d) - 1.0) < 2e-3;
    return !not_finite(l.cos_outer) && !not_finite(d.x) && !not_finite(d.y) && !not_finite(d.z)
        && unit && l.cos_outer >= -1.0 && l.cos_outer <= 1.0;
}

// The smallest sphere around everything the light reaches (scene/mod.rs `bounding_sphere`).
fn light_bounding_sphere(l: Light) -> vec4<f32> {
    let c = l.cos_outer;
    let r = l.range;
    if (c >= 0.70710677) {
        let t = r / (2.0 * c);
        return vec4<f32>(l.position + l.direction * t, t);
    }
    if (c > 0.0) {
        let s = sqrt(max(1.0 - c * c, 0.0));
        return vec4<f32>(l.position + l.direction * (r * c), r * s);
    }
    return vec4<f32>(l.position, r);
}

@compute @workgroup_size(ASSIGN_THREADS)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.y * nwg.x * ASSIGN_THREADS + gid.x;
    if (i >= frame.light_count) {
        return;
    }
    var l = caller_lights[i];
    l.position = l.position - frame.eye;
    if (!light_is_valid(l)) {
        atomicAdd(&frame_counters[COUNTER_INVALID_LIGHTS], 1u);
        // Behind the camera, reaching nothing: no frustum, rectangle or box holds it.
        l.position = (frame.inv_view * vec4<f32>(0.0, 0.0, 1e30, 0.0)).xyz;
        l.range = 0.0;
        l.cos_outer = POINT_LIGHT_COS;
        lights_out[i] = l;
        bounds_out[i] = vec4<f32>(l.position, 0.0);
        return;
    }
    lights_out[i] = l;
    bounds_out[i] = light_bounding_sphere(l);
}
