// The one light function. Every pipeline shades through `light_terms` / `shade_light`;
// none has its own attenuation or BRDF.

// A shading sample: everything the light function needs, wherever it came from
// (interpolated vertex data or a G-buffer).
struct Surface {
    position: vec3<f32>,   // camera-relative (world minus the eye; scene_bindings.wgsl)
    normal: vec3<f32>,     // world orientation, unit length
    diffuse: vec3<f32>,
    alpha: f32,
    specular: vec3<f32>,
    shininess: f32,
    emissive: vec3<f32>,
    ambient: vec3<f32>,
    material: u32,         // index into `materials` (its shader and paint)
}

// Diffuse and specular irradiance from one light, before the material colours multiply them.
// The light pre-pass accumulates these two separately; everything else uses `shade_light`.
struct LightTerms {
    diffuse: vec3<f32>,
    specular: vec3<f32>,
}

// Smooth window that is 1 at the light and reaches exactly 0 at `range`, with zero slope there:
// (1 - (d/r)^2)^2. Lights are bounded (tiled-shading §1.1): nothing beyond the range, nor
// outside a spot's outer cone, so culling by those bounds is exact.
fn range_falloff(dist_sq: f32, range: f32) -> f32 {
    let t = saturate(1.0 - dist_sq / (range * range));
    return t * t;
}

// A spot's angular window: 1 inside the inner cone, a smoothstep to exactly 0 at the outer
// cone, 0 outside; 1 for a point light. `l` is the unit vector from the surface to the light.
fn spot_falloff(light: Light, l: vec3<f32>) -> f32 {
    if (light.cos_outer <= POINT_LIGHT_COS) {
        return 1.0;
    }
    return smoothstep(light.cos_outer, light.cos_inner, dot(-l, light.direction));
}

// Blinn-Phong from a point or spot light with a finite range. `view_dir` points from the
// surface to the eye.
fn light_terms(s: Surface, view_dir: vec3<f32>, light: Light) -> LightTerms {
    var out: LightTerms;
    out.diffuse = vec3<f32>(0.0);
    out.specular = vec3<f32>(0.0);
    let to_light = light.position - s.position;
    let dist_sq = dot(to_light, to_light);
    if (dist_sq >= light.range * light.range) {
        return out;
    }
    let l = to_light * inverseSqrt(max(dist_sq, 1e-12));
    let n_dot_l = dot(s.normal, l);
    let cone = spot_falloff(light, l);
    if (n_dot_l <= 0.0 || cone <= 0.0) {
        return out;
    }
    let radiance = light.radiance * (range_falloff(dist_sq, light.range) * cone);
    let h = normalize(l + view_dir);
    let n_dot_h = max(dot(s.normal, h), 0.0);
    out.diffuse = radiance * n_dot_l;
    out.specular = radiance * (pow(n_dot_h, s.shininess) * n_dot_l);
    return out;
}

fn shade_light(s: Surface, view_dir: vec3<f32>, light: Light) -> vec3<f32> {
    let t = light_terms(s, view_dir, light);
    return t.diffuse * s.diffuse + t.specular * s.specular;
}

// Per-material shaders (tiled-forward-shading §4.7: each draw may have its own lighting
// model). A material shader only changes the colour the one light function's diffuse term is
// multiplied by, from the view: car paint blends its diffuse colour toward a flip colour at
// grazing angles, a rim material adds a rim colour there (lit by the lights reaching it). So
// the result is linear in each light's terms, and forward (one pipeline per shader), deferred
// (a branch on the G-buffer's material) and the light pre-pass (applied once to the summed
// irradiance) give the same image.
// Forward pipelines set MATERIAL_SHADER per pipeline and draw each shader's geometry with its
// own; MATERIAL_SHADER_ANY (the default) branches on the material's own id.
override MATERIAL_SHADER: u32 = MATERIAL_SHADER_ANY;

fn apply_material(s: Surface) -> Surface {
    let m = materials[s.material];
    let kind = select(MATERIAL_SHADER, m.shader, MATERIAL_SHADER == MATERIAL_SHADER_ANY);
    let grazing = pow(1.0 - saturate(dot(s.normal, view_dir_to(s.position))), m.paint_power);
    var out = s;
    switch kind {
        case MATERIAL_SHADER_CAR_PAINT: {
            out.diffuse = mix(s.diffuse, m.paint, grazing);
        }
        case MATERIAL_SHADER_RIM: {
            out.diffuse = s.diffuse + m.paint * grazing;
        }
        default: {}
    }
    return out;
}

// Every light of the frame on the surface: brute force (`forward`, and the transparent pass
// of `forward`), with the loop checked.
fn shade_all_lights(s: Surface, view_dir: vec3<f32>) -> vec3<f32> {
    var acc = vec3<f32>(0.0);
    var i = 0u;
    for (; i < frame.light_count; i = i + 1u) {
        acc += shade_light(s, view_dir, lights[i]);
    }
    check_loop(i, frame.light_count);
    return acc;
}

// The part of a sample's colour that does not depend on any light.
fn surface_base(s: Surface) -> vec3<f32> {
    return s.emissive + s.ambient * SCENE_AMBIENT;
}

// Relative luminance of linear RGB (Rec. 709 weights).
fn luminance(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}

// The light pre-pass compromise (deferred-shading-vs-deferred-lighting): specular irradiance
// stored as one luminance value and re-coloured with the diffuse irradiance's chromaticity.
// Exact when all lights reaching a sample share one colour; otherwise the specular takes the
// mixture's colour.
fn mono_specular(diffuse_irradiance: vec3<f32>, specular_luminance: f32) -> vec3<f32> {
    let l = luminance(diffuse_irradiance);
    if (l <= 1e-8) {
        return vec3<f32>(specular_luminance);
    }
    return diffuse_irradiance * (specular_luminance / l);
}

// The same compromise on the deferred-shading side (the blog's fair counterpart): the
// specular albedo as one value, its luminance, in every channel. Exact for grey specular
// (every catalog material); a coloured one (a glTF metal) loses its tint.
fn mono_albedo(specular: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(luminance(specular));
}
