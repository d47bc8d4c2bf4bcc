//! Small self-contained charts for the benchmark: line charts (linear or log axes) and stacked
//! bars, each rendered to SVG (text as SVG text) and to PNG (a built-in 5×7 pixel font), so
//! plots need no font files or system libraries.

use image::{Rgba, RgbaImage};
use std::fmt::Write as _;

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

const W: f64 = 960.0;
const H: f64 = 540.0;
const LEFT: f64 = 90.0;
const RIGHT: f64 = 230.0;
const TOP: f64 = 40.0;
const BOTTOM: f64 = 60.0;

const PALETTE: [[u8; 3]; 16] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
    [188, 189, 34],
    [23, 190, 207],
    [0, 0, 128],
    [128, 64, 0],
    [0, 128, 96],
    [160, 160, 255],
    [255, 200, 0],
    [90, 0, 90],
];

fn color(i: usize) -> [u8; 3] {
    PALETTE[i % PALETTE.len()]
}

/// Drawing primitives shared by the two outputs, in pixel coordinates (y down).
enum Prim {
    Line {
        a: (f64, f64),
        b: (f64, f64),
        rgb: [u8; 3],
        width: f64,
        dashed: bool,
    },
    Rect {
        x: f64,
        y: f64,
        w: f64,
        h: f64,
        rgb: [u8; 3],
    },
    Text {
        x: f64,
        y: f64,
        text: String,
        anchor_end: bool,
        bold: bool,
    },
}

/// An axis mapping values to pixels.
struct Axis {
    lo: f64,
    hi: f64,
    log: bool,
}

impl Axis {
    fn new(values: impl Iterator<Item = f64>, log: bool) -> Axis {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in values.filter(|v| v.is_finite() && (!log || *v > 0.0)) {
            lo = lo.min(v);
            hi = hi.max(v);
        }
        if !lo.is_finite() {
            (lo, hi) = (if log { 1.0 } else { 0.0 }, 1.0);
        }
        if log {
            lo = 10f64.powf(lo.log10().floor());
            hi = 10f64.powf(hi.log10().ceil().max(lo.log10() + 1.0));
        } else {
            lo = lo.min(0.0);
            if hi <= lo {
                hi = lo + 1.0;
            }
            let step = nice_step((hi - lo) / 5.0);
            hi = (hi / step).ceil() * step;
        }
        Axis { lo, hi, log }
    }

    fn frac(&self, v: f64) -> f64 {
        if self.log {
            (v.max(self.lo).log10() - self.lo.log10()) / (self.hi.log10() - self.lo.log10())
        } else {
            (v - self.lo) / (self.hi - self.lo)
        }
    }

    fn ticks(&self) -> Vec<f64> {
        if self.log {
            let (a, b) = (
                self.lo.log10().round() as i32,
                self.hi.log10().round() as i32,
            );
            (a..=b).map(|e| 10f64.powi(e)).collect()
        } else {
            let step = nice_step((self.hi - self.lo) / 5.0);
            let mut t = (self.lo / step).ceil() * step;
            let mut out = Vec::new();
            while t <= self.hi + step * 1e-9 {
                out.push(t);
                t += step;
            }
            out
        }
    }
}

fn nice_step(raw: f64) -> f64 {
    let p = 10f64.powf(raw.max(1e-12).log10().floor());
    let f = raw / p;
    p * if f <= 1.0 {
        1.0
    } else if f <= 2.0 {
        2.0
    } else if f <= 5.0 {
        5.0
    } else {
        10.0
    }
}

/// Short number for tick labels: 1200 -> "1.2k", 3e6 -> "3M".
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
        format!("{}", x.round())
    } else {
        format!("{x:.1}")
    };
    format!("{txt}{s}")
}

fn frame_prims(title: &str, y_label: &str, x_label: &str, prims: &mut Vec<Prim>) {
    prims.push(Prim::Text {
        x: W / 2.0 - (title.len() as f64) * 3.0,
        y: 22.0,
        text: title.to_string(),
        anchor_end: false,
        bold: true,
    });
    prims.push(Prim::Text {
        x: 8.0,
        y: TOP - 8.0,
        text: y_label.to_string(),
        anchor_end: false,
        bold: false,
    });
    prims.push(Prim::Text {
        x: LEFT + (W - LEFT - RIGHT) / 2.0 - x_label.len() as f64 * 3.0,
        y: H - 15.0,
        text: x_label.to_string(),
        anchor_end: false,
        bold: false,
    });
    let (x0, x1, y0, y1) = (LEFT, W - RIGHT, TOP, H - BOTTOM);
    for (a, b) in [((x0, y1), (x1, y1)), ((x0, y0), (x0, y1))] {
        prims.push(Prim::Line {
            a,
            b,
            rgb: [0, 0, 0],
            width: 1.0,
            dashed: false,
        });
    }
}

