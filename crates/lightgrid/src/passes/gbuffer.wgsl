// G-buffer pass (tiled-shading §8): normal + material index, diffuse colour, specular colour + shininess,
// and the light-independent term (emissive + ambient). Depth goes to the shared depth target.
// The mono-specular layout (`fs_gbuffer_mono`) has no specular target: location 2 stays empty.

struct GBufferOut {
    @location(0) normal: vec4<f32>,
    @location(1) diffuse: vec4<f32>,
    @location(2) specular: vec4<f32>,
    @location(3) base: vec4<f32>,
}

@fragment
fn fs_gbuffer(v: VertexOut, @builtin(front_facing) front: bool) -> GBufferOut {
    let s = raw_surface_from_vertex(v, front);
    var out: GBufferOut;
    // The material index rides in the normal's fourth channel (exact in 16-bit floats up to
    // MAX_MATERIALS): the shading pass branches on its shader.
    out.normal = vec4<f32>(s.normal, f32(s.material));
    out.diffuse = vec4<f32>(s.diffuse, s.alpha);
    out.specular = vec4<f32>(s.specular, s.shininess);
    out.base = vec4<f32>(surface_base(s), 1.0);
    return out;
}

struct GBufferMonoOut {
    @location(0) normal: vec4<f32>,
    @location(1) diffuse: vec4<f32>,
    @location(3) base: vec4<f32>,
}

// The blog's compromise on the deferred-shading side: the specular albedo as one value
// (`mono_albedo`), stored in the diffuse target's otherwise unused alpha.
@fragment
fn fs_gbuffer_mono(v: VertexOut, @builtin(front_facing) front: bool) -> GBufferMonoOut {
    let s = raw_surface_from_vertex(v, front);
    var out: GBufferMonoOut;
    out.normal = vec4<f32>(s.normal, f32(s.material));
    out.diffuse = vec4<f32>(s.diffuse, mono_albedo(s.specular).x);
    out.base = vec4<f32>(surface_base(s), 1.0);
    return out;
}
