//! The lights-per-tile view (forward-plus Fig. 2b style): each tile tinted by its light count
//! over a dimmed copy of the frame, with a colour legend (blue 0, green half, red the maximum)
//! and its end values drawn underneath. For a clustered grid each pixel shows the list of the
//! cluster its visible sample reads (its fullest cluster where it has none, the sky), so what
//! culls by depth and by cone (spot pools on the ground) shows per sample, not as the far
//! field's density.

use crate::culling::LightGrid;
use image::{Rgba, RgbaImage};

/// Blue → green → red ramp over t in [0, 1].
pub fn ramp(t: f32) -> [f32; 3] {
    let t = t.clamp(0.0, 1.0);
    if t < 0.5 {
        let u = t * 2.0;
        [0.0, u, 1.0 - u]
    } else {
        let u = (t - 0.5) * 2.0;
        [u, 1.0 - u, 0.0]
    }
}

/// 3×5 pixel digits, one row per u8 (3 low bits, left = 4).
const DIGITS: [[u8; 5]; 10] = [
    [7, 5, 5, 5, 7],
    [2, 6, 2, 2, 7],
    [7, 1, 7, 4, 7],
    [7, 1, 7, 1, 7],
    [5, 5, 7, 1, 1],
    [7, 4, 7, 1, 7],
    [7, 4, 7, 5, 7],
    [7, 1, 1, 1, 1],
    [7, 5, 7, 5, 7],
    [7, 5, 7, 1, 7],
];

fn draw_number(img: &mut RgbaImage, mut x: u32, y: u32, n: u32, scale: u32) {
    for ch in n.to_string().bytes() {
        let glyph = DIGITS[(ch - b'0') as usize];
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..3u32 {
                if bits & (4 >> col) != 0 {
                    for dy in 0..scale {
                        for dx in 0..scale {
                            let (px, py) = (x + col * scale + dx, y + row as u32 * scale + dy);
                            if px < img.width() && py < img.height() {
                                img.put_pixel(px, py, Rgba([255, 255, 255, 255]));
                            }
                        }
                    }
                }
            }
        }
        x += 4 * scale;
    }
}

/// The heatmap of `grid` over `frame`; the result is taller than the frame by the legend, and
/// at least `LEGEND_MIN_WIDTH` wide (narrow frames get a black margin on the right).
/// Narrowest legend (pixels at scale 1): bar, "0" and a seven-digit maximum.
const LEGEND_MIN_WIDTH: u32 = 96;

/// `view_distance`: the frame's per-pixel view distance (infinite for no sample), which a
/// clustered grid's view needs to find each pixel's cluster.
pub fn heatmap(frame: &RgbaImage, grid: &LightGrid, view_distance: Option<&[f32]>) -> RgbaImage {
    heatmap_scaled(frame, grid, view_distance, None)
}

/// [`heatmap`] on a fixed scale `0..=max` (counts above it show as the top of the ramp), so
/// frames and runs compare by colour (Forward+ Fig. 2(b) uses 0 to 50); `None`: the frame's
/// own maximum.
pub fn heatmap_scaled(
    frame: &RgbaImage,
    grid: &LightGrid,
    view_distance: Option<&[f32]>,
    max: Option<u32>,
) -> RgbaImage {
    let (w, h) = frame.dimensions();
    let scale = (w / 320).max(1);
    let legend_h = 14 * scale;
    let counts = cell_counts(grid, view_distance);
    let max = max
        .unwrap_or_else(|| counts.iter().copied().max().unwrap_or(0))
        .max(1);
    let tinted = tint(frame, &counts, max, grid.dims.tile_size);
    // The legend needs room for its bar and two numbers: frames narrower than that get a
    // black margin on the right instead of a legend drawn off the image.
    let out_w = w.max(LEGEND_MIN_WIDTH * scale);
    let mut out = RgbaImage::from_pixel(out_w, h + legend_h, Rgba([0, 0, 0, 255]));
    image::imageops::replace(&mut out, &tinted, 0, 0);
    // Legend: the ramp from 0 to max lights per tile, labelled at both ends.
    let (bar_x0, bar_x1) = (
        14 * scale,
        out_w.saturating_sub(30 * scale).max(14 * scale + 1),
    );
    for x in bar_x0..bar_x1 {
        let c = ramp((x - bar_x0) as f32 / (bar_x1 - bar_x0) as f32);
        for y in h + 2 * scale..h + 8 * scale {
            out.put_pixel(
                x,
                y,
                Rgba([
                    (c[0] * 255.0) as u8,
                    (c[1] * 255.0) as u8,
                    (c[2] * 255.0) as u8,
                    255,
                ]),
            );
        }
    }
    draw_number(&mut out, 2 * scale, h + 3 * scale, 0, scale);
    draw_number(&mut out, bar_x1 + 3 * scale, h + 3 * scale, max, scale);
    out
}

/// Per pixel (row-major), the light count of the cell it reads: its tile's fullest list, or for
/// a clustered grid with `view_distance` the cluster of its visible sample (the tile's fullest
/// where it has none).
pub(crate) fn cell_counts(grid: &LightGrid, view_distance: Option<&[f32]>) -> Vec<u32> {
    let dims = grid.dims;
    let tile_max = grid.tile_max_counts();
    let (w, h) = (dims.width, dims.height);
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| match view_distance {
            Some(vd) if dims.slices > 1 => {
                let d = vd[(y * w + x) as usize];
                if d.is_finite() {
                    grid.cells[dims.cell_of(x, y, d)][1]
                } else {
                    tile_max[dims.tile_of(x, y)]
                }
            }
            _ => tile_max[dims.tile_of(x, y)],
        })
        .collect()
}

/// `frame` dimmed and tinted per pixel by `values[i] / max` on [`ramp`]; zero values stay
/// dark grey, and the tile grid (`tile_size`; 0 for none) is drawn at half brightness.
pub fn tint(frame: &RgbaImage, values: &[u32], max: u32, tile_size: u32) -> RgbaImage {
    let (w, h) = frame.dimensions();
    let max = max.max(1);
    let mut out = RgbaImage::new(w, h);
    for (x, y, p) in frame.enumerate_pixels() {
        let value = values[(y * w + x) as usize];
        let c = ramp(value as f32 / max as f32);
        let luma = (0.2 * p[0] as f32 + 0.6 * p[1] as f32 + 0.2 * p[2] as f32) / 255.0;
        let px = |i: usize| ((0.55 * c[i] + 0.45 * luma) * 255.0) as u8;
        let on_edge = tile_size > 0 && (x % tile_size == 0 || y % tile_size == 0);
        let v = if value == 0 {
            [(luma * 90.0) as u8; 3]
        } else {
            [px(0), px(1), px(2)]
        };
        let v = if on_edge { v.map(|c| c / 2) } else { v };
        out.put_pixel(x, y, Rgba([v[0], v[1], v[2], 255]));
    }
    debug_assert_eq!(out.dimensions(), (w, h));
    out
}
