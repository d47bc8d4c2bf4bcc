// tiled_deferred_single with MSAA (tiled-shading §7 and §2.1; tiled-deferred-tricks: edge
// detection, per-sample shading of the edge pixels, their redistribution over the workgroup).
//
// As the single-sample kernel (tiled_deferred_single.wgsl): one workgroup of TILE_THREADS x
// TILE_THREADS invocations per block of a tile, one pixel per invocation; the tile's depth
// bounds, here over every sample; all lights culled against the tile's frustum into
// workgroup memory TILE_LIGHT_BATCH at a time (nothing dropped). Then, as the grid kernel
// (tiled_deferred_msaa.wgsl), edge-aware: each invocation tests its pixel with the shared
// edge test (`differs`, passes/msaa_edges.wgsl) and shades it once, at its centre from the
// samples' mean depth, or at sample 0 for an edge pixel. An edge pixel's other covered
// samples are queued in workgroup memory before the first batch; every invocation takes
// queued samples in turn (li, li + GROUP_PIXELS, ...: at most SAMPLES - 1 each) and shades
// them with each batch beside its own pixel, their sums held in registers across the
// batches. Outputs (per-sample colours or the in-kernel resolve) are msaa_sample_outputs.wgsl.
//
// Loops: an invocation runs, per batch, at most TILE_LIGHT_BATCH / GROUP_PIXELS culling steps
// and n light steps for its pixel and for each queued sample it took (n: the batch's lights
// in the tile), so at most SAMPLES times the single-sample kernel's light steps where a block
// is all edges; a workload past llvmpipe's loop guard is counted (`check_loop`), and the frame
// refused.
// Workgroup memory: the batch (4 KiB), the queue (1 KiB per sample above the first) and the
// in-kernel resolve's sums (2 KiB): 13 KiB at 8x, within WebGPU's default 16 KiB; 16x needs
// 21 KiB, which native adapters offer (the device takes the adapter's limits).
// Counts: every shading point of the tile loops the tile's whole list, added to its pixel in
// the per-pixel counts (`count_pixel`); the frame counters get edge pixels, samples shaded and samples with geometry,
// as the grid kernel's.

@group(1) @binding(0) var<uniform> tile: LightGridParams;

// The queue of edge samples and the counts: msaa_edge_queue.wgsl.
const GROUP_WIDTH: u32 = TILE_THREADS;

fn msaa_depth(p: vec2<u32>, s: u32) -> f32 {
    return textureLoad(gb_depth, p, s);
}

// An edge pixel's sample without geometry: black.
fn background_sample(p: vec2<u32>, l: u32, s: u32) {
    output_sample(p, l, s, vec3<f32>(0.0), 1.0 / f32(SAMPLES));
}

var<workgroup> batch: array<u32, TILE_LIGHT_BATCH>;
var<workgroup> batch_count: atomic<u32>;

// Sample `s` of pixel `p` at framebuffer position `xy` and depth-buffer value `depth`.
fn surface_at(p: vec2<u32>, s: u32, xy: vec2<f32>, depth: f32) -> Surface {
    return apply_material(raw_surface_from_gbuffer(p, s, position_from_screen(xy, depth)));
}

// Queued sample `item`'s surface, in the block at `origin`.
fn queued_surface(origin: vec2<u32>, item: u32) -> Surface {
    let q = queued_pixel(origin, item);
    let s = queued_sample(item);
    return surface_at(q, s, vec2<f32>(q) + sample_position(s), textureLoad(gb_depth, q, s));
}

