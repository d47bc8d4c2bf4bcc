// The transparent objects, after any pipeline's opaque image: forward shading blended over
// it, depth-tested against the opaque depth without writing depth (tiled-shading §4). Each
// fragment is lit by the one light function and counted like an opaque sample.

// Early depth test forced, as in the opaque forward passes (no discard, no depth write).
// `forward`: every light (the reference, for transparent geometry too).
@fragment
#if EARLY_DEPTH_TEST
@early_depth_test(force)
#endif
fn fs_all_lights(v: VertexOut, @builtin(front_facing) front: bool) -> LitOut {
    let s = surface_from_vertex(v, front);
    let color = surface_base(s) + shade_all_lights(s, view_dir_to(s.position));
    return lit_blended(v.clip, color, s.alpha, frame.light_count);
}

// Every other pipeline: the lights of the fragment's transparent list (tiled-forward-shading
// §4.5: its cell spans near..opaque max, so it holds every light reaching the fragment).
@fragment
#if EARLY_DEPTH_TEST
@early_depth_test(force)
#endif
fn fs_grid(v: VertexOut, @builtin(front_facing) front: bool) -> LitOut {
    let s = surface_from_vertex(v, front);
    let w = view_distance_from_depth(v.clip.z);
    let cell = light_grid_cell_transparent(v.clip.xy, w);
    let color = surface_base(s) + light_grid_shade_fragment(s, view_dir_to(s.position), cell, w);
    return lit_blended(v.clip, color, s.alpha, light_grid_cell_count(cell));
}
