// Reading the G-buffer (group 2) in deferred passes, fragment or compute.

@group(2) @binding(0) var gb_normal: texture_2d<f32>;
@group(2) @binding(1) var gb_diffuse: texture_2d<f32>;
@group(2) @binding(2) var gb_specular: texture_2d<f32>;
@group(2) @binding(3) var gb_base: texture_2d<f32>;
@group(2) @binding(4) var gb_depth: texture_depth_2d;

// The surface stored at pixel `p`, its material's shader applied (the branch of deferred
// shading on the stored material); the light-independent term travels as `emissive`.
fn surface_from_gbuffer(p: vec2<u32>, depth: f32) -> Surface {
    let n = textureLoad(gb_normal, p, 0);
    let d = textureLoad(gb_diffuse, p, 0);
    let sp = textureLoad(gb_specular, p, 0);
    let b = textureLoad(gb_base, p, 0);
    var s: Surface;
    s.position = world_from_depth(p, depth);
    s.normal = normalize(n.xyz);
    s.diffuse = d.rgb;
    s.alpha = d.a;
    s.specular = sp.rgb;
    s.shininess = sp.a;
    s.emissive = b.rgb;
    s.ambient = vec3<f32>(0.0);
    s.material = u32(n.w + 0.5);
    return apply_material(s);
}
