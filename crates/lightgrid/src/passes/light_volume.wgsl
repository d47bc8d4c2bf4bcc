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

@vertex
fn vs_volume(v: VolumeIn) -> VolumeOut {
    let b = light_bounds[v.light];
    var out: VolumeOut;
    out.clip = frame.view_proj * vec4<f32>(b.xyz + v.position * b.w, 1.0);
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
// itself is sampled in the same pass); this writes the copy.
@group(1) @binding(0) var copy_source: texture_depth_2d;

@fragment
fn fs_copy_depth(@builtin(position) pos: vec4<f32>) -> @builtin(frag_depth) f32 {
    return textureLoad(copy_source, vec2<u32>(pos.xy), 0);
}

@vertex
fn vs_copy_depth(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(i);
}
