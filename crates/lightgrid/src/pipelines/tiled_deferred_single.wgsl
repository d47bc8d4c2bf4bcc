// tiled_deferred_single (tiled-shading §7, the single-kernel variant): one workgroup per tile
// computes the tile's depth bounds, culls all lights against the tile's frustum into
// workgroup memory, then shades the tile's samples. Lights are culled TILE_LIGHT_BATCH at a
// time, so the workgroup list can never overflow and no light is ever dropped.

@group(1) @binding(0) var<uniform> tile: GridParams;

const PIXELS_PER_THREAD: u32 = (MAX_TILE_SIZE / TILE_THREADS) * (MAX_TILE_SIZE / TILE_THREADS);

var<workgroup> batch: array<u32, TILE_LIGHT_BATCH>;
var<workgroup> batch_count: atomic<u32>;

struct TileFrustum {
    planes: array<vec3<f32>, 4>,  // inward normals of the side planes (through the eye)
    w_min: f32,
    w_max: f32,
}

fn light_in_tile(f: TileFrustum, light: Light) -> bool {
    let c = (frame.view * vec4<f32>(light.position, 1.0)).xyz;
    let r = light.range;
    let w = -c.z;
    if (w + r < f.w_min * (1.0 - 1e-4) || w - r > f.w_max * (1.0 + 1e-4)) {
        return false;
    }
    for (var i = 0u; i < 4u; i = i + 1u) {
        if (dot(f.planes[i], c) < -r) {
            return false;
        }
    }
    return true;
}

@compute @workgroup_size(TILE_THREADS, TILE_THREADS)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    // 1. Depth bounds of the tile.
    let range = reduce_tile_depth(gb_depth, wg.xy, tile.tile_size, lid.xy, li);
    let has_samples = range.x <= range.y;

    // 2. The tile's frustum in view space.
    let size = frame.viewport;
    let lo = vec2<f32>(wg.xy * tile.tile_size);
    let hi = min(lo + vec2<f32>(f32(tile.tile_size)), size);
    let ndc_lo = vec2<f32>(lo.x / size.x * 2.0 - 1.0, 1.0 - lo.y / size.y * 2.0);  // left, top
    let ndc_hi = vec2<f32>(hi.x / size.x * 2.0 - 1.0, 1.0 - hi.y / size.y * 2.0);  // right, bottom
    let p00 = frame.proj[0][0];
    let p11 = frame.proj[1][1];
    var f: TileFrustum;
    f.planes[0] = normalize(vec3<f32>(1.0, 0.0, ndc_lo.x / p00));
    f.planes[1] = normalize(vec3<f32>(-1.0, 0.0, -ndc_hi.x / p00));
    f.planes[2] = normalize(vec3<f32>(0.0, 1.0, ndc_hi.y / p11));
    f.planes[3] = normalize(vec3<f32>(0.0, -1.0, -ndc_lo.y / p11));
    f.w_min = view_distance_from_depth(range.x);
    f.w_max = view_distance_from_depth(range.y);

    // 3. This thread's samples: pixels lid + (i, j) * TILE_THREADS of the tile.
    let per_edge = (tile.tile_size + TILE_THREADS - 1u) / TILE_THREADS;
    let origin = wg.xy * tile.tile_size;
    let screen = vec2<u32>(size);
    var acc: array<vec3<f32>, PIXELS_PER_THREAD>;  // WGSL zero-initializes both
    var counts: array<u32, PIXELS_PER_THREAD>;

    // 4. Cull a batch of lights into workgroup memory, shade with it, repeat. The G-buffer is
    //    read once per sample and batch: once, unless a frame has more than TILE_LIGHT_BATCH
    //    lights. (Caching whole surfaces in per-thread arrays instead made the kernel ~10x
    //    slower on lavapipe without a warm shader cache: 5.2 s vs 0.49 s at 640x360.)
    for (var first = 0u; first < frame.light_count; first = first + TILE_LIGHT_BATCH) {
        if (li == 0u) {
            atomicStore(&batch_count, 0u);
        }
        workgroupBarrier();
        for (var i = li; i < TILE_LIGHT_BATCH; i = i + TILE_THREADS * TILE_THREADS) {
            let l = first + i;
            if (has_samples && l < frame.light_count && light_in_tile(f, lights[l])) {
                batch[atomicAdd(&batch_count, 1u)] = l;
            }
        }
        workgroupBarrier();
        let n = atomicLoad(&batch_count);
        for (var k = 0u; k < per_edge * per_edge; k = k + 1u) {
            let local = lid.xy + vec2<u32>(k % per_edge, k / per_edge) * TILE_THREADS;
            let p = origin + local;
            if (n > 0u && local.x < tile.tile_size && local.y < tile.tile_size && p.x < screen.x && p.y < screen.y) {
                let depth = textureLoad(gb_depth, p, 0);
                if (depth < 1.0) {
                    let s = surface_from_gbuffer(p, depth);
                    let view_dir = view_dir_to(s.position);
                    for (var j = 0u; j < n; j = j + 1u) {
                        acc[k] += shade_light(s, view_dir, lights[batch[j]]);
                    }
                    counts[k] += n;
                }
            }
        }
        workgroupBarrier();
    }

    // 5. Write the tile: the light-independent term plus the accumulated lights.
    for (var k = 0u; k < per_edge * per_edge; k = k + 1u) {
        let local = lid.xy + vec2<u32>(k % per_edge, k / per_edge) * TILE_THREADS;
        let p = origin + local;
        if (local.x < tile.tile_size && local.y < tile.tile_size && p.x < screen.x && p.y < screen.y) {
            let depth = textureLoad(gb_depth, p, 0);
            if (depth < 1.0) {
                write_sample(p, textureLoad(gb_base, p, 0).rgb + acc[k], counts[k]);
            } else {
                write_sample(p, vec3<f32>(0.0), 0u);
            }
        }
    }
}
