// GPU gather (forward-plus §4): one workgroup per tile tests all lights against the tile's
// frustum in parallel. Three entry points make the index lists exactly as long as needed
// (sized from counts by a prefix sum, so nothing is ever dropped):
// 1. count_main: lights per tile -> cells[t].y
// 2. scan_main (one workgroup): exclusive prefix sum of the counts -> cells[t].x, and the
//    total -> totals[0]
// 3. write_main: the same test again, each hit appended at cells[t].x + an atomic cursor; a
//    hit past the cell's counted length (impossible unless the two passes disagree) is counted
//    in totals[1] and reported as overflow, never written out of bounds.

@group(1) @binding(0) var<uniform> grid: GridParams;
@group(1) @binding(1) var<storage, read> bounds: array<vec2<f32>>;
@group(1) @binding(2) var<storage, read_write> cells: array<vec2<u32>>;
@group(1) @binding(3) var<storage, read_write> indices: array<u32>;
@group(1) @binding(4) var<storage, read_write> totals: array<atomic<u32>, 2>;

var<workgroup> tile_hits: atomic<u32>;
var<workgroup> partial: array<u32, 256>;

fn gather_frustum(wg: vec2<u32>) -> TileFrustum {
    return tile_frustum(wg, grid.tile_size, bounds[wg.y * grid.tiles_x + wg.x]);
}

@compute @workgroup_size(TILE_THREADS, TILE_THREADS)
fn count_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    if (li == 0u) {
        atomicStore(&tile_hits, 0u);
    }
    workgroupBarrier();
    let f = gather_frustum(wg.xy);
    for (var l = li; l < frame.light_count; l = l + TILE_THREADS * TILE_THREADS) {
        if (light_in_tile(f, lights[l])) {
            atomicAdd(&tile_hits, 1u);
        }
    }
    workgroupBarrier();
    if (li == 0u) {
        cells[wg.y * grid.tiles_x + wg.x].y = atomicLoad(&tile_hits);
    }
}

@compute @workgroup_size(256)
fn scan_main(@builtin(local_invocation_index) li: u32) {
    let n = grid.tiles_x * grid.tiles_y;
    let chunk = (n + 255u) / 256u;
    let first = li * chunk;
    var sum = 0u;
    for (var i = first; i < min(first + chunk, n); i = i + 1u) {
        sum += cells[i].y;
    }
    partial[li] = sum;
    workgroupBarrier();
    // Inclusive Hillis-Steele scan of the 256 chunk sums.
    for (var d = 1u; d < 256u; d = d * 2u) {
        var v = 0u;
        if (li >= d) {
            v = partial[li - d];
        }
        workgroupBarrier();
        partial[li] += v;
        workgroupBarrier();
    }
    var offset = partial[li] - sum;
    for (var i = first; i < min(first + chunk, n); i = i + 1u) {
        cells[i].x = offset;
        offset += cells[i].y;
    }
    if (li == 255u) {
        atomicStore(&totals[0], partial[255]);
        atomicStore(&totals[1], 0u);
    }
}

@compute @workgroup_size(TILE_THREADS, TILE_THREADS)
fn write_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    if (li == 0u) {
        atomicStore(&tile_hits, 0u);
    }
    workgroupBarrier();
    let t = wg.y * grid.tiles_x + wg.x;
    let cell = cells[t];
    let f = gather_frustum(wg.xy);
    for (var l = li; l < frame.light_count; l = l + TILE_THREADS * TILE_THREADS) {
        if (light_in_tile(f, lights[l])) {
            let slot = atomicAdd(&tile_hits, 1u);
            if (slot < cell.y) {
                indices[cell.x + slot] = l;
            } else {
                atomicAdd(&totals[1], 1u);
            }
        }
    }
}
