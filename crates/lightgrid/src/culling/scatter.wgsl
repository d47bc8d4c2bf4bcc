// GPU scatter (forward-plus §4): one invocation per light finds the cells it overlaps (the
// tiles under its projected sphere, the depth slices its view-depth interval spans, kept where
// the cell's sample bounds overlap that interval) and emits (cell, light) pairs; the pairs are
// radix-sorted by cell and each cell's offset and count read off the sorted keys. The test is
// the CPU assignment's, line for line (`assign_cpu.rs`), so that is this stage's CPU twin.
// count_main sizes each light's run of pairs; a prefix sum gives the offsets; write_main
// fills them.

@group(2) @binding(0) var<storage, read_write> light_counts: array<u32>;
@group(2) @binding(1) var<storage, read_write> light_offsets: array<u32>;
@group(2) @binding(2) var<storage, read_write> pair_keys: array<u32>;
@group(2) @binding(3) var<storage, read_write> pair_vals: array<u32>;
@group(2) @binding(4) var<storage, read_write> pair_total: array<u32>;

const WORKGROUP_SIZE: u32 = ASSIGN_THREADS;
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
    let x_lo = ((p00 * sx.x) * 0.5 + 0.5) * size.x - 0.01;
    let x_hi = ((p00 * sx.y) * 0.5 + 0.5) * size.x + 0.01;
    let y_lo = (0.5 - (p11 * sy.y) * 0.5) * size.y - 0.01;
    let y_hi = (0.5 - (p11 * sy.x) * 0.5) * size.y + 0.01;
    if (x_hi < 0.0 || y_hi < 0.0 || x_lo > size.x || y_lo > size.y) {
        return none;
    }
    let max_px = vec2<f32>(size) - 1.0;
    let px0 = min(max(floor(x_lo), 0.0), max_px.x);
    let px1 = min(max(floor(x_hi), 0.0), max_px.x);
    let py0 = min(max(floor(y_lo), 0.0), max_px.y);
    let py1 = min(max(floor(y_hi), 0.0), max_px.y);
    let t = i32(grid.tile_size);
    return vec4<i32>(i32(px0) / t, i32(py0) / t, i32(px1) / t, i32(py1) / t);
}

// Visit (or count) the cells light `l` overlaps; in write mode emit pairs from `first` on.
fn scatter_light(l: u32, write: bool) -> u32 {
    let light = lights[l];
    let c = (frame.view * vec4<f32>(light.position, 1.0)).xyz;
    let r = light.range;
    let rect = light_tiles(c, r);
    let w_min = -c.z - r;
    let w_max = -c.z + r;
    let k0 = grid_slice(w_min * (1.0 - ASSIGN_DEPTH_SLACK));
    let k1 = grid_slice(w_max * (1.0 + ASSIGN_DEPTH_SLACK));
    let tiles = grid.tiles_x * grid.tiles_y;
    var n = 0u;
    var first = 0u;
    var room = 0u;
    if (write) {
        first = light_offsets[l];
        room = light_counts[l];
    }
    for (var ty = rect.y; ty <= rect.w; ty = ty + 1) {
        for (var tx = rect.x; tx <= rect.z; tx = tx + 1) {
            let tile = u32(ty) * grid.tiles_x + u32(tx);
            for (var k = k0; k <= k1; k = k + 1u) {
                let cell = k * tiles + tile;
                let b = cell_bounds[cell];
                if (b.x <= b.y && w_max >= b.x * (1.0 - ASSIGN_DEPTH_SLACK) && w_min <= b.y * (1.0 + ASSIGN_DEPTH_SLACK)) {
                    if (write) {
                        if (n < room) {
                            pair_keys[first + n] = cell;
                            pair_vals[first + n] = l;
                        } else {
                            atomicAdd(&counters[WRITE_OVERFLOW], 1u);
                        }
                    }
                    n = n + 1u;
                }
            }
        }
    }
    return n;
}

fn light_of(gid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return gid.y * nwg.x * ASSIGN_THREADS + gid.x;
}

@compute @workgroup_size(ASSIGN_THREADS)
fn count_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let l = light_of(gid, nwg);
    if (l < frame.light_count) {
        light_counts[l] = scatter_light(l, false);
    }
}

@compute @workgroup_size(ASSIGN_THREADS)
fn write_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let l = light_of(gid, nwg);
    if (l < frame.light_count) {
        scatter_light(l, true);
    }
}

// After the sort: the first pair of a cell's run writes the cell's offset, the last its end.
@compute @workgroup_size(ASSIGN_THREADS)
fn bounds_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = light_of(gid, nwg);
    let n = pair_total[0];  // set by the scan of light counts
    if (i >= n) {
        return;
    }
    let cell = pair_keys[i];
    if (i == 0u || pair_keys[i - 1u] != cell) {
        cells[cell].x = i;
    }
    if (i + 1u == n || pair_keys[i + 1u] != cell) {
        cells[cell].y = i + 1u;
    }
}

// Then (end, start) -> (offset, count); untouched cells stay (0, 0).
@compute @workgroup_size(ASSIGN_THREADS)
fn counts_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let c = light_of(gid, nwg);
    if (c < grid.tiles_x * grid.tiles_y * grid.slices) {
        cells[c].y = cells[c].y - cells[c].x;
    }
}
