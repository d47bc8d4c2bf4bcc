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
