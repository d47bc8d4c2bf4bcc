// tiled_forward / tiled_forward_prez / clustered_forward: forward shading that loops only the
// lights listed for the fragment's cell (tiled-shading §3, Listing 3; clusters: §4.8).

// Early depth test forced: the loop check may write the frame counters (a side effect), and
// a fragment shader with side effects would otherwise be depth-tested after shading, losing
// early-Z (measured on lavapipe: tiled_forward_prez 2-3x slower). Sound here: the shader
// neither discards nor writes depth, so early and late tests keep the same fragments.
@fragment
#if EARLY_DEPTH_TEST
@early_depth_test(force)
#endif
fn fs_main(v: VertexOut, @builtin(front_facing) front: bool) -> LitOut {
    let s = surface_from_vertex(v, front);
    let w = view_distance_from_depth(v.clip.z);
    let cell = light_grid_cell(v.clip.xy, w);
    let color = surface_base(s) + light_grid_shade_fragment(s, view_dir_to(s.position), cell, w);
    return lit(v.clip, color, light_grid_cell_count(cell));
}

