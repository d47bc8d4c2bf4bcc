// GPU build of the light BVH (bvh_gpu.rs drives it; `build_bvh` in bvh.rs is the CPU twin):
// 1. box_main: the bounding box of the lights' view-space centres (atomics on order-preserving
//    u32 encodings of the floats);
// 2. morton_main: each light's 30-bit Morton code in that box, as (key, light) pairs for the
//    radix sort (radix_sort.wgsl), which orders lights along the curve;
// 3. leaves_main: one invocation per leaf boxes 32 consecutive sorted lights;
// 4. inner_main, once per level bottom-up: one invocation per node boxes its 32 children.
// The node layout (root first, level by level) is fixed by the light count, as on the CPU.

@group(1) @binding(0) var<uniform> level: LevelParams;
@group(1) @binding(1) var<storage, read_write> keys: array<u32>;
@group(1) @binding(2) var<storage, read_write> vals: array<u32>;
@group(1) @binding(3) var<storage, read_write> nodes: array<BvhNode>;
// [0..3]: !ordered(min) per axis, [3..6]: ordered(max) per axis (both grown with atomicMax
// from a zeroed buffer).
@group(1) @binding(4) var<storage, read_write> centre_box: array<atomic<u32>, 6>;

fn ordered(f: f32) -> u32 {
    let b = bitcast<u32>(f);
    return select(~b, b | 0x80000000u, f >= 0.0);
}

fn unordered(u: u32) -> f32 {
    return bitcast<f32>(select(~u, u & 0x7fffffffu, (u & 0x80000000u) != 0u));
}

fn item(gid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return gid.y * nwg.x * ASSIGN_THREADS + gid.x;
}

fn view_centre(l: u32) -> vec3<f32> {
    return (frame.view * vec4<f32>(light_sphere(l).xyz, 1.0)).xyz;
}

@compute @workgroup_size(ASSIGN_THREADS)
fn box_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let l = item(gid, nwg);
    if (l >= frame.light_count) {
        return;
    }
    let c = view_centre(l);
    for (var a = 0u; a < 3u; a = a + 1u) {
        atomicMax(&centre_box[a], ~ordered(c[a]));
        atomicMax(&centre_box[3u + a], ordered(c[a]));
    }
}

fn spread_bits(v: u32) -> u32 {
    var x = v & 0x3ffu;
    x = (x | (x << 16u)) & 0x030000ffu;
    x = (x | (x << 8u)) & 0x0300f00fu;
    x = (x | (x << 4u)) & 0x030c30c3u;
    return (x | (x << 2u)) & 0x09249249u;
}

@compute @workgroup_size(ASSIGN_THREADS)
fn morton_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let l = item(gid, nwg);
    if (l >= frame.light_count) {
        return;
    }
    var lo: vec3<f32>;
    var hi: vec3<f32>;
    for (var a = 0u; a < 3u; a = a + 1u) {
        lo[a] = unordered(~atomicLoad(&centre_box[a]));
        hi[a] = unordered(atomicLoad(&centre_box[3u + a]));
    }
    let q = clamp((view_centre(l) - lo) / max(hi - lo, vec3<f32>(1e-20)) * 1023.0, vec3<f32>(0.0), vec3<f32>(1023.0));
    let code = spread_bits(u32(q.x)) | (spread_bits(u32(q.y)) << 1u) | (spread_bits(u32(q.z)) << 2u);
    keys[l] = code;
    vals[l] = l;
}

@compute @workgroup_size(ASSIGN_THREADS)
fn leaves_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let j = item(gid, nwg);
    if (j >= level.count) {
        return;
    }
    let first = j * BVH_WIDTH;
    let count = min(BVH_WIDTH, frame.light_count - first);
    var lo = vec3<f32>(3.0e38);
    var hi = vec3<f32>(-3.0e38);
    var k = 0u;
    for (; k < count; k = k + 1u) {
        let l = vals[first + k];
        let c = view_centre(l);
        let r = light_sphere(l).w;
        // The padding of `pad` in bvh.rs: GPU and CPU view positions differ by a few ulps.
        let e = r * 2e-4 + max(max(abs(c.x), abs(c.y)), abs(c.z)) * 1e-5 + 1e-5;
        let b = reach_box(l, c, r);
        lo = min(lo, b[0] - vec3<f32>(e));
        hi = max(hi, b[1] + vec3<f32>(e));
    }
    check_loop(k, count);
    nodes[level.first + j] = BvhNode(lo, first, hi, count | BVH_LEAF);
}

@compute @workgroup_size(ASSIGN_THREADS)
fn inner_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let j = item(gid, nwg);
    if (j >= level.count) {
        return;
    }
    let first = level.child_first + j * BVH_WIDTH;
    let count = min(BVH_WIDTH, level.child_count - j * BVH_WIDTH);
    var lo = vec3<f32>(3.0e38);
    var hi = vec3<f32>(-3.0e38);
    var k = 0u;
    for (; k < count; k = k + 1u) {
        let child = nodes[first + k];
        lo = min(lo, child.lo);
        hi = max(hi, child.hi);
    }
    check_loop(k, count);
    nodes[level.first + j] = BvhNode(lo, first, hi, count);
}
