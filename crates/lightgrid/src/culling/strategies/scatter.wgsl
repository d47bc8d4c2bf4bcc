// GPU scatter (forward-plus §4): each light finds the cells it overlaps (the tiles under its
// projected sphere, the depth slices its view-depth interval spans, kept where the cell's
// sample bounds overlap that interval) and emits (cell, light) pairs; the pairs are
// radix-sorted by cell and each cell's offset and count read off the sorted keys. The test is
// the CPU assignment's, line for line (`assign_cpu.rs`), so that is this stage's CPU twin.
// A light's work is spread over one invocation per tile of its rectangle, so no invocation
// loops over more than one tile's slices (a light covering the screen would otherwise run a
// loop of tiles x slices iterations, past llvmpipe's loop guard):
// 1. rect_main: per light, its tile rectangle and the number of tiles in it (items);
// 2. (prefix sum of the items: item offsets and the total);
// 3. items_args_main: indirect dispatch arguments for one invocation per item;
// 4. emit_main: per item, find its light (binary search of the offsets), test the tile's
//    slices, append pairs at an atomic cursor (COUNTER_PAIRS_NEEDED); pairs past the end of
//    the pair buffer (sized from earlier frames) are counted (COUNTER_PAIRS_OUT_OF_ROOM);
// 5. pad_main: keys past the emitted pairs become 0xffffffff, so they sort last;
// 6. (radix sort of the whole pair buffer by cell);
// 7. bounds_main / counts_main: each cell's (offset, count) from the sorted keys.
// Each kernel's pipeline layout holds only the bindings it uses (`scatter.rs` `KERNELS`):
// all of them together are 12 storage buffers, each kernel's at most WebGPU's default 8.

@group(2) @binding(0) var<storage, read_write> light_items: array<u32>;
@group(2) @binding(1) var<storage, read_write> item_offsets: array<u32>;
@group(2) @binding(2) var<storage, read_write> pair_keys: array<u32>;
@group(2) @binding(3) var<storage, read_write> pair_vals: array<u32>;
@group(2) @binding(4) var<storage, read_write> item_total: array<u32>;
@group(2) @binding(5) var<storage, read_write> light_rects: array<vec4<i32>>;

// The workgroup size assign_bindings.wgsl's helpers stride by.
const WORKGROUP_SIZE: u32 = ASSIGN_THREADS;

fn flat_index(gid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return gid.y * nwg.x * ASSIGN_THREADS + gid.x;
}

// 1. The light's tile rectangle (x0 > x1: none) and its number of tiles.
@compute @workgroup_size(ASSIGN_THREADS)
fn rect_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let l = flat_index(gid, nwg);
    if (l >= frame.light_count) {
        return;
    }
    let b = light_sphere(l);
    let c = (frame.view * vec4<f32>(b.xyz, 1.0)).xyz;
    let rect = light_tiles(c, b.w);
    light_rects[l] = rect;
    var n = 0u;
    if (rect.x <= rect.z && rect.y <= rect.w) {
        n = u32(rect.z - rect.x + 1) * u32(rect.w - rect.y + 1);
    }
    light_items[l] = n;
}

// 3. One invocation per item, folded into two dimensions past 65535 workgroups.
@compute @workgroup_size(1)
fn items_args_main() {
    let blocks = (item_total[0] + ASSIGN_THREADS - 1u) / ASSIGN_THREADS;
    let x = min(max(blocks, 1u), 65535u);
    atomicStore(&frame_counters[COUNTER_ITEM_ARGS], x);
    atomicStore(&frame_counters[COUNTER_ITEM_ARGS + 1u], (blocks + x - 1u) / x);
    atomicStore(&frame_counters[COUNTER_ITEM_ARGS + 2u], 1u);
    atomicStore(&frame_counters[COUNTER_ITEM_ARGS + 3u], item_total[0]);
}

// Bisection steps that find any light among MAX_LIGHTS (2^20): ceil(log2(2^20 + 1)).
const SEARCH_STEPS: u32 = 21u;

