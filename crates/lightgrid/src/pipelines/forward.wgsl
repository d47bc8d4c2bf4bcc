// forward: every light for every fragment. The reference image; it never reads a light grid.

@fragment
fn fs_main(v: VertexOut, @builtin(front_facing) front: bool) -> LitOut {
    let s = surface_from_vertex(v, front);
    let view_dir = view_dir_to(s.position);
    var color = surface_base(s);
    for (var i = 0u; i < frame.light_count; i = i + 1u) {
        color += shade_light(s, view_dir, lights[i]);
    }
    return lit(color, frame.light_count);
}