@compute @workgroup_size(TILE_THREADS, TILE_THREADS)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    clear_resolve(li);
    clear_edge_queue(li);
    // Workgroup (tile, block): blocks per tile edge, the block's first pixel and this
    // invocation's pixel.
    let blocks = (tile.tile_size + TILE_THREADS - 1u) / TILE_THREADS;
    let tile_xy = wg.xy / blocks;
    let block = (wg.xy % blocks) * TILE_THREADS;
    let origin = tile_xy * tile.tile_size + block;
    let local = block + lid.xy;
    let p = origin + lid.xy;
    let screen = vec2<u32>(frame.viewport);

    // 1. Depth bounds of the whole tile over every sample (its barrier orders the clears).
    let range = reduce_tile_depth(gb_depth, tile_xy, tile.tile_size, lid.xy, li);

    // 2. The tile's frustum in view space (empty when the tile has no samples).
    let f = tile_frustum(tile_xy, tile.tile_size, depth_to_w_range(range));

    // 3. This invocation's pixel: the edge test, its one shading point, its queued samples.
    let inside = local.x < tile.tile_size && local.y < tile.tile_size && p.x < screen.x && p.y < screen.y;
    var edge = false;
    var first = false;
    var s0: Surface;
    var view0 = vec3<f32>(0.0);
    if (inside) {
        let d0 = textureLoad(gb_depth, p, 0);
        let n0 = textureLoad(gb_normal, p, 0);
        var geometry = 0u;
        var depth_sum = 0.0;
        for (var s = 0u; s < SAMPLES; s = s + 1u) {
            let d = textureLoad(gb_depth, p, s);
            geometry += select(1u, 0u, is_background(d));
            depth_sum += d;
            edge = edge || (s > 0u && differs(p, s, d0, n0));
        }
        if (!is_background(d0)) {
            if (edge) {
                s0 = surface_at(p, 0u, vec2<f32>(p) + sample_position(0u), d0);
            } else {
                // The samples' mean depth is the centre's (tiled_deferred_msaa.wgsl).
                s0 = surface_at(p, 0u, vec2<f32>(p) + vec2<f32>(0.5), depth_sum / f32(SAMPLES));
            }
            view0 = view_dir_to(s0.position);
            first = true;
        }
        enqueue_pixel(p, li, edge, first, geometry);
    }
    let n_queued = workgroupUniformLoad(&queued);

    // 4. Cull a batch of lights into workgroup memory, shade this invocation's pixel and its
    // queued samples with it, repeat.
    var acc0 = vec3<f32>(0.0);
    var taken_acc: array<vec3<f32>, SAMPLES - 1u>;
    var count = 0u;
    var start = 0u;
    for (; start < frame.light_count; start = start + TILE_LIGHT_BATCH) {
        if (li == 0u) {
            atomicStore(&batch_count, 0u);
        }
        workgroupBarrier();
        var i = li;
        for (; i < TILE_LIGHT_BATCH; i = i + GROUP_PIXELS) {
            let l = start + i;
            if (l < frame.light_count && light_in_tile(f, l)) {
                batch[atomicAdd(&batch_count, 1u)] = l;
            }
        }
        check_loop(i, TILE_LIGHT_BATCH);
        workgroupBarrier();
        let n = atomicLoad(&batch_count);
        if (first) {
            var j = 0u;
            for (; j < n; j = j + 1u) {
                acc0 += shade_light(s0, view0, batch[j]);
            }
            check_loop(j, n);
        }
        if (n > 0u) {
            var k = 0u;
            var t = li;
            for (; t < n_queued; t = t + GROUP_PIXELS) {
                let surface = queued_surface(origin, queue[t]);
                let view_dir = view_dir_to(surface.position);
                var j = 0u;
                for (; j < n; j = j + 1u) {
                    taken_acc[k] += shade_light(surface, view_dir, batch[j]);
                }
                check_loop(j, n);
                k = k + 1u;
            }
            check_loop(t, n_queued);
        }
        count += n;
        workgroupBarrier();
    }
    check_loop(start, frame.light_count);

    // 5. Output: the pixel, then the samples this invocation took.
    if (inside) {
        var c0 = vec3<f32>(0.0);
        if (first) {
            c0 = surface_base(s0) + acc0;
            count_pixel(p, count);
        }
        output_pixel(p, li, edge, c0);
    }
    var k = 0u;
    var t = li;
    for (; t < n_queued; t = t + GROUP_PIXELS) {
        let item = queue[t];
        let q = queued_pixel(origin, item);
        let color = surface_base(queued_surface(origin, item)) + taken_acc[k];
        output_sample(q, queued_local(item), queued_sample(item), color, 1.0 / f32(SAMPLES));
        count_pixel(q, count);
        k = k + 1u;
    }
    check_loop(t, n_queued);
    finish_resolve(p, li, inside);
    report_edge_counts(li, n_queued);
}
