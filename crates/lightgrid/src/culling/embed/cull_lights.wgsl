// LightCuller's first pass: a caller's lights (world space, in the caller's own struct as
// `LightLayout` describes it; `CullLight`'s by default) into the camera-relative record every
// culling kernel reads (`CullRecord`: the light's reach and its bounding sphere,
// `Light::bounding_sphere`'s formula in f32 as the CPU computes it). A
// light whose position, range or spot cone is not finite, or whose range is not positive, is
// counted (COUNTER_INVALID_LIGHTS) and given a sphere no cell holds: the report says the
// frame lacks it, never a silently wrong grid.

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
// Where a light's fields lie in the caller's buffer, in 4-byte words (`LightLayout::words`).
struct CallerLightLayout {
    stride: u32,
    position: u32,
    range: u32,
    direction: u32,
    cos_outer: u32,
    // 1: the buffer has spot lights (direction and cos_outer); 0: points only.
    spot: u32,
    pad0: u32,
    pad1: u32,
}

@group(0) @binding(1) var<storage, read> caller_lights: array<u32>;
@group(0) @binding(2) var<storage, read_write> records_out: array<CullRecord>;
@group(0) @binding(3) var<storage, read_write> frame_counters: array<atomic<u32>, COUNTER_SLOTS>;
@group(0) @binding(4) var<uniform> caller_layout: CallerLightLayout;

fn caller_f32(word: u32) -> f32 {
    return bitcast<f32>(caller_lights[word]);
}

fn caller_vec3(word: u32) -> vec3<f32> {
    return vec3<f32>(caller_f32(word), caller_f32(word + 1u), caller_f32(word + 2u));
}

// Light `i` of the caller's buffer: what culling reads of it (the rest is the caller's).
fn caller_light(i: u32) -> Light {
    let base = i * caller_layout.stride;
    var l: Light;
    l.position = caller_vec3(base + caller_layout.position);
    l.range = caller_f32(base + caller_layout.range);
    l.radiance = vec3<f32>(0.0);
    l.cos_inner = 0.0;
    l.direction = vec3<f32>(0.0, 0.0, -1.0);
    l.cos_outer = POINT_LIGHT_COS;
    if (caller_layout.spot != 0u) {
        l.direction = caller_vec3(base + caller_layout.direction);
        l.cos_outer = caller_f32(base + caller_layout.cos_outer);
    }
    return l;
}

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
    var l = caller_light(i);
    l.position = l.position - frame.eye;
    if (!light_is_valid(l)) {
        atomicAdd(&frame_counters[COUNTER_INVALID_LIGHTS], 1u);
        // Behind the camera, reaching nothing: no frustum, rectangle or box holds it.
        l.position = (frame.inv_view * vec4<f32>(0.0, 0.0, 1e30, 0.0)).xyz;
        l.range = 0.0;
        l.cos_outer = POINT_LIGHT_COS;
        records_out[i] = CullRecord(vec4<f32>(l.position, 0.0), l.position, l.range, l.direction, l.cos_outer);
        return;
    }
    records_out[i] = CullRecord(light_bounding_sphere(l), l.position, l.range, l.direction, l.cos_outer);
}
