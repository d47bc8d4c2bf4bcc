// The engine example's shader: its own light struct (read by lightgrid's culler in place,
// `LightLayout`), its light function, an opaque and a glass fragment stage. Each writes two
// images: lit from its cell's lights (`light_grid_*`, declared by `LightCuller::wgsl` in front
// of this file) and lit by every light, for the example's per-frame check.

struct Frame { view_proj: mat4x4<f32>, view: mat4x4<f32>, eye: vec3<f32>, light_count: u32 }
// 64 bytes: the culler reads position (32), range (48), direction (16) and cos_outer (28).
struct EngineLight {
    color: vec3<f32>,
    intensity: f32,
    direction: vec3<f32>,
    cos_outer: f32,
    position: vec3<f32>,
    kind: u32,
    range: f32,
    shadow_index: i32,
    pad: vec2<f32>,
}
@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<storage, read> lights: array<EngineLight>;

struct V {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) dist: f32,
}

@vertex fn vs(@location(0) p: vec3<f32>, @location(1) n: vec3<f32>) -> V {
    let view = frame.view * vec4<f32>(p, 1.0);
    return V(frame.view_proj * vec4<f32>(p, 1.0), p, n, -view.z);
}

const SPOT: u32 = 1u;

// The engine's light function: Lambert (two-sided for glass), a falloff to zero at the
// range, a spot's cone.
fn shade(l: EngineLight, v: V, two_sided: bool) -> vec3<f32> {
    let d = l.position - v.world;
    let dist = length(d);
    if (dist >= l.range) { return vec3<f32>(0.0); }
    let x = dist / l.range;
    var n_dot_l = dot(normalize(v.normal), d / dist);
    if (two_sided) { n_dot_l = abs(n_dot_l); }
    var k = (1.0 - x * x) * max(n_dot_l, 0.0);
    if (l.kind == SPOT) {
        k *= smoothstep(l.cos_outer, l.cos_outer + 0.05, dot(-d / dist, l.direction));
    }
    return l.color * l.intensity * k;
}

fn tone(c: vec3<f32>, alpha: f32) -> vec4<f32> { return vec4<f32>(1.0 - exp(-(c + 0.02)), alpha); }

struct Out { @location(0) grid: vec4<f32>, @location(1) all: vec4<f32> }

// The two images of one surface: its cell's lights, and every light (plus `ambient`).
fn lit(v: V, cell: u32, albedo: vec3<f32>, ambient: f32, alpha: f32, two_sided: bool) -> Out {
    var grid = vec3<f32>(0.0);
    var walk = light_grid_walk(cell);
    while (light_grid_next(&walk)) {
        grid += shade(lights[walk.light], v, two_sided);
    }
    var all = vec3<f32>(0.0);
    for (var i = 0u; i < frame.light_count; i++) {
        all += shade(lights[i], v, two_sided);
    }
    return Out(tone((grid + ambient) * albedo, alpha), tone((all + ambient) * albedo, alpha));
}

@fragment fn fs_opaque(v: V) -> Out {
    return lit(v, light_grid_cell(v.clip.xy, v.dist), vec3<f32>(0.8), 0.0, 1.0, false);
}

// Glass over the opaque scene: the lists for transparent surfaces in front of the depth
// (without a depth pre-pass every cell already spans its whole slice: the same call works).
@fragment fn fs_glass(v: V) -> Out {
    return lit(v, light_grid_cell_transparent(v.clip.xy, v.dist), vec3<f32>(0.5, 0.8, 1.0), 0.6, 0.45, true);
}
