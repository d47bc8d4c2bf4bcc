// Group 1 of the GPU light-assignment kernels (gather, BVH traversal, scatter): the grid being
// built, each cell's view-distance bounds (cell_bounds.wgsl) and the count/offset arrays of the
// count -> prefix sum -> write scheme. Rust side: `culling/gpu_assign.rs`.

@group(1) @binding(0) var<uniform> grid: GridParams;
@group(1) @binding(1) var<storage, read> cell_bounds: array<vec2<f32>>;
@group(1) @binding(2) var<storage, read_write> cells: array<vec2<u32>>;   // (offset, count)
@group(1) @binding(3) var<storage, read_write> indices: array<u32>;
// [0]: hits that did not fit their counted list (must stay 0; reported as an error).
@group(1) @binding(4) var<storage, read_write> overflow: array<atomic<u32>, 4>;
@group(1) @binding(5) var<storage, read_write> cell_counts: array<u32>;
@group(1) @binding(6) var<storage, read_write> cell_offsets: array<u32>;
// The cells holding samples and their number (cell_bounds.wgsl); per-cell kernels are
// dispatched indirectly, one workgroup per entry.
@group(1) @binding(7) var<storage, read> occupied_cells: array<u32>;
@group(1) @binding(8) var<storage, read> occupancy: array<u32, 4>;

// The cell a per-cell workgroup works on, or NO_CELL for a workgroup past the end of the
// list (the dispatch is rounded up to whole rows).
const NO_CELL: u32 = 0xffffffffu;
fn cell_of_group(wg: vec3<u32>, nwg: vec3<u32>) -> u32 {
    let i = wg.y * nwg.x + wg.x;
    if (i >= occupancy[0]) {
        return NO_CELL;
    }
    return occupied_cells[i];
}

// The cell's frustum: its tile's side planes and its samples' view-distance bounds (an empty
// frustum for NO_CELL).
fn cell_frustum(c: u32) -> TileFrustum {
    if (c == NO_CELL) {
        return tile_frustum(vec2<u32>(0u), grid.tile_size, vec2<f32>(1.0, 0.0));
    }
    let tile = c % (grid.tiles_x * grid.tiles_y);
    let xy = vec2<u32>(tile % grid.tiles_x, tile / grid.tiles_x);
    return tile_frustum(xy, grid.tile_size, cell_bounds[c]);
}

// Lights found so far for the workgroup's cell (per-cell kernels).
var<workgroup> cell_hits: atomic<u32>;

// Record that `light` is in cell `c`: in the count pass only `cell_hits` grows; in the write
// pass the light goes to that slot of the cell's list, which the count pass sized.
fn record_hit(c: u32, light: u32, write: bool) {
    let slot = atomicAdd(&cell_hits, 1u);
    if (write) {
        if (slot < cell_counts[c]) {
            indices[cell_offsets[c] + slot] = light;
        } else {
            atomicAdd(&overflow[0], 1u);
        }
    }
}

// After a cell's hits are recorded (called by one invocation): the count, or the grid entry.
fn finish_cell(c: u32, hits: u32, write: bool) {
    if (c == NO_CELL) {
        return;
    }
    if (write) {
        cells[c] = vec2<u32>(cell_offsets[c], cell_counts[c]);
    } else {
        cell_counts[c] = hits;
    }
}
