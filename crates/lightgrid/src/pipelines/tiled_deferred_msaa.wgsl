// tiled_deferred / clustered_deferred with MSAA: edge-aware shading over a per-sample
// G-buffer (tiled-shading §2.1, tiled-deferred-tricks: edge detection, and Lauritzen's
// redistribution of the edge samples over the workgroup).
//
// Each invocation owns a pixel. It compares the pixel's samples (edge: a sample with or
// without geometry where sample 0 differs, another material, a normal more than ~8 degrees
// off (EDGE_NORMAL_COS), or off sample 0's tangent plane (EDGE_PLANE_SIN)) and shades the
// pixel once. A pixel that is no edge is done: its one colour goes to every sample. An edge
// pixel queues its other covered samples in workgroup memory; after a barrier every
// invocation of the workgroup takes queued samples in turn, so a workgroup with few edges
// does not leave most invocations idle while a few loop over their samples. A pixel is
// shaded at its centre, an edge sample at its own place (its depth at its standard position
// in the pixel: `sample_position`), and each sample's colour is stored in
// `sample_colors`; a fragment pass writes them into the multisampled HDR target
// (`sample_expand.wgsl`), where the transparent pass blends and the tonemap resolves. Or,
// with RESOLVE_IN_KERNEL, the samples are resolved here (Trick 1; both in
// msaa_sample_outputs.wgsl, shared with the single kernel's MSAA variant).
// Counts go to the per-pixel counts (`count_pixel`: lighting computations) and the frame counters (edge pixels,
// samples shaded, samples with geometry).

// The queue of edge samples and the counts: msaa_edge_queue.wgsl.
const GROUP_WIDTH: u32 = SCREEN_WORKGROUP;

fn msaa_depth(p: vec2<u32>, s: u32) -> f32 {
    return textureLoad(gb_depth, p, s);
}

// An edge pixel's sample without geometry: black.
fn background_sample(p: vec2<u32>, l: u32, s: u32) {
    output_sample(p, l, s, vec3<f32>(0.0), 1.0 / f32(SAMPLES));
}

// Sample `s` of pixel `p` at framebuffer position `xy` and depth-buffer value `depth`: shaded
// from its cell's lights, counted into the pixel.
fn shade_at(p: vec2<u32>, s: u32, xy: vec2<f32>, depth: f32) -> vec3<f32> {
    let surface = apply_material(raw_surface_from_gbuffer(p, s, position_from_screen(xy, depth)));
    let cell = light_grid_cell(vec2<f32>(p), view_distance_from_depth(depth));
    count_pixel(p, light_grid_cell_count(cell));
    return surface_base(surface) + light_grid_shade(surface, view_dir_to(surface.position), cell);
}

// `differs(p, s, d0, n0)`, the edge test, is in passes/msaa_edges.wgsl.

@compute @workgroup_size(SCREEN_WORKGROUP, SCREEN_WORKGROUP)
fn main(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
) {
    clear_resolve(li);
    clear_edge_queue(li);
    workgroupBarrier();
    let size = vec2<u32>(frame.viewport);
    let p = gid.xy;
    if (p.x < size.x && p.y < size.y) {
        let d0 = textureLoad(gb_depth, p, 0);
        let n0 = textureLoad(gb_normal, p, 0);
        var edge = false;
        var geometry = 0u;
        var depth_sum = 0.0;
        for (var s = 0u; s < SAMPLES; s = s + 1u) {
            let d = textureLoad(gb_depth, p, s);
            geometry += select(1u, 0u, is_background(d));
            depth_sum += d;
            edge = edge || (s > 0u && differs(p, s, d0, n0));
        }
        var c0 = vec3<f32>(0.0);
        if (!is_background(d0)) {
            if (edge) {
                c0 = shade_at(p, 0u, vec2<f32>(p) + sample_position(0u), d0);
            } else {
                // One surface over the whole pixel: the standard patterns' sample positions
                // average to the pixel centre and depth is affine over a triangle, so the
                // samples' mean depth is the centre's, where forward shades the pixel.
                c0 = shade_at(p, 0u, vec2<f32>(p) + vec2<f32>(0.5), depth_sum / f32(SAMPLES));
            }
        }
        output_pixel(p, li, edge, c0);
        enqueue_pixel(p, li, edge, !is_background(d0), geometry);
    }
    // Every invocation takes queued edge samples in turn.
    let n = workgroupUniformLoad(&queued);
    let origin = wg.xy * SCREEN_WORKGROUP;
    var i = li;
    for (; i < n; i = i + GROUP_PIXELS) {
        let item = queue[i];
        let q = queued_pixel(origin, item);
        let s = queued_sample(item);
        let xy = vec2<f32>(q) + sample_position(s);
        let color = shade_at(q, s, xy, textureLoad(gb_depth, q, s));
        output_sample(q, queued_local(item), s, color, 1.0 / f32(SAMPLES));
    }
    check_loop(i, n);
    finish_resolve(p, li, p.x < size.x && p.y < size.y);
    report_edge_counts(li, n);
}
