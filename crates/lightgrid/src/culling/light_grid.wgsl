// The one light-grid accessor (tiled-shading Listing 1): find the sample's cell, loop the
// lights listed for it, call the one light function. Every grid-reading pipeline (forward
// fragment shaders and deferred compute shaders) shades through `grid_shade`.

@group(1) @binding(0) var<uniform> grid: GridParams;
@group(1) @binding(1) var<storage, read> grid_cells: array<vec2<u32>>;  // (offset, count)
@group(1) @binding(2) var<storage, read> grid_indices: array<u32>;

// Depth slice of a sample at view distance `w`: exponential spacing between near and far
// (tiled-forward-shading §4.8). A tiled grid has one slice.
fn grid_slice(w: f32) -> u32 {
    if (grid.slices <= 1u) {
        return 0u;
    }
    let s = floor(log(max(w, 1e-6)) * grid.slice_scale + grid.slice_bias);
    return u32(clamp(s, 0.0, f32(grid.slices - 1u)));
}

// Cell of the sample at framebuffer position `pixel` and view distance `w`.
fn grid_cell(pixel: vec2<f32>, w: f32) -> u32 {
    let t = min(vec2<u32>(pixel) / grid.tile_size, vec2<u32>(grid.tiles_x - 1u, grid.tiles_y - 1u));
    return (grid_slice(w) * grid.tiles_y + t.y) * grid.tiles_x + t.x;
}

fn grid_cell_count(cell: u32) -> u32 {
    return grid_cells[cell].y;
}

// The light at position `i` of the cell's list.
fn grid_light(cell: u32, i: u32) -> Light {
    return lights[grid_indices[grid_cells[cell].x + i]];
}

// Sum of the cell's lights on the surface (Listing 1's computeLight).
fn grid_shade(s: Surface, view_dir: vec3<f32>, cell: u32) -> vec3<f32> {
    var acc = vec3<f32>(0.0);
    let count = grid_cell_count(cell);
    for (var i = 0u; i < count; i = i + 1u) {
        acc += shade_light(s, view_dir, grid_light(cell, i));
    }
    return acc;
}
