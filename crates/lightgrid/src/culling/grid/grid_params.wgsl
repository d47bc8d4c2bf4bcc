// The light grid's uniform (`gpu_types::GridParams`, 48 bytes): tiles, slices and where a
// z-binned grid keeps its masks. Shared by lightgrid's shaders and a caller's
// (`LightCuller::wgsl`).
struct LightGridParams {
    tile_size: u32,
    tiles_x: u32,
    tiles_y: u32,
    slices: u32,
    slice_scale: f32,
    slice_bias: f32,
    lists: u32,
    layer_cells: u32,
    zbin_words: u32,   // a z-binned grid's words per tile mask (0: per-cell lists)
    zbin_masks: u32,   // where its tile masks start in the index buffer
    pad_a: u32,
    pad_b: u32,
}
