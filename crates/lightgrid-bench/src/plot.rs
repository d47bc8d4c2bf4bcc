//! Charts for the benchmark: line charts (linear or log axes) and stacked bars, drawn with
//! plotters to SVG and to PNG. Text is set in DejaVu Sans, embedded in the crate
//! (`assets/DejaVuSans.ttf`) and registered once as plotters' `sans-serif`, so drawing a chart
//! looks up no system font.

use image::RgbaImage;
use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::register_font;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::error::Error;
use std::sync::Once;

/// A line of a line chart.
#[derive(Clone, Debug)]
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    /// Drawn dashed and black (e.g. the ideal).
    pub emphasis: bool,
}

/// A line chart.
#[derive(Clone, Debug)]
pub struct LineChart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub log_x: bool,
    pub log_y: bool,
    pub series: Vec<Series>,
}

/// Stacked bars: one bar per entry, segments stacked bottom up.
#[derive(Clone, Debug)]
pub struct StackedBars {
    pub title: String,
    pub y_label: String,
    pub bars: Vec<(String, Vec<(String, f64)>)>,
}

/// Size of every chart, in pixels (the SVG's user units).
pub const SIZE: (u32, u32) = (960, 540);
/// Width of the legend column at the right, at least (longer names widen it, up to half the
/// chart).
const LEGEND_W: u32 = 230;
/// Legend pixels per character of a name (13-px sans serif, generous).
const LEGEND_CHAR_PX: u32 = 7;
/// The family the embedded font is registered as.
const FONT: &str = "sans-serif";
const TITLE_PX: f64 = 19.0;
const TEXT_PX: f64 = 13.0;
/// Series with at most this many points get a marker on each point.
const MARKED_POINTS: usize = 16;

static DEJAVU_SANS: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Register the embedded font with plotters (once per process).
fn register_embedded_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        if register_font(FONT, FontStyle::Normal, DEJAVU_SANS).is_err() {
            panic!("assets/DejaVuSans.ttf is not a font plotters can read");
        }
    });
}

const PALETTE: [RGBColor; 16] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
    RGBColor(0, 0, 128),
    RGBColor(128, 64, 0),
    RGBColor(0, 128, 96),
    RGBColor(160, 160, 255),
    RGBColor(255, 200, 0),
    RGBColor(90, 0, 90),
];

