// lightgrid's renderer's MSAA fragment bounds (`pipelines/fragment_bounds.rs`): its geometry
// drawn with the shading passes' depth tests (opaque LessEqual against the pre-pass depth,
// transparent Less), each fragment handed to the culler's `light_grid_bound_fragment`
// (`LightCuller::fragment_bounds_wgsl`, composed before this part at group 1).

// Only a centre within near..far is in a cell.
fn bound_fragment(v: VertexOut, transparent: bool) {
    let w = view_distance_from_depth(v.clip.z);
    if (w < frame.near || w > frame.far) {
        return;
    }
    light_grid_bound_fragment(v.clip.xy, w, transparent);
}

// Opaque fragments: their cells in the first layer.
@fragment
#if EARLY_DEPTH_TEST
@early_depth_test(force)
#endif
fn fs_opaque(v: VertexOut) {
    let m = materials[v.material];
    alpha_test(m, m.alpha * base_colour(m, v, tex_coords(v)).a);
    bound_fragment(v, false);
}

// Transparent fragments: the second layer with separate lists, else the one list.
@fragment
#if EARLY_DEPTH_TEST
@early_depth_test(force)
#endif
fn fs_transparent(v: VertexOut) {
    bound_fragment(v, true);
}
