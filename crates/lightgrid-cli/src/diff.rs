//! `lightgrid diff`: the per-pixel difference of two images.

use crate::args::parse_non_negative;
use crate::files::{Files, Kind};
use anyhow::{bail, Result};
use clap::Args;
use lightgrid::image_io::{diff, difference_histogram, load_image, save_png};
use std::path::PathBuf;

#[derive(Args)]
pub(crate) struct DiffArgs {
    pub(crate) a: PathBuf,
    pub(crate) b: PathBuf,
    /// Print a JSON object {"mean", "p99", "max", "alpha_max"} instead of text.
    #[arg(long)]
    pub(crate) json: bool,
    /// Exit with status 1 when the mean difference is above this (a number at least 0).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_non_negative)]
    pub(crate) max_mean: Option<f64>,
    /// Exit with status 1 when the 99th-percentile difference is above this (at least 0).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_non_negative)]
    pub(crate) max_p99: Option<f64>,
    /// Exit with status 1 when more than COUNT pixels differ by more than LEVEL levels
    /// (LEVEL:COUNT, e.g. 4:10): a region one missing light darkens can stay below the mean
    /// and the 99th percentile, never below a count.
    #[arg(long, value_name = "LEVEL:COUNT", value_parser = parse_max_over)]
    pub(crate) max_over: Option<(u8, u64)>,
    /// Write a visual diff image here (a *.png file; not one of the inputs).
    #[arg(long)]
    pub(crate) diff_image: Option<PathBuf>,
}

pub(crate) fn diff_cmd(a: &DiffArgs) -> Result<()> {
    let mut files = Files::default();
    files.input("A", &a.a)?;
    files.input("B", &a.b)?;
    files.output("--diff-image", a.diff_image.as_deref(), Kind::Png)?;
    let img_a = load_image(&a.a)?;
    let img_b = load_image(&a.b)?;
    let (d, vis) = diff(&img_a, &img_b)?;
    let over = match a.max_over {
        Some((level, _)) => Some(
            difference_histogram(&img_a, &img_b)?[usize::from(level) + 1..]
                .iter()
                .sum::<u64>(),
        ),
        None => None,
    };
    if let Some(p) = &a.diff_image {
        save_png(&vis, p)?;
    }
    // The measure is of colour (what the renderer's images differ in); alpha, which a user's
    // image may carry, is reported beside it rather than silently dropped.
    let alpha_max = img_a
        .pixels()
        .zip(img_b.pixels())
        .map(|(pa, pb)| pa[3].abs_diff(pb[3]))
        .max()
        .unwrap_or(0);
    if a.json {
        let mut v = serde_json::to_value(d)?;
        v["alpha_max"] = alpha_max.into();
        if let (Some((level, _)), Some(n)) = (a.max_over, over) {
            v["pixels_over"] = serde_json::json!({ "level": level, "count": n });
        }
        outln!("{}", serde_json::to_string(&v)?);
    } else {
        outln!(
            "mean {:.4}  p99 {}  max {}  (8-bit sRGB levels, largest colour channel per pixel)",
            d.mean,
            d.p99,
            d.max
        );
        if let (Some((level, _)), Some(n)) = (a.max_over, over) {
            outln!("{n} pixels differ by more than {level} levels");
        }
        if alpha_max == 0 {
            outln!("alpha: equal");
        } else {
            outln!("alpha: differs by up to {alpha_max} levels (not part of the measure above)");
        }
    }
    let mut broken = Vec::new();
    if let Some(m) = a.max_mean.filter(|&m| d.mean > m) {
        broken.push(format!("mean {:.4} > {m}", d.mean));
    }
    if let Some(m) = a.max_p99.filter(|&m| d.p99 > m) {
        broken.push(format!("p99 {} > {m}", d.p99));
    }
    if let (Some((level, count)), Some(n)) = (a.max_over, over) {
        if n > count {
            broken.push(format!(
                "{n} pixels differ by more than {level} levels (at most {count} allowed)"
            ));
        }
    }
    if !broken.is_empty() {
        bail!("images differ: {}", broken.join(", "));
    }
    Ok(())
}

/// `--max-over LEVEL:COUNT`: a level 0 to 254 and a pixel count.
fn parse_max_over(s: &str) -> Result<(u8, u64), String> {
    let bad =
        || format!("'{s}' is not LEVEL:COUNT (a level 0 to 254 and a pixel count, e.g. 4:10)");
    let (level, count) = s.split_once(':').ok_or_else(bad)?;
    let level: u8 = level.trim().parse().map_err(|_| bad())?;
    let count: u64 = count.trim().parse().map_err(|_| bad())?;
    if level == 255 {
        return Err(format!("'{s}': no pixel differs by more than 255 levels"));
    }
    Ok((level, count))
}
