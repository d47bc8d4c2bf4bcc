// Reading the G-buffer (group 2) in deferred passes, fragment or compute. The texture types
// come from the frame's sample count (`shader/msaa.wgsl`): with MSAA every target holds
// each sample, `textureLoad(t, p, s)` reading sample `s`.

@group(2) @binding(0) var gb_normal: SampleTexture;
@group(2) @binding(1) var gb_diffuse: SampleTexture;
// Binding 2, the specular target, is declared by the layout's piece (gbuffer_specular*.wgsl):
// the mono-specular layout has none.
@group(2) @binding(3) var gb_base: SampleTexture;
@group(2) @binding(4) var gb_depth: DepthTexture;

// The surface stored at pixel `p`, its material's shader applied (the branch of deferred
// shading on the stored material); the light-independent term travels as `emissive`.
fn surface_from_gbuffer(p: vec2<u32>, depth: f32) -> Surface {
    return apply_material(raw_surface_from_gbuffer(p, 0u, position_from_depth(p, depth)));
}

// Sample `s` of pixel `p` as stored, at world position `position`.
fn raw_surface_from_gbuffer(p: vec2<u32>, s: u32, position: vec3<f32>) -> Surface {
    let n = textureLoad(gb_normal, p, s);
    let d = textureLoad(gb_diffuse, p, s);
    let b = textureLoad(gb_base, p, s);
    var out: Surface;
    out.position = position;
    out.normal = normalize(n.xyz);
    out.diffuse = d.rgb;
    // The G-buffer holds opaque samples only (alpha-tested ones passed): no lighting reads it.
    out.alpha = 1.0;
    out.emissive = b.rgb;
    out.ambient = vec3<f32>(0.0);
    out.material = u32(n.w + 0.5);
    let sp = gbuffer_specular(p, s, d, out.material);
    out.specular = sp.rgb;
    out.shininess = sp.a;
    return out;
}
