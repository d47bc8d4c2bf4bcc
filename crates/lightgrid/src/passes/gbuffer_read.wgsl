// Reading the G-buffer in a deferred compute pass (group 2), and writing the pass's outputs:
// HDR colour and the per-pixel lighting-computation count.

@group(2) @binding(0) var gb_normal: texture_2d<f32>;
@group(2) @binding(1) var gb_diffuse: texture_2d<f32>;
@group(2) @binding(2) var gb_specular: texture_2d<f32>;
@group(2) @binding(3) var gb_base: texture_2d<f32>;
@group(2) @binding(4) var gb_depth: texture_depth_2d;
@group(2) @binding(5) var out_color: texture_storage_2d<rgba16float, write>;
@group(2) @binding(6) var out_count: texture_storage_2d<r32float, write>;

// World position of the sample at the centre of pixel `p` with depth-buffer value `depth`.
fn world_from_depth(p: vec2<u32>, depth: f32) -> vec3<f32> {
    let uv = (vec2<f32>(p) + vec2<f32>(0.5)) / frame.viewport;
    let ndc = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, depth, 1.0);
    let h = frame.inv_view_proj * ndc;
    return h.xyz / h.w;
}

// The surface stored at pixel `p`; the light-independent term travels as `emissive`.
fn surface_from_gbuffer(p: vec2<u32>, depth: f32) -> Surface {
    let n = textureLoad(gb_normal, p, 0);
    let d = textureLoad(gb_diffuse, p, 0);
    let sp = textureLoad(gb_specular, p, 0);
    let b = textureLoad(gb_base, p, 0);
    var s: Surface;
    s.position = world_from_depth(p, depth);
    s.normal = normalize(n.xyz);
    s.diffuse = d.rgb;
    s.alpha = d.a;
    s.specular = sp.rgb;
    s.shininess = sp.a;
    s.emissive = b.rgb;
    s.ambient = vec3<f32>(0.0);
    return s;
}

fn write_sample(p: vec2<u32>, color: vec3<f32>, count: u32) {
    textureStore(out_color, p, vec4<f32>(color, 1.0));
    textureStore(out_count, p, vec4<f32>(f32(count), 0.0, 0.0, 0.0));
}
