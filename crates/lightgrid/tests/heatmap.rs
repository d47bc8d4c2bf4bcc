//! The lights-per-tile heatmap at every frame size, down to one pixel: no panic, the frame
//! drawn unscaled at the top left, the legend below it; and the colours of known counts.

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

/// The colours of known counts: over a black frame a tile's interior is 55 % of its ramp
/// colour (green at half the maximum, red at the maximum), a tile without lights stays black, the tile
/// grid is drawn at half brightness, and on a fixed scale counts above it show as its top.
#[test]
fn known_counts_get_their_ramp_colours() {
    let (w, h) = (64, 16);
    let frame = RgbaImage::from_pixel(w, h, Rgba([0, 0, 0, 255]));
    let dims = GridDims::new(w, h, 16).unwrap();
    // Tiles of 0, 2, 4 and 8 lights: none, a quarter, half and all of the maximum.
    let lists: Vec<Vec<u32>> = [0u32, 2, 4, 8].iter().map(|&n| (0..n).collect()).collect();
    let grid = LightGrid::from_lists(dims, &lists);
    let map = heatmap(&frame, &grid, None);
    let inside = |tile: u32| map.get_pixel(tile * 16 + 8, 8).0;
    // 0.55 * 255 = 140.25 and 0.55 * 0.5 * 255 = 70.125, truncated.
    assert_eq!(inside(0), [0, 0, 0, 255], "no lights");
    assert_eq!(
        inside(1),
        [0, 70, 70, 255],
        "a quarter: between blue and green"
    );
    assert_eq!(inside(2), [0, 140, 0, 255], "half: green");
    assert_eq!(inside(3), [140, 0, 0, 255], "the maximum: red");
    assert_eq!(
        map.get_pixel(3 * 16, 8).0,
        [70, 0, 0, 255],
        "tile edge at half"
    );
    // On a fixed scale of 4, the 8-light tile is clipped to the top and 2 is half.
    let fixed = lightgrid::heatmap::heatmap_scaled(&frame, &grid, None, Some(4));
    assert_eq!(fixed.get_pixel(3 * 16 + 8, 8).0, [140, 0, 0, 255]);
    assert_eq!(fixed.get_pixel(16 + 8, 8).0, [0, 140, 0, 255]);
    // The legend's bar runs from blue at its left end to red at its right.
    let bar_y = h + 4;
    let left = map.get_pixel(14, bar_y).0;
    let right = map.get_pixel(w.max(96) - 31, bar_y).0;
    assert_eq!((left[0], left[2]), (0, 255), "{left:?}");
    assert!(right[0] > 240 && right[2] == 0, "{right:?}");
}
