// tiled_light_prepass: compute-based deferred lighting [And11], Forward+'s baseline
// (forward-plus §5, Fig. 3): after the light pre-pass's attributes pass, one invocation per
// pixel reads depth and the normal + exponent once, finds its tile, and accumulates the
// tile's lights' diffuse irradiance and specular luminance (the monochrome compromise of
// deferred-shading-vs-deferred-lighting) into one RGBA16F target; the light pre-pass's
// shading pass then applies the materials. Group 1: the grid; 2: attributes + depth
// (light_prepass_attributes.wgsl); 3: the irradiance target and the count target
// (compute_outputs.wgsl).

@compute @workgroup_size(SCREEN_WORKGROUP, SCREEN_WORKGROUP)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = vec2<u32>(frame.viewport);
    if (gid.x >= size.x || gid.y >= size.y) {
        return;
    }
    let p = gid.xy;
    let depth = textureLoad(attr_depth, p, 0);
    if (is_background(depth)) {
        write_output(p, vec4<f32>(0.0), 0u);
        return;
    }
    let s = attributes_pixel_surface(p);
    let cell = light_grid_cell(vec2<f32>(p), view_distance_from_depth(depth));
    write_output(p, light_grid_irradiance_mono(s, view_dir_to(s.position), cell), light_grid_cell_count(cell));
}
