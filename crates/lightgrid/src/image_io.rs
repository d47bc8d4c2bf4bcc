//! Images: PNG files written whole or not at all, and the per-pixel difference measure used by
//! `lightgrid diff` and the image tests.

use crate::error::{Error, Result};
use image::RgbaImage;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Per-pixel difference summary, in 8-bit sRGB levels (0-255). A pixel's difference is the
/// largest absolute difference of its three colour channels.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DiffSummary {
    pub mean: f64,
    /// 99th percentile (nearest rank) of the per-pixel differences.
    pub p99: f64,
    pub max: f64,
}

/// Compare two images of the same size; returns the summary and a visual diff image
/// (difference ×8, in red, over a dimmed copy of `a`).
pub fn diff(a: &RgbaImage, b: &RgbaImage) -> Result<(DiffSummary, RgbaImage)> {
    if a.dimensions() != b.dimensions() {
        return Err(Error::invalid(
            "images",
            format!(
                "sizes differ: {}x{} vs {}x{}",
                a.width(),
                a.height(),
                b.width(),
                b.height()
            ),
        ));
    }
    let mut histogram = [0u64; 256];
    let mut sum = 0u64;
    let mut vis = RgbaImage::new(a.width(), a.height());
    for ((pa, pb), pv) in a.pixels().zip(b.pixels()).zip(vis.pixels_mut()) {
        let d = (0..3).map(|c| pa[c].abs_diff(pb[c])).max().unwrap_or(0);
        histogram[d as usize] += 1;
        sum += u64::from(d);
        let luma = ((u32::from(pa[0]) + u32::from(pa[1]) + u32::from(pa[2])) / 12) as u8;
        let red = (u32::from(d) * 8).min(255) as u8;
        *pv = image::Rgba([red.max(luma), luma, luma, 255]);
    }
    let n = u64::from(a.width()) * u64::from(a.height());
    let rank = ((n as f64) * 0.99).ceil().max(1.0) as u64;
    let mut seen = 0;
    let mut p99 = 0;
    for (level, count) in histogram.iter().enumerate() {
        seen += count;
        if seen >= rank {
            p99 = level;
            break;
        }
    }
    let max = histogram.iter().rposition(|&c| c > 0).unwrap_or(0);
    Ok((
        DiffSummary {
            mean: sum as f64 / n.max(1) as f64,
            p99: p99 as f64,
            max: max as f64,
        },
        vis,
    ))
}

/// Most pixels [`load_image`] decodes: 8192 x 8192 (256 MiB as RGBA8), so comparing two images
/// stays far below a gigabyte whatever their headers declare.
pub const MAX_DECODED_PIXELS: u64 = 8192 * 8192;

/// Largest image file [`load_image`] reads.
pub const MAX_IMAGE_FILE_BYTES: u64 = 1 << 30;

/// Read a PNG (or any format the image crate decodes) as RGBA8, refusing images larger than
/// [`MAX_DECODED_PIXELS`] from their header, before anything is allocated.
pub fn load_image(path: &Path) -> Result<RgbaImage> {
    let io = |cause| Error::Io {
        path: path.display().to_string(),
        cause,
    };
    // Read whole, so only regular files of a bounded size (never a device or a FIFO).
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() || meta.len() > MAX_IMAGE_FILE_BYTES {
        return Err(Error::Image {
            path: path.display().to_string(),
            reason: format!(
                "not a regular image file of at most {} MiB",
                MAX_IMAGE_FILE_BYTES >> 20
            ),
        });
    }
    let bytes = std::fs::read(path).map_err(io)?;
    decode_image(&bytes, &path.display().to_string())
}

/// Decode image bytes (PNG, JPEG) as RGBA8 with [`load_image`]'s limits; errors name `name`.
pub fn decode_image(bytes: &[u8], name: &str) -> Result<RgbaImage> {
    let bad = |reason: String| Error::Image {
        path: name.to_string(),
        reason,
    };
    let reader = || {
        image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| bad(e.to_string()))
    };
    // A file's header decides how much a decoder allocates: refuse what no comparison here
    // needs before decoding (MAX_DECODED_PIXELS, RGBA8 plus the decoder's own copy).
    let edge = crate::consts::MAX_FRAME_EDGE;
    let (w, h) = reader()?
        .into_dimensions()
        .map_err(|e| bad(e.to_string()))?;
    if w > edge || h > edge || u64::from(w) * u64::from(h) > MAX_DECODED_PIXELS {
        return Err(bad(format!(
            "declares {w}x{h} pixels; images of at most {edge} pixels per edge and {} million pixels are read",
            MAX_DECODED_PIXELS / 1_000_000
        )));
    }
    let mut reader = reader()?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(edge);
    limits.max_image_height = Some(edge);
    limits.max_alloc = Some(2 * 4 * MAX_DECODED_PIXELS);
    reader.limits(limits);
    let img = reader.decode().map_err(|e| bad(e.to_string()))?;
    Ok(img.to_rgba8())
}

