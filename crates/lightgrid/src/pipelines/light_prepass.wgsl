// light_prepass / light_prepass_mono (deferred lighting): attributes, irradiance per light
// volume, then a second geometry pass that applies the materials.
//
// With MSAA (tiled-deferred-tricks, as `deferred.wgsl`; `light_prepass.rs`): every target
// holds each sample; `fs_mark_edges` sets the stencil's edge bit on the pixels whose samples
// need irradiance of their own (`attributes_differ`); the irradiance of every other pixel is
// computed once, at its centre, and written to all its samples (`fs_irradiance*`), that of
// an edge pixel sample by sample where each lies (`fs_irradiance*_sample`, which read
// `sample_index` and so run per sample). The shading pass tests the same edge bit: per pixel
// elsewhere (every sample holds the pixel's irradiance: sample 0's is read), per sample on
// edge pixels (each sample reads its own). Lighting computations count into the per-pixel counts (`count_pixel`),
// each pixel once (by the fragment covering sample 0, as in `deferred.wgsl`); the full-screen
// `fs_count*` draws count edge pixels, irradiance samples computed and samples with geometry.
// Entries with side effects force the early depth and stencil tests, so the per-sample
// pipelines count only the samples the edge bit lets through.

// --- 1. attributes: normal and specular exponent, and the specular colour (GGX's Fresnel
// F0, which its irradiance holds); depth goes to the depth target. Each is the sample's own,
// as forward shades it (`light_prepass_attributes.wgsl` reads them).
struct AttributesOut {
    @location(0) normal_shininess: vec4<f32>,
    @location(1) specular: vec4<f32>,
}

@fragment
fn fs_attributes(v: VertexOut, @builtin(front_facing) front: bool) -> AttributesOut {
    let s = surface_from_vertex(v, front);
    var out: AttributesOut;
    out.normal_shininess = vec4<f32>(s.normal, s.shininess);
    out.specular = vec4<f32>(s.specular, 1.0);
    return out;
}

// --- 2. irradiance: group 2 = attributes + scene depth (light_prepass_attributes.wgsl)

struct IrradianceOut {
    @location(0) diffuse: vec4<f32>,
    @location(1) specular: vec4<f32>,
    @location(2) count: f32,
}


// The lighting computation of a volume fragment at pixel `p`, counted `n` times.
fn irradiance_out(p: vec2<u32>, s: Surface, light: u32, n: u32) -> IrradianceOut {
    if (MULTISAMPLED) {
        count_pixel(p, n);
    }
    let t = light_terms(s, view_dir_to(s.position), light);
    var out: IrradianceOut;
    out.diffuse = vec4<f32>(t.diffuse, 0.0);
    out.specular = vec4<f32>(t.specular, 0.0);
    out.count = f32(n);
    return out;
}

// The common compromise: specular irradiance kept as its luminance, in the diffuse alpha.
fn mono(out: IrradianceOut) -> IrradianceOut {
    var m = out;
    m.diffuse.a = luminance(out.specular.rgb);
    m.specular = vec4<f32>(0.0);
    return m;
}

// One fragment per pixel (no edge; every pixel without MSAA), at the pixel centre.
fn irradiance_pixel(v: VolumeOut, mask: u32) -> IrradianceOut {
    let p = vec2<u32>(v.clip.xy);
    if (is_background(textureLoad(attr_depth, p, 0))) {
        discard;
    }
    return irradiance_out(p, attributes_pixel_surface(p), v.light, select(0u, 1u, counts_for_pixel(mask)));
}

// One fragment per sample of an edge pixel: the sample's own surface where it lies.
fn irradiance_sample(v: VolumeOut, i: u32) -> IrradianceOut {
    let p = vec2<u32>(v.clip.xy);
    let depth = textureLoad(attr_depth, p, i);
    if (is_background(depth)) {
        discard;
    }
    return irradiance_out(p, attributes_sample_surface(p, i, depth), v.light, 1u);
}

@fragment
#if EARLY_DEPTH_TEST
@early_depth_test(force)
#endif
fn fs_irradiance(v: VolumeOut, @builtin(sample_mask) mask: u32) -> IrradianceOut {
    return irradiance_pixel(v, mask);
}

@fragment
#if EARLY_DEPTH_TEST
@early_depth_test(force)
#endif
fn fs_irradiance_sample(v: VolumeOut, @builtin(sample_index) i: u32) -> IrradianceOut {
    return irradiance_sample(v, i);
}

@fragment
#if EARLY_DEPTH_TEST
@early_depth_test(force)
#endif
fn fs_irradiance_mono(v: VolumeOut, @builtin(sample_mask) mask: u32) -> IrradianceOut {
    return mono(irradiance_pixel(v, mask));
}

@fragment
#if EARLY_DEPTH_TEST
@early_depth_test(force)
#endif
fn fs_irradiance_mono_sample(v: VolumeOut, @builtin(sample_index) i: u32) -> IrradianceOut {
    return mono(irradiance_sample(v, i));
}

