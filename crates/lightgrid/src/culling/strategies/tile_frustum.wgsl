// A screen tile's frustum in view space: four side planes through the eye and a view-distance
// range. Used by GPU light assignment (gather, BVH traversal) and the single-kernel tiled
// deferred pipeline; `culling/strategies/gather.rs` has the CPU twin of both functions.

struct TileFrustum {
    planes: array<vec3<f32>, 4>,  // inward unit normals of the side planes
    w_min: f32,
    w_max: f32,
    // Bounding sphere (centre, radius) of the frustum piece between the slack-widened depth
    // bounds: what spot cones are tested against (`ViewSetup::cell_sphere`).
    sphere: vec4<f32>,
    // The cell's 2.5D depth mask (`depth_mask.wgsl`); none unless the cell came from a grid
    // built with `--depth-mask on` (`cell_frustum` in assign_bindings.wgsl).
    mask: vec4<u32>,
    // The cell's tight view-space box (cell_box.wgsl; box_lo.w == 0: none), from a grid built
    // with `--cell-box on`.
    box_lo: vec4<f32>,
    box_hi: vec4<f32>,
}

// `tile`: tile coordinates; `w_range`: the view-distance [min, max] of the samples the frustum
// must cover (min > max: no samples, the frustum contains no light).
fn tile_frustum(tile: vec2<u32>, tile_size: u32, w_range: vec2<f32>) -> TileFrustum {
    let size = frame.viewport;
    let lo = vec2<f32>(tile * tile_size);
    let hi = min(lo + vec2<f32>(f32(tile_size)), size);
    // Shifted by an off-centre projection's (jitter, a VR eye) proj[2].xy: ndc + shift = p00 x / w.
    let shift = vec2<f32>(frame.proj[2][0], frame.proj[2][1]);
    let ndc_lo = vec2<f32>(lo.x / size.x * 2.0 - 1.0, 1.0 - lo.y / size.y * 2.0) + shift;  // left, top
    let ndc_hi = vec2<f32>(hi.x / size.x * 2.0 - 1.0, 1.0 - hi.y / size.y * 2.0) + shift;  // right, bottom
    let p00 = frame.proj[0][0];
    let p11 = frame.proj[1][1];
    var f: TileFrustum;
    f.planes[0] = normalize(vec3<f32>(1.0, 0.0, ndc_lo.x / p00));
    f.planes[1] = normalize(vec3<f32>(-1.0, 0.0, -ndc_hi.x / p00));
    f.planes[2] = normalize(vec3<f32>(0.0, 1.0, ndc_hi.y / p11));
    f.planes[3] = normalize(vec3<f32>(0.0, -1.0, -ndc_lo.y / p11));
    f.w_min = w_range.x;
    f.w_max = w_range.y;
    f.mask = depth_mask_none();
    f.box_lo = vec4<f32>(0.0);
    f.box_hi = vec4<f32>(0.0);
    f.sphere = frustum_sphere(ndc_lo, ndc_hi, w_range.x * (1.0 - ASSIGN_DEPTH_SLACK), w_range.y * (1.0 + ASSIGN_DEPTH_SLACK));
    return f;
}

// The centre of the eight corners of the frustum piece over NDC rectangle [lo, hi] (shifted by
// the projection's centre: `tile_frustum`) between view distances w0 and w1, and its farthest
// corner.
fn frustum_sphere(ndc_lo: vec2<f32>, ndc_hi: vec2<f32>, w0: f32, w1: f32) -> vec4<f32> {
    var corners: array<vec3<f32>, 8>;
    var i = 0u;
    var centre = vec3<f32>(0.0);
    for (var k = 0u; k < 8u; k = k + 1u) {
        let w = select(w0, w1, (k & 4u) != 0u);
        let nx = select(ndc_lo.x, ndc_hi.x, (k & 2u) != 0u);
        let ny = select(ndc_lo.y, ndc_hi.y, (k & 1u) != 0u);
        corners[k] = vec3<f32>(nx / frame.proj[0][0] * w, ny / frame.proj[1][1] * w, -w);
        centre = centre + corners[k];
    }
    centre = centre / 8.0;
    var radius = 0.0;
    for (var k = 0u; k < 8u; k = k + 1u) {
        radius = max(radius, distance(corners[k], centre));
    }
    return vec4<f32>(centre, radius);
}

// View-distance range of a tile's [min, max] depth-buffer values. Reversed-Z: the greatest
// depth is the nearest sample, so the ends swap (an empty tile, min > max, stays empty: the
// map is monotonic).
fn depth_to_w_range(depth_range: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(view_distance_from_depth(depth_range.y), view_distance_from_depth(depth_range.x));
}

// Does the view-space sphere (c, r) reach into the frustum (side planes and depth range)?
fn sphere_in_tile(f: TileFrustum, c: vec3<f32>, r: f32) -> bool {
    let w = -c.z;
    if (f.w_min > f.w_max || w + r < f.w_min * (1.0 - ASSIGN_DEPTH_SLACK) || w - r > f.w_max * (1.0 + ASSIGN_DEPTH_SLACK)) {
        return false;
    }
    if (!depth_mask_meets(f.mask, w - r, w + r)) {
        return false;
    }
    for (var i = 0u; i < 4u; i = i + 1u) {
        if (dot(f.planes[i], c) < -r) {
            return false;
        }
    }
    return sphere_meets_box(f.box_lo, f.box_hi, c, r);
}

