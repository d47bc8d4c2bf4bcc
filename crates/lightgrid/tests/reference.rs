//! GPU: the forward reference guarded by a blessed PNG, and a frame that is really lit.
//!
//! `LIGHTGRID_BLESS=1 cargo test --release -p lightgrid --test reference` rewrites the
//! blessed images. On failure the actual image and a diff image go to target/test-output/.

mod common;

use lightgrid::image_io::{diff, load_image, save_png};
use lightgrid::scene::catalog::{self, SceneParams};
use lightgrid::Renderer;

/// Tolerance against the blessed image, in 8-bit sRGB levels. The blessed PNGs come from
/// lavapipe, which is deterministic on one machine; other drivers round floats and
/// rasterize edges differently, so a few edge pixels may differ by many levels while the mean
/// stays far below one level.
const MAX_MEAN: f64 = 0.5;
const MAX_P99: f64 = 4.0;

fn check_against_golden(scene: &str, frame: u32, (w, h): (u32, u32)) {
    let ctx = common::gpu();
    let s = catalog::build(scene, &SceneParams::default()).unwrap();
    let mut r = Renderer::new(&ctx, w, h, Default::default()).unwrap();
    let out = r.render(&s, frame, "forward").unwrap();
    let name = format!("{scene}-f{frame}-{w}x{h}-forward.png");
    let golden = common::golden_dir().join(&name);
    if common::blessing() {
        save_png(&out.image, &golden).unwrap();
        eprintln!("blessed {}", golden.display());
        return;
    }
    let expected = load_image(&golden).unwrap_or_else(|e| {
        panic!("missing blessed image ({e}); run with LIGHTGRID_BLESS=1 to create it")
    });
    let (d, vis) = diff(&expected, &out.image).unwrap();
    if d.mean > MAX_MEAN || d.p99 > MAX_P99 {
        let dir = common::output_dir();
        save_png(&out.image, &dir.join(format!("actual-{name}"))).unwrap();
        save_png(&vis, &dir.join(format!("diff-{name}"))).unwrap();
        panic!(
            "{name}: differs from the blessed image (mean {:.3}, p99 {}, max {}); actual and diff in {}",
            d.mean,
            d.p99,
            d.max,
            dir.display()
        );
    }
}

#[test]
fn forward_reference_matches_blessed_robots_many() {
    check_against_golden("robots-many", 200, (192, 108));
}

#[test]
fn forward_reference_matches_blessed_robots_few() {
    check_against_golden("robots-few", 200, (160, 90));
}

#[test]
fn lights_really_light_the_street() {
    // The same frame with and without lights: the lit one must be much brighter, so a broken
    // light loop cannot hide behind an ambient-only image that happens to match itself.
    let ctx = common::gpu();
    let s = catalog::build("robots-few", &SceneParams::default()).unwrap();
    let mut dark = s.clone();
    for l in &mut dark.lights {
        l.light.intensity = 0.0;
    }
    let mut r = Renderer::new(&ctx, 128, 72, Default::default()).unwrap();
    let lit = r.render(&s, 200, "forward").unwrap();
    let unlit = r.render(&dark, 200, "forward").unwrap();
    let mean = |img: &image::RgbaImage| {
        img.pixels()
            .map(|p| p[0] as f64 + p[1] as f64 + p[2] as f64)
            .sum::<f64>()
            / img.len() as f64
    };
    assert!(
        mean(&lit.image) > 1.5 * mean(&unlit.image) + 5.0,
        "lit {} vs unlit {}",
        mean(&lit.image),
        mean(&unlit.image)
    );
    let stats = &lit.stats;
    assert_eq!((stats.width, stats.height, stats.lights), (128, 72, 11));
    assert!(stats.gpu_ms > 0.0);
}

#[test]
fn bad_sizes_and_frames_are_errors_not_panics() {
    let ctx = common::gpu();
    assert!(Renderer::new(&ctx, 0, 10, Default::default()).is_err());
    let too_big = ctx.max_texture_edge() + 1;
    assert!(Renderer::new(&ctx, too_big, 8, Default::default()).is_err());
    let s = catalog::build("robots-few", &SceneParams::default()).unwrap();
    let mut r = Renderer::new(&ctx, 32, 32, Default::default()).unwrap();
    assert!(r.render(&s, s.frame_count(), "forward").is_err());
    assert!(r.render(&s, 0, "no-such-pipeline").is_err());
}
