// The per-lane light loop (`--light-loop lane`, the default): each sample walks its own
// cell's lights. Composed after light_grid.wgsl.

// The z-binned form of `light_grid_shade` (mono: the light pre-pass's irradiance and specular
// luminance instead of the colour; rgb in both cases, a used only by mono).
fn zbin_shade(s: Surface, view_dir: vec3<f32>, cell: u32, mono: bool) -> vec4<f32> {
    let z = light_grid_zbin_walk(cell);
    var acc = vec4<f32>(0.0);
    var shaded = 0u;
    var listed = 0u;
    var k = z.word_begin;
    for (; k < z.word_end; k = k + 1u) {
        var bits = light_grid_zbin_word(z, k);
        listed += countOneBits(bits);
        for (; bits != 0u; bits = bits & (bits - 1u)) {
            acc += light_sum(s, view_dir, light_grid_indices[k * 32u + firstTrailingBit(bits)], mono);
            shaded += 1u;
        }
    }
    check_loop(k, z.word_end);
    check_loop(shaded, listed);
    zbin_shaded = vec2<u32>(cell, shaded);
    return acc;
}

// The cell's lights' diffuse irradiance (rgb) and specular luminance (a): the light
// pre-pass's monochrome compromise, summed as the tiled light pre-pass stores it.
fn light_grid_irradiance_mono(s: Surface, view_dir: vec3<f32>, cell: u32) -> vec4<f32> {
    if (light_grid.zbin_words != 0u) {
        return zbin_shade(s, view_dir, cell, true);
    }
    var acc = vec4<f32>(0.0);
    let count = light_grid_cell_count(cell);
    var i = 0u;
    for (; i < count; i = i + 1u) {
        let t = light_terms(s, view_dir, light_grid_light(cell, i));
        acc += vec4<f32>(t.diffuse, luminance(t.specular));
    }
    check_loop(i, count);
    return acc;
}

// Sum of the cell's lights on the surface (Listing 1's computeLight).
fn light_grid_shade(s: Surface, view_dir: vec3<f32>, cell: u32) -> vec3<f32> {
    if (light_grid.zbin_words != 0u) {
        return zbin_shade(s, view_dir, cell, false).rgb;
    }
    var acc = vec3<f32>(0.0);
    let count = light_grid_cell_count(cell);
    var i = 0u;
    for (; i < count; i = i + 1u) {
        acc += shade_light(s, view_dir, light_grid_light(cell, i));
    }
    check_loop(i, count);
    return acc;
}
