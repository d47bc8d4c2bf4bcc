// What culling reads of light `l`, from the renderer's group 0 (its lights and their
// bounds): the single-kernel tiled deferred pass culls from them
// (`light_records.wgsl` is the culler's own).
fn light_cull(l: u32) -> CullRecord {
    let light = lights[l];
    return CullRecord(light_bounds[l], light.position, light.range, light.direction, light.cos_outer);
}

fn light_sphere(l: u32) -> vec4<f32> {
    return light_bounds[l];
}
