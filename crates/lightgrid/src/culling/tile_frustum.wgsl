// A screen tile's frustum in view space: four side planes through the eye and a view-distance
// range. Used by GPU light assignment (gather, BVH traversal) and the single-kernel tiled
// deferred pipeline; `culling/gather.rs` has the CPU twin of both functions.

struct TileFrustum {
    planes: array<vec3<f32>, 4>,  // inward unit normals of the side planes
    w_min: f32,
    w_max: f32,
}

// `tile`: tile coordinates; `w_range`: the view-distance [min, max] of the samples the frustum
// must cover (min > max: no samples, the frustum contains no light).
fn tile_frustum(tile: vec2<u32>, tile_size: u32, w_range: vec2<f32>) -> TileFrustum {
    let size = frame.viewport;
    let lo = vec2<f32>(tile * tile_size);
    let hi = min(lo + vec2<f32>(f32(tile_size)), size);
    let ndc_lo = vec2<f32>(lo.x / size.x * 2.0 - 1.0, 1.0 - lo.y / size.y * 2.0);  // left, top
    let ndc_hi = vec2<f32>(hi.x / size.x * 2.0 - 1.0, 1.0 - hi.y / size.y * 2.0);  // right, bottom
    let p00 = frame.proj[0][0];
    let p11 = frame.proj[1][1];
    var f: TileFrustum;
    f.planes[0] = normalize(vec3<f32>(1.0, 0.0, ndc_lo.x / p00));
    f.planes[1] = normalize(vec3<f32>(-1.0, 0.0, -ndc_hi.x / p00));
    f.planes[2] = normalize(vec3<f32>(0.0, 1.0, ndc_hi.y / p11));
    f.planes[3] = normalize(vec3<f32>(0.0, -1.0, -ndc_lo.y / p11));
    f.w_min = w_range.x;
    f.w_max = w_range.y;
    return f;
}

// View-distance range of a tile's [min, max] depth-buffer values (an empty tile stays empty:
// the map is monotonic).
fn depth_to_w_range(depth_range: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(view_distance_from_depth(depth_range.x), view_distance_from_depth(depth_range.y));
}

// Does the view-space sphere (c, r) reach into the frustum (side planes and depth range)?
fn sphere_in_tile(f: TileFrustum, c: vec3<f32>, r: f32) -> bool {
    let w = -c.z;
    if (f.w_min > f.w_max || w + r < f.w_min * (1.0 - ASSIGN_DEPTH_SLACK) || w - r > f.w_max * (1.0 + ASSIGN_DEPTH_SLACK)) {
        return false;
    }
    for (var i = 0u; i < 4u; i = i + 1u) {
        if (dot(f.planes[i], c) < -r) {
            return false;
        }
    }
    return true;
}

fn light_in_tile(f: TileFrustum, light: Light) -> bool {
    return sphere_in_tile(f, (frame.view * vec4<f32>(light.position, 1.0)).xyz, light.range);
}
