// Z-binning (Drobot 2017, "Improved culling for tiled and clustered rendering"), built on the
// GPU by zbin.rs (CPU twin: `zbins_cpu`):
// 1. keys_main: each light's view depth (its bounding sphere's centre) as an order-preserving
//    key, sorted with its index by the radix sort (radix_sort.wgsl); the sorted indices are
//    copied to the front of the grid's index buffer;
// 2. bins_main: one invocation per sorted light widens the index range [first, end) of every
//    depth bin its sphere's view-depth span covers (the grid's slices; atomics, the first
//    stored complemented so both grow with atomicMax from a zeroed buffer), and keeps the
//    light's projected tile rectangle (light_tiles.wgsl);
// 3. masks_main: one invocation per tile and mask word keeps the bit mask of the sorted lights
//    whose rectangle holds the tile and that reach the tile's frustum over the depth range of
//    all its cells' bounds (every slice and layer: opaque samples, transparent fragments and
//    MSAA fragment centres alike).
// A sample shades the set bits of its tile's mask inside its bin's range (light_grid.wgsl).

@group(1) @binding(0) var<uniform> light_grid: LightGridParams;
@group(1) @binding(1) var<storage, read> cell_bounds: array<vec2<f32>>;
// The grid's cell buffer: per bin (~first, end) while building.
@group(1) @binding(2) var<storage, read_write> bins: array<atomic<u32>>;
// The grid's index buffer: the sorted light indices, then the tile masks at grid.zbin_masks.
@group(1) @binding(3) var<storage, read_write> zbin_out: array<u32>;
@group(1) @binding(4) var<storage, read_write> keys: array<u32>;
@group(1) @binding(5) var<storage, read_write> vals: array<u32>;

fn item(gid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return gid.y * nwg.x * ASSIGN_THREADS + gid.x;
}

fn view_sphere(l: u32) -> vec4<f32> {
    let b = light_sphere(l);
    return vec4<f32>((frame.view * vec4<f32>(b.xyz, 1.0)).xyz, b.w);
}

@compute @workgroup_size(ASSIGN_THREADS)
fn keys_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let l = item(gid, nwg);
    if (l >= frame.light_count) {
        return;
    }
    keys[l] = ordered_bits(-view_sphere(l).z);
    vals[l] = l;
    if (l == 0u) {
        // The grid's index entries, reported as every strategy's are.
        let entries = frame.light_count + light_grid.tiles_x * light_grid.tiles_y * light_grid.zbin_words;
        atomicMax(&frame_counters[COUNTER_INDEX_NEEDED], entries);
    }
}

@compute @workgroup_size(ASSIGN_THREADS)
fn bins_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = item(gid, nwg);
    if (i >= frame.light_count) {
        return;
    }
    let s = view_sphere(zbin_out[i]);
    let lo = (-s.z - s.w) * (1.0 - ASSIGN_DEPTH_SLACK);
    let hi = (-s.z + s.w) * (1.0 + ASSIGN_DEPTH_SLACK);
    // The sorted keys and values are spent: they now hold each sorted light's tile rectangle
    // (x0 | x1 << 16, y0 | y1 << 16; x0 > x1: none), the masks' pre-filter.
    keys[i] = 0xffffu;
    vals[i] = 0u;
    // A sphere wholly in front of the near plane or behind the far plane reaches no sample.
    if (hi < frame.near * (1.0 - ASSIGN_DEPTH_SLACK) || lo > frame.far * (1.0 + ASSIGN_DEPTH_SLACK)) {
        return;
    }
    let rect = light_tiles(s.xyz, s.w);
    if (rect.x <= rect.z && rect.y <= rect.w) {
        keys[i] = u32(rect.x) | (u32(rect.z) << 16u);
        vals[i] = u32(rect.y) | (u32(rect.w) << 16u);
    }
    let k1 = light_grid_slice(hi);
    var k = light_grid_slice(lo);
    for (; k <= k1; k = k + 1u) {
        atomicMax(&bins[2u * k], ~i);
        atomicMax(&bins[2u * k + 1u], i + 1u);
    }
    check_loop(k, k1 + 1u);
}

// One invocation per (mask word, tile), neighbouring tiles side by side so that the lanes
// of a SIMD group test the same light: the tile's range is the union of the bounds of its
// cells (every slice and layer), and each of the word's 32 sorted lights whose rectangle
// holds the tile is tested against the tile's frustum over it.
@compute @workgroup_size(ASSIGN_THREADS)
fn masks_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let g = item(gid, nwg);
    let tiles = light_grid.tiles_x * light_grid.tiles_y;
    let words = light_grid.zbin_words;
    if (g >= tiles * words) {
        return;
    }
    let t = g % tiles;
    let word = g / tiles;
    var range = vec2<f32>(3.4e38, -3.4e38);
    let layers = light_grid_cell_total() / tiles;
    var k = 0u;
    for (; k < layers; k = k + 1u) {
        let b = cell_bounds[k * tiles + t];
        if (b.x <= b.y) {
            range = vec2<f32>(min(range.x, b.x), max(range.y, b.y));
        }
    }
    check_loop(k, layers);
    var bits = 0u;
    if (range.x <= range.y) {
        let xy = vec2<u32>(t % light_grid.tiles_x, t / light_grid.tiles_x);
        let f = tile_frustum(xy, light_grid.tile_size, range);
        let first = word * 32u;
        let n = min(32u, frame.light_count - first);
        var j = 0u;
        for (; j < n; j = j + 1u) {
            let rx = keys[first + j];
            let ry = vals[first + j];
            let in_rect = xy.x >= (rx & 0xffffu) && xy.x <= (rx >> 16u)
                && xy.y >= (ry & 0xffffu) && xy.y <= (ry >> 16u);
            if (in_rect && light_in_tile(f, zbin_out[first + j])) {
                bits = bits | (1u << j);
            }
        }
        check_loop(j, n);
    }
    zbin_out[light_grid.zbin_masks + t * words + word] = bits;
}
