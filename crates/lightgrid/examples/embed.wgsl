// The embed example's own shader: its vertex stage, its light function, and a fragment stage
// that loops over its cell's lights (lightgrid's `LightCuller::wgsl` in front of this file
// declares `light_grid_*`) and, for comparison, over every light.

struct Camera { view_proj: mat4x4<f32>, view: mat4x4<f32>, eye: vec3<f32>, count: u32 }
struct MyLight { position: vec3<f32>, range: f32, color: vec4<f32>, direction: vec3<f32>, cos_outer: f32 }
@group(0) @binding(0) var<uniform> camera: Camera;
@group(0) @binding(1) var<storage, read> lights: array<MyLight>;

struct V { @builtin(position) clip: vec4<f32>, @location(0) world: vec3<f32>, @location(1) normal: vec3<f32>, @location(2) dist: f32 }

@vertex fn vs(@location(0) p: vec3<f32>, @location(1) n: vec3<f32>) -> V {
    let view = camera.view * vec4<f32>(p, 1.0);
    return V(camera.view_proj * vec4<f32>(p, 1.0), p, n, -view.z);
}

// This program's light function: Lambert, a falloff to zero at the range, a spot cone.
fn light(l: MyLight, v: V) -> vec3<f32> {
    let d = l.position - v.world;
    let dist = length(d);
    if (dist >= l.range) { return vec3<f32>(0.0); }
    let x = dist / l.range;
    var k = (1.0 - x * x) * max(dot(normalize(v.normal), d / dist), 0.0);
    if (l.cos_outer > -1.5) {
        k *= smoothstep(l.cos_outer, l.cos_outer + 0.05, dot(-d / dist, l.direction));
    }
    return l.color.rgb * l.color.a * k;
}

fn tone(c: vec3<f32>) -> vec4<f32> { return vec4<f32>(1.0 - exp(-(c + 0.02)), 1.0); }

// Both images at once: the cell's lights (lightgrid's grid) and every light.
struct Out { @location(0) grid: vec4<f32>, @location(1) all: vec4<f32> }

@fragment fn fs(v: V) -> Out {
    let cell = light_grid_cell(v.clip.xy, v.dist);
    var grid = vec3<f32>(0.0);
    var walk = light_grid_walk(cell);
    while (light_grid_next(&walk)) {
        grid += light(lights[walk.light], v);
    }
    var all = vec3<f32>(0.0);
    for (var i = 0u; i < camera.count; i++) {
        all += light(lights[i], v);
    }
    return Out(tone(grid), tone(all));
}
