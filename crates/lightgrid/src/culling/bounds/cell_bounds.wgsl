// cell_bounds: one workgroup per screen tile reduces its samples' view distances into the
// [min, max] of every cell (tile x depth slice) of the tile: an invocation per row of the tile
// reduces it in registers (`bounds_row`), each run of samples in one slice into workgroup
// atomics. A cell without samples gets min > max (+inf, 0). A sample within
// ASSIGN_DEPTH_SLACK of a slice boundary counts for both slices, as the shading pass may place
// it in either. Positive floats order like their bit patterns, so u32 atomics do the
// reduction. CPU twin: `cell_bounds_cpu` (cell_bounds.rs).
// Cells with samples are also appended to the occupied-cell list of `cell_lists` (in no
// particular order), and args_main turns their number into indirect dispatch arguments, so
// the per-cell assignment kernels run one workgroup per occupied cell instead of one per cell.

// With MSAA every sample of every pixel (tiled-forward-shading §4.6: the bounds cover every
// sample a fragment may shade).
@group(1) @binding(0) var depth_tex: DepthTexture;
@group(1) @binding(1) var<uniform> light_grid: LightGridParams;
@group(1) @binding(2) var<storage, read_write> bounds_out: array<vec2<f32>>;
// The cell lists (`CellBoundsPass::lists_buffer`): [0] the occupied cells' number, [1..4] the
// workgroup counts for dispatch_workgroups_indirect, from [4] the occupied cells; the second
// half of what follows is the assignment kernels' spill list (assign_bindings.wgsl). One
// buffer keeps the assignment kernels within WebGPU's 8 storage buffers per stage.
@group(1) @binding(3) var<storage, read_write> cell_lists: array<atomic<u32>>;
// With MSAA, the bounds of the fragments each cell's shading will look up
// (`fragment_bounds.wgsl`: (0xffffffff - min bits, max bits), zero = none); unused without.
@group(1) @binding(4) var<storage, read> fragment_bounds: array<u32>;
// Each cell's culling record (cell_box.wgsl): with DEPTH_MASK (`--depth-mask on`) its 2.5D
// depth mask (depth_mask.wgsl), the bins of its bounds that hold samples, found by a second
// sweep over the tile once the bounds are known; with CELL_BOX (`--cell-box on`) the
// view-space box of its samples' pixel footprints, reduced in the first sweep; for the
// transparent layer of separate lists neither. Without either (CELL_CULLS false) the buffer
// holds one record of neither, which every cell reads, and the kernel writes nothing.
@group(1) @binding(5) var<storage, read_write> cell_culls: array<CellCull>;

#if CELL_BOX
// Per slice of the tile: the view-space x and y extent of its samples' pixel footprints, as
// ordered bits (cell_box.wgsl); x0 > x1 while the slice has no sample.
var<workgroup> box_x0: array<atomic<u32>, MAX_SLICES>;
var<workgroup> box_x1: array<atomic<u32>, MAX_SLICES>;
var<workgroup> box_y0: array<atomic<u32>, MAX_SLICES>;
var<workgroup> box_y1: array<atomic<u32>, MAX_SLICES>;

// Includes a box given as ordered bits (x0, x1, y0, y1) in slice k's.
fn box_include(k: u32, e: vec4<u32>) {
    atomicMin(&box_x0[k], e.x);
    atomicMax(&box_x1[k], e.y);
    atomicMin(&box_y0[k], e.z);
    atomicMax(&box_y1[k], e.w);
}

// A sample of pixel p at view distance w: its pixel at its distance widened by the slack, as
// ordered bits (x0, x1, y0, y1). CPU twin: `cell_boxes_cpu`.
fn sample_box(w: f32, p: vec2<u32>) -> vec4<u32> {
    let q = vec2<f32>(p);
    let e = rect_extent(vec2<f32>(q.x, q.x + 1.0), vec2<f32>(q.y, q.y + 1.0), w * (1.0 - ASSIGN_DEPTH_SLACK), w * (1.0 + ASSIGN_DEPTH_SLACK));
    return vec4<u32>(ordered_bits(e.x), ordered_bits(e.y), ordered_bits(e.z), ordered_bits(e.w));
}

