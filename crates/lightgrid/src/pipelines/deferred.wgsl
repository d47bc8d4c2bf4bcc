// deferred / deferred_stencil / deferred_mono: per light volume fragment, read the G-buffer
// and add the one light's exit radiance (tiled-shading §1.1). Sky samples are discarded
// before the light function runs, so they are not counted.
//
// With MSAA (tiled-deferred-tricks; `light_volumes.rs`): `fs_mark_edges` sets the stencil's
// edge bit on the pixels whose samples show different surfaces; every other pixel is shaded
// once, at its centre (`fs_light`, `fs_base`: the colour covers all its samples), and the
// samples of an edge pixel one by one where they lie (`fs_light_sample`, `fs_base_sample`,
// which read `sample_index` and so run per sample). Lighting computations count into
// the per-pixel counts (`count_pixel`, `lit`); the base passes count the edge pixels, the samples shaded and the
// samples with geometry into the frame counters, as the edge-aware kernel counts them.
//
// Counting per pixel: with MSAA a pixel that two primitives of one draw share (a volume
// mesh's inner edges; lavapipe cuts the full-screen triangle along the screen's diagonal)
// runs one fragment for each, over the samples each covers (`sample_mask`); only the one
// covering sample 0 counts, so a pixel shaded once is counted once. The shading entries
// force the early depth and stencil tests (`shader::EARLY_DEPTH_TEST`): with their counting
// side effects the tests would otherwise run after them, and the per-sample pipelines would
// shade, and count, every sample before the edge bit rejected it. `counts_for_pixel` and the
// counting are light_volume.wgsl's, shared with the light pre-pass; `centre_depth` is
// msaa_surfaces.wgsl's.

// One fragment per pixel (no edge; every pixel without MSAA): sample 0's attributes at the
// pixel centre.
@fragment
#if EARLY_DEPTH_TEST
@early_depth_test(force)
#endif
fn fs_light(v: VolumeOut, @builtin(sample_mask) mask: u32) -> LitOut {
    let p = vec2<u32>(v.clip.xy);
    if (is_background(textureLoad(gb_depth, p, 0))) {
        discard;
    }
    let position = position_from_screen(vec2<f32>(p) + vec2<f32>(0.5), centre_depth(gb_depth, p));
    let s = apply_material(raw_surface_from_gbuffer(p, 0u, position));
    let n = select(0u, 1u, counts_for_pixel(mask));
    return lit(v.clip, shade_light(s, view_dir_to(s.position), v.light), n);
}

// One fragment per sample of an edge pixel: the sample's own surface where it lies.
@fragment
#if EARLY_DEPTH_TEST
@early_depth_test(force)
#endif
fn fs_light_sample(v: VolumeOut, @builtin(sample_index) i: u32) -> LitOut {
    let p = vec2<u32>(v.clip.xy);
    let depth = textureLoad(gb_depth, p, i);
    if (is_background(depth)) {
        discard;
    }
    let position = position_from_screen(vec2<f32>(p) + sample_position(i), depth);
    let s = apply_material(raw_surface_from_gbuffer(p, i, position));
    return lit(v.clip, shade_light(s, view_dir_to(s.position), v.light), 1u);
}

// The light-independent term of every pixel that is no edge, written before the lights add
// up (every sample holds the same surface: sample 0's). With MSAA it counts the pixel as one
// sample shaded, and its covered samples with geometry.
@fragment
#if EARLY_DEPTH_TEST
@early_depth_test(force)
#endif
fn fs_base(@builtin(position) pos: vec4<f32>, @builtin(sample_mask) mask: u32) -> LitOut {
    let p = vec2<u32>(pos.xy);
    var color = vec3<f32>(0.0);
    if (!is_background(textureLoad(gb_depth, p, 0))) {
        color = textureLoad(gb_base, p, 0).rgb;
        if (MULTISAMPLED) {
            count_pixel_once(gb_depth, p, mask);
        }
    }
    return lit(pos, color, 0u);
}

// The light-independent term of each sample of an edge pixel (MSAA only), counting the edge
// pixel once (at sample 0) and the sample as shaded and with geometry.
@fragment
#if EARLY_DEPTH_TEST
@early_depth_test(force)
#endif
fn fs_base_sample(@builtin(position) pos: vec4<f32>, @builtin(sample_index) i: u32) -> LitOut {
    let p = vec2<u32>(pos.xy);
    var color = vec3<f32>(0.0);
    count_edge_sample(gb_depth, p, i);
    if (!is_background(textureLoad(gb_depth, p, i))) {
        color = textureLoad(gb_base, p, i).rgb;
    }
    return lit(pos, color, 0u);
}

// MSAA: keep the pixels whose samples show different surfaces (`differs`, the edge-aware
// kernel's test), whose stencil the pipeline marks. No side effects: the stencil is written
// after the shader (late tests), so a discarded pixel stays unmarked; the base passes count.
@fragment
fn fs_mark_edges(@builtin(position) pos: vec4<f32>) -> LitOut {
    let p = vec2<u32>(pos.xy);
    let d0 = textureLoad(gb_depth, p, 0);
    let n0 = textureLoad(gb_normal, p, 0);
    var edge = false;
    for (var s = 1u; s < SAMPLES; s = s + 1u) {
        edge = edge || differs(p, s, d0, n0);
    }
    if (!edge) {
        discard;
    }
    var out: LitOut;
    return out;
}

// `deferred_stencil`'s z-fail marking: stencil only, nothing shaded or counted.
@fragment
fn fs_stencil_only() -> LitOut {
    var out: LitOut;
    return out;
}
