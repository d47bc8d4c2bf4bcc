// tiled_light_prepass: compute-based deferred lighting [And11], Forward+'s baseline
// (forward-plus §5, Fig. 3): after the light pre-pass's attributes pass, one invocation per
// pixel reads depth and the normal + exponent once, finds its tile, and accumulates the
// tile's lights' diffuse irradiance and specular luminance (the monochrome compromise of
// deferred-shading-vs-deferred-lighting) into one RGBA16F target; the light pre-pass's
// shading pass then applies the materials. Group 1: the grid; 2: attributes + depth
// (light_prepass_attributes.wgsl); 3: the irradiance target and the count target (storage).

@group(3) @binding(0) var out_irradiance: texture_storage_2d<rgba16float, write>;
@group(3) @binding(1) var out_count: texture_storage_2d<r32float, write>;

@compute @workgroup_size(SCREEN_WORKGROUP, SCREEN_WORKGROUP)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = vec2<u32>(frame.viewport);
    if (gid.x >= size.x || gid.y >= size.y) {
        return;
    }
    let p = gid.xy;
    let depth = textureLoad(attr_depth, p, 0);
    if (depth >= 1.0) {
        textureStore(out_irradiance, p, vec4<f32>(0.0));
        textureStore(out_count, p, vec4<f32>(0.0));
        return;
    }
    let s = attributes_surface(p, depth);
    let view_dir = view_dir_to(s.position);
    let cell = grid_cell(vec2<f32>(p), view_distance_from_depth(depth));
    let count = grid_cell_count(cell);
    var diffuse = vec3<f32>(0.0);
    var specular = 0.0;
    var i = 0u;
    for (; i < count; i = i + 1u) {
        let t = light_terms(s, view_dir, grid_light(cell, i));
        diffuse += t.diffuse;
        specular += luminance(t.specular);
    }
    check_loop(i, count);
    textureStore(out_irradiance, p, vec4<f32>(diffuse, specular));
    textureStore(out_count, p, vec4<f32>(f32(count), 0.0, 0.0, 0.0));
}
