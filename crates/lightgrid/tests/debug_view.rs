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
    let mut gpu_fragments: Option<Vec<f32>> = None;
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
        // The per-pixel ideal counts the transparent fragments the CPU rasterizes; the GPU
        // can rasterize a pixel centre within round-off of a triangle edge the other way (a
        // fill rule in f32 against fixed-point subpixels), leaving that pixel's count short
        // of an ideal it never shades. `forward`'s count says how many fragments the GPU
        // shaded per pixel (each loops every light): every pixel the GPU shaded as often as
        // the CPU rasterized gets at least its ideal, and the others must stay rare.
        let lights = out.stats.lights as f32;
        let gpu_fragments = gpu_fragments
            .get_or_insert_with(|| counts.iter().map(|&c| c as f32 / lights).collect());
        let state = scene.frame(60);
        let opaque_w = out.setup.view_distances(&out.depth);
        let mut cpu_fragments: Vec<f32> = opaque_w
            .iter()
            .map(|w| if w.is_finite() { 1.0 } else { 0.0 })
            .collect();
        let glass = scene.geometry(&state).transparent_triangles(0);
        for f in lightgrid::scene::rasterize(&out.setup, &glass, &opaque_w) {
            cpu_fragments[(f.y * w + f.x) as usize] += 1.0;
        }
        let mut unshaded = 0;
        for (p, (&c, &i)) in counts.iter().zip(&out.ideal_counts).enumerate() {
            if gpu_fragments[p] + 1e-3 < cpu_fragments[p] {
                unshaded += 1;
            } else {
                assert!(
                    c as f32 + 1e-3 >= i,
                    "{id}: pixel ({}, {}) looped {c} lights, {i} reach its samples",
                    p as u32 % w,
                    p as u32 / w
                );
            }
        }
        assert!(
            unshaded <= (w * h) as usize / 1000,
            "{id}: {unshaded} pixels where the GPU rasterized fewer fragments than the CPU"
        );
    }
    // Brute force wastes the most: culling is what the view shows.
    assert!(
        wasted[0].1 > wasted[1].1 && wasted[0].1 > wasted[2].1,
        "{wasted:?}"
    );
}
