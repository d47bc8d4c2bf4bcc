// depth_range: where a clustered grid's depth slices go. Spread exponentially over near..far
// (tiled-forward-shading §4.8), a camera with znear 10⁻⁶ and zfar 10⁶ puts nearly every slice
// where no sample is and the clusters degenerate into tiles; spread over the view-distance
// range of the frame's samples, they cut the depth the frame actually has.
// 1. `reduce`: one workgroup per TILE_THREADS² block of pixels with one invocation per row of
//    it, reducing the row's samples in registers; a workgroup min/max in shared memory, one
//    global atomic per workgroup into `range` (view-distance bit patterns: positive floats
//    order like their bits). Rows, not an invocation per pixel with workgroup atomics per
//    sample: lavapipe runs those atomics in software and every invocation of a workgroup
//    through its barriers (2.8 -> 0.8 ms at 640x360).
// 2. `finish` (one invocation): the slicing range, `range` clamped to near..far (near..far
//    when the frame has no samples) and kept at least SLICING_MIN_RATIO wide, written back
//    to `range`, and the grid's parameters with the slices spread over it into `params_out`,
//    which the builder copies over every uniform copy of the grid's parameters.
// CPU twins: `depth_range_cpu` and `slicing_range` (depth_range.rs).

@group(1) @binding(0) var depth_tex: DepthTexture;
@group(1) @binding(1) var<uniform> light_grid: LightGridParams;
@group(1) @binding(2) var<storage, read_write> range: array<atomic<u32>, 2>;
@group(1) @binding(3) var<storage, read_write> params_out: LightGridParams;

const W_INFINITY: u32 = 0x7f800000u;

var<workgroup> wg_lo: atomic<u32>;
var<workgroup> wg_hi: atomic<u32>;

@compute @workgroup_size(TILE_THREADS)
fn reduce(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    if (li == 0u) {
        atomicStore(&wg_lo, W_INFINITY);
        atomicStore(&wg_hi, 0u);
    }
    workgroupBarrier();
    let size = textureDimensions(depth_tex);
    let origin = wg.xy * TILE_THREADS;
    let extent = min(vec2<u32>(TILE_THREADS), size - min(origin, size));
    if (li < extent.y) {
        var lo = W_INFINITY;
        var hi = 0u;
        var x = 0u;
        for (; x < extent.x; x = x + 1u) {
            for (var s = 0u; s < SAMPLES; s = s + 1u) {
                let d = textureLoad(depth_tex, origin + vec2<u32>(x, li), s);
                if (!is_background(d)) {
                    let bits = bitcast<u32>(view_distance_from_depth(d));
                    lo = min(lo, bits);
                    hi = max(hi, bits);
                }
            }
        }
        check_loop(x, extent.x);
        atomicMin(&wg_lo, lo);
        atomicMax(&wg_hi, hi);
    }
    workgroupBarrier();
    if (li == 0u) {
        atomicMin(&range[0], atomicLoad(&wg_lo));
        atomicMax(&range[1], atomicLoad(&wg_hi));
    }
}

@compute @workgroup_size(1)
fn finish() {
    var lo = bitcast<f32>(atomicLoad(&range[0]));
    var hi = bitcast<f32>(atomicLoad(&range[1]));
    if (lo > hi) {
        lo = frame.near;
        hi = frame.far;
    }
    lo = clamp(lo, frame.near, frame.far);
    hi = max(clamp(hi, frame.near, frame.far), lo * SLICING_MIN_RATIO);
    atomicStore(&range[0], bitcast<u32>(lo));
    atomicStore(&range[1], bitcast<u32>(hi));
    // GridDims::slice_params' formula over [lo, hi].
    var p = light_grid;
    let s = f32(light_grid.slices);
    let span = log(hi / lo);
    p.slice_scale = s / span;
    p.slice_bias = -s * log(lo) / span;
    params_out = p;
}