/// Where an output named `path` is written: through a symlink to its target, never over a
/// directory or a file that is not a regular one (a device, FIFO or socket), since outputs
/// are replaced whole by a rename and that would replace the device itself.
fn output_target(path: &Path) -> Result<std::path::PathBuf> {
    let refuse = |what: &str| {
        Err(Error::invalid(
            "output path",
            format!("{} is {what}; name a regular file", path.display()),
        ))
    };
    match std::fs::metadata(path) {
        Ok(m) if m.is_dir() => refuse("a directory"),
        Ok(m) if !m.is_file() => refuse("not a regular file (a device, FIFO or socket)"),
        Ok(_) => std::fs::canonicalize(path).map_err(|cause| Error::Io {
            path: path.display().to_string(),
            cause,
        }),
        Err(_) => Ok(path.to_path_buf()),
    }
}

/// Write `bytes` to `path` through a temporary file in the same directory and a rename, so
/// the file is either the complete new content or untouched (see [`output_target`]).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let target = output_target(path)?;
    let io = |cause| Error::Io {
        path: path.display().to_string(),
        cause,
    };
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    if target.file_name().is_none() {
        return Err(Error::invalid(
            "output path",
            format!("{} has no file name", path.display()),
        ));
    }
    let tmp = dir.join(sibling_name("tmp"));
    std::fs::write(&tmp, bytes).map_err(io)?;
    std::fs::rename(&tmp, &target).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        io(e)
    })
}

/// A temporary file name beside an output, short whatever the output's name (a name of 255
/// bytes is valid, and `.NAME.tmp` beside it would not be) and unique within this process.
fn sibling_name(kind: &str) -> String {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    format!(".lightgrid-{}-{n}.{kind}", std::process::id())
}

/// Refuse an image output whose name does not end in `.png` (any case): PNG bytes under a
/// `.jpg` name would be read as something they are not.
pub fn check_png_name(path: &Path) -> Result<()> {
    let png = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if png {
        Ok(())
    } else {
        Err(Error::invalid(
            "output path",
            format!(
                "{}: images are written as PNG; name the file *.png",
                path.display()
            ),
        ))
    }
}

/// The PNG bytes of `img`, to be written to `path` (whose name must end in `.png`,
/// [`check_png_name`]).
pub fn encode_png(img: &RgbaImage, path: &Path) -> Result<Vec<u8>> {
    check_png_name(path)?;
    let mut bytes = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .map_err(|e| Error::Image {
        path: path.display().to_string(),
        reason: e.to_string(),
    })?;
    Ok(bytes)
}

/// Encode as PNG and write atomically ([`encode_png`], [`write_atomic`]).
pub fn save_png(img: &RgbaImage, path: &Path) -> Result<()> {
    write_atomic(path, &encode_png(img, path)?)
}

/// Fail early (before rendering) when `path` cannot be written: its directory must exist and
/// accept a new file, and the path must not be a directory or another non-regular file.
pub fn check_writable(path: &Path) -> Result<()> {
    let target = output_target(path)?;
    let probe = target.with_file_name(sibling_name("probe"));
    std::fs::write(&probe, b"").map_err(|cause| Error::Io {
        path: path.display().to_string(),
        cause,
    })?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// What a path names, for telling whether two arguments name the same file: the canonical path
/// of an existing file (symlinks followed), else its canonical directory joined with its name.
/// Paths whose directory does not exist are returned as given (they fail the writability check).
pub fn file_identity(path: &Path) -> std::path::PathBuf {
    if let Ok(p) = std::fs::canonicalize(path) {
        return p;
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    match (std::fs::canonicalize(dir), path.file_name()) {
        (Ok(d), Some(name)) => d.join(name),
        _ => path.to_path_buf(),
    }
}
