//! The `embed` example is the documentation of `LightCuller`: this runs it (the same code,
//! compiled into the test) and fails when its image from the grid differs from its
//! brute-force loop's beyond the tolerance it states, or its culling report is incomplete.

// Formatted as an example (`examples/rustfmt.toml`), not from here.
#[rustfmt::skip]
#[path = "../examples/embed.rs"]
#[allow(dead_code)]
mod embed;

#[test]
fn the_embed_example_shades_from_the_grid_like_its_brute_force_loop() {
    if let Err(e) = embed::run(None) {
        panic!("the embed example failed: {e}");
    }
}
