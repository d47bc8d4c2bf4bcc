// 2.5D culling (`--depth-mask on`; Harada et al. 2012, "A 2.5D culling for Forward+"): a cell's
// depth bounds cut into DEPTH_MASK_BINS equal bins, and a 32-bit mask of the bins holding
// samples. A light is listed for the cell only when the bins its view-depth span covers meet
// the mask, so a tile whose samples sit on two surfaces far apart no longer lists the lights
// floating between them. A cell's mask is (bits, lo, inv, 0) as u32s: the bin of view distance
// w is floor((w - lo) * inv) clamped to [0, DEPTH_MASK_BINS - 1] (inv is 0 for a cell of one
// depth: every sample in bin 0); bits DEPTH_MASK_ALL is no mask. Only a subtraction and a
// multiplication, both correctly rounded in WGSL, so the CPU twin (`depth_mask.rs`) bins every
// distance exactly as the GPU does from the same (lo, inv).

fn depth_mask_bin(w: f32, m: vec4<u32>) -> u32 {
    let b = floor((w - bitcast<f32>(m.y)) * bitcast<f32>(m.z));
    return u32(clamp(b, 0.0, f32(DEPTH_MASK_BINS - 1u)));
}

// The bits of the bins [w0, w1] covers (none when w0 > w1).
fn depth_mask_span(w0: f32, w1: f32, m: vec4<u32>) -> u32 {
    let b0 = depth_mask_bin(w0, m);
    let b1 = depth_mask_bin(w1, m);
    return (0xffffffffu >> (31u - b1)) & (0xffffffffu << b0);
}

// Does the view-depth span [w0, w1] meet a bin of mask `m` that holds samples?
fn depth_mask_meets(m: vec4<u32>, w0: f32, w1: f32) -> bool {
    return m.x == DEPTH_MASK_ALL || (depth_mask_span(w0, w1, m) & m.x) != 0u;
}

// No mask: every bin.
fn depth_mask_none() -> vec4<u32> {
    return vec4<u32>(DEPTH_MASK_ALL, 0u, 0u, 0u);
}