// Slice k's cell box: its samples' footprints and, over `extra` (a range of what is not a
// sample: MSAA forward fragments, a shared list's transparent fragments), the tile whose
// pixels start at `origin`; its depth from the cell's bounds `b`, widened by the slack.
// None (lo.w == 0) for a cell without samples.
fn slice_box(k: u32, b: vec2<f32>, extra: vec2<f32>, origin: vec2<u32>) -> array<vec4<f32>, 2> {
    let x0 = atomicLoad(&box_x0[k]);
    let x1 = atomicLoad(&box_x1[k]);
    var has = x0 <= x1;
    var e = vec4<f32>(from_ordered_bits(x0), from_ordered_bits(x1), from_ordered_bits(atomicLoad(&box_y0[k])), from_ordered_bits(atomicLoad(&box_y1[k])));
    if (extra.x <= extra.y) {
        let lo = vec2<f32>(origin);
        let hi = min(lo + vec2<f32>(f32(light_grid.tile_size)), frame.viewport);
        let t = rect_extent(vec2<f32>(lo.x, hi.x), vec2<f32>(lo.y, hi.y), extra.x * (1.0 - ASSIGN_DEPTH_SLACK), extra.y * (1.0 + ASSIGN_DEPTH_SLACK));
        let u = vec4<f32>(min(e.x, t.x), max(e.y, t.y), min(e.z, t.z), max(e.w, t.w));
        e = select(t, u, has);
        has = true;
    }
    if (!has || b.x > b.y) {
        return array<vec4<f32>, 2>(vec4<f32>(0.0), vec4<f32>(0.0));
    }
    return array<vec4<f32>, 2>(
        vec4<f32>(e.x, e.z, -b.y * (1.0 + ASSIGN_DEPTH_SLACK), 1.0),
        vec4<f32>(e.y, e.w, -b.x * (1.0 - ASSIGN_DEPTH_SLACK), 0.0),
    );
}
#endif

#if DEPTH_MASK
// Per slice of the tile: the mask's (lo, inv) as bits, and the bins holding samples.
var<workgroup> mask_scale: array<vec2<u32>, MAX_SLICES>;
var<workgroup> mask_bits: array<atomic<u32>, MAX_SLICES>;

// The bins of `span`, inflated by the slack as a sample is, in slice k's mask (none when the
// span is empty).
fn mask_span(k: u32, span: vec2<f32>) -> u32 {
    if (span.x > span.y) {
        return 0u;
    }
    let m = vec4<u32>(0u, mask_scale[k].x, mask_scale[k].y, 0u);
    return depth_mask_span(span.x * (1.0 - ASSIGN_DEPTH_SLACK), span.y * (1.0 + ASSIGN_DEPTH_SLACK), m);
}

// 2. Row `row` of the tile's samples: each sample's bins in the slices its distance (with the
// slack) lies in, as in the first sweep; the bins of a run of samples in one slice are ORed in
// registers and set with one atomic when the slice changes (as `bounds_row`'s runs).
fn mask_row(origin: vec2<u32>, row: u32, width: u32) {
    var k = NO_SLICE;
    var bits = 0u;
    var x = 0u;
    for (; x < width; x = x + 1u) {
        let p = origin + vec2<u32>(x, row);
        for (var s = 0u; s < SAMPLES; s = s + 1u) {
            let d = textureLoad(depth_tex, p, s);
            if (!is_background(d)) {
                let w = view_distance_from_depth(d);
                let k0 = light_grid_slice(w * (1.0 - ASSIGN_DEPTH_SLACK));
                let k1 = light_grid_slice(w * (1.0 + ASSIGN_DEPTH_SLACK));
                if (k0 != k) {
                    if (k != NO_SLICE) {
                        atomicOr(&mask_bits[k], bits);
                    }
                    k = k0;
                    bits = 0u;
                }
                bits = bits | mask_span(k0, vec2<f32>(w, w));
                if (k1 != k0) {
                    atomicOr(&mask_bits[k1], mask_span(k1, vec2<f32>(w, w)));
                }
            }
        }
    }
    check_loop(x, width);
    if (k != NO_SLICE) {
        atomicOr(&mask_bits[k], bits);
    }
}
#endif

#if SUBGROUP_REDUCTION
// `--depth-reduction subgroup`: the invocations' register bounds, one subgroup min/max, and
// one lane per subgroup writes (naga has no subgroupElect): the first active one.
// With CELL_BOX the register box (ordered bits) is reduced the same way.
fn subgroup_reduce(lo: u32, hi: u32, tile_max: u32, e: vec4<u32>, li: u32) {
    let l = subgroupMin(lo);
    let h = subgroupMax(hi);
    let t = subgroupMax(tile_max);
#if CELL_BOX
    let b = vec4<u32>(subgroupMin(e.x), subgroupMax(e.y), subgroupMin(e.z), subgroupMax(e.w));
#endif
    if (li == subgroupBroadcastFirst(li)) {
        atomicMin(&slice_lo[0], l);
        atomicMax(&slice_hi[0], h);
        atomicMax(&tile_hi, t);
#if CELL_BOX
        box_include(0u, b);
#endif
    }
}
#endif

