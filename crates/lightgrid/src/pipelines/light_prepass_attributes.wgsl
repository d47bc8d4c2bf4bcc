// The light pre-pass's attributes (pass 1's normal + specular exponent, specular colour and
// depth, each sample with MSAA: `shader/msaa.wgsl`'s texture types) as read by its irradiance
// passes (group 2): the light volumes' fragments (`light_prepass.wgsl`) and the tiled compute
// kernel (`tiled_light_prepass.wgsl`). Both specular inputs are the sample's own, as the
// forward pass computes them (a metallic-roughness texture or a metal's base colour varies
// them within a material).

@group(2) @binding(0) var attr_normal_shininess: SampleTexture;
@group(2) @binding(1) var attr_depth: DepthTexture;
@group(2) @binding(2) var attr_specular: SampleTexture;

// The specular colour (GGX's Fresnel F0) of sample `s` of pixel `p`: Blinn-Phong's irradiance
// does not read it (its shading pass multiplies by the colour).
fn attributes_specular(p: vec2<u32>, s: u32) -> vec3<f32> {
    if (SHADING_BRDF == BRDF_GGX) {
        return textureLoad(attr_specular, p, s).rgb;
    }
    return vec3<f32>(0.0);
}

// The surface the irradiance is computed at: sample `s` of pixel `p`'s normal, exponent and
// specular colour, at camera-relative `position`.
fn attributes_surface_at(p: vec2<u32>, s: u32, position: vec3<f32>) -> Surface {
    let a = textureLoad(attr_normal_shininess, p, s);
    var surface: Surface;
    surface.position = position;
    surface.normal = normalize(a.xyz);
    surface.shininess = a.w;
    surface.specular = attributes_specular(p, s);
    return surface;
}


// Pixel `p` shaded once (no edge; every pixel without MSAA): sample 0's normal and exponent
// at the pixel centre.
fn attributes_pixel_surface(p: vec2<u32>) -> Surface {
    let position = position_from_screen(vec2<f32>(p) + vec2<f32>(0.5), centre_depth(attr_depth, p));
    return attributes_surface_at(p, 0u, position);
}

// Sample `s` of an edge pixel `p`, with depth-buffer value `depth`, where it lies.
fn attributes_sample_surface(p: vec2<u32>, s: u32, depth: f32) -> Surface {
    return attributes_surface_at(p, s, position_from_screen(vec2<f32>(p) + sample_position(s), depth));
}

// The MSAA edge test over the attributes (`msaa_surfaces.wgsl`): do samples 0 (depth `d0`,
// attributes `a0`) and `s` of pixel `p` need irradiance of their own? Geometry against sky,
// another specular exponent (under GGX another specular colour), or another plane or normal.
// Another material alone is no edge: the irradiance is a function of position, normal and
// exponent (and GGX's F0) alone; the materials' diffuse colours are applied by the shading
// pass, whose fragments cover exactly their own triangle's samples, so two materials meeting
// in one plane with one exponent read one irradiance correctly (the G-buffer's test marks such pixels only because it
// shades the material there too).
fn attributes_differ(p: vec2<u32>, s: u32, d0: f32, a0: vec4<f32>) -> bool {
    let d = textureLoad(attr_depth, p, s);
    if (is_background(d) != is_background(d0)) {
        return true;
    }
    if (is_background(d0)) {
        return false;
    }
    let a = textureLoad(attr_normal_shininess, p, s);
    // Another exponent, or under GGX another specular colour (its Fresnel is inside the
    // irradiance), gives other irradiance from one light at one place.
    let other = a.w != a0.w || any(attributes_specular(p, s) != attributes_specular(p, 0u));
    return surfaces_differ(p, s, d0, a0.xyz, d, a.xyz, other);
}

// Is pixel `p` an MSAA edge (some sample differs from sample 0)? Never without MSAA.
fn attributes_edge(p: vec2<u32>) -> bool {
    let d0 = textureLoad(attr_depth, p, 0);
    let a0 = textureLoad(attr_normal_shininess, p, 0);
    var edge = false;
    for (var s = 1u; s < SAMPLES; s = s + 1u) {
        edge = edge || attributes_differ(p, s, d0, a0);
    }
    return edge;
}