// 4. Item i: the light whose run of items holds i (the last light with offset <= i; lights
// without items share the next light's offset), the tile, and its slices.
@compute @workgroup_size(ASSIGN_THREADS)
fn emit_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat_index(gid, nwg);
    if (i >= atomicLoad(&frame_counters[COUNTER_ITEM_ARGS + 3u])) {
        return;
    }
    var lo = 0u;
    var hi = frame.light_count;
    var step = 0u;
    for (; step < SEARCH_STEPS; step = step + 1u) {
        if (lo < hi) {
            let mid = (lo + hi) / 2u;
            if (item_offsets[mid] <= i) {
                lo = mid + 1u;
            } else {
                hi = mid;
            }
        }
    }
    check_loop(step, SEARCH_STEPS);
    let l = lo - 1u;
    let rect = light_rects[l];
    let k = i - item_offsets[l];
    let width = u32(rect.z - rect.x + 1);
    let tile = u32(rect.y + i32(k / width)) * light_grid.tiles_x + u32(rect.x + i32(k % width));

    let light = light_cull(l);
    let b = light.sphere;
    let c = (frame.view * vec4<f32>(b.xyz, 1.0)).xyz;
    let radius = b.w;
    let w_min = -c.z - b.w;
    let w_max = -c.z + b.w;
    // Spots culled by their cone test it against each cell's sphere, as assign_cpu does.
    let by_cone = frame.spot_cull != 0u && light.cos_outer > POINT_LIGHT_COS;
    // A spot's sector box must overlap a cell's tight box too (the sphere's box otherwise,
    // which the sphere test already implies), as assign_cpu tests.
    let sector = reach_box(l, c, radius);
    let xy = vec2<u32>(tile % light_grid.tiles_x, tile / light_grid.tiles_x);
    let k0 = light_grid_slice(w_min * (1.0 - ASSIGN_DEPTH_SLACK));
    let k1 = light_grid_slice(w_max * (1.0 + ASSIGN_DEPTH_SLACK));
    let tiles = light_grid.tiles_x * light_grid.tiles_y;
    let capacity = arrayLength(&pair_keys);
    // With separate transparent lists the second layer's cells are walked after the first:
    // item s of the loop is slice k0 + s % n of layer s / n.
    let n = k1 - k0 + 1u;
    let steps = n * select(1u, 2u, light_grid.lists == LIGHT_GRID_LISTS_SEPARATE);
    var s = 0u;
    for (; s < steps; s = s + 1u) {
        let cell = (s / n) * light_grid.layer_cells + (k0 + s % n) * tiles + tile;
        let b = cell_bounds[cell];
        let in_depth = b.x <= b.y && w_max >= b.x * (1.0 - ASSIGN_DEPTH_SLACK) && w_min <= b.y * (1.0 + ASSIGN_DEPTH_SLACK);
        let cull = cell_cull(cell);
        let in_cull = depth_mask_meets(cull.mask, w_min, w_max) && sphere_meets_box(cull.lo, cull.hi, c, radius) && box_meets_box(cull.lo, cull.hi, sector[0], sector[1]);
        if (in_depth && in_cull && (!by_cone || cone_margin(light, cone_sphere(tile_frustum(xy, light_grid.tile_size, b).sphere, cull.lo, cull.hi)) >= 0.0)) {
            let slot = atomicAdd(&frame_counters[COUNTER_PAIRS_NEEDED], 1u);
            if (slot < capacity) {
                pair_keys[slot] = cell;
                pair_vals[slot] = l;
            } else {
                atomicAdd(&frame_counters[COUNTER_PAIRS_OUT_OF_ROOM], 1u);
            }
        }
    }
    check_loop(s, steps);
}

// The pairs emitted and kept: the cursor, clamped to the buffer.
fn pair_count() -> u32 {
    return min(atomicLoad(&frame_counters[COUNTER_PAIRS_NEEDED]), arrayLength(&pair_keys));
}

// 5. Keys past the pairs sort last (the sort uses enough bits to hold the cell count itself).
@compute @workgroup_size(ASSIGN_THREADS)
fn pad_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat_index(gid, nwg);
    if (i >= pair_count() && i < arrayLength(&pair_keys)) {
        pair_keys[i] = 0xffffffffu;
    }
}

// 7. After the sort: the first pair of a cell's run writes the cell's offset, the last its end.
@compute @workgroup_size(ASSIGN_THREADS)
fn bounds_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat_index(gid, nwg);
    let n = pair_count();
    if (i >= n) {
        return;
    }
    let cell = pair_keys[i];
    if (i == 0u || pair_keys[i - 1u] != cell) {
        cells[cell].x = i;
    }
    if (i + 1u == n || pair_keys[i + 1u] != cell) {
        cells[cell].y = i + 1u;
    }
}

// Then (end, start) -> (offset, count); untouched cells stay (0, 0).
@compute @workgroup_size(ASSIGN_THREADS)
fn counts_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let c = flat_index(gid, nwg);
    if (c < light_grid_cell_total()) {
        cells[c].y = cells[c].y - cells[c].x;
    }
}
