// The one light-grid accessor (tiled-shading Listing 1): find the sample's cell (grid_cell.wgsl),
// loop the lights listed for it, call the one light function. Every grid-reading pipeline
// (forward fragment shaders and deferred compute shaders) shades through `grid_shade`.

@group(1) @binding(0) var<uniform> grid: GridParams;
@group(1) @binding(1) var<storage, read> grid_cells: array<vec2<u32>>;  // (offset, count)
@group(1) @binding(2) var<storage, read> grid_indices: array<u32>;
// The view-distance bounds each cell's list was built for ([min, max], min > max: empty).
@group(1) @binding(3) var<storage, read> grid_bounds: array<vec2<f32>>;

// Does cell `cell`'s volume hold a point at view distance `w` (its screen position inside
// the cell's tile)? Then its list holds every light reaching the point.
fn grid_cell_holds(cell: u32, w: f32) -> bool {
    let b = grid_bounds[cell];
    return w >= b.x * (1.0 - ASSIGN_DEPTH_SLACK) && w <= b.y * (1.0 + ASSIGN_DEPTH_SLACK);
}

fn grid_cell_count(cell: u32) -> u32 {
    return grid_cells[cell].y;
}

// The light at position `i` of the cell's list.
fn grid_light(cell: u32, i: u32) -> Light {
    return lights[grid_indices[grid_cells[cell].x + i]];
}

// A forward fragment: its surface lit by the lights of `cell` (found at the fragment's pixel
// and view distance `w`). With MSAA a fragment covering part of a pixel is shaded at the pixel
// centre, which may lie off its triangle: its extrapolated depth can leave the bounds of every
// sample of the cell (measured: clustered_forward 75 levels off at such edges, lights
// missing). The cell bounds therefore include every fragment's `w` (`fragment_bounds.wgsl`),
// and a fragment outside them anyway is counted (COUNTER_OFF_BOUNDS_FRAGMENTS): the frame is
// reported wrong, never passed off as right. The grid covers the view volume only: a centre
// extrapolated out of it (past the near or far plane, or across its plane's horizon, behind
// the camera: measured w = -98 in scattered frame 77 at 250x141) shades no point of the
// scene, forward's colour there included; it is lit from its pixel's cell and not counted.
// (Looping over every light instead is no option: lavapipe runs helper lanes, whose
// extrapolated depths leave the bounds, to the end of such a loop, 15x slower: measured.)
fn grid_shade_fragment(s: Surface, view_dir: vec3<f32>, cell: u32, w: f32) -> vec3<f32> {
    let in_view = w >= frame.near && w <= frame.far;
    if (MULTISAMPLED && in_view && !grid_cell_holds(cell, w)) {
        atomicAdd(&frame_counters[COUNTER_OFF_BOUNDS_FRAGMENTS], 1u);
    }
    return grid_shade(s, view_dir, cell);
}

// The cell's lights' diffuse irradiance (rgb) and specular luminance (a): the light
// pre-pass's monochrome compromise, summed as the tiled light pre-pass stores it.
fn grid_irradiance_mono(s: Surface, view_dir: vec3<f32>, cell: u32) -> vec4<f32> {
    var acc = vec4<f32>(0.0);
    let count = grid_cell_count(cell);
    var i = 0u;
    for (; i < count; i = i + 1u) {
        let t = light_terms(s, view_dir, grid_light(cell, i));
        acc += vec4<f32>(t.diffuse, luminance(t.specular));
    }
    check_loop(i, count);
    return acc;
}

// Sum of the cell's lights on the surface (Listing 1's computeLight).
fn grid_shade(s: Surface, view_dir: vec3<f32>, cell: u32) -> vec3<f32> {
    var acc = vec3<f32>(0.0);
    let count = grid_cell_count(cell);
    var i = 0u;
    for (; i < count; i = i + 1u) {
        acc += shade_light(s, view_dir, grid_light(cell, i));
    }
    check_loop(i, count);
    return acc;
}