// How far a spot's cone reaches into the view-space sphere `cell` (>= 0: it may reach it);
// 1 for point lights and when spots are culled by their sphere only (`spot_cull` 0). The
// argument for why this never rejects a sphere the cone reaches is at its CPU twin,
// `ViewLight::cone_margin`.
fn cone_margin(light: CullRecord, cell: vec4<f32>) -> f32 {
    if (frame.spot_cull == 0u || light.cos_outer <= POINT_LIGHT_COS) {
        return 1.0;
    }
    let r = cell.w * (1.0 + CONE_SLACK) + CONE_SLACK;
    let apex = (frame.view * vec4<f32>(light.position, 1.0)).xyz;
    let axis = normalize((frame.view * vec4<f32>(light.direction, 0.0)).xyz);
    let v = cell.xyz - apex;
    let m = light.range + r - length(v);
    if (light.cos_outer <= 0.0) {
        return m;
    }
    let along = dot(v, axis);
    // The perpendicular part's length, not sqrt(|v|² - along²), which cancels for far cells
    // (CPU twin: `ViewLight::cone_margin`).
    let across = length(v - axis * along);
    let sin_outer = sqrt(max(1.0 - light.cos_outer * light.cos_outer, 0.0));
    return min(m, min(along + r, r - (light.cos_outer * across - along * sin_outer)));
}

// The sphere a spot's cone is tested against: the bounding sphere of the cell's tight box
// (lo.w != 0: it has one) where it is the smaller, else `sphere`, the frustum piece's (CPU
// twin and argument: `cone_sphere`, cell_box.rs).
fn cone_sphere(sphere: vec4<f32>, lo: vec4<f32>, hi: vec4<f32>) -> vec4<f32> {
    let r = length(hi.xyz - lo.xyz) * 0.5;
    return select(sphere, vec4<f32>((lo.xyz + hi.xyz) * 0.5, r), lo.w != 0.0 && r < sphere.w);
}

// Does the view-space box [lo, hi] reach into the frustum (the BVH's node test; spots' boxes)?
fn box_in_cell(f: TileFrustum, lo: vec3<f32>, hi: vec3<f32>) -> bool {
    let w_lo = -hi.z;
    let w_hi = -lo.z;
    if (f.w_min > f.w_max || w_hi < f.w_min * (1.0 - ASSIGN_DEPTH_SLACK) || w_lo > f.w_max * (1.0 + ASSIGN_DEPTH_SLACK)) {
        return false;
    }
    if (!depth_mask_meets(f.mask, w_lo, w_hi)) {
        return false;
    }
    for (var i = 0u; i < 4u; i = i + 1u) {
        let n = f.planes[i];
        if (dot(n, select(lo, hi, n > vec3<f32>(0.0))) < 0.0) {
            return false;
        }
    }
    return box_meets_box(f.box_lo, f.box_hi, lo, hi);
}

// A spot's box in view space: the cone sector's box within its bounding sphere's (CPU twin
// and argument: `ViewLight::reach_box`); the sphere's box for point lights, wider cones and
// sphere culling.
fn reach_box(l: u32, c: vec3<f32>, radius: f32) -> array<vec3<f32>, 2> {
    var lo = c - vec3<f32>(radius);
    var hi = c + vec3<f32>(radius);
    let light = light_cull(l);
    if (frame.spot_cull == 0u || light.cos_outer <= 0.0) {
        return array<vec3<f32>, 2>(lo, hi);
    }
    let apex = (frame.view * vec4<f32>(light.position, 1.0)).xyz;
    let axis = normalize((frame.view * vec4<f32>(light.direction, 0.0)).xyz);
    let cos_o = light.cos_outer;
    let sin_o = sqrt(max(1.0 - cos_o * cos_o, 0.0));
    let r = light.range;
    for (var i = 0u; i < 3u; i = i + 1u) {
        let a = axis[i];
        let spread = sin_o * sqrt(max(1.0 - a * a, 0.0));
        let top = select(r * (cos_o * a + spread), r, a >= cos_o);
        let bottom = select(r * (cos_o * a - spread), -r, -a >= cos_o);
        hi[i] = min(hi[i], apex[i] + max(top, 0.0));
        lo[i] = max(lo[i], apex[i] + min(bottom, 0.0));
    }
    return array<vec3<f32>, 2>(lo, hi);
}

// Light `l` reaches into the frustum when its bounding sphere does and, for a spot culled by
// its cone, the cone may reach the frustum's bounding sphere and the sector's box reaches
// into the frustum.
fn light_in_tile(f: TileFrustum, l: u32) -> bool {
    let b = light_sphere(l);
    let c = (frame.view * vec4<f32>(b.xyz, 1.0)).xyz;
    if (!sphere_in_tile(f, c, b.w)) {
        return false;
    }
    let light = light_cull(l);
    if (cone_margin(light, f.sphere) < 0.0) {
        return false;
    }
    if (frame.spot_cull == 0u || light.cos_outer <= 0.0) {
        return true;
    }
    let sector = reach_box(l, c, b.w);
    return box_in_cell(f, sector[0], sector[1]);
}
