// depth_bounds: one workgroup per tile writes the tile's [min, max] depth-buffer value.

@group(0) @binding(0) var depth_tex: texture_depth_2d;
@group(0) @binding(1) var<uniform> grid: GridParams;
@group(0) @binding(2) var<storage, read_write> bounds: array<vec2<f32>>;

@compute @workgroup_size(TILE_THREADS, TILE_THREADS)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let range = reduce_tile_depth(depth_tex, wg.xy, grid.tile_size, lid.xy, li);
    if (li == 0u) {
        bounds[wg.y * grid.tiles_x + wg.x] = range;
    }
}
