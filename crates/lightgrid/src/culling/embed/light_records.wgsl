// Group 0 binding 5 of LightCuller's kernels: one record per light (cull_lights.wgsl writes
// them each frame), the only light data they bind: one storage buffer for both the lights and
// their spheres keeps the kernels within WebGPU's default 8 storage buffers per stage.
@group(0) @binding(5) var<storage, read> light_records: array<CullRecord>;

// What culling reads of light `l`.
fn light_cull(l: u32) -> CullRecord {
    return light_records[l];
}

// Its bounding sphere alone (the first test of every strategy: 16 bytes, not the record's 48).
fn light_sphere(l: u32) -> vec4<f32> {
    return light_records[l].sphere;
}
