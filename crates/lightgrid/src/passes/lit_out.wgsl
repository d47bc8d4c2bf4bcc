// Output of a lighting fragment shader: colour, and how many times it ran the light function
// (summed by additive blending into the count target).
struct LitOut {
    @location(0) color: vec4<f32>,
    @location(1) count: f32,
}

// `clip`: the fragment's position (`@builtin(position)`).
fn lit(clip: vec4<f32>, color: vec3<f32>, count: u32) -> LitOut {
    if (MULTISAMPLED) {
        count_pixel(vec2<u32>(clip.xy), count);
    }
    var out: LitOut;
    out.color = vec4<f32>(color, 1.0);
    out.count = f32(count);
    return out;
}

// A transparent fragment's output: blended over the image with coverage `alpha`.
fn lit_blended(clip: vec4<f32>, color: vec3<f32>, alpha: f32, count: u32) -> LitOut {
    var out = lit(clip, color, count);
    out.color.a = alpha;
    return out;
}