// The empty range (min > max).
// A runtime value: the same bitcast of a constant is a constant infinity, which WGSL
// refuses (Tint, in browsers; naga lets it through).
fn no_range() -> vec2<f32> {
    var bits = W_INFINITY;
    return vec2<f32>(bitcast<f32>(bits), 0.0);
}

// Cell `cell`'s fragment bounds (min > max when none).
fn fragment_range(cell: u32) -> vec2<f32> {
    if (SAMPLES == 1u) {
        return no_range();
    }
    let lo = fragment_bounds[2u * cell];
    if (lo == 0u) {
        return no_range();
    }
    return vec2<f32>(bitcast<f32>(0xffffffffu - lo), bitcast<f32>(fragment_bounds[2u * cell + 1u]));
}

const W_INFINITY: u32 = 0x7f800000u;

var<workgroup> slice_lo: array<atomic<u32>, MAX_SLICES>;
// The tile's opaque maximum, an empty pixel counting as the far plane (transparent lists).
var<workgroup> tile_hi: atomic<u32>;
var<workgroup> slice_hi: array<atomic<u32>, MAX_SLICES>;

// No slice: a run that holds no sample yet.
const NO_SLICE: u32 = 0xffffffffu;

// Distances [lo, hi] (bits) and, with CELL_BOX, box e (ordered bits) into slice k's.
fn include_run(k: u32, lo: u32, hi: u32, e: vec4<u32>) {
    atomicMin(&slice_lo[k], lo);
    atomicMax(&slice_hi[k], hi);
#if CELL_BOX
    box_include(k, e);
#endif
}

// 1. Row `row` of the tile (`width` pixels from `origin`): the slices each sample's view
// distance lies in (with the slack, both when it is near a boundary; with CELL_BOX their
// boxes). Returns the row's maximum distance, an empty pixel counting as the far plane (the
// tile maximum).
// A run, consecutive samples of the row in one slice (run_k), is reduced in registers (the
// distances' bits and, with CELL_BOX, the footprints' box as ordered bits) and included in
// the slice's workgroup bounds with one set of atomics when the slice changes or the row
// ends. A row of a surface mostly stays in one slice, so this takes the workgroup atomics
// from one set per sample to about one per row (lavapipe runs them in software); min and max
// do not depend on the order, so the bounds are those per-sample atomics give.
fn bounds_row(origin: vec2<u32>, row: u32, width: u32) -> u32 {
    var run_k = NO_SLICE;
    var run_lo = 0u;
    var run_hi = 0u;
    var run_box = vec4<u32>(0u);
    var row_hi = 0u;
    var x = 0u;
    for (; x < width; x = x + 1u) {
        let p = origin + vec2<u32>(x, row);
        for (var s = 0u; s < SAMPLES; s = s + 1u) {
            let d = textureLoad(depth_tex, p, s);
            let w = view_distance_from_depth(d);
            row_hi = max(row_hi, bitcast<u32>(select(frame.far, w, !is_background(d))));
            if (!is_background(d)) {
                let bits = bitcast<u32>(w);
                let k0 = light_grid_slice(w * (1.0 - ASSIGN_DEPTH_SLACK));
                let k1 = light_grid_slice(w * (1.0 + ASSIGN_DEPTH_SLACK));
                var e = vec4<u32>(0u);
#if CELL_BOX
                e = sample_box(w, p);
#endif
                if (k0 != run_k) {
                    if (run_k != NO_SLICE) {
                        include_run(run_k, run_lo, run_hi, run_box);
                    }
                    run_k = k0;
                    run_lo = bits;
                    run_hi = bits;
                    run_box = e;
                } else {
                    run_lo = min(run_lo, bits);
                    run_hi = max(run_hi, bits);
                    run_box = vec4<u32>(min(run_box.x, e.x), max(run_box.y, e.y), min(run_box.z, e.z), max(run_box.w, e.w));
                }
                if (k1 != k0) {
                    include_run(k1, bits, bits, e);
                }
            }
        }
    }
    check_loop(x, width);
    if (run_k != NO_SLICE) {
        include_run(run_k, run_lo, run_hi, run_box);
    }
    return row_hi;
}

// Invocations per workgroup: one per row of the grid's tiles (`shader::overrides`; the
// default is the largest tile). Not an invocation per pixel: lavapipe runs every invocation of
// a workgroup through its barriers, idle or not.
override CELL_THREADS: u32 = MAX_TILE_SIZE;

