// Analysis only: every sample of the multisampled depth target into a buffer, one plane per
// sample (a multisampled texture cannot be copied to a buffer).

@group(0) @binding(0) var depth_tex: DepthTexture;
@group(0) @binding(1) var<storage, read_write> planes: array<f32>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(depth_tex);
    if (gid.x >= size.x || gid.y >= size.y) {
        return;
    }
    let pixel = gid.y * size.x + gid.x;
    for (var s = 0u; s < SAMPLES; s = s + 1u) {
        planes[s * size.x * size.y + pixel] = textureLoad(depth_tex, gid.xy, s);
    }
}
