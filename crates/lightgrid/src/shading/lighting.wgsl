// The one light function. Every pipeline shades through `light_terms` / `shade_light`;
// none has its own attenuation or BRDF.

// The BRDF (`SHADING_BRDF`: BRDF_PHONG or BRDF_GGX), the distance falloff
// (`SHADING_FALLOFF`: FALLOFF_WINDOW, the papers' units, or FALLOFF_INVERSE_SQUARE,
// photometric), how lights are shadowed (`SHADING_SHADOWS`: SHADOWS_OFF, SHADOWS_RAYS,
// SHADOWS_MAPS or SHADOWS_MAPS_REUSED) and the spots' window between their cones
// (`SHADING_SPOT_CONE`: `scene::SpotCone`) are `const`s declared when a pipeline's module is
// made (`ComposedShader::specialized`, from the renderer's resolved `scene::Shading`), so
// the light loop carries no branch, and no registers, for the model a frame does not use. A
// module made without them does not compile.

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

// Diffuse and specular irradiance from one light, before the material colours multiply them:
// the sample's colour is `diffuse * s.diffuse + specular * specular_albedo(s)`. The light
// pre-pass accumulates these two separately; everything else uses `shade_light`.
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

// How a light's radiance falls off with distance, by the lights' units (`SHADING_FALLOFF`,
// scene/lighting.rs): the papers' window, or KHR_lights_punctual's inverse square with its
// recommended window clamp(1 - (d/r)^4, 0, 1)^2, which also reaches exactly 0 at the range.
fn distance_falloff(dist_sq: f32, range: f32) -> f32 {
    if (SHADING_FALLOFF == FALLOFF_INVERSE_SQUARE) {
        let x = dist_sq / (range * range);
        let t = saturate(1.0 - x * x);
        return t * t / max(dist_sq, MIN_LIGHT_DISTANCE_SQ);
    }
    return range_falloff(dist_sq, range);
}

// A spot's angular window: 1 inside the inner cone, falling to exactly 0 at the outer cone
// (the papers' smoothstep, or KHR_lights_punctual's t² of the linear ramp t:
// `SHADING_SPOT_CONE`), 0 outside; 1 for a point light. `l` is the unit vector from the
// surface to the light.
fn spot_falloff(light: Light, l: vec3<f32>) -> f32 {
    if (light.cos_outer <= POINT_LIGHT_COS) {
        return 1.0;
    }
    let cos_theta = dot(-l, light.direction);
    if (SHADING_SPOT_CONE == SPOT_CONE_SQUARED) {
        let t = saturate((cos_theta - light.cos_outer) / (light.cos_inner - light.cos_outer));
        return t * t;
    }
    return smoothstep(light.cos_outer, light.cos_inner, cos_theta);
}

const INV_PI: f32 = 0.318309886;

// GGX's roughness from the material's Blinn-Phong exponent: alpha = sqrt(2 / (s + 2)), the
// inverse of the glTF import's s = 2 / alpha^2 - 2 (scene/lighting.rs, `Brdf::Ggx`).
fn ggx_alpha(shininess: f32) -> f32 {
    return sqrt(2.0 / (max(shininess, 0.0) + 2.0));
}

// glTF 2.0's metallic-roughness BRDF (appendix B) for irradiance `e` arriving along `l`:
// the Lambert term (1 - F) c_diff / pi and F * D * V, with the GGX distribution D, Smith's
// height-correlated visibility V and Schlick's Fresnel F whose F0 is the specular colour
// (the spec's fresnel_mix). The Fresnel term holds the specular colour, so `specular_albedo`
// is 1 under GGX. Both terms depend on F0 per light, which keeps the light pre-pass's split
// exact because its irradiance pass reads the material's F0 (`light_prepass_attributes.wgsl`):
// the material's diffuse colour still multiplies the summed diffuse term afterwards.
fn ggx_terms(s: Surface, view_dir: vec3<f32>, l: vec3<f32>, n_dot_l: f32, e: vec3<f32>) -> LightTerms {
    let h = normalize(l + view_dir);
    let n_dot_v = saturate(dot(s.normal, view_dir));
    let n_dot_h = saturate(dot(s.normal, h));
    let v_dot_h = saturate(dot(view_dir, h));
    let a = ggx_alpha(s.shininess);
    let a2 = a * a;
    let k = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    let d = a2 * INV_PI / (k * k);
    let vis = 0.5 / (n_dot_l * sqrt(n_dot_v * n_dot_v * (1.0 - a2) + a2)
        + n_dot_v * sqrt(n_dot_l * n_dot_l * (1.0 - a2) + a2));
    let fresnel = s.specular + (vec3<f32>(1.0) - s.specular) * pow(1.0 - v_dot_h, 5.0);
    var out: LightTerms;
    out.diffuse = e * (vec3<f32>(1.0) - fresnel) * INV_PI;
    out.specular = e * fresnel * (d * vis);
    return out;
}

// Light `index`'s terms on the surface: Blinn-Phong or GGX (`SHADING_BRDF`) from a point or
// spot light with a finite range, times its visibility where it casts shadows
// (`SHADING_SHADOWS`, shadows.wgsl). `view_dir` points from the surface to the eye.
fn light_terms(s: Surface, view_dir: vec3<f32>, index: u32) -> LightTerms {
    let light = scene_light(index);
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
    // Only a light that would light the sample tests its shadow (shadows.wgsl).
    var visible = 1.0;
    if (SHADING_SHADOWS == SHADOWS_RAYS && shadow_blocked(index, s.position, s.normal, light.position)) {
        return out;
    }
    if (SHADING_SHADOWS == SHADOWS_MAPS || SHADING_SHADOWS == SHADOWS_MAPS_REUSED) {
        visible = shadow_map_visibility(index, s.position, s.normal, light.position, n_dot_l);
        if (visible <= 0.0) {
            return out;
        }
    }
    // Irradiance: the radiance is uploaded scaled by the exposure and the BRDF's convention
    // (`Lighting::light_scale`).
    let e = light.radiance * (distance_falloff(dist_sq, light.range) * cone * n_dot_l * visible);
    if (SHADING_BRDF == BRDF_GGX) {
        out = ggx_terms(s, view_dir, l, n_dot_l, e);
    } else {
        let h = normalize(l + view_dir);
        let n_dot_h = max(dot(s.normal, h), 0.0);
        out.diffuse = e;
        out.specular = e * pow(n_dot_h, s.shininess);
    }
    return out;
}

// What the specular term is multiplied by: the specular colour under Blinn-Phong; 1 under
// GGX, whose Fresnel term already holds it.
fn specular_albedo(s: Surface) -> vec3<f32> {
    return select(s.specular, vec3<f32>(1.0), SHADING_BRDF == BRDF_GGX);
}

fn shade_light(s: Surface, view_dir: vec3<f32>, light: u32) -> vec3<f32> {
    let t = light_terms(s, view_dir, light);
    return t.diffuse * s.diffuse + t.specular * specular_albedo(s);
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
        acc += shade_light(s, view_dir, i);
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
// mixture's colour. Where the diffuse irradiance is next to nothing beside the specular (a
// white metal, whose 1 − F rounds to a few ulps) its colour is rounding, so the specular
// stays grey.
fn mono_specular(diffuse_irradiance: vec3<f32>, specular_luminance: f32) -> vec3<f32> {
    let l = luminance(diffuse_irradiance);
    if (l <= max(1e-8, 1e-6 * specular_luminance)) {
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
