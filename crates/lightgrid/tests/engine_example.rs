//! The `engine` example is the documentation of `LightCuller` as an engine uses it (its own
//! light struct, a jittered off-centre eye, glass over an opaque scene, a mode without a depth
//! pre-pass): this runs it both ways and fails when a frame's image from the grid differs from
//! its brute-force loop's beyond the tolerance it states, or a frame lacks lights.

// Formatted as an example (`examples/rustfmt.toml`), not from here.
#[rustfmt::skip]
#[path = "../examples/engine.rs"]
#[allow(dead_code)]
mod engine;

fn run(prepass: bool) {
    let options = engine::Options {
        frames: 6,
        prepass,
        out: None,
    };
    if let Err(e) = engine::run(&options) {
        panic!("the engine example (pre-pass {prepass}) failed: {e}");
    }
}

#[test]
fn the_engine_example_with_a_depth_prepass_shades_every_frame_like_its_brute_force_loop() {
    run(true);
}

#[test]
fn the_engine_example_without_a_depth_prepass_shades_every_frame_like_its_brute_force_loop() {
    run(false);
}
