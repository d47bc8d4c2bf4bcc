// The MSAA edge test over a per-sample G-buffer (tiled-deferred-tricks: edge detection), shared
// by the edge-aware deferred kernel (`tiled_deferred_msaa.wgsl`) and the light volumes' edge
// marking (`deferred.wgsl`, `fs_mark_edges`), so both shade the same pixels per sample. Needs
// the G-buffer reader (`gb_depth`, `gb_normal`), `msaa_surfaces.wgsl` (composed before it by
// `MSAA_EDGES_WGSL`) and `shader/msaa.wgsl`'s `sample_position`.

// Do samples 0 and `s` of pixel `p` show different surfaces? Geometry against sky, another
// material, or what `surfaces_differ` tells from normals and planes.
fn differs(p: vec2<u32>, s: u32, d0: f32, n0: vec4<f32>) -> bool {
    let d = textureLoad(gb_depth, p, s);
    if (is_background(d) != is_background(d0)) {
        return true;
    }
    if (is_background(d0)) {
        return false;
    }
    let n = textureLoad(gb_normal, p, s);
    return surfaces_differ(p, s, d0, n0.xyz, d, n.xyz, u32(n.w + 0.5) != u32(n0.w + 0.5));
}
