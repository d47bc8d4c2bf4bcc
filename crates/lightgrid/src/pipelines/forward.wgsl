// forward: every light for every fragment. The reference image; it never reads a light grid.

// Early depth test forced: the loop check may write the frame counters (a side effect), and
// a fragment shader with side effects would otherwise be depth-tested after shading, losing
// early-Z (measured on lavapipe: tiled_forward_prez 2-3x slower). Sound here: the shader
// neither discards nor writes depth, so early and late tests keep the same fragments.
@fragment
#if EARLY_DEPTH_TEST
@early_depth_test(force)
#endif
fn fs_main(v: VertexOut, @builtin(front_facing) front: bool) -> LitOut {
    let s = surface_from_vertex(v, front);
    let color = surface_base(s) + shade_all_lights(s, view_dir_to(s.position));
    return lit(v.clip, color, frame.light_count);
}

// forward_mono: the reference for light_prepass_mono: every light for every fragment, with
// the same monochrome-specular model.
// Early depth test forced, as fs_main.
@fragment
#if EARLY_DEPTH_TEST
@early_depth_test(force)
#endif
fn fs_mono(v: VertexOut, @builtin(front_facing) front: bool) -> LitOut {
    let s = surface_from_vertex(v, front);
    let view_dir = view_dir_to(s.position);
    var diffuse = vec3<f32>(0.0);
    var specular = 0.0;
    var i = 0u;
    for (; i < frame.light_count; i = i + 1u) {
        let t = light_terms(s, view_dir, i);
        diffuse += t.diffuse;
        specular += luminance(t.specular);
    }
    check_loop(i, frame.light_count);
    let color = surface_base(s) + diffuse * s.diffuse + mono_specular(diffuse, specular) * specular_albedo(s);
    return lit(v.clip, color, frame.light_count);
}

// forward_mono_albedo: the reference for deferred_mono: every light for every fragment, with
// the specular albedo reduced to one value as deferred_mono's G-buffer stores it.
// Early depth test forced, as fs_main.
@fragment
#if EARLY_DEPTH_TEST
@early_depth_test(force)
#endif
fn fs_mono_albedo(v: VertexOut, @builtin(front_facing) front: bool) -> LitOut {
    var s = surface_from_vertex(v, front);
    s.specular = mono_albedo(s.specular);
    let color = surface_base(s) + shade_all_lights(s, view_dir_to(s.position));
    return lit(v.clip, color, frame.light_count);
}
