// The tone curve (exposure, then 1 - e^-x): HDR into [0, 1] before the display target
// encodes sRGB. The tonemap pass and the MSAA kernels' in-kernel resolve both apply it to
// each sample before averaging (tiled-deferred-tricks, Trick 1).
fn tone(c: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(1.0) - exp(-max(c, vec3<f32>(0.0)) * EXPOSURE);
}
