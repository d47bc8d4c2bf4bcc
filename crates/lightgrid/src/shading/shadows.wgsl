// Ray-cast shadows (`--shadows rays`; Forward+ §6: "local short ray casting to the lights"):
// one ray from the sample to each shadow-casting light that would light it, through two
// hierarchies over the opaque triangles (src/shadows/: the static objects' and the moving
// objects'). The CPU twin is `shadows::ShadowFrame::blocked`; the layout is written by
// `ShadowFrame::gpu_data`:
//   [0] origin = eye - anchor (camera-relative + origin = shadow space), absolute bias
//   [1] bits: static root, moving root (SHADOW_NO_TREE: empty), casters' first vec4; relative bias
//   node: [min, bits(right child's vec4 | first triangle's vec4)], [max, bits(triangle count;
//         0: two children, the left one following the node)]
//   triangle: [v0], [v1 - v0], [v2 - v0]
//   casters: one bit per light, 128 lights per vec4
@group(0) @binding(8) var<storage, read> shadow_data: array<vec4<f32>>;

// Does light `index` cast shadows this frame (`--shadow-lights`)?
fn shadow_casts(index: u32) -> bool {
    let at = bitcast<u32>(shadow_data[1].z) + index / 128u;
    let word = bitcast<vec4<u32>>(shadow_data[at])[(index / 32u) % 4u];
    return ((word >> (index % 32u)) & 1u) != 0u;
}

// Slab test: does the segment o + t d, 0 <= t <= t_max, meet the box (inv = 1 / d)?
fn shadow_box_hit(lo: vec3<f32>, hi: vec3<f32>, o: vec3<f32>, inv: vec3<f32>, t_max: f32) -> bool {
    let t0 = (lo - o) * inv;
    let t1 = (hi - o) * inv;
    let a = min(t0, t1);
    let b = max(t0, t1);
    let near = max(max(max(a.x, a.y), a.z), 0.0);
    let far = min(min(min(b.x, b.y), b.z), t_max);
    return near <= far;
}

// Moller-Trumbore, either side of the triangle at vec4 `at`: a crossing at 0 < t < t_max?
fn shadow_triangle_hit(at: u32, o: vec3<f32>, d: vec3<f32>, t_max: f32) -> bool {
    let v0 = shadow_data[at].xyz;
    let e1 = shadow_data[at + 1u].xyz;
    let e2 = shadow_data[at + 2u].xyz;
    let p = cross(d, e2);
    let det = dot(e1, p);
    if (abs(det) < 1e-12) {
        return false;
    }
    let inv = 1.0 / det;
    let s = o - v0;
    let u = dot(s, p) * inv;
    if (u < 0.0 || u > 1.0) {
        return false;
    }
    let q = cross(s, e1);
    let v = dot(d, q) * inv;
    if (v < 0.0 || u + v > 1.0) {
        return false;
    }
    let t = dot(e2, q) * inv;
    return t > 0.0 && t < t_max;
}

// Any hit in the tree at `root`. The walk is bounded by a stack the build's balanced trees
// never fill (bvh.rs); a walk that stops with nodes left (llvmpipe's loop guard, or a full
// stack) is counted as a truncated loop: the frame is reported wrong.
fn shadow_tree_blocked(root: u32, o: vec3<f32>, d: vec3<f32>, t_max: f32) -> bool {
    if (root == SHADOW_NO_TREE) {
        return false;
    }
    let inv = 1.0 / d;
    var stack: array<u32, SHADOW_STACK_DEPTH>;
    stack[0] = root;
    var depth = 1u;
    var steps = 0u;
    for (; depth > 0u && steps < SHADOW_MAX_STEPS; steps = steps + 1u) {
        depth = depth - 1u;
        let at = stack[depth];
        let lo = shadow_data[at];
        let hi = shadow_data[at + 1u];
        if (!shadow_box_hit(lo.xyz, hi.xyz, o, inv, t_max)) {
            continue;
        }
        let next = bitcast<u32>(lo.w);
        let count = bitcast<u32>(hi.w);
        if (count == 0u) {
            if (depth + 2u > SHADOW_STACK_DEPTH) {
                break;
            }
            stack[depth] = next;
            stack[depth + 1u] = at + 2u;
            depth = depth + 2u;
            continue;
        }
        for (var k = 0u; k < min(count, SHADOW_LEAF_TRIANGLES); k = k + 1u) {
            if (shadow_triangle_hit(next + 3u * k, o, d, t_max)) {
                return true;
            }
        }
    }
    check_loop(select(1u, 0u, depth > 0u), 1u);
    return false;
}

// Is the segment from the camera-relative surface point `p` (normal `n`) to the light at
// camera-relative `light_pos` blocked, for a light that casts shadows? Counts the ray.
fn shadow_blocked(index: u32, p: vec3<f32>, n: vec3<f32>, light_pos: vec3<f32>) -> bool {
    if (!shadow_casts(index)) {
        return false;
    }
    atomicAdd(&frame_counters[COUNTER_SHADOW_RAYS], 1u);
    let h0 = shadow_data[0];
    let h1 = shadow_data[1];
    // shadows::ray: pushed off the surface along its normal, ending at the light.
    let b = h0.w + h1.w * length(p);
    let o = p + n * b + h0.xyz;
    let d = light_pos + h0.xyz - o;
    return shadow_tree_blocked(bitcast<u32>(h1.x), o, d, 1.0)
        || shadow_tree_blocked(bitcast<u32>(h1.y), o, d, 1.0);
}
