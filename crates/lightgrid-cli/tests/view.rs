//! `lightgrid view` as a user runs it, in a real window on a virtual X display (Xvfb, which
//! CI installs): scripted sessions switch pipelines, resize the window and toggle the debug
//! views, and their screenshots must equal the headless renders of the same views. A test
//! here fails (never passes) when the window cannot be made: Xvfb missing, no adapter able
//! to present, or the viewer refusing to start.

/// The library's test helpers (GPU context, the missing-light cases and the shading reference).
#[path = "../../lightgrid/tests/common/mod.rs"]
mod common;
mod support;

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::Duration;
use support::{assert_fails_with, lightgrid, stderr, temp_dir};

/// A virtual X server on a display number it chose itself (`-displayfd`), so tests can run
/// side by side and never use the developer's own display.
struct Xvfb {
    child: Child,
    display: String,
}

impl Xvfb {
    fn start() -> Xvfb {
        let mut child = Command::new("Xvfb")
            .args([
                "-displayfd",
                "1",
                "-screen",
                "0",
                "1280x1024x24",
                "-nolisten",
                "tcp",
            ])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .unwrap_or_else(|e| {
                panic!(
                    "the viewer tests need Xvfb (`apt-get install xvfb`; .ci/run installs it): {e}"
                )
            });
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .expect("Xvfb prints its display number");
        let n: u32 = line
            .trim()
            .parse()
            .unwrap_or_else(|_| panic!("Xvfb gave no display number: {line:?}"));
        Xvfb {
            child,
            display: format!(":{n}"),
        }
    }

    /// Run `lightgrid` on this display; panics when it is still running after `limit`.
    fn run(&self, args: &[&str], limit: Duration) -> (Option<i32>, String) {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_lightgrid"));
        cmd.args(args)
            .env("DISPLAY", &self.display)
            .env_remove("WAYLAND_DISPLAY");
        support::run_limited(cmd, limit)
            .unwrap_or_else(|err| panic!("{args:?} still running after {limit:?}:\n{err}"))
    }

