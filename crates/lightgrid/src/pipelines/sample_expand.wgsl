// The MSAA deferred kernels' per-sample colours into the multisampled HDR target: run once
// per sample (`sample_index`), so the transparent pass can blend over every sample and the
// tonemap resolve them.

@group(0) @binding(0) var<storage, read> sample_colors: array<vec2<u32>>;

// The frame's width in pixels.
override WIDTH: u32;

@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(i);
}

@fragment
fn fs_expand(@builtin(position) pos: vec4<f32>, @builtin(sample_index) s: u32) -> @location(0) vec4<f32> {
    let p = vec2<u32>(pos.xy);
    let c = sample_colors[(p.y * WIDTH + p.x) * SAMPLES + s];
    return vec4<f32>(unpack2x16float(c.x), unpack2x16float(c.y));
}
