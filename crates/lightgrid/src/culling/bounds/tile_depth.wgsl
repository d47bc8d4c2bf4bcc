// Per-tile depth min/max over a depth texture, every sample of it (`DepthTexture` and SAMPLES
// from `shader/msaa.wgsl`: with MSAA the bounds hold every sample, tiled-shading §2.1), for a
// workgroup of TILE_THREADS x TILE_THREADS invocations striding over one tile (any tile size).
// The background (`is_background`: no geometry) is ignored; a tile without samples returns
// min > max. Positive floats order like their bit patterns, so workgroup u32 atomics do the
// reduction.

var<workgroup> tile_depth_min: atomic<u32>;
var<workgroup> tile_depth_max: atomic<u32>;

// Must be called from uniform control flow by the whole workgroup.
fn reduce_tile_depth(depth_tex: DepthTexture, tile: vec2<u32>, tile_size: u32, lid: vec2<u32>, li: u32) -> vec2<f32> {
    if (li == 0u) {
        atomicStore(&tile_depth_min, bitcast<u32>(1.0));
        atomicStore(&tile_depth_max, 0u);
    }
    workgroupBarrier();
    let dims = textureDimensions(depth_tex);
    let origin = tile * tile_size;
    var lo = 1.0;
    var hi = 0.0;
    var y = lid.y;
    for (; y < tile_size; y = y + TILE_THREADS) {
        var x = lid.x;
        for (; x < tile_size; x = x + TILE_THREADS) {
            let p = origin + vec2<u32>(x, y);
            if (p.x < dims.x && p.y < dims.y) {
                // Sample s (level 0 of a single-sample texture).
                for (var s = 0u; s < SAMPLES; s = s + 1u) {
                    let d = textureLoad(depth_tex, p, s);
                    if (!is_background(d)) {
                        lo = min(lo, d);
                        hi = max(hi, d);
                    }
                }
            }
        }
        check_loop(x, tile_size);
    }
    check_loop(y, tile_size);
    atomicMin(&tile_depth_min, bitcast<u32>(lo));
    atomicMax(&tile_depth_max, bitcast<u32>(hi));
    workgroupBarrier();
    return vec2<f32>(bitcast<f32>(atomicLoad(&tile_depth_min)), bitcast<f32>(atomicLoad(&tile_depth_max)));
}
