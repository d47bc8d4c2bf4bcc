// The edge-aware MSAA deferred kernels' outputs (group 3, `SampleOutputs` in tiled_deferred.rs),
// shared by the grid kernel (`tiled_deferred_msaa.wgsl`) and the single kernel
// (`tiled_deferred_single_msaa.wgsl`): each sample's colour into `sample_colors`, which a
// fragment pass writes into the multisampled HDR target (`sample_expand.wgsl`), or with
// RESOLVE_IN_KERNEL the pixel's samples resolved in workgroup memory (Trick 1, below).
// The kernel defines GROUP_PIXELS, its pixels per workgroup (one per invocation, local pixel
// `l` its `local_invocation_index`), and needs `tone` (shading/tone.wgsl).

// Per sample (pixel * SAMPLES + sample): HDR colour as two pack2x16float words.
@group(3) @binding(0) var<storage, read_write> sample_colors: array<vec2<u32>>;
// The in-kernel resolve's output: the display colour, sRGB-encoded (copied into the sRGB
// display target, which cannot be a storage texture).
@group(3) @binding(1) var resolved: texture_storage_2d<rgba8unorm, write>;

// Resolve inside the kernel (tiled-deferred-tricks, Trick 1) instead of storing every
// sample's colour: each pixel's tone-mapped samples, weighted 1/SAMPLES, are summed in
// workgroup memory as 16-bit fixed point (two channels per u32, one atomicAdd per pair; the
// weighted values are rounded down so a pixel's sum stays below 2^16 and never carries into
// the next channel).
override RESOLVE_IN_KERNEL: bool = false;

// Per pixel of the workgroup: (R | G << 16, B).
var<workgroup> accum: array<atomic<u32>, GROUP_PIXELS * 2u>;

// Clear local pixel `l`'s resolved colour (each invocation its own, before any output).
fn clear_resolve(l: u32) {
    atomicStore(&accum[2u * l], 0u);
    atomicStore(&accum[2u * l + 1u], 0u);
}

// Add `weight` of the tone-mapped `color` to local pixel `l`'s resolved colour.
fn accumulate(l: u32, color: vec3<f32>, weight: f32) {
    let q = vec3<u32>(floor(clamp(tone(color), vec3<f32>(0.0), vec3<f32>(1.0)) * weight * 65535.0));
    atomicAdd(&accum[2u * l], q.r | (q.g << 16u));
    atomicAdd(&accum[2u * l + 1u], q.b);
}

fn srgb_encode(c: vec3<f32>) -> vec3<f32> {
    return select(1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - 0.055, 12.92 * c, c <= vec3<f32>(0.0031308));
}

fn store_sample(pixel: u32, s: u32, color: vec3<f32>) {
    // Clamped: pack2x16float of a value beyond binary16's range is indeterminate (WGSL).
    let c = min(color, vec3<f32>(HALF_MAX));
    sample_colors[pixel * SAMPLES + s] = vec2<u32>(pack2x16float(c.rg), pack2x16float(vec2<f32>(c.b, 1.0)));
}

// Sample `s` of pixel `p`: stored, or added to local pixel `l`'s resolved colour.
fn output_sample(p: vec2<u32>, l: u32, s: u32, color: vec3<f32>, weight: f32) {
    if (RESOLVE_IN_KERNEL) {
        accumulate(l, color, weight);
    } else {
        store_sample(p.y * u32(frame.viewport.x) + p.x, s, color);
    }
}

// Pixel `p` (local `l`) shaded once, colour `c0`: sample 0's colour, and for a pixel that is
// no edge every sample's. An edge pixel's other samples are output by the kernel.
fn output_pixel(p: vec2<u32>, l: u32, edge: bool, c0: vec3<f32>) {
    if (RESOLVE_IN_KERNEL && !edge) {
        accumulate(l, c0, 1.0);
        return;
    }
    output_sample(p, l, 0u, c0, 1.0 / f32(SAMPLES));
    if (!edge) {
        let pixel = p.y * u32(frame.viewport.x) + p.x;
        for (var s = 1u; s < SAMPLES; s = s + 1u) {
            store_sample(pixel, s, c0);
        }
    }
}

// With RESOLVE_IN_KERNEL, once every sample of the workgroup is output: pixel `p`'s (local
// `l`) resolved colour. Call from uniform control flow (a barrier); `inside`: `p` is on screen.
fn finish_resolve(p: vec2<u32>, l: u32, inside: bool) {
    if (RESOLVE_IN_KERNEL) {
        workgroupBarrier();
        if (inside) {
            let rg = atomicLoad(&accum[2u * l]);
            let b = atomicLoad(&accum[2u * l + 1u]);
            let c = vec3<f32>(f32(rg & 0xffffu), f32(rg >> 16u), f32(b)) / 65535.0;
            textureStore(resolved, p, vec4<f32>(srgb_encode(c), 1.0));
        }
    }
}
