// lightgrid's light grid in a caller's shader (`LightCuller::wgsl`): the three arrays of
// tiled-shading §6.2 and the cells' depth bounds, at the caller's bind group, and the
// accessors of tiled-forward-shading Listing 4.1. The light loop and the BRDF are the
// caller's:
//
//     let cell = light_grid_cell(frag.position.xy, view_distance);
//     var walk = light_grid_walk(cell);
//     while (light_grid_next(&walk)) {
//         let light = my_lights[walk.light];
//         ...
//     }
//
// The walk reads whatever the strategy built: per-cell lists, or z-binning's sorted lights,
// per-bin ranges and per-tile masks (`Assign::ZBin`). `light_grid_count` and
// `light_grid_light(cell, i)` index a cell's lights directly: constant time on lists, a
// scan of the tile's mask words on z-bins.

// LightGridParams: culling/grid/grid_params.wgsl, composed before this part.

@group(LIGHT_GRID_GROUP) @binding(0) var<uniform> light_grid: LightGridParams;
@group(LIGHT_GRID_GROUP) @binding(1) var<storage, read> light_grid_cells: array<vec2<u32>>;  // (offset, count)
@group(LIGHT_GRID_GROUP) @binding(2) var<storage, read> light_grid_indices: array<u32>;
// Each cell's view-distance bounds its list was built for ([min, max], min > max: no samples).
@group(LIGHT_GRID_GROUP) @binding(3) var<storage, read> light_grid_bounds: array<vec2<f32>>;

// Where a walk over a cell's lights stands.
struct LightGridWalk {
    // The light `light_grid_next` found last (an index into the caller's light buffer).
    light: u32,
    // Lists: the next position and one past the last. Z-bins: the next mask word and one
    // past the last word of the bin's range.
    next: u32,
    end: u32,
    // Lists: the cell's offset.
    base: u32,
    // Z-bins: the cell's tile and bin (zbin_walk.wgsl) and the current word's bits
    // left.
    zbin: LightGridZBinWalk,
    bits: u32,
}

// A walk over cell `cell`'s lights (the cell of any layer).
fn light_grid_walk(cell: u32) -> LightGridWalk {
    if (light_grid.zbin_words == 0u) {
        let c = light_grid_cells[cell];
        return LightGridWalk(0u, 0u, c.y, c.x, LightGridZBinWalk(0u, 0u, 0u, 0u, 0u), 0u);
    }
    let z = light_grid_zbin_walk(cell);
    return LightGridWalk(0u, z.word_begin, z.word_end, 0u, z, 0u);
}

// The next light of the walk into `(*w).light`; false when there is none left.
fn light_grid_next(w: ptr<function, LightGridWalk>) -> bool {
    if (light_grid.zbin_words == 0u) {
        if ((*w).next >= (*w).end) {
            return false;
        }
        (*w).light = light_grid_indices[(*w).base + (*w).next];
        (*w).next += 1u;
        return true;
    }
    while ((*w).bits == 0u) {
        if ((*w).next >= (*w).end) {
            return false;
        }
        (*w).bits = light_grid_zbin_word((*w).zbin, (*w).next);
        (*w).next += 1u;
    }
    let b = firstTrailingBit((*w).bits);
    (*w).bits &= (*w).bits - 1u;
    (*w).light = light_grid_indices[((*w).next - 1u) * 32u + b];
    return true;
}

// How many lights cell `cell` has.
fn light_grid_count(cell: u32) -> u32 {
    if (light_grid.zbin_words == 0u) {
        return light_grid_cells[cell].y;
    }
    let z = light_grid_zbin_walk(cell);
    var n = 0u;
    for (var k = z.word_begin; k < z.word_end; k++) {
        n += countOneBits(light_grid_zbin_word(z, k));
    }
    return n;
}

// The index in the caller's light buffer of the `i`-th light of cell `cell` (i below
// `light_grid_count(cell)`).
fn light_grid_light(cell: u32, i: u32) -> u32 {
    if (light_grid.zbin_words == 0u) {
        return light_grid_indices[light_grid_cells[cell].x + i];
    }
    let z = light_grid_zbin_walk(cell);
    var left = i;
    for (var k = z.word_begin; k < z.word_end; k++) {
        var bits = light_grid_zbin_word(z, k);
        let n = countOneBits(bits);
        if (left < n) {
            for (var j = 0u; j < left; j++) {
                bits &= bits - 1u;
            }
            return light_grid_indices[k * 32u + firstTrailingBit(bits)];
        }
        left -= n;
    }
    return 0u;
}

// Cell addressing and the z-bin walk follow: lightgrid's own grid_cell.wgsl and zbin_walk.wgsl,
// whose names carry the `light_grid` prefix everywhere.
