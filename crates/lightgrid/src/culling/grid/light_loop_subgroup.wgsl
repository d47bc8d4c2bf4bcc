// The light loop scalarized over the subgroup (`--light-loop subgroup`, on adapters with
// subgroups; issue 31, after Drobot 2017): the lanes take their cells' lights one at a time
// for the whole subgroup, so each light's index and data are the same for every lane that
// evaluates it (one load, not one per lane), and a lane evaluates exactly its own cell's
// lights, as the per-lane loop does (the counts are the same). Composed after
// light_grid.wgsl, in place of light_loop_lane.wgsl.
//
// Per-cell lists are in no order (the GPU strategies append as they find), so the subgroup
// takes the smallest light index any lane still has next: every lane advances past each of its
// entries exactly once, in at most the sum of the lanes' list lengths rounds (their union
// when the lists are sorted, as the CPU strategy's are). Z-bins are sorted by construction:
// the subgroup walks the union of its lanes' mask words, one set bit at a time.

const NO_LIGHT: u32 = 0xffffffffu;

fn list_sum(s: Surface, view_dir: vec3<f32>, cell: u32, mono: bool) -> vec4<f32> {
    let count = light_grid_cell_count(cell);
    let offset = light_grid_cells[cell].x;
    var acc = vec4<f32>(0.0);
    var i = 0u;
    loop {
        var mine = NO_LIGHT;
        if (i < count) {
            mine = light_grid_indices[offset + i];
        }
        let l = subgroupMin(mine);
        if (l == NO_LIGHT) {
            break;
        }
        if (mine == l) {
            acc += light_sum(s, view_dir, l, mono);
            i += 1u;
        }
    }
    check_loop(i, count);
    return acc;
}

fn zbin_shade(s: Surface, view_dir: vec3<f32>, cell: u32, mono: bool) -> vec4<f32> {
    let z = light_grid_zbin_walk(cell);
    let has = z.word_begin < z.word_end;
    // The union of the lanes' word ranges, [lo, hi).
    let lo = subgroupMin(select(NO_LIGHT, z.word_begin, has));
    let hi = subgroupMax(z.word_end);
    var acc = vec4<f32>(0.0);
    if (lo == NO_LIGHT) {
        return acc;
    }
    var shaded = 0u;
    var listed = 0u;
    var k = lo;
    for (; k < hi; k = k + 1u) {
        var mine = 0u;
        if (k >= z.word_begin && k < z.word_end) {
            mine = light_grid_zbin_word(z, k);
        }
        listed += countOneBits(mine);
        for (var any = subgroupOr(mine); any != 0u; any = any & (any - 1u)) {
            let b = firstTrailingBit(any);
            if (((mine >> b) & 1u) != 0u) {
                acc += light_sum(s, view_dir, light_grid_indices[k * 32u + b], mono);
                shaded += 1u;
            }
        }
    }
    check_loop(k, hi);
    check_loop(shaded, listed);
    zbin_shaded = vec2<u32>(cell, shaded);
    return acc;
}

fn light_grid_irradiance_mono(s: Surface, view_dir: vec3<f32>, cell: u32) -> vec4<f32> {
    if (light_grid.zbin_words != 0u) {
        return zbin_shade(s, view_dir, cell, true);
    }
    return list_sum(s, view_dir, cell, true);
}

fn light_grid_shade(s: Surface, view_dir: vec3<f32>, cell: u32) -> vec3<f32> {
    if (light_grid.zbin_words != 0u) {
        return zbin_shade(s, view_dir, cell, false).rgb;
    }
    return list_sum(s, view_dir, cell, false).rgb;
}
