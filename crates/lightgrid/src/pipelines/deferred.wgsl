// deferred / deferred_stencil: per light volume fragment, read the G-buffer and add the one
// light's exit radiance (tiled-shading §1.1). Sky samples are discarded before the light
// function runs, so they are not counted.

@fragment
fn fs_light(v: VolumeOut) -> LitOut {
    let p = vec2<u32>(v.clip.xy);
    let depth = textureLoad(gb_depth, p, 0);
    if (is_background(depth)) {
        discard;
    }
    let s = surface_from_gbuffer(p, depth);
    return lit(v.clip, shade_light(s, view_dir_to(s.position), lights[v.light]), 1u);
}

// The light-independent term of every sample, written before the lights add up.
@fragment
fn fs_base(@builtin(position) pos: vec4<f32>) -> LitOut {
    let p = vec2<u32>(pos.xy);
    let depth = textureLoad(gb_depth, p, 0);
    var color = vec3<f32>(0.0);
    if (!is_background(depth)) {
        color = textureLoad(gb_base, p, 0).rgb;
    }
    return lit(pos, color, 0u);
}

@vertex
fn vs_base(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(i);
}