    fn run_ok(&self, args: &[&str]) -> String {
        let (code, err) = self.run(args, Duration::from_secs(600));
        assert_eq!(code, Some(0), "{args:?} failed:\n{err}");
        assert!(!err.contains("panicked"), "{args:?}:\n{err}");
        assert!(!err.contains("uncaptured GPU error"), "{args:?}:\n{err}");
        err
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn load(path: &Path) -> image::RgbaImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgba8()
}

/// Largest channel difference per pixel: (mean, max) in 8-bit levels.
fn difference(a: &image::RgbaImage, b: &image::RgbaImage) -> (f64, u8) {
    assert_eq!(a.dimensions(), b.dimensions(), "image sizes differ");
    let mut sum = 0u64;
    let mut max = 0u8;
    for (p, q) in a.pixels().zip(b.pixels()) {
        let d = (0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap();
        sum += u64::from(d);
        max = max.max(d);
    }
    (sum as f64 / f64::from(a.width() * a.height()), max)
}

fn render(args: &[&str]) {
    let o = lightgrid(args);
    assert!(o.status.success(), "{args:?}:\n{}", stderr(&o));
}

/// The session: start on one pipeline, switch, resize to a size that is no multiple
/// of the tile, show each debug view, back to shaded, hide the panel, leave with a
/// screenshot. Every screenshot equals the headless render of its view.
#[test]
fn a_scripted_session_shows_what_the_headless_renderer_renders() {
    let x = Xvfb::start();
    let dir = temp_dir("view-session");
    let shot = dir.join("shot.png");
    let views = ["lights", "bounds", "wasted"];
    let mut script =
        String::from("frame 40; pause; at 2 pipeline tiled_deferred; at 4 resize 300x200");
    for (i, v) in views.iter().enumerate() {
        let at = 6 + 2 * i;
        script += &format!(
            "; at {at} view {v}; at {} screenshot {}",
            at + 1,
            dir.join(format!("window-{v}.png")).display()
        );
    }
    script += "; at 12 view shaded; at 14 panel off";
    let err = x.run_ok(&[
        "view",
        "--scene",
        "robots-many",
        "--pipeline",
        "clustered_forward",
        "--size",
        "320x240",
        "--script",
        &script,
        "--exit-after-frames",
        "16",
        "--screenshot",
        shot.to_str().unwrap(),
    ]);
    assert!(err.contains("4 screenshot(s) written"), "{err}");
    assert!(err.contains(", 0 had shader loops cut short"), "{err}");
    assert!(err.contains("0 overflowed their lists"), "{err}");

    let headless = |view: &str, extra: &[&str]| {
        let out = dir.join(format!("render-{view}.png"));
        let mut args = vec![
            "render",
            "--scene",
            "robots-many",
            "--pipeline",
            "tiled_deferred",
            "--frame",
            "40",
            "--size",
            "300x200",
            "--view",
            view,
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        render(&args);
        load(&out)
    };
    let heatmap = dir.join("heatmap.png");
    let reference = headless("shaded", &["--heatmap", heatmap.to_str().unwrap()]);
    let shot = load(&shot);
    assert_eq!(
        shot.dimensions(),
        (300, 200),
        "the window's resize did not reach the frame"
    );
    // Tolerance: the blit decodes and re-encodes sRGB in floating point (one level at most);
    // the frame itself is the same pipeline, frame and size.
    let (mean, max) = difference(&shot, &reference);
    assert!(
        max <= 2 && mean < 0.05,
        "screenshot vs render: mean {mean}, max {max}"
    );
    for v in views {
        let window = load(&dir.join(format!("window-{v}.png")));
        let (mean, max) = difference(&window, &headless(v, &[]));
        assert!(
            max <= 2 && mean < 0.05,
            "{v}: window vs render --view: mean {mean}, max {max}"
        );
        let (mean, _) = difference(&window, &shot);
        assert!(
            mean > 5.0,
            "the {v} view looks like the shaded frame (mean {mean})"
        );
    }
    // The lights-per-cell view is the heatmap `render --heatmap` draws, without its legend.
    let lights = load(&dir.join("window-lights.png"));
    let heatmap = image::imageops::crop_imm(&load(&heatmap), 0, 0, 300, 200).to_image();
    let (mean, max) = difference(&lights, &heatmap);
    assert!(
        max <= 2 && mean < 0.05,
        "lights view vs heatmap: mean {mean}, max {max}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The flip-through's bound on a screenshot against its reference's: tests/pipelines.rs's
/// widest (the G-buffer's 16-bit rounding and the light-volume meshes' tessellation: mean 0.5,
/// p99 2, at most 5 pixels over 4 levels; measured 0 over 1 level); a missing light, even a
/// dim one, breaks the count (`a_dim_or_distant_missing_light_fails_the_flip_tolerance`).
const FLIP_TOLERANCE: common::ImageTolerance = common::ImageTolerance {
    max_mean: 0.5,
    max_p99: 2.0,
    level: 4,
    max_over: 5,
    fine: None,
};

/// The flip-through's bound catches one dim or distant missing light on its own frame
/// (robots-few, frame 120, 203x117): `forward` with the light against `forward` without.
#[test]
fn a_dim_or_distant_missing_light_fails_the_flip_tolerance() {
    use lightgrid::scene::catalog::{self, SceneParams};
    let ctx = common::gpu();
    let s = catalog::build("robots-few", &SceneParams::default()).unwrap();
    let (size, frame) = ((203, 117), 120);
    let settings = lightgrid::RenderSettings {
        grid: lightgrid::CullConfig {
            tile_size: 12,
            ..lightgrid::CullConfig::default()
        },
        ..Default::default()
    };
    let mut r = lightgrid::Renderer::new(&ctx, size.0, size.1, settings).unwrap();
    let unlit = r.render(&s, frame, "forward").unwrap().image;
    for case in common::MissingLight::ALL {
        let with = common::with_missing_light(&s, frame, size, case);
        let lit = r.render(&with, frame, "forward").unwrap().image;
        let grid = r.render(&with, frame, "tiled_deferred").unwrap().image;
        common::assert_missing_light_fails(
            "view flip-through",
            case,
            FLIP_TOLERANCE,
            [&lit, &grid, &unlit],
            None,
        );
    }
}

/// Every pipeline the registry has, flipped through live in one window at 1x, shows the
/// image its reference renders (`forward`, or the one with the same approximations).
#[test]
fn flipping_through_every_pipeline_keeps_the_image() {
    let x = Xvfb::start();
    let dir = temp_dir("view-flip");
    let ids: Vec<&str> = lightgrid::pipelines::PIPELINES
        .iter()
        .map(|p| p.id)
        .collect();
    let mut script = String::from("frame 120; pause");
    for (i, id) in ids.iter().enumerate() {
        let at = 1 + 2 * i;
        script += &format!(
            "; at {at} pipeline {id}; at {} screenshot {}",
            at + 1,
            dir.join(format!("{id}.png")).display()
        );
    }
    let frames = (2 * ids.len() + 2).to_string();
    let err = x.run_ok(&[
        "view",
        "--scene",
        "robots-few",
        "--size",
        "203x117",
        "--tile",
        "12",
        "--script",
        &script,
        "--exit-after-frames",
        &frames,
    ]);
    for p in lightgrid::pipelines::PIPELINES {
        // The viewer says what each screenshot showed: the switch happened.
        let said = format!(
            "screenshot {} ({}, frame 120, shaded, (203, 117))",
            dir.join(format!("{}.png", p.id)).display(),
            p.id
        );
        assert!(err.contains(&said), "missing '{said}' in:\n{err}");
        let reference = load(&dir.join(format!("{}.png", p.reference)));
        assert_eq!(reference.dimensions(), (203, 117));
        let id = p.id;
        let cmp = common::compare_images(
            &reference,
            &load(&dir.join(format!("{id}.png"))),
            FLIP_TOLERANCE,
        );
        eprintln!("{id} vs {}: {}", p.reference, cmp.describe());
        assert!(cmp.passes(), "{id} vs {}: {}", p.reference, cmp.describe());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The scene's options changed live reopen the scene, and the BRDF and the shadows a new
/// renderer: the frame equals a headless render made with those options from the start.
#[test]
fn scene_options_changed_live_equal_a_render_with_them() {
    let x = Xvfb::start();
    let dir = temp_dir("view-scene");
    let shot = dir.join("shot.png");
    x.run_ok(&[
        "view",
        "--scene",
        "robots-few",
        "--size",
        "200x120",
        "--frame",
        "30",
        "--paused",
        "--script",
        "at 1 add-lights 200; at 2 spots 0.5; at 3 transparency off; at 4 pipeline clustered_forward; at 5 brdf ggx; at 6 shadows maps",
        "--exit-after-frames",
        "8",
        "--screenshot",
        shot.to_str().unwrap(),
    ]);
    let reference = dir.join("reference.png");
    let before = dir.join("before.png");
    let common = [
        "render",
        "--scene",
        "robots-few",
        "--size",
        "200x120",
        "--frame",
        "30",
        "--pipeline",
        "clustered_forward",
    ];
    let mut with = common.to_vec();
    with.extend([
        "--add-lights",
        "200",
        "--spot-fraction",
        "0.5",
        "--transparency",
        "off",
        "--brdf",
        "ggx",
        "--shadows",
        "maps",
        "--out",
        reference.to_str().unwrap(),
    ]);
    render(&with);
    let mut without = common.to_vec();
    without.extend(["--out", before.to_str().unwrap()]);
    render(&without);
    let shot = load(&shot);
    let (mean, max) = difference(&shot, &load(&reference));
    assert!(
        max <= 2 && mean < 0.05,
        "screenshot vs render: mean {mean}, max {max}"
    );
    let (mean, _) = difference(&shot, &load(&before));
    assert!(mean > 1.0, "the options changed nothing (mean {mean})");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A failing step of a script ends the session with its reason, and nothing is written.
#[test]
fn a_script_step_that_cannot_run_fails_the_session() {
    let x = Xvfb::start();
    let dir = temp_dir("view-refused");
    let shot = dir.join("never.png");
    let (code, err) = x.run(
        &[
            "view",
            "--scene",
            "robots-few",
            "--size",
            "96x64",
            "--pipeline",
            "tiled_deferred",
            "--script",
            "pause; at 1 msaa 8",
            "--exit-after-frames",
            "4",
            "--screenshot",
            shot.to_str().unwrap(),
        ],
        Duration::from_secs(300),
    );
    assert_eq!(code, Some(1), "{err}");
    // lavapipe offers 1x and 4x only.
    assert!(err.contains("for every target"), "{err}");
    assert!(!shot.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// No display: a clear error and a non-zero exit, never a pass.
#[test]
fn without_a_display_the_viewer_says_so() {
    let o = Command::new(env!("CARGO_BIN_EXE_lightgrid"))
        .args(["view", "--scene", "robots-few", "--exit-after-frames", "1"])
        .env("DISPLAY", ":4095")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(err.contains("cannot open a window"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

/// What the command line can refuse before a window opens.
#[test]
fn bad_view_options_are_refused_before_a_window_opens() {
    let dir = temp_dir("view-bad");
    let d = dir.to_str().unwrap();
    let shot = format!("{d}/a.png");
    assert_fails_with(&["view", "--screenshot", &shot], "--exit-after-frames");
    for n in ["0", "-1", "1001", "NaN", "abc"] {
        assert_fails_with(&["view", "--exit-after-frames", n], "--exit-after-frames");
    }
    assert_fails_with(
        &["view", "--exit-after-frames", "1", "--screenshot", d],
        "--screenshot",
    );
    assert_fails_with(
        &[
            "view",
            "--exit-after-frames",
            "1",
            "--screenshot",
            &format!("{d}/a.jpg"),
        ],
        ".png",
    );
    assert_fails_with(
        &[
            "view",
            "--exit-after-frames",
            "1",
            "--screenshot",
            "/dev/null",
        ],
        "--screenshot",
    );
    let twice = format!("at 1 screenshot {shot}; at 2 screenshot {shot}");
    assert_fails_with(&["view", "--script", &twice], "both name");
    assert_fails_with(
        &[
            "view",
            "--script",
            &format!("at 1 screenshot {shot}"),
            "--exit-after-frames",
            "2",
            "--screenshot",
            &shot,
        ],
        "both name",
    );
    for (script, needle) in [
        ("tile 3", "tile"),
        ("tile 65", "tile"),
        ("msaa 3", "msaa"),
        ("pipeline nope", "nope"),
        ("resize 0x10", "both edges must be 1 to 4096"),
        ("resize 16384x16384", "both edges must be 1 to 4096"),
        ("at -1 pause", "not a whole number"),
        ("view sideways", "view is one of"),
        ("fly away", "unknown action"),
        ("spots 2", "from 0 to 1"),
        ("transparency maybe", "on or off"),
    ] {
        assert_fails_with(&["view", "--script", script], needle);
    }
    assert_fails_with(&["view", "--view", "sideways"], "--view");
    assert_fails_with(&["view", "--size", "0x10"], "--size");
    assert_fails_with(&["view", "--frame", "100000"], "past the end");
    assert!(
        std::fs::read_dir(&dir).unwrap().next().is_none(),
        "nothing is written"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Steps due at one frame run together: 10,000 of them over frames 0-4 end in a handful of
/// frames (one step per frame would show 10,000), and a step past the bound is refused.
#[test]
fn steps_at_one_frame_run_together_and_script_frames_are_bounded() {
    assert_fails_with(
        &["view", "--script", "at 4294967295 pause"],
        "at most 'at 1000'",
    );
    let x = Xvfb::start();
    let script: Vec<String> = (0..10_000)
        .map(|i| {
            let action = if i % 2 == 0 { "pause" } else { "play" };
            format!("at {} {action}", i % 5)
        })
        .collect();
    let script = script.join("; ");
    let err = x.run_ok(&[
        "view",
        "--scene",
        "robots-few",
        "--size",
        "64x36",
        "--script",
        &script,
        "--exit-after-frames",
        "6",
    ]);
    let frames: u64 = err
        .lines()
        .find_map(|l| {
            l.split(" frames shown")
                .next()
                .filter(|_| l.contains(" frames shown"))
        })
        .and_then(|n| n.trim().parse().ok())
        .unwrap_or_else(|| panic!("no frame count in:\n{err}"));
    assert!(frames < 100, "{frames} frames for 10,000 steps:\n{err}");
}

/// The X server going away mid-session ends the viewer with "display lost" and exit 1, not
/// a panic inside winit.
#[test]
fn a_lost_display_ends_the_viewer_with_a_message() {
    let mut x = Xvfb::start();
    let dir = temp_dir("view-display-lost");
    let shot = dir.join("shown.png");
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_lightgrid"));
    cmd.args([
        "view",
        "--scene",
        "robots-few",
        "--size",
        "64x36",
        "--script",
        &format!("at 1 screenshot {}", shot.display()),
    ])
    .env("DISPLAY", &x.display)
    .env_remove("WAYLAND_DISPLAY");
    let viewer = std::thread::spawn(move || support::run_limited(cmd, Duration::from_secs(300)));
    // Once it has shown frames (its screenshot is written), the display goes.
    let start = std::time::Instant::now();
    while !shot.exists() {
        assert!(
            start.elapsed() < Duration::from_secs(240),
            "the viewer showed no frame"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    std::thread::sleep(Duration::from_millis(500));
    x.child.kill().unwrap();
    x.child.wait().unwrap();
    let (code, err) = viewer
        .join()
        .unwrap()
        .unwrap_or_else(|err| panic!("the viewer kept running without its display:\n{err}"));
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("display lost"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}
