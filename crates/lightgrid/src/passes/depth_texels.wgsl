// Depth read by fragment shaders, for adapters that can neither copy a depth texture to a
// buffer nor `textureLoad` one as depth (wgpu's GL backend: `--adapter gl`, WebGL2): the depth
// target is bound as an unfilterable float texture, which GLSL reads with `texelFetch`.

@group(0) @binding(0) var depth_texels: texture_2d<f32>;

@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(i);
}

// Analysis: each pixel's depth-buffer value, bit for bit, into an R32Uint target (which any
// backend can copy to a buffer).
@fragment
fn fs_depth_bits(@builtin(position) pos: vec4<f32>) -> @location(0) u32 {
    return bitcast<u32>(textureLoad(depth_texels, vec2<i32>(pos.xy), 0).r);
}

// The texture grid's tile depth bounds without compute (tiled-shading §6.3): drawn into a
// target of one texel per tile, the fragment of tile (x, y) loops the tile's pixels (at most
// MAX_TILE_SIZE², within any driver's loop budget) and writes the least and greatest
// depth-buffer values of those holding geometry, as f32 bits (least > greatest: none).
// Reversed-Z (depth.rs): the background is 0; the CPU turns depth into view distance.
override TILE: u32 = 16u;

@fragment
fn fs_tile_depth(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<u32> {
    let size = vec2<u32>(textureDimensions(depth_texels));
    let origin = vec2<u32>(pos.xy) * TILE;
    let end = min(origin + vec2<u32>(TILE), size);
    var lo = 2.0;
    var hi = 0.0;
    for (var y = origin.y; y < end.y; y = y + 1u) {
        for (var x = origin.x; x < end.x; x = x + 1u) {
            let d = textureLoad(depth_texels, vec2<i32>(vec2<u32>(x, y)), 0).r;
            if (d > 0.0) {
                lo = min(lo, d);
                hi = max(hi, d);
            }
        }
    }
    return vec4<u32>(bitcast<u32>(lo), bitcast<u32>(hi), 0u, 0u);
}
