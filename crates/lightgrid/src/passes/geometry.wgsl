// The scene's vertex stage, shared by every pass that rasterizes geometry, and the
// conversion from interpolated vertex data to a shading `Surface`.

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) material: u32,
    @location(4) tangent: vec4<f32>,
    @location(5) color: vec4<f32>,
    @location(6) uv1: vec2<f32>,
}

struct VertexOut {
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) position: vec3<f32>,  // camera-relative
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) @interpolate(flat) material: u32,
    @location(4) tangent: vec4<f32>,
    @location(5) color: vec4<f32>,
    @location(6) uv1: vec2<f32>,
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
    out.tangent = v.tangent;
    out.color = v.color;
    out.uv1 = v.uv1;
    return out;
}

// Does any material of the scene read inputs per sample beyond its base colour (a
// metallic-roughness model, normal, occlusion or emissive textures: `Shading::material_inputs`)?
// `SHADING_MATERIAL_INPUTS`, a `const` declared when the module is made (as lighting.wgsl's
// `SHADING_*`). Without them the shader is made without those reads: a software rasterizer
// runs both sides of a branch, so an untaken one still costs (a third of lavapipe's G-buffer
// pass).

// The scene's base-colour textures (group 0; `passes/base_textures.rs`): one array, a layer
// per texture, sRGB-decoded when sampled, mipmapped, repeating.
@group(0) @binding(5) var base_textures: texture_2d_array<f32>;
@group(0) @binding(6) var base_sampler: sampler;
// Nearest-texel magnification, for textures whose glTF sampler asks for it.
// The same array bound again for it: GLSL (the GL backend) pairs a texture with one sampler.
@group(0) @binding(10) var nearest_sampler: sampler;
@group(0) @binding(11) var base_textures_nearest: texture_2d_array<f32>;

// Where a material's textures are read at a sample: both coordinate sets and their screen
// derivatives (taken here, in uniform control flow, so textures can be read in branches
// with explicit gradients: only the textures a material has are sampled).
struct TexCoords {
    uv: array<vec2<f32>, 2>,
    ddx: array<vec2<f32>, 2>,
    ddy: array<vec2<f32>, 2>,
}

fn tex_coords(v: VertexOut) -> TexCoords {
    var t: TexCoords;
    t.uv = array<vec2<f32>, 2>(v.uv, v.uv1);
    t.ddx = array<vec2<f32>, 2>(dpdx(v.uv), dpdx(v.uv1));
    t.ddy = array<vec2<f32>, 2>(dpdy(v.uv), dpdy(v.uv1));
    return t;
}

// One coordinate wrapped as a glTF sampler says: the GPU sampler repeats; clamping keeps the
// coordinate within half a texel of the edges (so the repeat never blends the far edge in);
// mirroring folds every other repeat back, and is then clamped the same way (at a fold an
// edge texel meets its own mirror image, not the far edge).
fn wrap_coordinate(x: f32, mode: u32, texels: f32) -> f32 {
    let half = 0.5 / texels;
    if (mode == WRAP_CLAMP) {
        return clamp(x, half, 1.0 - half);
    }
    if (mode == WRAP_MIRROR) {
        let t = fract(x * 0.5) * 2.0;
        return clamp(select(t, 2.0 - t, t > 1.0), half, 1.0 - half);
    }
    return x;
}

// Float `i` of a material's texture transforms.
fn uv_transform(m: Material, i: u32) -> f32 {
    return m.uv_transforms[i / 4u][i % 4u];
}

// Texture slot `slot` of material `m` (layer + 1 in `texture`; 0: none, then `none`) at the
// sample: its coordinate set and wrapping, the gradients of the unwrapped coordinates (so a
// seam of the wrapping does not change the mip level).
fn material_texel(m: Material, t: TexCoords, slot: u32, texture: u32, none: vec4<f32>) -> vec4<f32> {
    if (texture == 0u) {
        return none;
    }
    let coords = (m.uv_sets >> slot) & 1u;
    let wrap = (m.wraps >> (4u * slot)) & 15u;
    let texels = f32(textureDimensions(base_textures).x);
    // KHR_texture_transform: the slot's 2x3 matrix on the coordinates, its 2x2 part on
    // their gradients.
    let k = 6u * slot;
    let row_u = vec3<f32>(uv_transform(m, k), uv_transform(m, k + 1u), uv_transform(m, k + 2u));
    let row_v = vec3<f32>(uv_transform(m, k + 3u), uv_transform(m, k + 4u), uv_transform(m, k + 5u));
    let moved = vec2<f32>(dot(row_u, vec3<f32>(t.uv[coords], 1.0)), dot(row_v, vec3<f32>(t.uv[coords], 1.0)));
    let linear = mat2x2<f32>(vec2<f32>(row_u.x, row_v.x), vec2<f32>(row_u.y, row_v.y));
    let ddx = linear * t.ddx[coords];
    let ddy = linear * t.ddy[coords];
    let uv = vec2<f32>(
        wrap_coordinate(moved.x, wrap & 3u, texels),
        wrap_coordinate(moved.y, wrap >> 2u, texels),
    );
    let layer = texture - 1u;
    if (((m.nearest >> slot) & 1u) != 0u) {
        return textureSampleGrad(base_textures_nearest, nearest_sampler, uv, layer, ddx, ddy);
    }
    return textureSampleGrad(base_textures, base_sampler, uv, layer, ddx, ddy);
}

