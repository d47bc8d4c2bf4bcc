// What the edge-aware MSAA kernels share (tiled_deferred_msaa.wgsl,
// tiled_deferred_single_msaa.wgsl, tiled_light_prepass_msaa.wgsl; tiled-deferred-tricks,
// Lauritzen's redistribution): each invocation owns a pixel and computes it once; an edge
// pixel's other samples with geometry are queued in workgroup memory and, after a barrier,
// taken in turn by every invocation of the workgroup; the kernels count edge pixels, points
// computed and samples with geometry into the frame counters alike.
// The including kernel defines GROUP_WIDTH (its workgroup's edge), `msaa_depth(p, s)` (its
// depth texture's sample) and `background_sample(p, l, s)` (what sample `s` of an edge
// pixel `p`, local index `l`, gets where it holds no geometry).

const GROUP_PIXELS: u32 = GROUP_WIDTH * GROUP_WIDTH;

// The queued edge samples: (local pixel index << 8) | sample.
var<workgroup> queue: array<u32, GROUP_PIXELS * (SAMPLES - 1u)>;
var<workgroup> queued: atomic<u32>;
var<workgroup> group_edges: atomic<u32>;
var<workgroup> group_first: atomic<u32>;
var<workgroup> group_geometry: atomic<u32>;

// Before the first barrier of the workgroup.
fn clear_edge_queue(li: u32) {
    if (li == 0u) {
        atomicStore(&queued, 0u);
        atomicStore(&group_edges, 0u);
        atomicStore(&group_first, 0u);
        atomicStore(&group_geometry, 0u);
    }
}

// Pixel `p` (local index `li`) with `geometry` samples holding geometry: counted, its first
// point computed when `first`; an edge pixel's other samples with geometry queued, the rest
// given to `background_sample`.
fn enqueue_pixel(p: vec2<u32>, li: u32, edge: bool, first: bool, geometry: u32) {
    if (first) {
        atomicAdd(&group_first, 1u);
    }
    if (edge) {
        for (var s = 1u; s < SAMPLES; s = s + 1u) {
            if (!is_background(msaa_depth(p, s))) {
                queue[atomicAdd(&queued, 1u)] = (li << 8u) | s;
            } else {
                background_sample(p, li, s);
            }
        }
        atomicAdd(&group_edges, 1u);
    }
    atomicAdd(&group_geometry, geometry);
}

// Queued `item`'s local pixel index, its pixel in the workgroup whose first pixel is
// `origin`, and its sample.
fn queued_local(item: u32) -> u32 {
    return item >> 8u;
}

fn queued_pixel(origin: vec2<u32>, item: u32) -> vec2<u32> {
    let l = queued_local(item);
    return origin + vec2<u32>(l % GROUP_WIDTH, l / GROUP_WIDTH);
}

fn queued_sample(item: u32) -> u32 {
    return item & 0xffu;
}

// After the queue was read (`workgroupUniformLoad(&queued)`: n items): the workgroup's counts
// into the frame counters.
fn report_edge_counts(li: u32, n: u32) {
    if (li == 0u) {
        atomicAdd(&frame_counters[COUNTER_EDGE_PIXELS], atomicLoad(&group_edges));
        atomicAdd(&frame_counters[COUNTER_SHADED_SAMPLES], atomicLoad(&group_first) + n);
        atomicAdd(&frame_counters[COUNTER_GEOMETRY_SAMPLES], atomicLoad(&group_geometry));
    }
}
