// Outputs of a deferred compute pass (group 3): HDR colour (or, for the tiled light
// pre-pass, its irradiance) and the per-pixel lighting-computation count.

@group(3) @binding(0) var out_color: texture_storage_2d<rgba16float, write>;
@group(3) @binding(1) var out_count: texture_storage_2d<r32float, write>;

fn write_sample(p: vec2<u32>, color: vec3<f32>, count: u32) {
    write_output(p, vec4<f32>(color, 1.0), count);
}

fn write_output(p: vec2<u32>, value: vec4<f32>, count: u32) {
    textureStore(out_color, p, value);
    textureStore(out_count, p, vec4<f32>(f32(count), 0.0, 0.0, 0.0));
}
