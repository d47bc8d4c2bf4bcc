// cell_bounds: one workgroup per screen tile reduces its samples' view distances into the
// [min, max] of every cell (tile x depth slice) of the tile; a cell without samples gets
// min > max (+inf, 0). A sample within ASSIGN_DEPTH_SLACK of a slice boundary counts for both
// slices, as the shading pass may place it in either. Positive floats order like their bit
// patterns, so u32 atomics do the reduction. CPU twin: `cell_bounds_cpu` (cell_bounds.rs).
// Cells with samples are also appended to `occupied_cells` (in no particular order), and
// args_main turns their number into indirect dispatch arguments, so the per-cell assignment
// kernels run one workgroup per occupied cell instead of one per cell.

@group(1) @binding(0) var depth_tex: texture_depth_2d;
@group(1) @binding(1) var<uniform> grid: GridParams;
@group(1) @binding(2) var<storage, read_write> bounds_out: array<vec2<f32>>;
@group(1) @binding(3) var<storage, read_write> occupied_cells: array<u32>;
// [0]: occupied cells; [1..4]: workgroup counts for dispatch_workgroups_indirect.
@group(1) @binding(4) var<storage, read_write> occupancy: array<atomic<u32>, 4>;

const W_INFINITY: u32 = 0x7f800000u;

var<workgroup> slice_lo: array<atomic<u32>, MAX_SLICES>;
var<workgroup> slice_hi: array<atomic<u32>, MAX_SLICES>;

fn include_sample(k: u32, bits: u32) {
    atomicMin(&slice_lo[k], bits);
    atomicMax(&slice_hi[k], bits);
}

@compute @workgroup_size(TILE_THREADS, TILE_THREADS)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    var k0 = li;
    for (; k0 < grid.slices; k0 = k0 + TILE_THREADS * TILE_THREADS) {
        atomicStore(&slice_lo[k0], W_INFINITY);
        atomicStore(&slice_hi[k0], 0u);
    }
    check_loop(k0, grid.slices);
    workgroupBarrier();
    let size = textureDimensions(depth_tex);
    let origin = wg.xy * grid.tile_size;
    var y = lid.y;
    for (; y < grid.tile_size; y = y + TILE_THREADS) {
        var x = lid.x;
        for (; x < grid.tile_size; x = x + TILE_THREADS) {
            let p = origin + vec2<u32>(x, y);
            if (p.x < size.x && p.y < size.y) {
                let d = textureLoad(depth_tex, p, 0);
                if (d < 1.0) {
                    let w = view_distance_from_depth(d);
                    let bits = bitcast<u32>(w);
                    let k0 = grid_slice(w * (1.0 - ASSIGN_DEPTH_SLACK));
                    let k1 = grid_slice(w * (1.0 + ASSIGN_DEPTH_SLACK));
                    include_sample(k0, bits);
                    if (k1 != k0) {
                        include_sample(k1, bits);
                    }
                }
            }
        }
        check_loop(x, grid.tile_size);
    }
    check_loop(y, grid.tile_size);
    workgroupBarrier();
    let tile = wg.y * grid.tiles_x + wg.x;
    let tiles = grid.tiles_x * grid.tiles_y;
    var k = li;
    for (; k < grid.slices; k = k + TILE_THREADS * TILE_THREADS) {
        let lo = atomicLoad(&slice_lo[k]);
        let hi = atomicLoad(&slice_hi[k]);
        bounds_out[k * tiles + tile] = vec2<f32>(bitcast<f32>(lo), bitcast<f32>(hi));
        if (lo <= hi) {
            occupied_cells[atomicAdd(&occupancy[0], 1u)] = k * tiles + tile;
        }
    }
    check_loop(k, grid.slices);
}

// One invocation: the occupied-cell count as (x, y, 1) workgroups, x at most 65535.
@compute @workgroup_size(1)
fn args_main() {
    let n = atomicLoad(&occupancy[0]);
    let x = min(max(n, 1u), 65535u);
    atomicStore(&occupancy[1], x);
    atomicStore(&occupancy[2], (n + x - 1u) / x);
    atomicStore(&occupancy[3], 1u);
}
