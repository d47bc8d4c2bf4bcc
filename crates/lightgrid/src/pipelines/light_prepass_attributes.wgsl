// The light pre-pass's attributes (pass 1's normal + specular exponent and depth) as read by
// its irradiance passes (group 2): the light volumes' fragments (`light_prepass.wgsl`) and
// the tiled compute kernel (`tiled_light_prepass.wgsl`).

@group(2) @binding(0) var attr_normal_shininess: texture_2d<f32>;
@group(2) @binding(1) var attr_depth: texture_depth_2d;

// The surface the irradiance is computed at: pixel `p` at depth-buffer value `depth` (< 1).
fn attributes_surface(p: vec2<u32>, depth: f32) -> Surface {
    let a = textureLoad(attr_normal_shininess, p, 0);
    var s: Surface;
    s.position = position_from_depth(p, depth);
    s.normal = normalize(a.xyz);
    s.shininess = a.w;
    return s;
}
