// The texture grid (`culling/texture_grid.rs`): tiled-shading Listing 1's three arrays read
// with `textureLoad` alone, the way a tiled forward renderer runs without compute shaders or
// storage buffers (tiled-forward-shading §4.2). Composed in place of light_grid.wgsl and a
// light loop, after grid_cell.wgsl; it also gives the light function its lights
// (`scene_light`), from the grid's light texture.

@group(1) @binding(0) var<uniform> light_grid: LightGridParams;
// Per tile, (offset, count) into the index lists.
@group(1) @binding(1) var light_grid_cell_texels: texture_2d<u32>;
// The index lists, row-major: entry k at (k % width, k / width).
@group(1) @binding(2) var light_grid_index_texels: texture_2d<u32>;
// The camera-relative lights, LIGHT_TEXELS texels each, whole lights per row.
@group(1) @binding(3) var light_grid_light_texels: texture_2d<f32>;

// Light `index` of the frame's list (the light function reads its lights through this).
fn scene_light(index: u32) -> Light {
    let per_row = textureDimensions(light_grid_light_texels).x / LIGHT_TEXELS;
    let x = i32((index % per_row) * LIGHT_TEXELS);
    let y = i32(index / per_row);
    let a = textureLoad(light_grid_light_texels, vec2<i32>(x, y), 0);
    let b = textureLoad(light_grid_light_texels, vec2<i32>(x + 1, y), 0);
    let c = textureLoad(light_grid_light_texels, vec2<i32>(x + 2, y), 0);
    return Light(a.xyz, a.w, b.xyz, b.w, c.xyz, c.w);
}

// The (offset, count) of tile cell `cell`.
fn light_grid_cell_texel(cell: u32) -> vec2<u32> {
    let t = vec2<u32>(cell % light_grid.tiles_x, cell / light_grid.tiles_x);
    return textureLoad(light_grid_cell_texels, vec2<i32>(t), 0).xy;
}

fn light_grid_cell_count(cell: u32) -> u32 {
    return light_grid_cell_texel(cell).y;
}

// Entry `k` of the index lists (row-major).
fn light_grid_index_entry(k: u32) -> u32 {
    let width = textureDimensions(light_grid_index_texels).x;
    return textureLoad(light_grid_index_texels, vec2<i32>(vec2<u32>(k % width, k / width)), 0).x;
}

// The index (into the lights) of the light at position `i` of the cell's list.
fn light_grid_light(cell: u32, i: u32) -> u32 {
    return light_grid_index_entry(light_grid_cell_texel(cell).x + i);
}

// A forward fragment: its surface lit by the lights of `cell` (Listing 1's computeLight).
// The texture grid is single-sample, so no fragment leaves its cell's bounds (`w` unused).
fn light_grid_shade_fragment(s: Surface, view_dir: vec3<f32>, cell: u32, w: f32) -> vec3<f32> {
    // The cell's texel read once, not per light (`light_grid_light` reads it each time).
    let c = light_grid_cell_texel(cell);
    var acc = vec3<f32>(0.0);
    var i = 0u;
    for (; i < c.y; i = i + 1u) {
        acc += shade_light(s, view_dir, light_grid_index_entry(c.x + i));
    }
    check_loop(i, c.y);
    return acc;
}
