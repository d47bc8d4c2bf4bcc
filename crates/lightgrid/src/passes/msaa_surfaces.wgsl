// The MSAA edge test's core (tiled-deferred-tricks: edge detection), for samples of one pixel
// that both hold geometry: `msaa_edges.wgsl`'s `differs` over the G-buffer (material id in
// the normal's w), and the light pre-pass's `attributes_differ` over its attributes (the
// specular exponent in w: `light_prepass_attributes.wgsl`). Needs `shader/msaa.wgsl`'s
// `sample_position`.

// Pixel `p`'s depth at its centre, where forward shades it, read from `depth`: for a pixel
// that is no edge (one surface over it) the samples' mean, as the standard patterns' positions
// average to the centre and depth is affine over a triangle.
fn centre_depth(depth: DepthTexture, p: vec2<u32>) -> f32 {
    var sum = 0.0;
    for (var s = 0u; s < SAMPLES; s = s + 1u) {
        sum += textureLoad(depth, p, s);
    }
    return sum / f32(SAMPLES);
}

// Do sample 0 (depth `d0`, normal `n0`) and sample `s` (depth `d`, normal `n`) of pixel `p`
// show different surfaces, given whether what each reader stores besides the normal differs
// (`kinds_differ`)? A normal more than ~8 degrees off, or a sample off sample 0's tangent
// plane: its offset from sample 0 leaving the plane by more than EDGE_PLANE_SIN of its length
// (a surface behind another with the same normal). Depth alone cannot tell: one slanted plane
// changes depth by far more than 1% across a pixel of a small frame (measured at 64x36: a
// depth-ratio test marked 90% of the pixels).
fn surfaces_differ(p: vec2<u32>, s: u32, d0: f32, n0: vec3<f32>, d: f32, n: vec3<f32>, kinds_differ: bool) -> bool {
    let normal0 = normalize(n0);
    if (kinds_differ || dot(normalize(n), normal0) < EDGE_NORMAL_COS) {
        return true;
    }
    let p0 = position_from_screen(vec2<f32>(p) + sample_position(0u), d0);
    let offset = position_from_screen(vec2<f32>(p) + sample_position(s), d) - p0;
    return abs(dot(normal0, offset)) > EDGE_PLANE_SIN * length(offset);
}
