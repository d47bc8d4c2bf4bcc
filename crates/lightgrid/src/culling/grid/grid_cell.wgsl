// Cell addressing of the light grid, shared by the shading accessor (light_grid.wgsl) and the
// cell-bounds kernel, and a LightCuller caller's (embed.wgsl). Needs a `light_grid: LightGridParams`
// binding from the including shader.
// Cell index = (layer * slices + slice) * tiles_y + tile_y) * tiles_x + tile_x; a tiled grid
// has one slice; a grid with separate transparent lists (GRID_LISTS_SEPARATE) has a second layer.

// Depth slice of a sample at view distance `w`: exponential spacing between near and far
// (tiled-forward-shading §4.8). A tiled grid has one slice.
fn light_grid_slice(w: f32) -> u32 {
    if (light_grid.slices <= 1u) {
        return 0u;
    }
    let s = floor(log(max(w, 1e-6)) * light_grid.slice_scale + light_grid.slice_bias);
    return u32(clamp(s, 0.0, f32(light_grid.slices - 1u)));
}

// Cell of the sample at framebuffer position `pixel` and view distance `w`.
fn light_grid_cell(pixel: vec2<f32>, w: f32) -> u32 {
    let t = min(vec2<u32>(pixel) / light_grid.tile_size, vec2<u32>(light_grid.tiles_x - 1u, light_grid.tiles_y - 1u));
    return (light_grid_slice(w) * light_grid.tiles_y + t.y) * light_grid.tiles_x + t.x;
}


// Cell of a transparent fragment: the second layer's cell with separate lists, else the same.
fn light_grid_cell_transparent(pixel: vec2<f32>, w: f32) -> u32 {
    return light_grid_cell(pixel, w) + select(0u, light_grid.layer_cells, light_grid.lists == LIGHT_GRID_LISTS_SEPARATE);
}

// All cells of the grid (every layer).
fn light_grid_cell_total() -> u32 {
    return light_grid.layer_cells * select(1u, 2u, light_grid.lists == LIGHT_GRID_LISTS_SEPARATE);
}
