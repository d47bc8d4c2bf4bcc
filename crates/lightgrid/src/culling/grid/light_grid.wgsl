// The one light-grid accessor (tiled-shading Listing 1): find the sample's cell (grid_cell.wgsl),
// loop the lights listed for it, call the one light function. Every grid-reading pipeline
// (forward fragment shaders and deferred compute shaders) shades through `light_grid_shade`.

@group(1) @binding(0) var<uniform> light_grid: LightGridParams;
@group(1) @binding(1) var<storage, read> light_grid_cells: array<vec2<u32>>;  // (offset, count)
@group(1) @binding(2) var<storage, read> light_grid_indices: array<u32>;
// The view-distance bounds each cell's list was built for ([min, max], min > max: empty).
@group(1) @binding(3) var<storage, read> light_grid_bounds: array<vec2<f32>>;

// Does cell `cell`'s volume hold a point at view distance `w` (its screen position inside
// the cell's tile)? Then its list holds every light reaching the point.
fn light_grid_cell_holds(cell: u32, w: f32) -> bool {
    let b = light_grid_bounds[cell];
    return w >= b.x * (1.0 - ASSIGN_DEPTH_SLACK) && w <= b.y * (1.0 + ASSIGN_DEPTH_SLACK);
}

// The lights a sample of `cell` evaluates: its list's length, or for a z-binned grid the set
// bits of its tile's mask inside its bin's range.
fn light_grid_cell_count(cell: u32) -> u32 {
    if (light_grid.zbin_words != 0u) {
        return zbin_count(cell);
    }
    return light_grid_cells[cell].y;
}

// The cell `zbin_shade` shaded last and how many lights it evaluated: the pipelines ask for
// the count after shading, and need not walk the masks twice.
var<private> zbin_shaded: vec2<u32> = vec2<u32>(0xffffffffu, 0u);

fn zbin_count(cell: u32) -> u32 {
    if (zbin_shaded.x == cell) {
        return zbin_shaded.y;
    }
    let z = light_grid_zbin_walk(cell);
    var n = 0u;
    var k = z.word_begin;
    for (; k < z.word_end; k = k + 1u) {
        n += countOneBits(light_grid_zbin_word(z, k));
    }
    check_loop(k, z.word_end);
    return n;
}

// The index (into `lights`) of the light at position `i` of the cell's list.
fn light_grid_light(cell: u32, i: u32) -> u32 {
    return light_grid_indices[light_grid_cells[cell].x + i];
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
fn light_grid_shade_fragment(s: Surface, view_dir: vec3<f32>, cell: u32, w: f32) -> vec3<f32> {
    let in_view = w >= frame.near && w <= frame.far;
    if (MULTISAMPLED && in_view && !light_grid_cell_holds(cell, w)) {
        atomicAdd(&frame_counters[COUNTER_OFF_BOUNDS_FRAGMENTS], 1u);
    }
    return light_grid_shade(s, view_dir, cell);
}

// One light's term in a loop's sum: the colour (rgb), or for the light pre-pass's monochrome
// compromise the diffuse irradiance (rgb) and the specular luminance (a).
fn light_sum(s: Surface, view_dir: vec3<f32>, light: u32, mono: bool) -> vec4<f32> {
    if (mono) {
        let t = light_terms(s, view_dir, light);
        return vec4<f32>(t.diffuse, luminance(t.specular));
    }
    return vec4<f32>(shade_light(s, view_dir, light), 0.0);
}

// The light loop itself, `light_grid_shade`, `light_grid_irradiance_mono` and `zbin_shade`, is in
// light_loop_lane.wgsl (one lane at a time) or light_loop_subgroup.wgsl (`--light-loop`).