@compute @workgroup_size(CELL_THREADS)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    var k0 = li;
    for (; k0 < light_grid.slices; k0 = k0 + CELL_THREADS) {
        atomicStore(&slice_lo[k0], W_INFINITY);
        atomicStore(&slice_hi[k0], 0u);
#if CELL_BOX
        atomicStore(&box_x0[k0], 0xffffffffu);
        atomicStore(&box_x1[k0], 0u);
        atomicStore(&box_y0[k0], 0xffffffffu);
        atomicStore(&box_y1[k0], 0u);
#endif
    }
    check_loop(k0, light_grid.slices);
    if (li == 0u) {
        atomicStore(&tile_hi, 0u);
    }
    workgroupBarrier();
    let size = textureDimensions(depth_tex);
    let origin = wg.xy * light_grid.tile_size;
    // The tile's pixels that are on the screen.
    let extent = min(vec2<u32>(light_grid.tile_size), size - min(origin, size));
    // `--depth-reduction subgroup` on a tiled grid: this invocation's samples in registers
    // (bit patterns, ordered as the distances are), reduced across the subgroup below.
    let registers = SUBGROUP_REDUCTION && light_grid.slices == 1u;
    if (registers) {
        var lo = W_INFINITY;
        var hi = 0u;
        var t_hi = 0u;
        var e = vec4<u32>(0xffffffffu, 0u, 0xffffffffu, 0u);
        let pixels = extent.x * extent.y;
        var i = li;
        for (; i < pixels; i = i + CELL_THREADS) {
            let p = origin + vec2<u32>(i % extent.x, i / extent.x);
            for (var s = 0u; s < SAMPLES; s = s + 1u) {
                let d = textureLoad(depth_tex, p, s);
                let w = view_distance_from_depth(d);
                t_hi = max(t_hi, bitcast<u32>(select(frame.far, w, !is_background(d))));
                if (!is_background(d)) {
                    lo = min(lo, bitcast<u32>(w));
                    hi = max(hi, bitcast<u32>(w));
#if CELL_BOX
                    // Registers only on a tiled grid: every sample is in slice 0.
                    let b = sample_box(w, p);
                    e = vec4<u32>(min(e.x, b.x), max(e.y, b.y), min(e.z, b.z), max(e.w, b.w));
#endif
                }
            }
        }
        check_loop(i, pixels);
#if SUBGROUP_REDUCTION
        subgroup_reduce(lo, hi, t_hi, e, li);
#endif
    } else if (li < extent.y) {
        // One invocation per row of the tile (CELL_THREADS is at least the tile size).
        atomicMax(&tile_hi, bounds_row(origin, li, extent.x));
    }
    workgroupBarrier();
    let tile = wg.y * light_grid.tiles_x + wg.x;
    let tiles = light_grid.tiles_x * light_grid.tiles_y;
    var k = li;
    for (; k < light_grid.slices; k = k + CELL_THREADS) {
        let cell = k * tiles + tile;
        // What the cell's list serves besides its samples: MSAA forward fragments' range and,
        // with one shared list, the range transparent fragments may lie in.
        let fragments = fragment_range(cell);
        var shared_transparent = no_range();
        if (light_grid.lists != LIGHT_GRID_LISTS_OPAQUE) {
            let t = transparent_bounds(k, bitcast<f32>(atomicLoad(&tile_hi)));
            if (light_grid.lists == LIGHT_GRID_LISTS_SHARED) {
                shared_transparent = t;
            } else {
                write_bounds(light_grid.layer_cells + cell, bounds_union(t, fragment_range(light_grid.layer_cells + cell)));
            }
        }
        var b = vec2<f32>(bitcast<f32>(atomicLoad(&slice_lo[k])), bitcast<f32>(atomicLoad(&slice_hi[k])));
        b = bounds_union(bounds_union(b, fragments), shared_transparent);
        write_bounds(cell, open_bounds(k, b));
#if CELL_BOX
        // `--cell-box` needs both bounds too, so `b` is the cell's bounds.
        let bx = slice_box(k, b, bounds_union(fragments, shared_transparent), origin);
        cell_culls[cell].lo = bx[0];
        cell_culls[cell].hi = bx[1];
#else
#if CELL_CULLS
        cell_culls[cell].lo = vec4<f32>(0.0);
        cell_culls[cell].hi = vec4<f32>(0.0);
#endif
#endif
#if DEPTH_MASK
        // 1. The mask's bins over the cell's bounds (`--depth-mask` needs both bounds, so these
        // are `b`); what is not a sample (MSAA forward fragments, the transparent part of a
        // shared list) sets every bin of its range.
        let inv = select(0.0, f32(DEPTH_MASK_BINS) / (b.y - b.x), b.y > b.x);
        mask_scale[k] = vec2<u32>(bitcast<u32>(b.x), bitcast<u32>(inv));
        atomicStore(&mask_bits[k], mask_span(k, fragments) | mask_span(k, shared_transparent));
#else
#if CELL_CULLS
        cell_culls[cell].mask = depth_mask_none();
#endif
#endif
#if CELL_CULLS
        if (light_grid.lists == LIGHT_GRID_LISTS_SEPARATE) {
            cell_culls[light_grid.layer_cells + cell] = cell_cull_none();
        }
#endif
    }
    check_loop(k, light_grid.slices);
