// The mono-specular G-buffer layout's specular (`GBufferLayout::MonoSpecular`, the
// deferred-shading side of the blog's compromise): one specular value in the diffuse
// target's alpha, no specular target. The exponent is the material's: the blog packs it beside
// the normal, where this G-buffer keeps the material index that names it.
fn gbuffer_specular(p: vec2<u32>, s: u32, diffuse: vec4<f32>, material: u32) -> vec4<f32> {
    return vec4<f32>(vec3<f32>(diffuse.a), materials[material].shininess);
}
