// tiled_deferred_single (tiled-shading §7, the single-kernel variant): per tile, compute the
// tile's depth bounds, cull all lights against the tile's frustum into workgroup memory, then
// shade the tile's samples. Lights are culled TILE_LIGHT_BATCH at a time, so the workgroup
// list can never overflow and no light is ever dropped.
//
// One workgroup of TILE_THREADS x TILE_THREADS invocations shades one block of that many
// pixels of its tile, one pixel per invocation; a tile larger than TILE_THREADS is covered by
// several workgroups, each reducing the whole tile's depth and culling the whole tile's
// frustum. That repeats the culling per block, but bounds each invocation's loops by its one
// sample's light list (plus the batches), instead of the list times the pixels it would shade
// in a single larger workgroup: a 64-pixel tile with 8,000 lights ran 16 x 8,000 iterations
// per invocation, past llvmpipe's loop guard, and came out black.

@group(1) @binding(0) var<uniform> tile: LightGridParams;

var<workgroup> batch: array<u32, TILE_LIGHT_BATCH>;
var<workgroup> batch_count: atomic<u32>;

@compute @workgroup_size(TILE_THREADS, TILE_THREADS)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    // Workgroup (tile, block): blocks per tile edge, and this invocation's pixel.
    let blocks = (tile.tile_size + TILE_THREADS - 1u) / TILE_THREADS;
    let tile_xy = wg.xy / blocks;
    let local = (wg.xy % blocks) * TILE_THREADS + lid.xy;
    let p = tile_xy * tile.tile_size + local;
    let screen = vec2<u32>(frame.viewport);

    // 1. Depth bounds of the whole tile.
    let range = reduce_tile_depth(gb_depth, tile_xy, tile.tile_size, lid.xy, li);

    // 2. The tile's frustum in view space (empty when the tile has no samples).
    let f = tile_frustum(tile_xy, tile.tile_size, depth_to_w_range(range));

    // 3. This invocation's sample.
    let inside = local.x < tile.tile_size && local.y < tile.tile_size && p.x < screen.x && p.y < screen.y;
    var depth = 0.0;
    if (inside) {
        depth = textureLoad(gb_depth, p, 0);
    }
    let shaded = inside && !is_background(depth);
    var s: Surface;
    var view_dir = vec3<f32>(0.0);
    if (shaded) {
        s = surface_from_gbuffer(p, depth);
        view_dir = view_dir_to(s.position);
    }
    var acc = vec3<f32>(0.0);
    var count = 0u;

    // 4. Cull a batch of lights into workgroup memory, shade with it, repeat.
    var first = 0u;
    for (; first < frame.light_count; first = first + TILE_LIGHT_BATCH) {
        if (li == 0u) {
            atomicStore(&batch_count, 0u);
        }
        workgroupBarrier();
        var i = li;
        for (; i < TILE_LIGHT_BATCH; i = i + TILE_THREADS * TILE_THREADS) {
            let l = first + i;
            if (l < frame.light_count && light_in_tile(f, l)) {
                batch[atomicAdd(&batch_count, 1u)] = l;
            }
        }
        check_loop(i, TILE_LIGHT_BATCH);
        workgroupBarrier();
        let n = atomicLoad(&batch_count);
        if (shaded) {
            var j = 0u;
            for (; j < n; j = j + 1u) {
                acc += shade_light(s, view_dir, batch[j]);
            }
            check_loop(j, n);
            count += n;
        }
        workgroupBarrier();
    }
    check_loop(first, frame.light_count);

    // 5. Write the sample: the light-independent term plus the accumulated lights.
    if (shaded) {
        write_sample(p, textureLoad(gb_base, p, 0).rgb + acc, count);
    } else if (inside) {
        write_sample(p, vec3<f32>(0.0), 0u);
    }
}
