// GPU gather (forward-plus §4): one workgroup per occupied cell tests every light against the
// cell's frustum in parallel, appending hits to a workgroup-memory list that is flushed to the
// global index list at an atomically reserved offset (assign_bindings.wgsl); cells with more
// lights than the list holds are finished by spill_main.

const WORKGROUP_SIZE: u32 = TILE_THREADS * TILE_THREADS;

fn gather_cell(wg: vec3<u32>, nwg: vec3<u32>, li: u32, spill: bool) {
    let c = cell_of_group(wg, nwg, spill);
    let f = cell_frustum(c);
    begin_cell(li);
    if (f.w_min <= f.w_max) {
        var l = li;
        for (; l < frame.light_count; l = l + WORKGROUP_SIZE) {
            if (light_in_tile(f, l)) {
                record_hit(c, l, spill);
            }
        }
        check_loop(l, frame.light_count);
    }
    end_cell(c, li, spill);
}

@compute @workgroup_size(TILE_THREADS, TILE_THREADS)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    gather_cell(wg, nwg, li, false);
}

@compute @workgroup_size(TILE_THREADS, TILE_THREADS)
fn spill_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    gather_cell(wg, nwg, li, true);
}