// A material's base colour at the sample: its texture's texel times the vertex colour (white
// without either).
fn base_colour(m: Material, v: VertexOut, t: TexCoords) -> vec4<f32> {
    return material_texel(m, t, TEXTURE_SLOT_BASE, m.texture, vec4<f32>(1.0)) * v.color;
}

// A material's emissive colour at the sample: its emissive factor times its emissive
// texture's texel (glTF's emissiveTexture), or the factor alone.
fn emissive_colour(m: Material, t: TexCoords) -> vec3<f32> {
    if (!SHADING_MATERIAL_INPUTS) {
        return m.emissive;
    }
    let one = vec4<f32>(1.0);
    return m.emissive * material_texel(m, t, TEXTURE_SLOT_EMISSIVE, m.emissive_texture, one).rgb;
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
    alpha_test(m, m.alpha * base_colour(m, v, tex_coords(v)).a);
}

// The surface a lighting pass shades: the material's colours with its shader applied.
fn surface_from_vertex(v: VertexOut, front_facing: bool) -> Surface {
    return apply_material(raw_surface_from_vertex(v, front_facing));
}

// The material's own colours (what the G-buffer stores; the shading pass applies the shader).
fn raw_surface_from_vertex(v: VertexOut, front_facing: bool) -> Surface {
    let m = materials[v.material];
    let t = tex_coords(v);
    let base = base_colour(m, v, t);
    alpha_test(m, m.alpha * base.a);
    var s: Surface;
    s.position = v.position;
    s.normal = mapped_normal(m, v, t);
    // Two-sided: flip the normal on back faces so thin geometry is lit from both sides.
    s.normal = select(-s.normal, s.normal, front_facing);
    s.diffuse = m.diffuse * base.rgb;
    s.alpha = m.alpha * base.a;
    s.specular = m.specular;
    s.shininess = m.shininess;
    if (SHADING_MATERIAL_INPUTS && (m.flags & MATERIAL_FLAG_METALLIC_ROUGHNESS) != 0u) {
        // glTF's metallic-roughness per sample, by the import's rule (map_material):
        // the texture's B is metallic, G roughness.
        let one = vec4<f32>(1.0);
        let mr = material_texel(m, t, TEXTURE_SLOT_METAL_ROUGH, m.metal_rough_texture, one);
        let metallic = clamp(m.metallic * mr.b, 0.0, 1.0);
        let roughness = clamp(m.roughness * mr.g, 0.0, 1.0);
        let colour = m.base * base.rgb;
        let alpha_g = max(roughness * roughness, 1e-3);
        s.diffuse = colour * (1.0 - metallic);
        s.specular = mix(vec3<f32>(0.04), colour, metallic);
        s.shininess = clamp(2.0 / (alpha_g * alpha_g) - 2.0, MIN_SHININESS, MAX_SHININESS);
    }
    s.emissive = emissive_colour(m, t);
    // Occlusion darkens the ambient term only (glTF: indirect light), by its strength.
    s.ambient = m.ambient * base.rgb;
    if (SHADING_MATERIAL_INPUTS) {
        let occlusion = material_texel(m, t, TEXTURE_SLOT_OCCLUSION, m.occlusion_texture, vec4<f32>(1.0)).r;
        s.ambient *= 1.0 + m.occlusion_strength * (occlusion - 1.0);
    }
    s.material = v.material;
    return s;
}

// The shading normal: the vertex normal, or the normal texture's tangent-space normal (its
// x and y times the scale) through the vertex's tangent frame (glTF §3.9.3).
fn mapped_normal(m: Material, v: VertexOut, t: TexCoords) -> vec3<f32> {
    let n = normalize(v.normal);
    if (!SHADING_MATERIAL_INPUTS || m.normal_texture == 0u) {
        return n;
    }
    let texel = material_texel(m, t, TEXTURE_SLOT_NORMAL, m.normal_texture, vec4<f32>(0.5, 0.5, 1.0, 1.0));
    let tn = (texel.xyz * 2.0 - 1.0) * vec3<f32>(m.normal_scale, m.normal_scale, 1.0);
    let tangent = v.tangent.xyz - n * dot(n, v.tangent.xyz);
    if (dot(tangent, tangent) < 1e-12) {
        return n;
    }
    let tu = normalize(tangent);
    let bv = cross(n, tu) * select(1.0, -1.0, v.tangent.w < 0.0);
    let mapped = tu * tn.x + bv * tn.y + n * tn.z;
    return select(n, normalize(mapped), dot(mapped, mapped) > 1e-12);
}
