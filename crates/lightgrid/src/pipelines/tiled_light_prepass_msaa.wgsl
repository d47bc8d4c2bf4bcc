// tiled_light_prepass with MSAA: the irradiance kernel made edge-aware, as the deferred one is
// (`tiled_deferred_msaa.wgsl`: tiled-shading §2.1, tiled-deferred-tricks' edge detection and
// Lauritzen's redistribution of the edge samples over the workgroup).
//
// Each invocation owns a pixel of the per-sample attributes. It finds whether the pixel is an
// edge (`attributes_edge`: the light volumes' test, so the stencil marks of the expand pass
// that follows are the pixels this kernel shaded per sample) and accumulates its tile's
// lights once: at the pixel centre (the samples' mean depth) for a pixel that is no edge,
// that value stored for every sample; at sample 0's own place for an edge pixel, whose other
// samples with geometry are queued in workgroup memory and taken in turn by every invocation
// of the workgroup after a barrier. Each sample's mono irradiance (diffuse rgb, specular
// luminance) goes to `sample_irradiance` as two pack2x16float words; a fragment pass writes
// it into the multisampled irradiance target (`fs_expand_irradiance`) for the shading pass.
// Counts go to the per-pixel counts (`count_pixel`) and the frame counters (edge pixels, samples computed, samples
// with geometry).

// Per sample (pixel * SAMPLES + sample): the irradiance as two pack2x16float words.
@group(3) @binding(0) var<storage, read_write> sample_irradiance: array<vec2<u32>>;

// The queue of edge samples and the counts: msaa_edge_queue.wgsl.
const GROUP_WIDTH: u32 = SCREEN_WORKGROUP;

fn msaa_depth(p: vec2<u32>, s: u32) -> f32 {
    return textureLoad(attr_depth, p, s);
}

// An edge pixel's sample without geometry: no irradiance.
fn background_sample(p: vec2<u32>, l: u32, s: u32) {
    store_irradiance(p, s, vec4<f32>(0.0));
}

// pack2x16float of a value beyond binary16's range is indeterminate (WGSL): clamped to the
// largest half (HALF_MAX), a highlight's irradiance saturates the tone curve as the RGBA16F
// targets' conversion does.
fn store_irradiance(p: vec2<u32>, s: u32, value: vec4<f32>) {
    let i = (p.y * u32(frame.viewport.x) + p.x) * SAMPLES + s;
    let v = min(value, vec4<f32>(HALF_MAX));
    sample_irradiance[i] = vec2<u32>(pack2x16float(v.rg), pack2x16float(v.ba));
}

// The tile's lights on `surface` at depth-buffer value `depth`, counted into pixel `p`.
fn irradiance_at(p: vec2<u32>, surface: Surface, depth: f32) -> vec4<f32> {
    let cell = light_grid_cell(vec2<f32>(p), view_distance_from_depth(depth));
    count_pixel(p, light_grid_cell_count(cell));
    return light_grid_irradiance_mono(surface, view_dir_to(surface.position), cell);
}

@compute @workgroup_size(SCREEN_WORKGROUP, SCREEN_WORKGROUP)
fn main(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
) {
    clear_edge_queue(li);
    workgroupBarrier();
    let size = vec2<u32>(frame.viewport);
    let p = gid.xy;
    if (p.x < size.x && p.y < size.y) {
        let d0 = textureLoad(attr_depth, p, 0);
        var geometry = 0u;
        for (var s = 0u; s < SAMPLES; s = s + 1u) {
            geometry += select(1u, 0u, is_background(textureLoad(attr_depth, p, s)));
        }
        let edge = attributes_edge(p);
        var v0 = vec4<f32>(0.0);
        if (!is_background(d0)) {
            if (edge) {
                v0 = irradiance_at(p, attributes_sample_surface(p, 0u, d0), d0);
            } else {
                v0 = irradiance_at(p, attributes_pixel_surface(p), centre_depth(attr_depth, p));
            }
        }
        store_irradiance(p, 0u, v0);
        if (!edge) {
            for (var s = 1u; s < SAMPLES; s = s + 1u) {
                store_irradiance(p, s, v0);
            }
        }
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
        let depth = textureLoad(attr_depth, q, s);
        store_irradiance(q, s, irradiance_at(q, attributes_sample_surface(q, s, depth), depth));
    }
    check_loop(i, n);
    report_edge_counts(li, n);
}