#if DEPTH_MASK
    workgroupBarrier();
    if (li < extent.y) {
        mask_row(origin, li, extent.x);
    }
    workgroupBarrier();
    // 3. The masks.
    var mk = li;
    for (; mk < light_grid.slices; mk = mk + CELL_THREADS) {
        let sc = mask_scale[mk];
        cell_culls[mk * tiles + tile].mask = vec4<u32>(atomicLoad(&mask_bits[mk]), sc.x, sc.y, 0u);
    }
    check_loop(mk, light_grid.slices);
#endif
}

fn write_bounds(cell: u32, b: vec2<f32>) {
    bounds_out[cell] = b;
    if (b.x <= b.y) {
        atomicStore(&cell_lists[4u + atomicAdd(&cell_lists[0], 1u)], cell);
    }
}

// `--depth-bounds` (DEPTH_BOUNDS, from the kernel's key `CellBoundsKey`): one side of an occupied
// cell's bounds opened to its slice's end, or (none) every cell given its whole slice.
// Twin: `open_bounds` in cell_bounds.rs.
fn open_bounds(k: u32, b: vec2<f32>) -> vec2<f32> {
    if (DEPTH_BOUNDS == DEPTH_BOUNDS_BOTH) {
        return b;
    }
    let span = slice_span(k);
    if (DEPTH_BOUNDS == DEPTH_BOUNDS_NONE) {
        return bounds_union(b, span);
    }
    if (b.x > b.y) {
        return b;
    }
    if (DEPTH_BOUNDS == DEPTH_BOUNDS_MIN) {
        return vec2<f32>(b.x, max(b.y, span.y));
    }
    return vec2<f32>(min(b.x, span.x), b.y);
}

// The view-distance range of slice k, within near..far.
fn slice_span(k: u32) -> vec2<f32> {
    var lo = frame.near;
    var hi = frame.far;
    if (light_grid.slices > 1u) {
        if (k > 0u) {
            lo = max(lo, exp((f32(k) - light_grid.slice_bias) / light_grid.slice_scale));
        }
        if (k + 1u < light_grid.slices) {
            hi = min(hi, exp((f32(k + 1u) - light_grid.slice_bias) / light_grid.slice_scale));
        }
    }
    return vec2<f32>(lo, hi);
}

// Where transparent fragments of slice k can lie in a tile whose opaque maximum is
// `tile_max`: in front of it, behind the near plane, inside the slice's range widened by
// twice the slack (the fragment's slice is computed in f32). Twin: `transparent_bounds`.
fn transparent_bounds(k: u32, tile_max: f32) -> vec2<f32> {
    let span = slice_span(k);
    let lo = max(frame.near, span.x * (1.0 - 2.0 * ASSIGN_DEPTH_SLACK));
    let hi = min(tile_max, span.y * (1.0 + 2.0 * ASSIGN_DEPTH_SLACK));
    if (lo > hi) {
        return no_range();
    }
    return vec2<f32>(lo, hi);
}

// The smallest range holding both (either may be empty: min > max).
fn bounds_union(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    if (a.x > a.y) {
        return b;
    }
    if (b.x > b.y) {
        return a;
    }
    return vec2<f32>(min(a.x, b.x), max(a.y, b.y));
}

// One invocation: the occupied-cell count as (x, y, 1) workgroups, x at most 65535.
@compute @workgroup_size(1)
fn args_main() {
    let n = atomicLoad(&cell_lists[0]);
    let x = min(max(n, 1u), 65535u);
    atomicStore(&cell_lists[1], x);
    atomicStore(&cell_lists[2], (n + x - 1u) / x);
    atomicStore(&cell_lists[3], 1u);
}
