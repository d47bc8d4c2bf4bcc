// The one light-grid accessor (tiled-shading Listing 1): find the sample's cell (grid_cell.wgsl),
// loop the lights listed for it, call the one light function. Every grid-reading pipeline
// (forward fragment shaders and deferred compute shaders) shades through `grid_shade`.

@group(1) @binding(0) var<uniform> grid: GridParams;
@group(1) @binding(1) var<storage, read> grid_cells: array<vec2<u32>>;  // (offset, count)
@group(1) @binding(2) var<storage, read> grid_indices: array<u32>;

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
    var i = 0u;
    for (; i < count; i = i + 1u) {
        acc += shade_light(s, view_dir, grid_light(cell, i));
    }
    check_loop(i, count);
    return acc;
}
