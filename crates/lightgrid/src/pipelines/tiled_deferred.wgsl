// tiled_deferred: one invocation per sample reads the G-buffer once, finds its tile and
// accumulates the tile's lights in registers (tiled-shading §2, Listing 2).

@compute @workgroup_size(SCREEN_WORKGROUP, SCREEN_WORKGROUP)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = vec2<u32>(frame.viewport);
    if (gid.x >= size.x || gid.y >= size.y) {
        return;
    }
    let p = gid.xy;
    let depth = textureLoad(gb_depth, p, 0);
    if (is_background(depth)) {
        write_sample(p, vec3<f32>(0.0), 0u);
        return;
    }
    let s = surface_from_gbuffer(p, depth);
    let cell = light_grid_cell(vec2<f32>(p), view_distance_from_depth(depth));
    let color = surface_base(s) + light_grid_shade(s, view_dir_to(s.position), cell);
    write_sample(p, color, light_grid_cell_count(cell));
}
