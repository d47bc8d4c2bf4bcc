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
    /// Mean of the per-pixel differences over all pixels.
    pub mean: f64,
    /// 99th percentile (nearest rank) of the per-pixel differences.
    pub p99: f64,
    /// The largest per-pixel difference.
    pub max: f64,
}

/// Per difference level (0-255), how many pixels differ by exactly that much (the largest
/// colour channel's difference): the bounds on how many pixels may differ by more than a
/// level (`lightgrid diff --max-over`, the image tests) read it.
pub fn difference_histogram(a: &RgbaImage, b: &RgbaImage) -> Result<[u64; 256]> {
    check_same_size(a, b)?;
    let mut histogram = [0u64; 256];
    for (pa, pb) in a.pixels().zip(b.pixels()) {
        histogram[usize::from(pixel_difference(pa, pb))] += 1;
    }
    Ok(histogram)
}

/// The largest absolute difference of two pixels' colour channels.
fn pixel_difference(a: &image::Rgba<u8>, b: &image::Rgba<u8>) -> u8 {
    (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap_or(0)
}

fn check_same_size(a: &RgbaImage, b: &RgbaImage) -> Result<()> {
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
    Ok(())
}

/// Compare two images of the same size; returns the summary and a visual diff image
/// (difference ×8, in red, over a dimmed copy of `a`).
pub fn diff(a: &RgbaImage, b: &RgbaImage) -> Result<(DiffSummary, RgbaImage)> {
    check_same_size(a, b)?;
    let mut histogram = [0u64; 256];
    let mut sum = 0u64;
    let mut vis = RgbaImage::new(a.width(), a.height());
    for ((pa, pb), pv) in a.pixels().zip(b.pixels()).zip(vis.pixels_mut()) {
        let d = pixel_difference(pa, pb);
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
pub(crate) const MAX_DECODED_PIXELS: u64 = 8192 * 8192;

/// Largest image file [`load_image`] reads.
pub(crate) const MAX_IMAGE_FILE_BYTES: u64 = 1 << 30;

/// Read a PNG (or any format the image crate decodes) as RGBA8, refusing images larger than
/// `MAX_DECODED_PIXELS` from their header, before anything is allocated.
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
pub(crate) fn decode_image(bytes: &[u8], name: &str) -> Result<RgbaImage> {
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
/// the file is either the complete new content or untouched (see `output_target`). The
/// temporary file is removed when the write fails (a full disk) and, through
/// [`remove_temporaries`], when a signal ends the process; a file that is replaced keeps its
/// permission mode.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic_with(path, |f| std::io::Write::write_all(f, bytes))
}

/// [`write_atomic`] with the writing done by `write` (the seam a test uses to fail part-way).
fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut std::fs::File) -> std::io::Result<()>,
) -> Result<()> {
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
    // The mode of the file being replaced (a 0600 file stays private): the rename replaces the
    // inode, so the temporary file must carry it.
    let mode = std::fs::metadata(&target).ok().map(|m| m.permissions());
    let tmp = Temporary::new(dir.join(sibling_name("tmp")));
    {
        // Closed at the end of this block, before the rename or copy.
        let mut file = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(tmp.path())
            .map_err(io)?;
        write(&mut file).map_err(io)?;
        // Errors a full disk reports only when the data is flushed show here, not after the
        // rename.
        file.sync_data().map_err(io)?;
    }
    if hard_linked(&target) {
        // A rename would give this name a new inode and leave the file's other names with the
        // old bytes. The whole new content exists (and fitted on the disk) in the temporary
        // file, so the target is overwritten in place from it, keeping inode, links and mode;
        // only this step is not atomic.
        std::fs::copy(tmp.path(), &target).map_err(io)?;
        return Ok(());
    }
    if let Some(mode) = mode {
        std::fs::set_permissions(tmp.path(), mode).map_err(io)?;
    }
    std::fs::rename(tmp.path(), &target).map_err(io)?;
    tmp.keep();
    Ok(())
}

/// Does `path` name a file with more than one name (hard links)?
fn hard_linked(path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        std::fs::metadata(path).is_ok_and(|m| m.is_file() && m.nlink() > 1)
    }
    #[cfg(not(unix))]
    {
        let _ = path;
        false
    }
}

/// Temporary files and directories alive in this process, so a signal handler can remove them
/// ([`remove_temporaries`]) before the process exits.
static TEMPORARIES: std::sync::Mutex<Vec<std::path::PathBuf>> = std::sync::Mutex::new(Vec::new());

/// A temporary file or directory, listed while it lives and removed when dropped unless
/// [`Temporary::keep`] says it became (by a rename) something that stays.
pub struct Temporary {
    path: std::path::PathBuf,
    keep: bool,
}

impl Temporary {
    /// List `path` (not created here) as a temporary to remove on drop or on a signal.
    pub fn new(path: std::path::PathBuf) -> Temporary {
        lock_temporaries().push(path.clone());
        Temporary { path, keep: false }
    }

    /// The temporary's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The path was renamed into place (or moved away): nothing to remove.
    pub fn keep(mut self) {
        self.keep = true;
    }
}

impl Drop for Temporary {
    fn drop(&mut self) {
        let mut live = lock_temporaries();
        if let Some(i) = live.iter().position(|p| *p == self.path) {
            live.swap_remove(i);
        }
        if !self.keep {
            remove_path(&self.path);
        }
    }
}

fn lock_temporaries() -> std::sync::MutexGuard<'static, Vec<std::path::PathBuf>> {
    // A panic while the list was held leaves it valid (pushes and removals only).
    TEMPORARIES
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

