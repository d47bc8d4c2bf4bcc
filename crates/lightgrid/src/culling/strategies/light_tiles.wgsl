// A light's bounding sphere projected to the screen: the tiles it may cover (scatter's
// rectangles, z-binning's tile pre-filter). Needs `frame` (scene bindings) and `light_grid`. CPU
// twin: `project_sphere` in assign_cpu.rs.

const NO_RANGE: vec3<f32> = vec3<f32>(0.0, 0.0, 0.0);
const BIG: f32 = 1e30;

// Range of s = u / w over the disc (u, w) = (cu, cw) radius r clipped to w >= near, as
// (lo, hi, 1); (0, 0, 0) when nothing is in front of the near plane. `axis_range` in
// assign_cpu.rs.
fn axis_range(cu: f32, cw: f32, r: f32, near: f32) -> vec3<f32> {
    if (cw + r < near) {
        return NO_RANGE;
    }
    var lo = BIG;
    var hi = -BIG;
    let d2 = cu * cu + cw * cw;
    let r2 = r * r;
    if (d2 > r2) {
        let t2 = d2 - r2;
        let t = sqrt(t2);
        for (var i = 0u; i < 2u; i = i + 1u) {
            let sign = select(-1.0, 1.0, i == 1u);
            let u = (t2 * cu + sign * t * r * -cw) / d2;
            let w = (t2 * cw + sign * t * r * cu) / d2;
            if (w >= near) {
                lo = min(lo, u / w);
                hi = max(hi, u / w);
            }
        }
    }
    let dn = cw - near;
    if (abs(dn) <= r) {
        let k = sqrt(max(r2 - dn * dn, 0.0));
        lo = min(lo, min((cu - k) / near, (cu + k) / near));
        hi = max(hi, max((cu - k) / near, (cu + k) / near));
    }
    if (lo > hi) {
        return vec3<f32>(-BIG, BIG, 1.0);
    }
    return vec3<f32>(lo, hi, 1.0);
}

// Tiles (x0, y0, x1, y1), inclusive, under the light's projected sphere; x0 > x1 when none.
// `project_sphere` in assign_cpu.rs.
fn light_tiles(c: vec3<f32>, r: f32) -> vec4<i32> {
    let none = vec4<i32>(1, 0, 0, 0);
    let cw = -c.z;
    if (cw - r > frame.far) {
        return none;
    }
    let sx = axis_range(c.x, cw, r, frame.near);
    let sy = axis_range(c.y, cw, r, frame.near);
    if (sx.z == 0.0 || sy.z == 0.0) {
        return none;
    }
    let size = frame.viewport;
    let p00 = frame.proj[0][0];
    let p11 = frame.proj[1][1];
    // An off-centre projection (jitter, a VR eye) shifts NDC by -proj[2].xy.
    let p20 = frame.proj[2][0];
    let p21 = frame.proj[2][1];
    let x_lo = ((p00 * sx.x - p20) * 0.5 + 0.5) * size.x - 0.01;
    let x_hi = ((p00 * sx.y - p20) * 0.5 + 0.5) * size.x + 0.01;
    let y_lo = (0.5 - (p11 * sy.y - p21) * 0.5) * size.y - 0.01;
    let y_hi = (0.5 - (p11 * sy.x - p21) * 0.5) * size.y + 0.01;
    if (x_hi < 0.0 || y_hi < 0.0 || x_lo > size.x || y_lo > size.y) {
        return none;
    }
    let max_px = vec2<f32>(size) - 1.0;
    let px0 = min(max(floor(x_lo), 0.0), max_px.x);
    let px1 = min(max(floor(x_hi), 0.0), max_px.x);
    let py0 = min(max(floor(y_lo), 0.0), max_px.y);
    let py1 = min(max(floor(y_hi), 0.0), max_px.y);
    let t = i32(light_grid.tile_size);
    return vec4<i32>(i32(px0) / t, i32(py0) / t, i32(px1) / t, i32(py1) / t);
}

