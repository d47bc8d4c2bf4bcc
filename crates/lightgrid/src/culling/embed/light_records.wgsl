// Group 0 binding 5 of LightCuller's kernels: one record per light (cull_lights.wgsl writes
// them each frame), the only light data they bind: one storage buffer for both the lights and
// their spheres keeps the kernels within WebGPU's default 8 storage buffers per stage.
@group(0) @binding(5) var<storage, read> light_records: array<CullRecord>;

// What culling reads of light `l`.
fn light_cull(l: u32) -> CullRecord {
    return light_records[l];
}
