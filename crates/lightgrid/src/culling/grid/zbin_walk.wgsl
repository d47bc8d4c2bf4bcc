// The walk over a z-binned grid (culling/strategies/zbin.rs, Drobot 2017), shared by lightgrid's light
// loops (light_grid.wgsl and light_loop_*.wgsl) and, unchanged, a
// LightCuller caller's (embed.wgsl). The index buffer holds the lights sorted by view depth,
// then one bit mask over them per screen tile (`zbin_words` words each, from `zbin_masks`);
// the cell buffer holds per depth bin (the grid's slices) the sorted range (~first, end) of
// the lights whose depth span meets the bin. A cell (tile, slice, layer) reads its tile's mask
// within its slice's range: the bins apply at any depth, so transparent fragments need no
// second list. Needs the grid's bindings `light_grid`, `light_grid_cells` and
// `light_grid_indices`.

struct LightGridZBinWalk {
    tile_mask: u32,  // index of the tile's first mask word
    first: u32,      // the bin's sorted range [first, end)
    end: u32,
    word_begin: u32,      // the mask words the range touches, [word_begin, word_end) (empty: 0, 0)
    word_end: u32,
}

fn light_grid_zbin_walk(cell: u32) -> LightGridZBinWalk {
    let c = cell % light_grid.layer_cells;
    let tiles = light_grid.tiles_x * light_grid.tiles_y;
    let bin = light_grid_cells[c / tiles];
    let first = ~bin.x;
    let end = bin.y;
    let some = first < end;
    return LightGridZBinWalk(
        light_grid.zbin_masks + (c % tiles) * light_grid.zbin_words,
        first,
        end,
        select(0u, first / 32u, some),
        select(0u, (end - 1u) / 32u + 1u, some),
    );
}

// The tile mask's word `k` (k * 32 .. k * 32 + 31 in sorted order, k in [word_begin, word_end))
// limited to the bin's range.
fn light_grid_zbin_word(z: LightGridZBinWalk, k: u32) -> u32 {
    let lo = max(z.first, k * 32u) - k * 32u;
    let hi = min(z.end, k * 32u + 32u) - k * 32u;  // > lo for the words the walk visits
    let range = (0xffffffffu << lo) & (0xffffffffu >> (32u - hi));
    return light_grid_indices[z.tile_mask + k] & range;
}