fn y_ticks(axis: &Axis, prims: &mut Vec<Prim>) {
    let (x0, x1, y0, y1) = (LEFT, W - RIGHT, TOP, H - BOTTOM);
    for t in axis.ticks() {
        let y = y1 - axis.frac(t) * (y1 - y0);
        prims.push(Prim::Line {
            a: (x0, y),
            b: (x1, y),
            rgb: [225, 225, 225],
            width: 1.0,
            dashed: false,
        });
        prims.push(Prim::Text {
            x: x0 - 6.0,
            y: y + 4.0,
            text: short_number(t),
            anchor_end: true,
            bold: false,
        });
    }
}

fn legend(entries: &[(String, [u8; 3], bool)], prims: &mut Vec<Prim>) {
    let x = W - RIGHT + 15.0;
    for (i, (name, rgb, dashed)) in entries.iter().enumerate() {
        let y = TOP + 10.0 + i as f64 * 18.0;
        prims.push(Prim::Line {
            a: (x, y),
            b: (x + 22.0, y),
            rgb: *rgb,
            width: 3.0,
            dashed: *dashed,
        });
        prims.push(Prim::Text {
            x: x + 28.0,
            y: y + 4.0,
            text: name.clone(),
            anchor_end: false,
            bold: false,
        });
    }
}

impl LineChart {
    fn prims(&self) -> Vec<Prim> {
        let mut p = Vec::new();
        frame_prims(&self.title, &self.y_label, &self.x_label, &mut p);
        let ys = Axis::new(
            self.series
                .iter()
                .flat_map(|s| s.points.iter().map(|q| q.1)),
            self.log_y,
        );
        let xs = Axis::new(
            self.series
                .iter()
                .flat_map(|s| s.points.iter().map(|q| q.0)),
            self.log_x,
        );
        y_ticks(&ys, &mut p);
        let (x0, x1, y0, y1) = (LEFT, W - RIGHT, TOP, H - BOTTOM);
        for t in xs.ticks() {
            let x = x0 + xs.frac(t) * (x1 - x0);
            p.push(Prim::Line {
                a: (x, y1),
                b: (x, y1 + 4.0),
                rgb: [0, 0, 0],
                width: 1.0,
                dashed: false,
            });
            p.push(Prim::Text {
                x: x - 6.0,
                y: y1 + 18.0,
                text: short_number(t),
                anchor_end: false,
                bold: false,
            });
        }
        let mut entries = Vec::new();
        for (i, s) in self.series.iter().enumerate() {
            let rgb = if s.emphasis { [0, 0, 0] } else { color(i) };
            let pts: Vec<(f64, f64)> = s
                .points
                .iter()
                .filter(|q| q.1.is_finite() && (!self.log_y || q.1 > 0.0))
                .filter(|q| !self.log_x || q.0 > 0.0)
                .map(|q| (x0 + xs.frac(q.0) * (x1 - x0), y1 - ys.frac(q.1) * (y1 - y0)))
                .collect();
            for w in pts.windows(2) {
                p.push(Prim::Line {
                    a: w[0],
                    b: w[1],
                    rgb,
                    width: 2.0,
                    dashed: s.emphasis,
                });
            }
            if pts.len() == 1 {
                p.push(Prim::Rect {
                    x: pts[0].0 - 2.0,
                    y: pts[0].1 - 2.0,
                    w: 4.0,
                    h: 4.0,
                    rgb,
                });
            }
            entries.push((s.name.clone(), rgb, s.emphasis));
        }
        legend(&entries, &mut p);
        p
    }

    pub fn svg(&self) -> String {
        to_svg(&self.prims())
    }

    pub fn png(&self) -> RgbaImage {
        to_png(&self.prims())
    }
}

