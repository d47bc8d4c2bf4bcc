// MSAA only: the view distance at which every forward fragment will look up its cell, folded
// into that cell's bounds (tiled-forward-shading §4.6 reduces the bounds over every sample;
// this also covers the fragments). A fragment covering part of a pixel is shaded at the pixel
// centre, which may lie off its triangle: its extrapolated depth can leave the bounds of every
// sample of its cell, and the cell's list would miss lights reaching it. This pass draws the
// frame's geometry with the shading passes' depth tests (opaque LessEqual against the
// pre-pass depth, transparent Less), early, so exactly the fragments that will be shaded run,
// and each adds its view distance to its cell; the cell-bounds kernel then unions these with
// the samples' bounds (`cell_bounds.wgsl`). Encoding: per cell (0xffffffff - bits of the
// minimum, bits of the maximum), both reduced with atomicMax, so a buffer cleared to zero is
// empty everywhere (positive floats order like their bit patterns).

@group(1) @binding(0) var<uniform> light_grid: LightGridParams;
@group(1) @binding(1) var<storage, read_write> fragment_bounds: array<atomic<u32>>;

fn include_fragment(cell: u32, w: f32) {
    let bits = bitcast<u32>(w);
    atomicMax(&fragment_bounds[2u * cell], 0xffffffffu - bits);
    atomicMax(&fragment_bounds[2u * cell + 1u], bits);
}

// A fragment within ASSIGN_DEPTH_SLACK of a slice boundary counts for both slices, as a
// sample does in the cell-bounds kernel. A centre extrapolated out of the view volume (past
// the near or far plane, or behind the camera) is in no cell (`light_grid_shade_fragment`).
fn include_fragment_cells(pixel: vec2<f32>, w: f32, layer_offset: u32) {
    if (w < frame.near || w > frame.far) {
        return;
    }
    let c0 = light_grid_cell(pixel, w * (1.0 - ASSIGN_DEPTH_SLACK)) + layer_offset;
    let c1 = light_grid_cell(pixel, w * (1.0 + ASSIGN_DEPTH_SLACK)) + layer_offset;
    include_fragment(c0, w);
    if (c1 != c0) {
        include_fragment(c1, w);
    }
    let c = light_grid_cell(pixel, w) + layer_offset;
    if (c != c0 && c != c1) {
        include_fragment(c, w);
    }
}

// Opaque fragments: their cells in the first layer.
@fragment
#if EARLY_DEPTH_TEST
@early_depth_test(force)
#endif
fn fs_opaque(v: VertexOut) {
    let m = materials[v.material];
    alpha_test(m, m.alpha * base_colour(m, v, tex_coords(v)).a);
    include_fragment_cells(v.clip.xy, view_distance_from_depth(v.clip.z), 0u);
}

// Transparent fragments: the second layer with separate lists, else the one list.
@fragment
#if EARLY_DEPTH_TEST
@early_depth_test(force)
#endif
fn fs_transparent(v: VertexOut) {
    let layer = select(0u, light_grid.layer_cells, light_grid.lists == LIGHT_GRID_LISTS_SEPARATE);
    include_fragment_cells(v.clip.xy, view_distance_from_depth(v.clip.z), layer);
}
