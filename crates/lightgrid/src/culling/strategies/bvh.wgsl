// Light BVH traversal (tiled-forward-shading §4.4): one workgroup of BVH_WIDTH invocations per
// occupied cell walks the hierarchy depth first. Each step pops one node; invocation i tests child i
// (an inner node's child box, or a leaf's light) against the cell's frustum; boxes that pass
// are pushed, lights that pass are recorded. The final test is the gather test, so the lists
// equal gather's; the boxes only prune. Hits go through the same workgroup list, flush and
// spill pass as gather's (assign_bindings.wgsl).

const WORKGROUP_SIZE: u32 = BVH_WIDTH;

// The hierarchy (bvh.rs `BvhBuffers`): the leaf slots' lights, four per entry and
// ceil(light_count / 4) entries, then the nodes, two entries each. One buffer keeps the walk
// within WebGPU's default 8 storage buffers per stage.
@group(2) @binding(0) var<storage, read> bvh: array<vec4<u32>>;

fn bvh_node(i: u32) -> BvhNode {
    let at = (frame.light_count + 3u) / 4u + 2u * i;
    let a = bvh[at];
    let b = bvh[at + 1u];
    return BvhNode(bitcast<vec3<f32>>(a.xyz), a.w, bitcast<vec3<f32>>(b.xyz), b.w);
}

// The light of leaf slot `slot`.
fn bvh_light(slot: u32) -> u32 {
    return bvh[slot / 4u][slot % 4u];
}

var<workgroup> bvh_stack: array<u32, BVH_STACK>;
var<workgroup> bvh_top: u32;
var<workgroup> bvh_pushed: atomic<u32>;

fn traverse_cell(wg: vec3<u32>, nwg: vec3<u32>, li: u32, spill: bool) {
    let c = cell_of_group(wg, nwg, spill);
    let f = cell_frustum(c);
    begin_cell(li);
    if (li == 0u) {
        bvh_stack[0] = 0u;
        let root = bvh_node(0u);
        bvh_top = select(0u, 1u, frame.light_count > 0u && box_in_cell(f, root.lo, root.hi));
    }
    loop {
        let top = workgroupUniformLoad(&bvh_top);
        if (top == 0u) {
            break;
        }
        let node = bvh_node(bvh_stack[top - 1u]);
        if (li == 0u) {
            atomicStore(&bvh_pushed, 0u);
        }
        workgroupBarrier();
        if (li < (node.count & ~BVH_LEAF)) {
            if ((node.count & BVH_LEAF) != 0u) {
                let l = bvh_light(node.first + li);
                if (light_in_tile(f, l)) {
                    record_hit(c, l, spill);
                }
            } else {
                let child = node.first + li;
                let b = bvh_node(child);
                if (box_in_cell(f, b.lo, b.hi)) {
                    let s = atomicAdd(&bvh_pushed, 1u);
                    bvh_stack[top - 1u + s] = child;
                }
            }
        }
        workgroupBarrier();
        if (li == 0u) {
            bvh_top = top - 1u + atomicLoad(&bvh_pushed);
        }
    }
    // The walk visits each node at most once (about 34k for 2^20 lights), but a stack left
    // non-empty means the loop was cut short.
    if (li == 0u && bvh_top != 0u) {
        atomicAdd(&frame_counters[COUNTER_TRUNCATED_LOOPS], 1u);
    }
    end_cell(c, li, spill);
}

@compute @workgroup_size(BVH_WIDTH)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    traverse_cell(wg, nwg, li, false);
}

@compute @workgroup_size(BVH_WIDTH)
fn spill_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    traverse_cell(wg, nwg, li, true);
}