fn remove_path(path: &Path) {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.is_dir() => drop(std::fs::remove_dir_all(path)),
        Ok(_) => drop(std::fs::remove_file(path)),
        Err(_) => {}
    }
}

/// Remove every live [`Temporary`]: for a signal handler that exits the process next, since
/// an exit runs no destructors. The list stays locked, so no new temporary is listed (and
/// left behind) between this and the exit.
pub fn remove_temporaries() -> impl Drop {
    let live = lock_temporaries();
    for p in live.iter() {
        remove_path(p);
    }
    live
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
    let probe = Temporary::new(target.with_file_name(sibling_name("probe")));
    // The error names the output the user gave, not the probe's own name.
    std::fs::write(probe.path(), b"").map_err(|cause| Error::Io {
        path: path.display().to_string(),
        cause,
    })?;
    Ok(())
}

/// What a file is, for telling whether two paths name the same file: an existing file by its
/// device and inode where the platform has them (so hard links, symlinks and `./` spellings of
/// one file are one identity), otherwise by its canonical path (symlinks followed), and a path
/// that does not exist yet by its canonical directory joined with its name. Paths whose
/// directory does not exist are kept as given (they fail the writability check).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum FileIdentity {
    /// An existing file's device and inode.
    Inode {
        /// The device (filesystem) the file lives on (`st_dev`).
        device: u64,
        /// The file's inode number on that device (`st_ino`).
        inode: u64,
    },
    /// A canonical path: of an existing file where there are no inodes, or where a new file
    /// would be created.
    Path(std::path::PathBuf),
}

/// The [`FileIdentity`] of `path`.
pub fn file_identity(path: &Path) -> FileIdentity {
    #[cfg(unix)]
    if let Ok(m) = std::fs::metadata(path) {
        use std::os::unix::fs::MetadataExt;
        return FileIdentity::Inode {
            device: m.dev(),
            inode: m.ino(),
        };
    }
    if let Ok(p) = std::fs::canonicalize(path) {
        return FileIdentity::Path(p);
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    FileIdentity::Path(match (std::fs::canonicalize(dir), path.file_name()) {
        (Ok(d), Some(name)) => d.join(name),
        _ => path.to_path_buf(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Held by each test here: `remove_temporaries` removes every live temporary of the
    /// process, those of a test writing beside it too.
    static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

    fn scratch(name: &str) -> std::path::PathBuf {
        let dir =
            std::env::temp_dir().join(format!("lightgrid-image-io-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_write_failing_part_way_leaves_the_old_file_and_no_temporary() {
        let _one = ONE_AT_A_TIME
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let dir = scratch("fail");
        let out = dir.join("out.json");
        std::fs::write(&out, b"old").unwrap();
        // As a full disk fails: after part of the bytes.
        let err = write_atomic_with(&out, |f| {
            std::io::Write::write_all(f, b"partial")?;
            Err(std::io::Error::from_raw_os_error(28))
        })
        .unwrap_err()
        .to_string();
        assert!(
            err.contains("out.json") && err.contains("No space left"),
            "{err}"
        );
        assert_eq!(std::fs::read(&out).unwrap(), b"old");
        assert_eq!(names(&dir), ["out.json"], "no temporary file left");
        assert!(
            !lock_temporaries().iter().any(|p| p.starts_with(&dir)),
            "nothing left listed"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn replacing_a_file_keeps_its_mode() {
        let _one = ONE_AT_A_TIME
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        use std::os::unix::fs::PermissionsExt;
        let dir = scratch("mode");
        let out = dir.join("private.json");
        std::fs::write(&out, b"old").unwrap();
        for mode in [0o600, 0o640, 0o755] {
            std::fs::set_permissions(&out, std::fs::Permissions::from_mode(mode)).unwrap();
            write_atomic(&out, b"new").unwrap();
            let got = std::fs::metadata(&out).unwrap().permissions().mode() & 0o777;
            assert_eq!(got, mode, "{got:o} != {mode:o}");
            assert_eq!(std::fs::read(&out).unwrap(), b"new");
        }
        assert_eq!(names(&dir), ["private.json"]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn replacing_a_hard_linked_file_keeps_its_links() {
        let _one = ONE_AT_A_TIME
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        use std::os::unix::fs::MetadataExt;
        let dir = scratch("links");
        let (out, other) = (dir.join("a.json"), dir.join("b.json"));
        std::fs::write(&out, b"old, and longer than the new").unwrap();
        std::fs::hard_link(&out, &other).unwrap();
        let inode = std::fs::metadata(&out).unwrap().ino();
        write_atomic(&out, b"new").unwrap();
        assert_eq!(std::fs::metadata(&out).unwrap().ino(), inode);
        assert_eq!(
            std::fs::read(&other).unwrap(),
            b"new",
            "the other name sees it"
        );
        assert_eq!(names(&dir), ["a.json", "b.json"], "no temporary left");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn live_temporaries_are_removed_on_request() {
        let _one = ONE_AT_A_TIME
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let dir = scratch("signal");
        let file = Temporary::new(dir.join(".lightgrid-x.tmp"));
        std::fs::write(file.path(), b"partial").unwrap();
        let sub = Temporary::new(dir.join(".lightgrid-run-x"));
        std::fs::create_dir_all(sub.path().join("inner")).unwrap();
        drop(remove_temporaries());
        assert!(names(&dir).is_empty(), "{:?}", names(&dir));
        // A kept temporary (renamed into place) is not removed on drop.
        let kept = Temporary::new(dir.join("kept"));
        std::fs::write(kept.path(), b"").unwrap();
        kept.keep();
        drop((file, sub));
        assert_eq!(names(&dir), ["kept"]);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
