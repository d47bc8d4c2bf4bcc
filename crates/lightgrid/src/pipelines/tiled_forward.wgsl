// tiled_forward / tiled_forward_prez / clustered_forward: forward shading that loops only the
// lights listed for the fragment's cell (tiled-shading §3, Listing 3; clusters: §4.8).

@fragment
fn fs_main(v: VertexOut, @builtin(front_facing) front: bool) -> LitOut {
    let s = surface_from_vertex(v, front);
    let cell = grid_cell(v.clip.xy, view_distance_from_depth(v.clip.z));
    let color = surface_base(s) + grid_shade(s, view_dir_to(s.position), cell);
    return lit(color, grid_cell_count(cell));
}