fn color(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Short number for tick labels: 1200 -> "1.2k", 3e6 -> "3M", 0.05 -> "0.05".
pub fn short_number(v: f64) -> String {
    let a = v.abs();
    let (d, s) = if a >= 1e9 {
        (1e9, "G")
    } else if a >= 1e6 {
        (1e6, "M")
    } else if a >= 1e3 {
        (1e3, "k")
    } else {
        (1.0, "")
    };
    let x = v / d;
    let txt = if (x - x.round()).abs() < 1e-6 {
        format!("{}", x.round() + 0.0)
    } else if x.abs() >= 1.0 {
        format!("{x:.1}")
    } else {
        // Below one: two significant digits, trailing zeros dropped.
        let digits = (1.0 - x.abs().log10().floor()).clamp(1.0, 12.0) as usize;
        let t = format!("{x:.digits$}");
        t.trim_end_matches('0').trim_end_matches('.').to_string()
    };
    format!("{txt}{s}")
}

/// The largest magnitude an axis reaches: values past it (up to f64's 1.8e308, which a
/// results file may hold) are drawn at it, so every range, width and tick count stays finite.
const AXIS_LIMIT: f64 = 1e300;
/// The most decades a log axis spans; values below the lowest are drawn on it.
const MAX_DECADES: i32 = 30;

/// The range an axis shows: whole decades on log axes (at most [`MAX_DECADES`], within
/// 1e-300..1e300), from zero (or below) on linear value axes, the data's extent on linear x
/// axes (within ±[`AXIS_LIMIT`]). Bounded for any value: a tick or grid computation over it
/// takes a bounded number of steps.
fn axis_range(values: impl Iterator<Item = f64>, log: bool, from_zero: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && (!log || *v > 0.0)) {
        let v = v.clamp(-AXIS_LIMIT, AXIS_LIMIT);
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return if log { (1.0, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        let limit = AXIS_LIMIT.log10() as i32;
        let b = (hi.log10().ceil() as i32).clamp(-limit, limit);
        let a = (lo.log10().floor() as i32).clamp(-limit, limit).min(b - 1);
        let a = a.max(b - MAX_DECADES);
        (10f64.powi(a), 10f64.powi(b))
    } else if from_zero {
        let lo = lo.min(0.0);
        let hi = if hi > lo {
            hi + (hi - lo) * 0.05
        } else {
            lo + 1.0
        };
        (lo, hi)
    } else if hi > lo {
        (lo, hi)
    } else {
        (lo - 0.5, hi + 0.5)
    }
}

/// Ticks of a log axis over whole decades `lo..hi` (an [`axis_range`]): labelled decades
/// (and 2 and 5 times them when there are few), grid lines at every integer multiple within
/// a decade. At most [`MAX_DECADES`] decades, whatever the range.
fn log_ticks(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>) {
    let limit = AXIS_LIMIT.log10() as i32 + 1;
    let exponent = |v: f64| (v.log10().round() as i32).clamp(-limit, limit);
    let b = exponent(hi);
    let a = exponent(lo).max(b - MAX_DECADES);
    let mantissas: &[f64] = if b - a <= 2 { &[1.0, 2.0, 5.0] } else { &[1.0] };
    let mut bold = Vec::new();
    let mut light = Vec::new();
    for e in a..=b {
        let decade = 10f64.powi(e);
        bold.extend(mantissas.iter().map(|m| m * decade).filter(|&v| v <= hi));
        if e < b {
            light.extend((2..10).map(|m| f64::from(m) * decade));
        }
    }
    (bold, light)
}

type DrawResult = Result<(), Box<dyn Error>>;

/// An x range and a y range.
type Ranges = ((f64, f64), (f64, f64));

/// The plot area and the legend column of a chart.
type Panes<DB> = (DrawingArea<DB, Shift>, DrawingArea<DB, Shift>);

/// One legend row: name, colour, dashed.
type LegendEntry = (String, RGBColor, bool);

fn text_style(px: f64) -> TextStyle<'static> {
    (FONT, px).into_font().color(&BLACK)
}

/// The title across the top, then the body split into the plot and a legend column wide
/// enough for the longest of `names`.
fn frame<'a, DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    names: impl Iterator<Item = &'a str>,
) -> Result<Panes<DB>, Box<dyn Error>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let body = root.titled(title, text_style(TITLE_PX))?;
    let (w, _) = root.dim_in_pixel();
    let longest = names.map(|n| n.chars().count() as u32).max().unwrap_or(0);
    let legend_w = (longest * LEGEND_CHAR_PX + 50).clamp(LEGEND_W, w / 2);
    Ok(body.split_horizontally(w - legend_w))
}

/// The legend column: a line (or block) of each entry's colour and its name.
fn legend<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, entries: &[LegendEntry]) -> DrawResult
where
    DB::ErrorType: 'static,
{
    if entries.is_empty() {
        return Ok(());
    }
    let (_, h) = area.dim_in_pixel();
    let (top, x) = (20, 10);
    let step = ((h as i32 - 2 * top) / entries.len() as i32).clamp(8, 20);
    let style = text_style(TEXT_PX).pos(Pos::new(HPos::Left, VPos::Center));
    let bottom = top + step * (entries.len() as i32 - 1);
    area.draw(&Rectangle::new(
        [
            (x - 6, top - step / 2 - 4),
            (area.dim_in_pixel().0 as i32 - 8, bottom + step / 2 + 4),
        ],
        RGBColor(200, 200, 200).stroke_width(1),
    ))?;
    for (i, (name, rgb, dashed)) in entries.iter().enumerate() {
        let y = top + i as i32 * step;
        let line = rgb.stroke_width(3);
        if *dashed {
            for s in [0, 10, 20] {
                area.draw(&PathElement::new([(x + s, y), (x + s + 6, y)], line))?;
            }
        } else {
            area.draw(&PathElement::new([(x, y), (x + 26, y)], line))?;
        }
        area.draw(&Text::new(name.clone(), (x + 34, y), style.clone()))?;
    }
    Ok(())
}

