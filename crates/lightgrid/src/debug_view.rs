//! The viewer's debug views of an analysis frame ([`FrameOutput`]), each an image of the
//! frame's own size with the numbers its legend needs:
//! - **lights per cell** (Forward+ Fig. 2(b)): each pixel tinted by the list length of the cell
//!   it reads (`heatmap::cell_counts`);
//! - **cell depth bounds**: each pixel tinted by the view-distance span `max - min` of its
//!   cell's samples (tiled-shading §6.3: long spans are where depth discontinuities make a
//!   tile's lists long); cells without bounds (`brute-force` pipelines) show none;
//! - **wasted work**: per pixel, the lighting computations the pipeline made minus the ideal
//!   (the lights reaching its samples, `FrameOutput::ideal_counts`), what culling left to do.

use crate::analysis::FrameOutput;
use crate::heatmap;
use image::RgbaImage;

/// What the viewer shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DebugView {
    /// The shaded frame itself (the real-time path; no analysis).
    Shaded,
    /// Each pixel tinted by the length of its cell's light list.
    LightsPerCell,
    /// Each pixel tinted by the view-distance span (`max - min`) of its cell's depth bounds.
    CellBounds,
    /// Each pixel tinted by its lighting computations above the ideal.
    WastedWork,
}

impl DebugView {
    /// Every view, in the order [`DebugView::next`] cycles through them.
    pub const ALL: [DebugView; 4] = [
        DebugView::Shaded,
        DebugView::LightsPerCell,
        DebugView::CellBounds,
        DebugView::WastedWork,
    ];

    /// The view's human-readable name, for legends and menus (e.g. "lights per cell").
    pub fn name(self) -> &'static str {
        match self {
            DebugView::Shaded => "shaded",
            DebugView::LightsPerCell => "lights per cell",
            DebugView::CellBounds => "cell depth bounds",
            DebugView::WastedWork => "wasted work",
        }
    }

    /// The view a script or option names (`shaded`, `lights`, `bounds`, `wasted`).
    pub fn parse(s: &str) -> Option<DebugView> {
        match s.trim() {
            "shaded" => Some(DebugView::Shaded),
            "lights" | "heatmap" | "lights-per-cell" => Some(DebugView::LightsPerCell),
            "bounds" | "depth-bounds" | "cell-bounds" => Some(DebugView::CellBounds),
            "wasted" | "wasted-work" => Some(DebugView::WastedWork),
            _ => None,
        }
    }

    /// The next view (a key cycles through them).
    pub fn next(self) -> DebugView {
        let i = DebugView::ALL.iter().position(|&v| v == self).unwrap_or(0);
        DebugView::ALL[(i + 1) % DebugView::ALL.len()]
    }
}

/// A debug view's image and its legend: the ramp runs from 0 to `max` `unit`.
pub struct DebugImage {
    /// The frame tinted by the view's per-pixel values, at the frame's own size.
    pub image: RgbaImage,
    /// The value at the top of the ramp: the largest in the frame, in `unit`s.
    pub max: f64,
    /// The legend's unit (e.g. "lights"); empty where the view shows nothing.
    pub unit: &'static str,
    /// Why the view shows nothing where it cannot be drawn (no counts, no grid).
    pub note: Option<String>,
    /// Summed over the frame, where the view has a sum (wasted work: computations).
    pub total: Option<f64>,
}

/// Draw `view` of `out` (None for [`DebugView::Shaded`], which is the frame itself).
pub fn draw(view: DebugView, out: &FrameOutput) -> Option<DebugImage> {
    match view {
        DebugView::Shaded => None,
        DebugView::LightsPerCell => Some(lights_per_cell(out)),
        DebugView::CellBounds => Some(cell_bounds(out)),
        DebugView::WastedWork => Some(wasted_work(out)),
    }
}

