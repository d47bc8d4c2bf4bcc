//! The viewer's debug views on real frames: the per-pixel ideal sums to the frame's ideal
//! count, the wasted-work view sums to the computations above it, and every view is an image of
//! the frame's size (with glass, so transparent fragments are in both the counts and the ideal).

mod common;

use lightgrid::debug_view::{draw, DebugView};
use lightgrid::scene::catalog::{self, SceneParams};
use lightgrid::{RenderSettings, Renderer};

#[test]
fn the_ideal_per_pixel_and_the_wasted_work_add_up_to_the_frame_counts() {
    let ctx = common::gpu();
    let scene = catalog::build("robots-many", &SceneParams::default()).unwrap();
    let (w, h) = (173, 111);
    let mut renderer = Renderer::new(&ctx, w, h, RenderSettings::default()).unwrap();
    let mut wasted = Vec::new();
    for id in ["forward", "tiled_deferred", "clustered_forward"] {
        let out = renderer.render(&scene, 60, id).unwrap();
        assert!(
            out.stats.transparent_fragments > 0,
            "{id}: the frame has glass"
        );
        assert_eq!(out.ideal_counts.len(), (w * h) as usize);
        let ideal: f64 = out.ideal_counts.iter().map(|&n| f64::from(n)).sum();
        let want = out.stats.ideal_lighting_computations as f64;
        assert!(
            (ideal - want).abs() <= 0.5 + want * 1e-6,
            "{id}: per-pixel ideal sums to {ideal}, the frame's is {want}"
        );
        let counts = out.counts.as_ref().expect("lavapipe counts");
        for view in DebugView::ALL {
            let Some(img) = draw(view, &out) else {
                assert_eq!(view, DebugView::Shaded);
                continue;
            };
            assert_eq!(img.image.dimensions(), (w, h), "{id} {}", view.name());
            assert!(img.max.is_finite() && img.max >= 0.0);
            if view == DebugView::WastedWork {
                let total = img.total.unwrap();
                let above = out.stats.lighting_computations.unwrap() as f64 - want;
                assert!(
                    (total - above).abs() <= above * 0.01 + 0.5 * (w * h) as f64 * 0.01,
                    "{id}: wasted {total}, computations above the ideal {above}"
                );
                wasted.push((id, total));
            }
        }
        assert!(counts
            .iter()
            .zip(&out.ideal_counts)
            .all(|(&c, &i)| c as f32 + 1e-3 >= i));
    }
    // Brute force wastes the most: culling is what the view shows.
    assert!(
        wasted[0].1 > wasted[1].1 && wasted[0].1 > wasted[2].1,
        "{wasted:?}"
    );
}
