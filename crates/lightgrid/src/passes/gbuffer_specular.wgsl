// The full G-buffer layout's specular (`GBufferLayout::Full`): colour and exponent in their
// own target.
@group(2) @binding(2) var gb_specular: SampleTexture;

// Specular colour (rgb) and exponent (a) of sample `s` of pixel `p`.
fn gbuffer_specular(p: vec2<u32>, s: u32, diffuse: vec4<f32>, material: u32) -> vec4<f32> {
    return textureLoad(gb_specular, p, s);
}
