// Group 1 of the GPU light-assignment kernels (gather, BVH walk, scatter): the grid being
// built, each cell's view-distance bounds (cell_bounds.wgsl), the occupied-cell list, and the
// counters of the single-pass scheme the per-cell kernels use (Rust side: gpu_assign.rs):
// a workgroup appends its cell's lights to a workgroup-memory list, then reserves the cell's
// range of the global index list with one atomicAdd on a cursor and copies the list there.
// A cell with more than CELL_LIST_CAPACITY lights keeps its reservation and is queued for the
// spill pass, which writes its whole list straight to global memory. A reservation past the
// end of the index buffer is counted; the CPU, reading the frame counters back (without
// waiting, a frame later), grows the buffer to the cursor and reports the frame as one whose
// lists did not fit (an analysis run grows and reruns it at once). The counters are group 0's
// `frame_counters` (slots COUNTER_* from consts.rs).

@group(1) @binding(0) var<uniform> light_grid: LightGridParams;
@group(1) @binding(1) var<storage, read> cell_bounds: array<vec2<f32>>;
@group(1) @binding(2) var<storage, read_write> cells: array<vec2<u32>>;   // (offset, count)
@group(1) @binding(3) var<storage, read_write> indices: array<u32>;
// The cell lists (cell_bounds.wgsl): [0] the number of cells holding samples, from [4]
// those cells (per-cell kernels are dispatched indirectly, one workgroup per entry), and
// from `spill_base()` the cells whose lists overflowed the workgroup list (the spill pass's).
// One buffer keeps gather within WebGPU's 8 storage buffers per stage.
@group(1) @binding(4) var<storage, read_write> cell_lists: array<u32>;
// Each cell's 2.5D depth mask and tight box (cell_box.wgsl; neither unless `--depth-mask on`
// / `--cell-box on`).
@group(1) @binding(5) var<storage, read> cell_culls: array<CellCull>;

// Where the spill list starts: the second half of `cell_lists` after its 4-word header (the
// buffer holds at least 4 + 2 x the cell count words: `CellBoundsPass::ensure`).
fn spill_base() -> u32 {
    return 4u + (arrayLength(&cell_lists) - 4u) / 2u;
}

// Cell c's culling record: a grid without masks or boxes binds one record of neither, which
// every cell reads.
fn cell_cull(c: u32) -> CellCull {
    return cell_culls[min(c, arrayLength(&cell_culls) - 1u)];
}

// The cell a per-cell workgroup works on, or NO_CELL for a workgroup past the end of its list
// (the dispatch is rounded up to whole rows). `spill`: the spill pass's list.
const NO_CELL: u32 = 0xffffffffu;
fn cell_of_group(wg: vec3<u32>, nwg: vec3<u32>, spill: bool) -> u32 {
    let i = wg.y * nwg.x + wg.x;
    if (spill) {
        if (i >= atomicLoad(&frame_counters[COUNTER_SPILLS])) {
            return NO_CELL;
        }
        return cell_lists[spill_base() + i];
    }
    if (i >= cell_lists[0]) {
        return NO_CELL;
    }
    return cell_lists[4u + i];
}

// The cell's frustum: its tile's side planes and its samples' view-distance bounds (an empty
// frustum for NO_CELL).
fn cell_frustum(c: u32) -> TileFrustum {
    if (c == NO_CELL) {
        return tile_frustum(vec2<u32>(0u), light_grid.tile_size, vec2<f32>(1.0, 0.0));
    }
    let tile = c % (light_grid.tiles_x * light_grid.tiles_y);
    let xy = vec2<u32>(tile % light_grid.tiles_x, tile / light_grid.tiles_x);
    var f = tile_frustum(xy, light_grid.tile_size, cell_bounds[c]);
    let cull = cell_cull(c);
    f.mask = cull.mask;
    f.box_lo = cull.lo;
    f.box_hi = cull.hi;
    f.sphere = cone_sphere(f.sphere, cull.lo, cull.hi);
    return f;
}

var<workgroup> cell_hits: atomic<u32>;
var<workgroup> cell_list: array<u32, CELL_LIST_CAPACITY>;
var<workgroup> cell_base: u32;

// Call from uniform control flow before the cell's lights are tested.
fn begin_cell(li: u32) {
    if (li == 0u) {
        atomicStore(&cell_hits, 0u);
    }
    workgroupBarrier();
}

// Light `light` reaches cell `c`: append it to the workgroup list (first pass) or write it to
// the cell's reserved range (spill pass).
fn record_hit(c: u32, light: u32, spill: bool) {
    let slot = atomicAdd(&cell_hits, 1u);
    if (!spill) {
        if (slot < CELL_LIST_CAPACITY) {
            cell_list[slot] = light;
        }
    } else if (slot < cells[c].y) {
        indices[cells[c].x + slot] = light;
    } else {
        atomicAdd(&frame_counters[COUNTER_WRITE_OVERFLOW], 1u);
    }
}

// Call from uniform control flow after every hit is recorded: the first pass reserves the
// cell's range and copies the workgroup list into it (queueing the cell for the spill pass
// when the list was too short).
fn end_cell(c: u32, li: u32, spill: bool) {
    workgroupBarrier();
    let n = atomicLoad(&cell_hits);
    let flush = !spill && c != NO_CELL;
    if (flush && li == 0u) {
        let base = atomicAdd(&frame_counters[COUNTER_INDEX_NEEDED], n);
        if (base + n > arrayLength(&indices)) {
            atomicAdd(&frame_counters[COUNTER_INDEX_OUT_OF_ROOM], n);
            cell_base = NO_CELL;
        } else {
            cell_base = base;
            cells[c] = vec2<u32>(base, n);
            if (n > CELL_LIST_CAPACITY) {
                cell_lists[spill_base() + atomicAdd(&frame_counters[COUNTER_SPILLS], 1u)] = c;
            }
        }
    }
    workgroupBarrier();
    let base = cell_base;
    if (flush && base != NO_CELL && n <= CELL_LIST_CAPACITY) {
        var i = li;
        for (; i < n; i = i + WORKGROUP_SIZE) {
            indices[base + i] = cell_list[i];
        }
        check_loop(i, n);
    }
}

// One invocation: the spill pass's indirect dispatch arguments (x at most 65535).
@compute @workgroup_size(1)
fn spill_args_main() {
    let n = atomicLoad(&frame_counters[COUNTER_SPILLS]);
    let x = min(max(n, 1u), 65535u);
    atomicStore(&frame_counters[COUNTER_SPILL_ARGS], x);
    atomicStore(&frame_counters[COUNTER_SPILL_ARGS + 1u], (n + x - 1u) / x);
    atomicStore(&frame_counters[COUNTER_SPILL_ARGS + 2u], 1u);
}