fn lights_per_cell(out: &FrameOutput) -> DebugImage {
    let vd = out.setup.view_distances(&out.depth);
    let counts = heatmap::cell_counts(&out.grid, Some(&vd));
    let max = counts.iter().copied().max().unwrap_or(0);
    DebugImage {
        image: heatmap::tint(&out.image, &counts, max, out.grid.dims.tile_size),
        max: f64::from(max),
        unit: "lights",
        note: (!out.grid_is_pipelines).then(|| {
            "this pipeline builds no grid: the depth-bounded tile grid of the ideal count is shown"
                .to_string()
        }),
        total: None,
    }
}

/// Millimetres per unit of the bounds view (its values are whole numbers).
const BOUNDS_SCALE: f32 = 1000.0;

fn cell_bounds(out: &FrameOutput) -> DebugImage {
    let dims = out.grid.dims;
    let (w, h) = out.image.dimensions();
    let Some(bounds) = &out.cell_bounds else {
        return DebugImage {
            image: heatmap::tint(&out.image, &vec![0; (w * h) as usize], 1, 0),
            max: 0.0,
            unit: "",
            note: Some("this pipeline has no cell bounds (it builds no light grid)".into()),
            total: None,
        };
    };
    let vd = out.setup.view_distances(&out.depth);
    let spans: Vec<u32> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            let d = vd[(y * w + x) as usize];
            let cell = if d.is_finite() {
                dims.cell_of(x, y, d)
            } else {
                dims.tile_of(x, y)
            };
            match bounds.get(cell) {
                Some(&[lo, hi]) if lo <= hi => ((hi - lo) * BOUNDS_SCALE).round().max(1.0) as u32,
                _ => 0,
            }
        })
        .collect();
    let max = spans.iter().copied().max().unwrap_or(0);
    DebugImage {
        image: heatmap::tint(&out.image, &spans, max, dims.tile_size),
        max: f64::from(max) / f64::from(BOUNDS_SCALE),
        unit: "view-distance span",
        note: None,
        total: None,
    }
}

fn wasted_work(out: &FrameOutput) -> DebugImage {
    let (w, h) = out.image.dimensions();
    let Some(counts) = &out.counts else {
        return DebugImage {
            image: heatmap::tint(&out.image, &vec![0; (w * h) as usize], 1, 0),
            max: 0.0,
            unit: "",
            note: Some(
                "this adapter cannot count lighting computations (no R32Float blending)".into(),
            ),
            total: None,
        };
    };
    let wasted = wasted_per_pixel(counts, &out.ideal_counts);
    let max = wasted.iter().copied().max().unwrap_or(0);
    DebugImage {
        image: heatmap::tint(&out.image, &wasted, max, 0),
        max: f64::from(max),
        unit: "computations above the ideal",
        note: None,
        total: Some(wasted.iter().map(|&n| f64::from(n)).sum()),
    }
}

/// Per pixel, the computations above the ideal (rounded; never below 0: a pipeline cannot
/// do less than the ideal, and MSAA's averaged ideal may sit a fraction above a count).
pub(crate) fn wasted_per_pixel(counts: &[u32], ideal: &[f32]) -> Vec<u32> {
    counts
        .iter()
        .zip(ideal)
        .map(|(&c, &i)| (c as f32 - i).round().max(0.0) as u32)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wasted_work_is_counts_minus_ideal() {
        assert_eq!(
            wasted_per_pixel(&[5, 3, 0, 7], &[5.0, 1.0, 0.0, 7.4]),
            vec![0, 2, 0, 0]
        );
        assert_eq!(wasted_per_pixel(&[10], &[2.5]), vec![8]);
    }

    #[test]
    fn views_parse_and_cycle_through_all() {
        for v in DebugView::ALL {
            let mut n = v;
            for _ in 0..DebugView::ALL.len() {
                n = n.next();
            }
            assert_eq!(n, v);
        }
        assert_eq!(DebugView::parse("heatmap"), Some(DebugView::LightsPerCell));
        assert_eq!(DebugView::parse("wasted"), Some(DebugView::WastedWork));
        assert_eq!(DebugView::parse("bounds"), Some(DebugView::CellBounds));
        assert_eq!(DebugView::parse("nope"), None);
    }
}