// MSAA: keep the pixels whose samples need irradiance of their own, whose stencil the
// pipeline marks. No side effects: the stencil is written after the shader (late tests), so
// a discarded pixel stays unmarked.
@fragment
fn fs_mark_edges(@builtin(position) pos: vec4<f32>) -> IrradianceOut {
    if (!attributes_edge(vec2<u32>(pos.xy))) {
        discard;
    }
    var out: IrradianceOut;
    return out;
}

// MSAA, per pixel that is no edge: one irradiance sample computed (counted by the fragment
// covering sample 0), and its covered samples with geometry. Adds nothing to the targets.
@fragment
#if EARLY_DEPTH_TEST
@early_depth_test(force)
#endif
fn fs_count(@builtin(position) pos: vec4<f32>, @builtin(sample_mask) mask: u32) -> IrradianceOut {
    let p = vec2<u32>(pos.xy);
    if (!is_background(textureLoad(attr_depth, p, 0))) {
        count_pixel_once(attr_depth, p, mask);
    }
    var out: IrradianceOut;
    return out;
}

// MSAA, per sample of an edge pixel: the edge pixel once (at sample 0), the sample as
// computed and with geometry. Adds nothing to the targets.
@fragment
#if EARLY_DEPTH_TEST
@early_depth_test(force)
#endif
fn fs_count_sample(@builtin(position) pos: vec4<f32>, @builtin(sample_index) i: u32) -> IrradianceOut {
    count_edge_sample(attr_depth, vec2<u32>(pos.xy), i);
    var out: IrradianceOut;
    return out;
}

// --- 3. shading: group 1 = the irradiance targets
@group(1) @binding(0) var irr_diffuse: SampleTexture;
@group(1) @binding(1) var irr_specular: SampleTexture;

fn shade(v: VertexOut, front: bool, i: u32) -> vec4<f32> {
    let s = surface_from_vertex(v, front);
    let p = vec2<u32>(v.clip.xy);
    let d = textureLoad(irr_diffuse, p, i).rgb;
    let sp = textureLoad(irr_specular, p, i).rgb;
    return vec4<f32>(surface_base(s) + d * s.diffuse + sp * specular_albedo(s), 1.0);
}

fn shade_mono(v: VertexOut, front: bool, i: u32) -> vec4<f32> {
    let s = surface_from_vertex(v, front);
    let d = textureLoad(irr_diffuse, vec2<u32>(v.clip.xy), i);
    return vec4<f32>(surface_base(s) + d.rgb * s.diffuse + mono_specular(d.rgb, d.a) * specular_albedo(s), 1.0);
}

// Per pixel (no edge; every pixel without MSAA): each sample holds the pixel's irradiance.
@fragment
fn fs_shade(v: VertexOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    return shade(v, front, 0u);
}

@fragment
fn fs_shade_mono(v: VertexOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    return shade_mono(v, front, 0u);
}

// Per sample of an edge pixel: the sample's own irradiance.
@fragment
fn fs_shade_sample(v: VertexOut, @builtin(front_facing) front: bool, @builtin(sample_index) i: u32) -> @location(0) vec4<f32> {
    return shade(v, front, i);
}

@fragment
fn fs_shade_mono_sample(v: VertexOut, @builtin(front_facing) front: bool, @builtin(sample_index) i: u32) -> @location(0) vec4<f32> {
    return shade_mono(v, front, i);
}

// --- tiled_light_prepass with MSAA: the kernel's per-sample irradiance (group 1,
// `tiled_light_prepass_msaa.wgsl`) into the multisampled irradiance target, sample by sample.
@group(1) @binding(0) var<storage, read> sample_irradiance: array<vec2<u32>>;

// Mark the pixels whose samples the kernel gave irradiance of their own, read from what it
// stored rather than decided again: the kernel's compute evaluation of the edge test and a
// fragment shader's can round differently on one device (measured on an NVIDIA H200: pixels
// the kernel shaded per sample were left unmarked and shaded from sample 0, up to 95 levels
// off `forward_mono` on 2CylinderEngine at 4x; lavapipe agreed with itself). A pixel whose
// samples hold one value shades alike per pixel and per sample. No side effects (see
// `fs_mark_edges`).
@fragment
fn fs_mark_irradiance_edges(@builtin(position) pos: vec4<f32>) -> IrradianceOut {
    let first = (u32(pos.y) * u32(frame.viewport.x) + u32(pos.x)) * SAMPLES;
    let c0 = sample_irradiance[first];
    var differ = false;
    for (var s = 1u; s < SAMPLES; s = s + 1u) {
        differ = differ || any(sample_irradiance[first + s] != c0);
    }
    if (!differ) {
        discard;
    }
    var out: IrradianceOut;
    return out;
}

@fragment
fn fs_expand_irradiance(@builtin(position) pos: vec4<f32>, @builtin(sample_index) s: u32) -> IrradianceOut {
    let p = vec2<u32>(pos.xy);
    let c = sample_irradiance[(p.y * u32(frame.viewport.x) + p.x) * SAMPLES + s];
    var out: IrradianceOut;
    out.diffuse = vec4<f32>(unpack2x16float(c.x), unpack2x16float(c.y));
    return out;
}
