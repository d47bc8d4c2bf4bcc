// Light `index` of the frame's list, as the light function reads it: group 0's storage
// buffer. Shaders reading the texture grid take `scene_light` from its light texture
// instead (culling/grid/light_grid_texels.wgsl).
fn scene_light(index: u32) -> Light {
    return lights[index];
}
