// lightgrid's light grid in a caller's shader (`LightCuller::wgsl`): the three arrays of
// tiled-shading §6.2 and the cells' depth bounds, at the caller's bind group, and the
// accessors of tiled-forward-shading Listing 4.1. The light loop and the BRDF are the
// caller's:
//
//     let cell = light_grid_cell(frag.position.xy, view_distance);
//     for (var i = 0u; i < light_grid_count(cell); i++) {
//         let light = my_lights[light_grid_light(cell, i)];
//         ...
//     }

// LightGridParams: lightgrid's GridParams (shading/types.wgsl), renamed.

@group(LIGHT_GRID_GROUP) @binding(0) var<uniform> light_grid: LightGridParams;
@group(LIGHT_GRID_GROUP) @binding(1) var<storage, read> light_grid_cells: array<vec2<u32>>;  // (offset, count)
@group(LIGHT_GRID_GROUP) @binding(2) var<storage, read> light_grid_indices: array<u32>;
// Each cell's view-distance bounds its list was built for ([min, max], min > max: no samples).
@group(LIGHT_GRID_GROUP) @binding(3) var<storage, read> light_grid_bounds: array<vec2<f32>>;

// How many lights cell `cell` lists.
fn light_grid_count(cell: u32) -> u32 {
    return light_grid_cells[cell].y;
}

// The index in the caller's light buffer of the `i`-th light of cell `cell`.
fn light_grid_light(cell: u32, i: u32) -> u32 {
    return light_grid_indices[light_grid_cells[cell].x + i];
}

// Cell addressing, the same as lightgrid's own shaders (grid_cell.wgsl, renamed):
