// tiled_forward / tiled_forward_prez: forward shading that loops only the lights listed for
// the fragment's tile (tiled-shading §3, Listing 3).

@fragment
fn fs_main(v: VertexOut, @builtin(front_facing) front: bool) -> LitOut {
    let s = surface_from_vertex(v, front);
    let cell = grid_cell(v.clip.xy);
    let color = surface_base(s) + grid_shade(s, view_dir_to(s.position), cell);
    return lit(color, grid_cell_count(cell));
}

