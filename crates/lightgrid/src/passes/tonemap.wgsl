// HDR -> display: exposure, a simple exponential tone curve, then the sRGB target encodes.

@group(0) @binding(0) var hdr: texture_2d<f32>;

@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(i);
}

@fragment
fn fs_tonemap(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(hdr, vec2<i32>(pos.xy), 0).rgb;
    let mapped = vec3<f32>(1.0) - exp(-max(c, vec3<f32>(0.0)) * EXPOSURE);
    return vec4<f32>(mapped, 1.0);
}