impl LineChart {
    /// Draw onto `root` with the x and y coordinate types the log flags ask for.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let xs = self
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.0));
        let ys = self
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.1));
        let (x0, x1) = axis_range(xs, self.log_x, false);
        let (y0, y1) = axis_range(ys, self.log_y, true);
        let lin = |a: f64, b: f64| RangedCoordf64::from(a..b);
        let log = |a: f64, b: f64| {
            let (bold, light) = log_ticks(a, b);
            LogCoord::from((a..b).log_scale())
                .with_key_points(bold)
                .with_light_points(light)
        };
        let within = ((x0, x1), (y0, y1));
        match (self.log_x, self.log_y) {
            (false, false) => self.draw_on(root, lin(x0, x1), lin(y0, y1), within),
            (false, true) => self.draw_on(root, lin(x0, x1), log(y0, y1), within),
            (true, false) => self.draw_on(root, log(x0, x1), lin(y0, y1), within),
            (true, true) => self.draw_on(root, log(x0, x1), log(y0, y1), within),
        }
    }

    /// Draw on the coordinates `x`, `y`, with points outside `within` (the axes' ranges)
    /// drawn on its edge.
    fn draw_on<DB, X, Y>(
        &self,
        root: &DrawingArea<DB, Shift>,
        x: X,
        y: Y,
        within: Ranges,
    ) -> DrawResult
    where
        DB: DrawingBackend,
        DB::ErrorType: 'static,
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        let names = self.series.iter().map(|s| s.name.as_str());
        let (plot, legend_area) = frame(root, &self.title, names)?;
        let mut chart = ChartBuilder::on(&plot)
            .margin(12)
            .margin_right(24)
            .x_label_area_size(48)
            .y_label_area_size(64)
            .build_cartesian_2d(x, y)?;
        chart
            .configure_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .x_label_formatter(&|v| short_number(*v))
            .y_label_formatter(&|v| short_number(*v))
            .label_style(text_style(TEXT_PX))
            .axis_desc_style(text_style(TEXT_PX + 1.0))
            .bold_line_style(RGBColor(215, 215, 215))
            .light_line_style(RGBColor(242, 242, 242))
            .draw()?;
        let mut entries = Vec::new();
        for (i, s) in self.series.iter().enumerate() {
            let rgb = if s.emphasis { BLACK } else { color(i) };
            let points: Vec<(f64, f64)> = s
                .points
                .iter()
                .copied()
                .filter(|&(x, y)| x.is_finite() && y.is_finite())
                .filter(|&(x, y)| (!self.log_x || x > 0.0) && (!self.log_y || y > 0.0))
                .map(|(x, y)| {
                    (
                        x.clamp(within.0 .0, within.0 .1),
                        y.clamp(within.1 .0, within.1 .1),
                    )
                })
                .collect();
            let line = rgb.stroke_width(2);
            if s.emphasis {
                chart.draw_series(DashedLineSeries::new(points.clone(), 8, 5, line))?;
            } else {
                chart.draw_series(LineSeries::new(points.clone(), line))?;
            }
            if points.len() <= MARKED_POINTS {
                chart.draw_series(points.iter().map(|&p| Circle::new(p, 3, rgb.filled())))?;
            }
            entries.push((s.name.clone(), rgb, s.emphasis));
        }
        legend(&legend_area, &entries)?;
        root.present()?;
        Ok(())
    }

    pub fn svg(&self) -> String {
        svg(|root| self.draw(root))
    }

    pub fn png(&self) -> RgbaImage {
        png(|root| self.draw(root))
    }
}

