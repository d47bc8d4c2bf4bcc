// HDR -> display: exposure, a simple exponential tone curve, then the sRGB target encodes.
// With MSAA this is also the resolve: each sample is tone-mapped (into [0, 1]) before the
// pixel's samples are averaged (tiled-deferred-tricks, Trick 1: resolving after the tone
// curve keeps a bright sample from swamping an edge).

@group(0) @binding(0) var hdr: SampleTexture;

@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(i);
}

@fragment
fn fs_tonemap(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    var sum = vec3<f32>(0.0);
    for (var s = 0u; s < SAMPLES; s = s + 1u) {
        sum += tone(textureLoad(hdr, p, i32(s)).rgb);
    }
    return vec4<f32>(sum / f32(SAMPLES), 1.0);
}
