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
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) @interpolate(flat) material: u32,
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = frame.view_proj * vec4<f32>(v.position, 1.0);
    out.world = v.position;
    out.normal = v.normal;
    out.uv = v.uv;
    out.material = v.material;
    return out;
}

// The surface a lighting pass shades: the material's colours with its shader applied.
fn surface_from_vertex(v: VertexOut, front_facing: bool) -> Surface {
    return apply_material(raw_surface_from_vertex(v, front_facing));
}

// The material's own colours (what the G-buffer stores; the shading pass applies the shader).
fn raw_surface_from_vertex(v: VertexOut, front_facing: bool) -> Surface {
    let m = materials[v.material];
    var s: Surface;
    s.position = v.world;
    // Two-sided: flip the normal on back faces so thin geometry is lit from both sides.
    s.normal = normalize(select(-v.normal, v.normal, front_facing));
    s.diffuse = m.diffuse;
    s.alpha = m.alpha;
    s.specular = m.specular;
    s.shininess = m.shininess;
    s.emissive = m.emissive;
    s.ambient = m.ambient;
    s.material = v.material;
    return s;
}
