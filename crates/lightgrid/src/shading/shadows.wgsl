// Shadows: the ray-cast form first, then the shadow maps (further down).
//
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
@group(0) @binding(7) var<storage, read> shadow_data: array<vec4<f32>>;

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

// Shadow maps (`--shadows maps`; src/shadows/maps.rs): every shadowed light's faces are
// tiles of one depth atlas, rendered before shading. The buffer then holds
//   [0] bits: texture width, tile side, the atlas's tiles per row, slots' first vec4
//   [1] bits: matrices' first vec4, texture height
//   slots: per light 0 (unshadowed) or (first face * 2 + cube) + 1, 4 per vec4
//   matrices: per face its view-projection's columns (camera-relative -> clip, depth near / w)
// Face f of a light lies in tile f of the atlas (all in flight), or in tile (f - first face)
// of the one re-used cube, 3 tiles a row (SHADOWS_MAPS_REUSED: the light-volume pipelines).
@group(0) @binding(8) var shadow_atlas: texture_depth_2d;
@group(0) @binding(9) var shadow_sampler: sampler_comparison;

// A face's view-projection.
fn shadow_tile_matrix(face: u32) -> mat4x4<f32> {
    let at = bitcast<u32>(shadow_data[1].x) + 4u * face;
    return mat4x4<f32>(shadow_data[at], shadow_data[at + 1u], shadow_data[at + 2u], shadow_data[at + 3u]);
}

// How much of light `index` reaches camera-relative `p` (normal `n`, n.l = `n_dot_l`): 1
// for a light without a map; else the 2x2 PCF of its map at the face the sample lies in,
// after the slope-scaled normal offset (maps.rs).
fn shadow_map_visibility(index: u32, p: vec3<f32>, n: vec3<f32>, light_pos: vec3<f32>, n_dot_l: f32) -> f32 {
    let h = bitcast<vec4<u32>>(shadow_data[0]);
    let slot = bitcast<vec4<u32>>(shadow_data[h.w + index / 4u])[index % 4u];
    if (slot == 0u) {
        return 1.0;
    }
    let first = (slot - 1u) >> 1u;
    var face = 0u;
    if (((slot - 1u) & 1u) != 0u) {
        let v = p - light_pos;
        let a = abs(v);
        if (a.x >= a.y && a.x >= a.z) {
            face = select(1u, 0u, v.x > 0.0);
        } else if (a.y >= a.z) {
            face = select(3u, 2u, v.y > 0.0);
        } else {
            face = select(5u, 4u, v.z > 0.0);
        }
    }
    // Re-used maps hold one light's cube at a time: its face's own tile.
    var tile = first + face;
    if (SHADING_SHADOWS == SHADOWS_MAPS_REUSED) {
        tile = face;
    }
    let m = shadow_tile_matrix(first + face);
    let size = vec2<f32>(f32(h.x), f32(bitcast<u32>(shadow_data[1].y)));
    let tile_side = f32(h.y);
    // One texel's world size at the sample's distance along the face's axis: the matrix's
    // second row is the view's up axis times 1 / tan(half the field of view).
    let focal = length(vec3<f32>(m[0][1], m[1][1], m[2][1]));
    let texel = 2.0 * (m * vec4<f32>(p, 1.0)).w / (focal * tile_side);
    let c = saturate(n_dot_l);
    let slope = min(sqrt(max(1.0 - c * c, 0.0)) / max(c, 1e-4), SHADOW_MAX_SLOPE);
    let q = p + n * (texel * (SHADOW_NORMAL_OFFSET + SHADOW_SLOPE_OFFSET * slope));
    let clip = m * vec4<f32>(q, 1.0);
    let ndc = clip.xyz / clip.w;
    // The 2x2 footprint stays a texel inside the tile.
    let local = clamp(
        vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5) * tile_side,
        vec2<f32>(1.0),
        vec2<f32>(tile_side - 1.0),
    );
    var per_row = h.z;
    if (SHADING_SHADOWS == SHADOWS_MAPS_REUSED) {
        per_row = 3u;
    }
    let origin = vec2<f32>(f32(tile % per_row), f32(tile / per_row)) * tile_side;
    return textureSampleCompareLevel(shadow_atlas, shadow_sampler, (origin + local) / size, ndc.z);
}