impl StackedBars {
    fn prims(&self) -> Vec<Prim> {
        let mut p = Vec::new();
        frame_prims(&self.title, &self.y_label, "", &mut p);
        let totals = self
            .bars
            .iter()
            .map(|b| b.1.iter().map(|s| s.1).sum::<f64>());
        let ys = Axis::new(totals, false);
        y_ticks(&ys, &mut p);
        let (x0, x1, y0, y1) = (LEFT, W - RIGHT, TOP, H - BOTTOM);
        let mut names: Vec<String> = Vec::new();
        for b in &self.bars {
            for (n, _) in &b.1 {
                if !names.contains(n) {
                    names.push(n.clone());
                }
            }
        }
        let slot = (x1 - x0) / self.bars.len().max(1) as f64;
        for (i, (label, segs)) in self.bars.iter().enumerate() {
            let bx = x0 + i as f64 * slot + slot * 0.15;
            let mut acc = 0.0;
            for (n, v) in segs {
                let c = color(names.iter().position(|m| m == n).unwrap_or(0));
                let (ya, yb) = (
                    y1 - ys.frac(acc) * (y1 - y0),
                    y1 - ys.frac(acc + v) * (y1 - y0),
                );
                p.push(Prim::Rect {
                    x: bx,
                    y: yb,
                    w: slot * 0.7,
                    h: (ya - yb).max(0.0),
                    rgb: c,
                });
                acc += v;
            }
            // Bar labels alternate rows so long ids stay readable.
            let ly = y1 + 16.0 + (i % 2) as f64 * 14.0;
            p.push(Prim::Text {
                x: bx,
                y: ly,
                text: label.clone(),
                anchor_end: false,
                bold: false,
            });
        }
        let entries: Vec<_> = names
            .iter()
            .enumerate()
            .map(|(i, n)| (n.clone(), color(i), false))
            .collect();
        legend(&entries, &mut p);
        p
    }

    pub fn svg(&self) -> String {
        to_svg(&self.prims())
    }

