// Tight cells (`--cell-box on`, `cell_box.rs`): each occupied cell's view-space box of its
// samples' pixel footprints, tested against a light's sphere exactly (the closest point) and
// against a spot's sector box (or a BVH node's box) by overlap. A cell's record is CellCull:
// its 2.5D depth mask (depth_mask.wgsl) and the box's corners, lo.w = 1 when it has a box.

struct CellCull {
    mask: vec4<u32>,
    lo: vec4<f32>,
    hi: vec4<f32>,
}

// No mask and no box.
fn cell_cull_none() -> CellCull {
    return CellCull(depth_mask_none(), vec4<f32>(0.0), vec4<f32>(0.0));
}

// The range of n / scale * w over n in {n0, n1} and w in {w0, w1} (CPU twin: `view_extent`).
fn view_extent(n0: f32, n1: f32, scale: f32, w0: f32, w1: f32) -> vec2<f32> {
    let a = n0 / scale;
    let b = n1 / scale;
    let v = vec4<f32>(a * w0, a * w1, b * w0, b * w1);
    return vec2<f32>(min(min(v.x, v.y), min(v.z, v.w)), max(max(v.x, v.y), max(v.z, v.w)));
}

// The view-space (x, y) extent of the pixel rectangle [x.x, x.y] × [y.x, y.y] (pixel edges)
// over view distances [w0, w1]: (x lo, x hi, y lo, y hi). CPU twin: `rect_box`.
fn rect_extent(x: vec2<f32>, y: vec2<f32>, w0: f32, w1: f32) -> vec4<f32> {
    let size = frame.viewport;
    // NDC shifted by an off-centre projection's proj[2].xy (ndc + shift = p00 x / w).
    let sx = frame.proj[2][0];
    let sy = frame.proj[2][1];
    let ex = view_extent(x.x / size.x * 2.0 - 1.0 + sx, x.y / size.x * 2.0 - 1.0 + sx, frame.proj[0][0], w0, w1);
    let ey = view_extent(1.0 - y.x / size.y * 2.0 + sy, 1.0 - y.y / size.y * 2.0 + sy, frame.proj[1][1], w0, w1);
    return vec4<f32>(ex, ey);
}

// Signed floats as u32s that order as the floats do (for atomicMin / atomicMax).
fn ordered_bits(x: f32) -> u32 {
    let b = bitcast<u32>(x);
    return select(b | 0x80000000u, ~b, (b & 0x80000000u) != 0u);
}

fn from_ordered_bits(u: u32) -> f32 {
    return bitcast<f32>(select(~u, u & 0x7fffffffu, (u & 0x80000000u) != 0u));
}

// Does the sphere (c, r) reach the box (lo, hi)? (true without a box: lo.w == 0)
fn sphere_meets_box(lo: vec4<f32>, hi: vec4<f32>, c: vec3<f32>, r: f32) -> bool {
    if (lo.w == 0.0) {
        return true;
    }
    let d = max(max(lo.xyz - c, vec3<f32>(0.0)), c - hi.xyz);
    return dot(d, d) <= r * r;
}

// Does the box [a, b] overlap the box (lo, hi)? (true without a box)
fn box_meets_box(lo: vec4<f32>, hi: vec4<f32>, a: vec3<f32>, b: vec3<f32>) -> bool {
    return lo.w == 0.0 || (all(a <= hi.xyz) && all(b >= lo.xyz));
}
