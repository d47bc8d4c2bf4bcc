// GPU gather (forward-plus §4): one workgroup per occupied cell tests every light against the
// cell's frustum in parallel. Run twice: count_main sizes the lists (then a prefix sum turns counts
// into offsets), write_main fills them, so no list is ever truncated.


fn gather_cell(wg: vec3<u32>, nwg: vec3<u32>, li: u32, write: bool) {
    if (li == 0u) {
        atomicStore(&cell_hits, 0u);
    }
    workgroupBarrier();
    let c = cell_of_group(wg, nwg);
    let f = cell_frustum(c);
    if (f.w_min <= f.w_max) {
        for (var l = li; l < frame.light_count; l = l + TILE_THREADS * TILE_THREADS) {
            if (light_in_tile(f, lights[l])) {
                record_hit(c, l, write);
            }
        }
    }
    workgroupBarrier();
    if (li == 0u) {
        finish_cell(c, atomicLoad(&cell_hits), write);
    }
}

@compute @workgroup_size(TILE_THREADS, TILE_THREADS)
fn count_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    gather_cell(wg, nwg, li, false);
}

@compute @workgroup_size(TILE_THREADS, TILE_THREADS)
fn write_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    gather_cell(wg, nwg, li, true);
}
