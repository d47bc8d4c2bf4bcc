//! The image difference measure and atomic PNG writing.

use image::{Rgba, RgbaImage};
use lightgrid::image_io::{check_writable, diff, load_image, save_png};

#[test]
fn identical_images_differ_by_nothing() {
    let a = RgbaImage::from_pixel(10, 10, Rgba([10, 20, 30, 255]));
    let (d, _) = diff(&a, &a).unwrap();
    assert_eq!((d.mean, d.p99, d.max), (0.0, 0.0, 0.0));
}

#[test]
fn difference_is_largest_channel_with_mean_p99_max() {
    let a = RgbaImage::from_pixel(10, 10, Rgba([100, 100, 100, 255]));
    let mut b = a.clone();
    // One pixel off by 50 in green (and 3 in red): per-pixel difference 50.
    b.put_pixel(3, 4, Rgba([103, 150, 100, 255]));
    let (d, _) = diff(&a, &b).unwrap();
    assert_eq!(d.max, 50.0);
    assert!((d.mean - 0.5).abs() < 1e-9);
    assert_eq!(
        d.p99, 0.0,
        "1 pixel in 100 sits exactly at the 99th percentile boundary"
    );
    // Two pixels off: the 99th percentile now sees one of them.
    b.put_pixel(0, 0, Rgba([100, 100, 120, 255]));
    let (d, _) = diff(&a, &b).unwrap();
    assert_eq!(d.p99, 20.0);
}

#[test]
fn size_mismatch_is_an_error() {
    let a = RgbaImage::new(4, 4);
    let b = RgbaImage::new(4, 5);
    assert!(diff(&a, &b).is_err());
}

#[test]
fn png_round_trips_and_unwritable_paths_fail_early() {
    let dir = std::env::temp_dir().join(format!("lightgrid-diff-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let img = RgbaImage::from_fn(7, 5, |x, y| Rgba([x as u8 * 30, y as u8 * 40, 7, 255]));
    let path = dir.join("a.png");
    save_png(&img, &path).unwrap();
    assert_eq!(load_image(&path).unwrap(), img);
    assert!(check_writable(&dir.join("no/such/dir/x.png")).is_err());
    assert!(check_writable(&dir).is_err(), "a directory is not a file");
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .collect();
    assert_eq!(leftovers.len(), 1, "no temporary files left behind");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A PNG of only a header declaring `w` x `h` (and an empty image stream): what a hostile or
/// truncated file looks like to the decoder.
fn png_header_only(w: u32, h: u32) -> Vec<u8> {
    fn crc32(bytes: &[u8]) -> u32 {
        let mut c = !0u32;
        for &b in bytes {
            c ^= u32::from(b);
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xEDB8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }
    let chunk = |kind: &[u8; 4], data: &[u8]| {
        let mut out = (data.len() as u32).to_be_bytes().to_vec();
        let mut body = kind.to_vec();
        body.extend_from_slice(data);
        out.extend_from_slice(&body);
        out.extend_from_slice(&crc32(&body).to_be_bytes());
        out
    };
    let mut ihdr = w.to_be_bytes().to_vec();
    ihdr.extend_from_slice(&h.to_be_bytes());
    ihdr.extend_from_slice(&[8, 6, 0, 0, 0]); // 8-bit RGBA
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend(chunk(b"IHDR", &ihdr));
    png.extend(chunk(b"IEND", &[]));
    png
}

#[test]
fn images_declaring_absurd_sizes_are_refused_from_their_header() {
    let dir = std::env::temp_dir().join(format!("lightgrid-decode-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (w, h) in [(30_000, 30_000), (16_000, 16_000), (100_000, 1)] {
        let path = dir.join(format!("{w}x{h}.png"));
        std::fs::write(&path, png_header_only(w, h)).unwrap();
        let err = load_image(&path).unwrap_err().to_string();
        assert!(
            err.contains(&format!("{w}x{h}")) && err.contains(path.to_str().unwrap()),
            "{err}"
        );
    }
    // A header within the limits but without pixel data is a decode error, not a panic.
    let path = dir.join("empty.png");
    std::fs::write(&path, png_header_only(64, 64)).unwrap();
    assert!(load_image(&path).is_err());
    // A real image of that size loads.
    let path = dir.join("ok.png");
    save_png(&RgbaImage::from_pixel(64, 64, Rgba([1, 2, 3, 255])), &path).unwrap();
    assert_eq!(load_image(&path).unwrap().dimensions(), (64, 64));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Outputs are replaced whole by a rename: that must never replace a FIFO or a device (run as
/// root, `--stats /dev/null` would have replaced /dev/null), and a symlink is written through.
#[test]
fn outputs_refuse_non_regular_files_and_write_through_symlinks() {
    use lightgrid::image_io::write_atomic;
    let dir = std::env::temp_dir().join(format!("lightgrid-outputs-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = dir.join("fifo");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    for result in [check_writable(&fifo), write_atomic(&fifo, b"x")] {
        let err = result.unwrap_err().to_string();
        assert!(err.contains("not a regular file"), "{err}");
    }
    let meta = std::fs::symlink_metadata(&fifo).unwrap();
    assert!(!meta.is_file(), "the FIFO is still a FIFO");
    for result in [check_writable(&dir), write_atomic(&dir, b"x")] {
        assert!(result.unwrap_err().to_string().contains("is a directory"));
    }
    let target = dir.join("target.json");
    std::fs::write(&target, b"old").unwrap();
    let link = dir.join("link.json");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    check_writable(&link).unwrap();
    write_atomic(&link, b"new").unwrap();
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(std::fs::read(&target).unwrap(), b"new");
    // An I/O error names the path and says its cause once.
    let missing = dir.join("no/such/dir/out.json");
    let err = check_writable(&missing).unwrap_err().to_string();
    assert_eq!(err.matches("No such file or directory").count(), 1, "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}