    pub fn png(&self) -> RgbaImage {
        to_png(&self.prims())
    }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

fn to_svg(prims: &[Prim]) -> String {
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{W}\" height=\"{H}\" viewBox=\"0 0 {W} {H}\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    );
    for p in prims {
        match p {
            Prim::Line {
                a,
                b,
                rgb,
                width,
                dashed,
            } => {
                let dash = if *dashed {
                    " stroke-dasharray=\"6 4\""
                } else {
                    ""
                };
                let _ = writeln!(
                    s,
                    "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"rgb({},{},{})\" stroke-width=\"{width}\"{dash}/>",
                    a.0, a.1, b.0, b.1, rgb[0], rgb[1], rgb[2]
                );
            }
            Prim::Rect { x, y, w, h, rgb } => {
                let _ = writeln!(
                    s,
                    "<rect x=\"{x:.1}\" y=\"{y:.1}\" width=\"{w:.1}\" height=\"{h:.1}\" fill=\"rgb({},{},{})\"/>",
                    rgb[0], rgb[1], rgb[2]
                );
            }
            Prim::Text {
                x,
                y,
                text,
                anchor_end,
                bold,
            } => {
                let anchor = if *anchor_end {
                    " text-anchor=\"end\""
                } else {
                    ""
                };
                let weight = if *bold { " font-weight=\"bold\"" } else { "" };
                let _ = writeln!(
                    s,
                    "<text x=\"{x:.1}\" y=\"{y:.1}\"{anchor}{weight}>{}</text>",
                    escape(text)
                );
            }
        }
    }
    s.push_str("</svg>\n");
    s
}

/// 5×7 glyphs, one byte per row (low 5 bits, bit 4 = left column). Lower case is drawn as
/// upper case; anything else missing as a hollow box.
fn glyph(c: char) -> [u8; 7] {
    match c.to_ascii_uppercase() {
        '0' => [0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E],
        '1' => [0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E],
        '2' => [0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F],
        '3' => [0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E],
        '4' => [0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02],
        '5' => [0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E],
        '6' => [0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E],
        '7' => [0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08],
        '8' => [0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E],
        '9' => [0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C],
        'A' => [0x0E, 0x11, 0x11, 0x11, 0x1F, 0x11, 0x11],
        'B' => [0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E],
        'C' => [0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E],
        'D' => [0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C],
        'E' => [0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F],
        'F' => [0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10],
        'G' => [0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F],
        'H' => [0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11],
        'I' => [0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E],
        'J' => [0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C],
        'K' => [0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11],
        'L' => [0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F],
        'M' => [0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11],
        'N' => [0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11],
        'O' => [0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E],
        'P' => [0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10],
        'Q' => [0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D],
        'R' => [0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11],
        'S' => [0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E],
        'T' => [0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04],
        'U' => [0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E],
        'V' => [0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04],
        'W' => [0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A],
        'X' => [0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11],
        'Y' => [0x11, 0x11, 0x11, 0x0A, 0x04, 0x04, 0x04],
        'Z' => [0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F],
        ' ' => [0; 7],
        '.' => [0, 0, 0, 0, 0, 0x0C, 0x0C],
        ',' => [0, 0, 0, 0, 0x0C, 0x04, 0x08],
        ':' => [0, 0x0C, 0x0C, 0, 0x0C, 0x0C, 0],
        '-' => [0, 0, 0, 0x1F, 0, 0, 0],
        '+' => [0, 0x04, 0x04, 0x1F, 0x04, 0x04, 0],
        '/' => [0, 0x01, 0x02, 0x04, 0x08, 0x10, 0],
        '(' => [0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02],
        ')' => [0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08],
        '[' => [0x0E, 0x08, 0x08, 0x08, 0x08, 0x08, 0x0E],
        ']' => [0x0E, 0x02, 0x02, 0x02, 0x02, 0x02, 0x0E],
        '%' => [0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03],
        '_' => [0, 0, 0, 0, 0, 0, 0x1F],
        '=' => [0, 0, 0x1F, 0, 0x1F, 0, 0],
        '<' => [0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02],
        '>' => [0x08, 0x04, 0x02, 0x01, 0x02, 0x04, 0x08],
        '#' => [0x0A, 0x0A, 0x1F, 0x0A, 0x1F, 0x0A, 0x0A],
        '\'' => [0x04, 0x04, 0x08, 0, 0, 0, 0],
        '?' => [0x0E, 0x11, 0x01, 0x02, 0x04, 0, 0x04],
        '!' => [0x04, 0x04, 0x04, 0x04, 0x04, 0, 0x04],
        '*' => [0, 0x04, 0x15, 0x0E, 0x15, 0x04, 0],
        _ => [0x1F, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1F],
    }
}

/// Width in pixels of `text` in the PNG font (6 px per character).
fn text_width(text: &str) -> f64 {
    text.chars().count() as f64 * 6.0
}

fn blend(img: &mut RgbaImage, x: i64, y: i64, rgb: [u8; 3]) {
    if x >= 0 && y >= 0 && (x as u32) < img.width() && (y as u32) < img.height() {
        img.put_pixel(x as u32, y as u32, Rgba([rgb[0], rgb[1], rgb[2], 255]));
    }
}

fn draw_text(img: &mut RgbaImage, x: f64, baseline: f64, text: &str, bold: bool) {
    let (x0, y0) = (x.round() as i64, baseline.round() as i64 - 7);
    for (i, c) in text.chars().enumerate() {
        for (row, bits) in glyph(c).iter().enumerate() {
            for col in 0..5 {
                if bits & (0x10 >> col) != 0 {
                    let px = x0 + i as i64 * 6 + col;
                    blend(img, px, y0 + row as i64, [0, 0, 0]);
                    if bold {
                        blend(img, px + 1, y0 + row as i64, [0, 0, 0]);
                    }
                }
            }
        }
    }
}

fn draw_line(
    img: &mut RgbaImage,
    a: (f64, f64),
    b: (f64, f64),
    rgb: [u8; 3],
    width: f64,
    dashed: bool,
) {
    let len = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
    let steps = (len.ceil() as usize).max(1);
    let r = (width / 2.0).floor() as i64;
    for i in 0..=steps {
        if dashed && (i / 6) % 2 == 1 {
            continue;
        }
        let t = i as f64 / steps as f64;
        let (x, y) = (
            (a.0 + (b.0 - a.0) * t).round() as i64,
            (a.1 + (b.1 - a.1) * t).round() as i64,
        );
        for dy in -r..=r.max(0) {
            for dx in -r..=r.max(0) {
                blend(img, x + dx, y + dy, rgb);
            }
        }
    }
}

fn to_png(prims: &[Prim]) -> RgbaImage {
    let mut img = RgbaImage::from_pixel(W as u32, H as u32, Rgba([255, 255, 255, 255]));
    for p in prims {
        match p {
            Prim::Line {
                a,
                b,
                rgb,
                width,
                dashed,
            } => draw_line(&mut img, *a, *b, *rgb, *width, *dashed),
            Prim::Rect { x, y, w, h, rgb } => {
                for py in y.round() as i64..(y + h).round() as i64 {
                    for px in x.round() as i64..(x + w).round() as i64 {
                        blend(&mut img, px, py, *rgb);
                    }
                }
            }
            Prim::Text {
                x,
                y,
                text,
                anchor_end,
                bold,
            } => {
                let x = if *anchor_end {
                    x - text_width(text)
                } else {
                    *x
                };
                draw_text(&mut img, x, *y, text, *bold);
            }
        }
    }
    img
}
