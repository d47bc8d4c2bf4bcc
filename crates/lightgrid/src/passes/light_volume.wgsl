// Light volumes for the classic deferred family (tiled-shading §1.1, §8): each light's range
// sphere (a mesh that encloses it) rasterized over the screen, or a full-screen triangle for
// a light that spans both the near and the far plane. The instance attribute is the light's
// index in the global light list.

struct VolumeIn {
    @location(0) position: vec3<f32>,  // unit-range sphere vertex (already scaled to enclose)
    @location(1) light: u32,
}

struct VolumeOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) light: u32,
}

// World position of a volume vertex: a unit-sphere vertex scaled to the light's bounding
// sphere, or for a spot up to 45° (light_volumes.rs `cone_volume`) a unit-cone vertex (xy on
// the circle, z the part: 0 apex, 1 the cap's rim, 2 the range) placed around its cone: the
// apex pulled back CONE_VOLUME_MARGIN of the range, a ring at the rim's depth r cos θ and one
// past the range by that margin, both widened by it over r sin θ / cos(π / segments), so the
// polygon holds the circle.
fn volume_position(p: vec3<f32>, l: u32) -> vec3<f32> {
    let light = lights[l];
    if (light.cos_outer < CONE_VOLUME_MIN_COS) {
        let b = light_bounds[l];
        return b.xyz + p * b.w;
    }
    let axis = light.direction;
    let helper = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(axis.x) > 0.9);
    let u = normalize(cross(helper, axis));
    let w = cross(axis, u);
    let r = light.range;
    let sin_outer = sqrt(max(1.0 - light.cos_outer * light.cos_outer, 0.0));
    let grow = 1.0 + CONE_VOLUME_MARGIN;
    let rho = r * sin_outer / cos(3.14159265 / f32(CONE_VOLUME_SEGMENTS)) * grow;
    if (p.z < 0.5) {
        return light.position - axis * (CONE_VOLUME_MARGIN * r);
    }
    let h = select(r * grow, r * light.cos_outer, p.z < 1.5);
    return light.position + axis * h + (u * p.x + w * p.y) * rho;
}

// With MSAA a pixel that two primitives of one draw share (a volume mesh's inner edges; the
// full-screen triangle, which lavapipe cuts along the screen's diagonal) runs one fragment
// for each, over the samples each covers: only the one covering sample 0 counts for it.
fn counts_for_pixel(mask: u32) -> bool {
    return (mask & 1u) != 0u;
}

// The MSAA counts of a pixel that is no edge (one point computed for it), from the fragment
// with coverage `mask`, its samples' depths in `depth`: the point (once per pixel) and the
// covered samples with geometry, as the edge-aware kernels count them.
fn count_pixel_once(depth: DepthTexture, p: vec2<u32>, mask: u32) {
    var geometry = 0u;
    for (var s = 0u; s < SAMPLES; s = s + 1u) {
        let covered = ((mask >> s) & 1u) != 0u;
        geometry += select(0u, 1u, covered && !is_background(textureLoad(depth, p, s)));
    }
    atomicAdd(&frame_counters[COUNTER_GEOMETRY_SAMPLES], geometry);
    if (counts_for_pixel(mask)) {
        atomicAdd(&frame_counters[COUNTER_SHADED_SAMPLES], 1u);
    }
}

// The MSAA counts of sample `i` of an edge pixel: the edge pixel (at its sample 0) and, where
// the sample holds geometry (`depth`), the point computed for it.
fn count_edge_sample(depth: DepthTexture, p: vec2<u32>, i: u32) {
    if (i == 0u) {
        atomicAdd(&frame_counters[COUNTER_EDGE_PIXELS], 1u);
    }
    if (!is_background(textureLoad(depth, p, i))) {
        atomicAdd(&frame_counters[COUNTER_SHADED_SAMPLES], 1u);
        atomicAdd(&frame_counters[COUNTER_GEOMETRY_SAMPLES], 1u);
    }
}

@vertex
fn vs_volume(v: VolumeIn) -> VolumeOut {
    var out: VolumeOut;
    out.clip = frame.view_proj * vec4<f32>(volume_position(v.position, v.light), 1.0);
    out.light = v.light;
    return out;
}

@vertex
fn vs_volume_fullscreen(@builtin(vertex_index) i: u32, @location(1) light: u32) -> VolumeOut {
    var out: VolumeOut;
    out.clip = fullscreen_position(i);
    out.light = light;
    return out;
}

// The volume passes test against a depth-stencil copy of the scene depth (the scene depth
// itself is sampled in the same pass); this writes the copy, sample by sample with MSAA
// (reading `sample_index` makes the fragment run per sample; `DepthTexture` and the sample
// count come from `shader/msaa.wgsl`).
@group(1) @binding(0) var copy_source: DepthTexture;

@fragment
fn fs_copy_depth(@builtin(position) pos: vec4<f32>, @builtin(sample_index) s: u32) -> @builtin(frag_depth) f32 {
    return textureLoad(copy_source, vec2<u32>(pos.xy), s);
}

@vertex
fn vs_copy_depth(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(i);
}

// Full-screen draws of a volume pass after the copy (`LightVolumes::fullscreen_pipeline`).
@vertex
fn vs_fullscreen_volume(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(i);
}
