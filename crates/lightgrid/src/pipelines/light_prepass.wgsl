// light_prepass / light_prepass_mono (deferred lighting): attributes, irradiance per light
// volume, then a second geometry pass that applies the materials.

// --- 1. attributes: normal and specular exponent (depth goes to the depth target)
@fragment
fn fs_attributes(v: VertexOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let s = surface_from_vertex(v, front);
    return vec4<f32>(s.normal, s.shininess);
}

// --- 2. irradiance: group 2 = attributes + scene depth (light_prepass_attributes.wgsl)

struct IrradianceOut {
    @location(0) diffuse: vec4<f32>,
    @location(1) specular: vec4<f32>,
    @location(2) count: f32,
}

// The light terms at the sample under a volume fragment; false for sky.
fn irradiance_terms(v: VolumeOut, out_terms: ptr<function, LightTerms>) -> bool {
    let p = vec2<u32>(v.clip.xy);
    let depth = textureLoad(attr_depth, p, 0);
    if (is_background(depth)) {
        return false;
    }
    let s = attributes_surface(p, depth);
    *out_terms = light_terms(s, view_dir_to(s.position), lights[v.light]);
    return true;
}

@fragment
fn fs_irradiance(v: VolumeOut) -> IrradianceOut {
    var t: LightTerms;
    if (!irradiance_terms(v, &t)) {
        discard;
    }
    var out: IrradianceOut;
    out.diffuse = vec4<f32>(t.diffuse, 0.0);
    out.specular = vec4<f32>(t.specular, 0.0);
    out.count = 1.0;
    return out;
}

// The common compromise: specular irradiance kept as its luminance, in the diffuse alpha.
struct MonoIrradianceOut {
    @location(0) diffuse: vec4<f32>,
    @location(2) count: f32,
}

@fragment
fn fs_irradiance_mono(v: VolumeOut) -> MonoIrradianceOut {
    var t: LightTerms;
    if (!irradiance_terms(v, &t)) {
        discard;
    }
    var out: MonoIrradianceOut;
    out.diffuse = vec4<f32>(t.diffuse, luminance(t.specular));
    out.count = 1.0;
    return out;
}

// --- 3. shading: group 1 = the irradiance targets
@group(1) @binding(0) var irr_diffuse: texture_2d<f32>;
@group(1) @binding(1) var irr_specular: texture_2d<f32>;

@fragment
fn fs_shade(v: VertexOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let s = surface_from_vertex(v, front);
    let p = vec2<u32>(v.clip.xy);
    let d = textureLoad(irr_diffuse, p, 0).rgb;
    let sp = textureLoad(irr_specular, p, 0).rgb;
    return vec4<f32>(surface_base(s) + d * s.diffuse + sp * s.specular, 1.0);
}

@fragment
fn fs_shade_mono(v: VertexOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let s = surface_from_vertex(v, front);
    let d = textureLoad(irr_diffuse, vec2<u32>(v.clip.xy), 0);
    return vec4<f32>(surface_base(s) + d.rgb * s.diffuse + mono_specular(d.rgb, d.a) * s.specular, 1.0);
}
