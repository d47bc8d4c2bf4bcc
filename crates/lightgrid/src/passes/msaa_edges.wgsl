// The MSAA edge test over a per-sample G-buffer (tiled-deferred-tricks: edge detection), shared
// by the edge-aware deferred kernel (`tiled_deferred_msaa.wgsl`) and the light volumes' edge
// marking (`deferred.wgsl`, `fs_mark_edges`), so both shade the same pixels per sample. Needs
// the G-buffer reader (`gb_depth`, `gb_normal`) and `shader::msaa_wgsl`'s `sample_position`.

// Do samples 0 and `s` of pixel `p` show different surfaces? Geometry against sky, another
// material, a normal more than ~8 degrees off, or a sample off sample 0's tangent plane: its
// offset from sample 0 leaving the plane by more than EDGE_PLANE_SIN of its length (a
// surface behind another with the same normal). Depth alone cannot tell: one slanted plane
// changes depth by far more than 1% across a pixel of a small frame (measured at 64x36: a
// depth-ratio test marked 90% of the pixels).
fn differs(p: vec2<u32>, s: u32, d0: f32, n0: vec4<f32>) -> bool {
    let d = textureLoad(gb_depth, p, s);
    if (is_background(d) != is_background(d0)) {
        return true;
    }
    if (is_background(d0)) {
        return false;
    }
    let n = textureLoad(gb_normal, p, s);
    let normal0 = normalize(n0.xyz);
    if (u32(n.w + 0.5) != u32(n0.w + 0.5) || dot(normalize(n.xyz), normal0) < EDGE_NORMAL_COS) {
        return true;
    }
    let p0 = position_from_screen(vec2<f32>(p) + sample_position(0u), d0);
    let offset = position_from_screen(vec2<f32>(p) + sample_position(s), d) - p0;
    return abs(dot(normal0, offset)) > EDGE_PLANE_SIN * length(offset);
}
