// The scene's vertex stage, shared by every pass that rasterizes geometry, and the
// conversion from interpolated vertex data to a shading `Surface`.

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) material: u32,
}

struct VertexOut {
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) position: vec3<f32>,  // camera-relative
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) @interpolate(flat) material: u32,
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    // Camera-relative (scene_bindings.wgsl): the difference of two nearby f32 world
    // positions is exact, so a scene far from the origin keeps its precision from here on.
    let p = v.position - frame.eye;
    out.clip = frame.view_proj * vec4<f32>(p, 1.0);
    out.position = p;
    out.normal = v.normal;
    out.uv = v.uv;
    out.material = v.material;
    return out;
}

// The scene's base-colour textures (group 0; `passes/base_textures.rs`): one array, a layer
// per texture, sRGB-decoded when sampled, mipmapped, repeating.
@group(0) @binding(6) var base_textures: texture_2d_array<f32>;
@group(0) @binding(7) var base_sampler: sampler;

// A material's base colour at `uv`: its texture's texel, or 1 without a texture. Always
// sampled (layer 0 stands in) so the implicit derivatives stay in uniform control flow.
fn base_colour(m: Material, uv: vec2<f32>) -> vec4<f32> {
    let texel = textureSample(base_textures, base_sampler, uv, max(m.texture, 1u) - 1u);
    return select(vec4<f32>(1.0), texel, m.texture != 0u);
}

// A material's emissive colour at `uv`: its emissive factor times its emissive texture's
// texel (glTF's emissiveTexture), or the factor alone. Always sampled, as `base_colour`.
fn emissive_colour(m: Material, uv: vec2<f32>) -> vec3<f32> {
    let layer = max(m.emissive_texture, 1u) - 1u;
    let texel = textureSample(base_textures, base_sampler, uv, layer).rgb;
    return m.emissive * select(vec3<f32>(1.0), texel, m.emissive_texture != 0u);
}

// The alpha test (glTF MASK): a fragment whose alpha is under its material's cutoff is not
// there, in any pass (a cutoff of 0 never discards).
fn alpha_test(m: Material, alpha: f32) {
    if (alpha < m.alpha_cutoff) {
        discard;
    }
}

// Depth-only passes draw alpha-tested runs with this stage (the others without one).
@fragment
fn fs_depth(v: VertexOut) {
    let m = materials[v.material];
    alpha_test(m, m.alpha * base_colour(m, v.uv).a);
}

// The surface a lighting pass shades: the material's colours with its shader applied.
fn surface_from_vertex(v: VertexOut, front_facing: bool) -> Surface {
    return apply_material(raw_surface_from_vertex(v, front_facing));
}

// The material's own colours (what the G-buffer stores; the shading pass applies the shader).
fn raw_surface_from_vertex(v: VertexOut, front_facing: bool) -> Surface {
    let m = materials[v.material];
    let base = base_colour(m, v.uv);
    alpha_test(m, m.alpha * base.a);
    var s: Surface;
    s.position = v.position;
    // Two-sided: flip the normal on back faces so thin geometry is lit from both sides.
    s.normal = normalize(select(-v.normal, v.normal, front_facing));
    s.diffuse = m.diffuse * base.rgb;
    s.alpha = m.alpha * base.a;
    s.specular = m.specular;
    s.shininess = m.shininess;
    s.emissive = emissive_colour(m, v.uv);
    s.ambient = m.ambient * base.rgb;
    s.material = v.material;
    return s;
}