impl StackedBars {
    /// Segment names in first-seen order (one colour each).
    fn segment_names(&self) -> Vec<&str> {
        let mut names: Vec<&str> = Vec::new();
        for (_, segs) in &self.bars {
            for (n, _) in segs {
                if !names.contains(&n.as_str()) {
                    names.push(n);
                }
            }
        }
        names
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let (plot, legend_area) = frame(root, &self.title, self.segment_names().into_iter())?;
        let n = self.bars.len().max(1);
        let totals = self
            .bars
            .iter()
            .map(|b| b.1.iter().map(|s| s.1).sum::<f64>());
        let (y0, y1) = axis_range(totals, false, true);
        let mut chart = ChartBuilder::on(&plot)
            .margin(12)
            .margin_right(24)
            .x_label_area_size(48)
            .y_label_area_size(64)
            .build_cartesian_2d(0.0..n as f64, y0..y1)?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(0)
            .y_desc(self.y_label.as_str())
            .y_label_formatter(&|v| short_number(*v))
            .label_style(text_style(TEXT_PX))
            .axis_desc_style(text_style(TEXT_PX + 1.0))
            .bold_line_style(RGBColor(215, 215, 215))
            .light_line_style(RGBColor(242, 242, 242))
            .draw()?;
        let names = self.segment_names();
        for (i, (_, segs)) in self.bars.iter().enumerate() {
            let (left, right) = (i as f64 + 0.15, i as f64 + 0.85);
            let mut acc = 0.0;
            chart.draw_series(segs.iter().map(|(name, v)| {
                let c = color(names.iter().position(|m| m == name).unwrap_or(0));
                let (bottom, top) = (acc, acc + v);
                let on_axis = |y: f64| if y.is_nan() { y0 } else { y.clamp(y0, y1) };
                let r =
                    Rectangle::new([(left, on_axis(bottom)), (right, on_axis(top))], c.filled());
                acc = top;
                r
            }))?;
        }
        // Bar names under the bars, on alternating rows when they would touch.
        let style = text_style(TEXT_PX - 1.0).pos(Pos::new(HPos::Center, VPos::Top));
        let slot = {
            let (a, _) = chart.backend_coord(&(0.0, y0));
            let (b, _) = chart.backend_coord(&(1.0, y0));
            b - a
        };
        let widest = self
            .bars
            .iter()
            .map(|(label, _)| {
                root.estimate_text_size(label, &style)
                    .map_or(0, |s| s.0 as i32)
            })
            .max()
            .unwrap_or(0);
        let rows = if widest + 6 > slot { 2 } else { 1 };
        for (i, (label, _)) in self.bars.iter().enumerate() {
            let (x, y) = chart.backend_coord(&(i as f64 + 0.5, y0));
            let y = y + 6 + (i as i32 % rows) * 17;
            root.draw(&Text::new(label.clone(), (x, y), style.clone()))?;
        }
        let entries: Vec<LegendEntry> = names
            .iter()
            .enumerate()
            .map(|(i, n)| (n.to_string(), color(i), false))
            .collect();
        legend(&legend_area, &entries)?;
        root.present()?;
        Ok(())
    }

    pub fn svg(&self) -> String {
        svg(|root| self.draw(root))
    }

    pub fn png(&self) -> RgbaImage {
        png(|root| self.draw(root))
    }
}

