//! The lights-per-tile heatmap at every frame size, down to one pixel: no panic, the frame
//! drawn unscaled at the top left, the legend below it.

use image::{Rgba, RgbaImage};
use lightgrid::culling::{GridDims, LightGrid};
use lightgrid::heatmap::heatmap;

#[test]
fn heatmaps_of_tiny_and_odd_frames_keep_the_frame_and_fit_the_legend() {
    for (w, h) in [
        (1, 1),
        (2, 7),
        (14, 3),
        (15, 15),
        (97, 5),
        (321, 181),
        (640, 360),
    ] {
        let frame = RgbaImage::from_pixel(w, h, Rgba([200, 200, 200, 255]));
        let dims = GridDims::new(w, h, 16).unwrap();
        // One light in the first tile, none elsewhere.
        let lists: Vec<Vec<u32>> = (0..dims.cell_count())
            .map(|c| if c == 0 { vec![0] } else { Vec::new() })
            .collect();
        let map = heatmap(&frame, &LightGrid::from_lists(dims, &lists), None);
        let scale = (w / 320).max(1);
        assert_eq!(
            map.dimensions(),
            (w.max(96 * scale), h + 14 * scale),
            "{w}x{h}"
        );
        // The first tile is coloured (a light), so it differs from the grey frame's luma.
        let inner = map.get_pixel((w - 1).min(1), (h - 1).min(1));
        assert_ne!(inner, &Rgba([0, 0, 0, 255]), "{w}x{h}: the frame is drawn");
    }
}
