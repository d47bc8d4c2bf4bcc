// The frame's sample count, for shaders reading its multisampled targets. SAMPLES,
// MULTISAMPLED_TARGETS and SAMPLE_POSITIONS come from the shader's key (`shader::msaa_defs`).
// Above one sample the textures are multisampled, so `textureLoad(t, p, s)` reads sample `s`;
// at one it reads level 0 of a plain texture.
#if MULTISAMPLED_TARGETS
alias DepthTexture = texture_depth_multisampled_2d;
alias SampleTexture = texture_multisampled_2d<f32>;
#else
alias DepthTexture = texture_depth_2d;
alias SampleTexture = texture_2d<f32>;
#endif

// The standard position of sample `s` in its pixel (`consts::msaa_sample_positions`).
fn sample_position(s: u32) -> vec2<f32> {
    var positions = SAMPLE_POSITIONS;
    return positions[s];
}