/// Draw into an SVG document.
///
/// # Panics
/// If drawing fails, which in memory only the embedded font could make it do.
fn svg(draw: impl FnOnce(&DrawingArea<SVGBackend<'_>, Shift>) -> DrawResult) -> String {
    register_embedded_font();
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, SIZE).into_drawing_area();
        if let Err(e) = draw(&root) {
            panic!("drawing an SVG chart failed: {e}");
        }
    }
    out
}

/// Draw into an RGB pixel buffer, returned as RGBA.
///
/// # Panics
/// As [`svg`].
fn png(draw: impl FnOnce(&DrawingArea<BitMapBackend<'_>, Shift>) -> DrawResult) -> RgbaImage {
    register_embedded_font();
    let (w, h) = SIZE;
    let mut rgb = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        if let Err(e) = draw(&root) {
            panic!("drawing a PNG chart failed: {e}");
        }
    }
    let rgb = image::RgbImage::from_raw(w, h, rgb).expect("the buffer holds w x h RGB pixels");
    image::DynamicImage::ImageRgb8(rgb).into_rgba8()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chart(log_x: bool, log_y: bool) -> LineChart {
        LineChart {
            title: "Assignment time & <growth>".into(),
            x_label: "lights".into(),
            y_label: "ms".into(),
            log_x,
            log_y,
            series: vec![
                Series {
                    name: "cpu".into(),
                    points: vec![(1000.0, 2.0), (4000.0, 9.0), (16000.0, 35.0)],
                    emphasis: false,
                },
                Series {
                    name: "ideal".into(),
                    points: vec![(1000.0, 1.0), (16000.0, 0.0), (4000.0, f64::NAN)],
                    emphasis: true,
                },
                Series {
                    name: "empty".into(),
                    points: vec![],
                    emphasis: false,
                },
            ],
        }
    }

    #[test]
    fn line_charts_draw_with_every_axis_kind() {
        for (lx, ly) in [(false, false), (false, true), (true, false), (true, true)] {
            let c = chart(lx, ly);
            let svg = c.svg();
            assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
            for text in [
                "Assignment time &amp; &lt;growth&gt;",
                "lights",
                "ms",
                "cpu",
                "ideal",
            ] {
                assert!(svg.contains(text), "{text} missing from the SVG");
            }
            let png = c.png();
            assert_eq!(png.dimensions(), SIZE);
            // Text and lines are drawn: far from all white.
            let inked = png.pixels().filter(|p| p.0[0] < 128).count();
            assert!(inked > 2000, "{inked} dark pixels");
        }
    }

    #[test]
    fn stacked_bars_and_empty_charts_draw() {
        let bars = StackedBars {
            title: "passes".into(),
            y_label: "ms".into(),
            bars: vec![
                (
                    lightgrid::pipelines::ids::TILED_DEFERRED.into(),
                    vec![("gbuffer".into(), 1.0), ("shade".into(), 2.0)],
                ),
                (
                    lightgrid::pipelines::ids::DEFERRED.into(),
                    vec![("gbuffer".into(), 1.0), ("lights".into(), 4.0)],
                ),
            ],
        };
        assert!(
            bars.svg()
                .contains(lightgrid::pipelines::ids::TILED_DEFERRED)
                && bars.svg().contains("lights")
        );
        assert_eq!(bars.png().dimensions(), SIZE);
        let empty = StackedBars {
            bars: vec![],
            ..bars
        };
        assert_eq!(empty.png().dimensions(), SIZE);
        let mut c = chart(true, true);
        c.series.clear();
        assert!(c.svg().contains("</svg>"));
    }

    #[test]
    fn short_numbers() {
        assert_eq!(short_number(1200.0), "1.2k");
        assert_eq!(short_number(3e6), "3M");
        assert_eq!(short_number(0.0), "0");
        assert_eq!(short_number(0.05), "0.05");
        assert_eq!(short_number(0.1), "0.1");
        assert_eq!(short_number(0.25), "0.25");
        assert_eq!(short_number(2.5), "2.5");
        assert_eq!(short_number(100.0), "100");
    }
}
