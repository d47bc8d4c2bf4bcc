// MSAA forward shading: the view distance at which each fragment will look its cell up,
// folded into that cell's bounds (`LightCuller::fragment_bounds_wgsl`; tiled-forward-shading
// §4.6 reduces the bounds over every sample, this also covers the fragments). A fragment
// covering part of a pixel is shaded at the pixel centre, which may lie off its triangle: its
// extrapolated depth can leave the bounds of every sample of its cell, and the cell's list
// would miss lights reaching it. The caller draws, with its shading passes' depth tests, the
// fragments it will shade from the grid (early, so exactly those run), and each calls
// `light_grid_bound_fragment`; the cell-bounds kernel then unions these with the samples'
// bounds. Encoding: per cell (0xffffffff - bits of the minimum, bits of the maximum), both
// reduced with atomicMax, so a buffer cleared to zero is empty everywhere (positive floats
// order like their bit patterns).

// LightGridParams: culling/grid/grid_params.wgsl, composed before this part.

@group(LIGHT_GRID_GROUP) @binding(0) var<uniform> light_grid: LightGridParams;
@group(LIGHT_GRID_GROUP) @binding(1) var<storage, read_write> light_grid_fragment_bounds: array<atomic<u32>>;

fn light_grid_include_fragment(cell: u32, w: f32) {
    let bits = bitcast<u32>(w);
    atomicMax(&light_grid_fragment_bounds[2u * cell], 0xffffffffu - bits);
    atomicMax(&light_grid_fragment_bounds[2u * cell + 1u], bits);
}

// The fragment at framebuffer position `pixel` (`@builtin(position).xy`) and view distance
// `view_distance` (−z in view space, within the frame's near..far: a centre extrapolated
// past them is in no cell, and the caller leaves it out), of an opaque surface or, with
// `transparent`, of a transparent one (the second layer with separate lists). Within
// LIGHT_GRID_DEPTH_SLACK of a slice boundary it counts for both slices, as a sample does in
// the cell-bounds kernel.
fn light_grid_bound_fragment(pixel: vec2<f32>, view_distance: f32, transparent: bool) {
    let w = view_distance;
    let layer = select(0u, light_grid.layer_cells, transparent && light_grid.lists == LIGHT_GRID_LISTS_SEPARATE);
    let c0 = light_grid_cell(pixel, w * (1.0 - LIGHT_GRID_DEPTH_SLACK)) + layer;
    let c1 = light_grid_cell(pixel, w * (1.0 + LIGHT_GRID_DEPTH_SLACK)) + layer;
    light_grid_include_fragment(c0, w);
    if (c1 != c0) {
        light_grid_include_fragment(c1, w);
    }
    let c = light_grid_cell(pixel, w) + layer;
    if (c != c0 && c != c1) {
        light_grid_include_fragment(c, w);
    }
}
