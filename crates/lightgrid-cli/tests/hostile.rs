//! Hostile and careless input, one test per class (README "What bad input gets"): outputs
//! that would destroy something, long runs that end badly, options out of range or beside
//! the point. Each test checks what happens to the files as well as the exit status.

mod support;

use std::path::Path;
use support::{assert_fails_with, lightgrid, stderr, temp_dir};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn json(p: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display())))
        .unwrap()
}

/// A tiny, fast render command (robots-few at 16x8).
fn render(extra: &[&str]) -> Vec<String> {
    let mut v: Vec<String> = [
        "render",
        "--scene",
        "robots-few",
        "--size",
        "16x8",
        "--warmup",
        "0",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    v.extend(extra.iter().map(|s| s.to_string()));
    v
}

fn run(args: &[String]) -> std::process::Output {
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    lightgrid(&refs)
}

fn fails_with(args: &[String], needle: &str) {
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    assert_fails_with(&refs, needle);
}

/// Every case fails with its message, and `dir` (named by the cases' outputs) stays empty.
fn all_refused_leaving_nothing(dir: &Path, cases: &[(&[&str], &str)]) {
    for (args, needle) in cases {
        assert_fails_with(args, needle);
    }
    assert_eq!(
        std::fs::read_dir(dir).unwrap().count(),
        0,
        "nothing created"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn two_outputs_naming_one_file_are_refused_and_nothing_is_written() {
    let dir = temp_dir("same-file");
    let a = dir.join("a.png");
    std::fs::write(&a, b"earlier").unwrap();
    fails_with(&render(&["--out", s(&a), "--stats", s(&a)]), "both name");
    // The same file under another spelling, and through a symlink.
    let other = format!("{}/./a.png", s(&dir));
    fails_with(&render(&["--out", s(&a), "--heatmap", &other]), "both name");
    let link = dir.join("link.png");
    std::os::unix::fs::symlink(&a, &link).unwrap();
    fails_with(
        &render(&["--out", s(&a), "--heatmap", s(&link)]),
        "both name",
    );
    assert_eq!(std::fs::read(&a).unwrap(), b"earlier");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn diff_never_writes_over_its_inputs() {
    let dir = temp_dir("diff-input");
    let (a, b) = (dir.join("a.png"), dir.join("b.png"));
    image::RgbaImage::from_pixel(4, 4, image::Rgba([9, 9, 9, 255]))
        .save(&a)
        .unwrap();
    std::fs::copy(&a, &b).unwrap();
    let before = std::fs::read(&a).unwrap();
    for target in [&a, &b] {
        assert_fails_with(
            &["diff", s(&a), s(&b), "--diff-image", s(target)],
            "an output cannot replace an input",
        );
    }
    assert_eq!(std::fs::read(&a).unwrap(), before);
    // Comparing a file with itself is fine.
    let o = lightgrid(&["diff", s(&a), s(&a), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn image_outputs_must_be_named_png() {
    let dir = temp_dir("ext");
    for flag in ["--out", "--heatmap"] {
        for name in ["x.jpg", "x", "x.png.tmp"] {
            let p = dir.join(name);
            fails_with(
                &render(&["--pipeline", "tiled_deferred", flag, s(&p)]),
                "name the file *.png",
            );
            assert!(!p.exists(), "{name} was written");
        }
    }
    let (a, b) = (dir.join("a.png"), dir.join("b.png"));
    image::RgbaImage::new(2, 2).save(&a).unwrap();
    std::fs::copy(&a, &b).unwrap();
    assert_fails_with(
        &["diff", s(&a), s(&b), "--diff-image", s(&dir.join("d.jpg"))],
        "*.png",
    );
    // Upper-case extensions are PNG too, and diff reads what render writes.
    let up = dir.join("UP.PNG");
    let o = run(&render(&["--out", s(&up)]));
    assert!(o.status.success(), "{}", stderr(&o));
    let o = lightgrid(&["diff", s(&up), s(&up)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 3, "a, b, UP");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_long_valid_file_name_is_written() {
    let dir = temp_dir("long-name");
    // 255 bytes: the longest name the file system takes; probes and temporary files beside
    // it must not be longer.
    let name = format!("{}.png", "n".repeat(251));
    assert_eq!(name.len(), 255);
    let p = dir.join(&name);
    let o = run(&render(&["--out", s(&p)]));
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(image::open(&p).unwrap().width(), 16);
    let names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, vec![name], "no probe or temporary file left");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn outputs_that_are_not_regular_files_are_refused_from_the_cli() {
    let dir = temp_dir("fifo");
    let fifo = dir.join("f.json");
    let ok = Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success();
    assert!(ok, "mkfifo");
    // Without the check this would block forever opening the FIFO, or replace it.
    fails_with(&render(&["--stats", s(&fifo)]), "not a regular file");
    assert!(std::fs::symlink_metadata(&fifo)
        .unwrap()
        .file_type()
        .is_fifo());
    fails_with(&render(&["--stats", s(&dir)]), "is a directory");
    fails_with(&render(&["--stats", "/dev/null"]), "not a regular file");
    std::fs::remove_dir_all(&dir).unwrap();
}

use std::os::unix::fs::FileTypeExt;
use std::process::Command;

#[test]
fn io_errors_name_the_path_and_say_the_cause_once() {
    let o = run(&render(&["--out", "/nonexistent/dir/x.png"]));
    let err = stderr(&o);
    assert!(!o.status.success());
    assert!(err.contains("/nonexistent/dir/x.png"), "{err}");
    assert_eq!(err.matches("No such file or directory").count(), 1, "{err}");
}

#[test]
fn a_failing_command_creates_no_directory_and_changes_no_file() {
    let dir = temp_dir("no-trace");
    let out = dir.join("out");
    // Refused after parsing, before anything is created: a bad pipeline, a bad frame range,
    // an option that applies to nothing chosen, a scene that takes no light count.
    let cases: Vec<Vec<String>> = vec![
        vec!["bench".into(), "--pipelines".into(), "nope".into()],
        vec!["bench".into(), "--frames".into(), "9..3".into()],
        vec!["bench".into(), "--lights".into(), "5".into()],
        vec!["scaling".into(), "--pipeline".into(), "deferred".into()],
        vec!["scaling".into(), "--lights".into(), "0".into()],
        vec!["compare".into(), "--scene".into(), "nope".into()],
        vec!["compare".into(), "--tile".into(), "3".into()],
    ];
    for mut case in cases {
        case.push(
            if case[0] == "compare" {
                "--out-dir"
            } else {
                "--out"
            }
            .into(),
        );
        case.push(s(&out).into());
        let o = run(&case);
        assert!(!o.status.success(), "{case:?}");
        assert!(!out.exists(), "{case:?} created {}", out.display());
    }
    // A render whose heatmap name is refused leaves the image it would also have written.
    let png = dir.join("x.png");
    std::fs::write(&png, b"earlier").unwrap();
    fails_with(
        &render(&["--out", s(&png), "--heatmap", s(&dir.join("h.jpg"))]),
        "*.png",
    );
    assert_eq!(std::fs::read(&png).unwrap(), b"earlier");
    // An output directory that is a file is refused, and the file is left alone.
    let file = dir.join("file");
    std::fs::write(&file, b"mine").unwrap();
    assert_fails_with(&["bench", "--out", s(&file)], "is a file, not a directory");
    assert_eq!(std::fs::read(&file).unwrap(), b"mine");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_bench_failing_part_way_keeps_what_it_measured() {
    let dir = temp_dir("bench-fail");
    // forward loops over all 70,000 lights per fragment: lavapipe cuts such loops short,
    // which lightgrid refuses, after tiled_deferred was measured.
    let o = lightgrid(&[
        "bench",
        "--scene",
        "stress",
        "--lights",
        "70000",
        "--pipelines",
        "tiled_deferred,forward",
        "--size",
        "32x18",
        "--frames",
        "0",
        "--out",
        s(&dir),
    ]);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(
        err.contains("failed: stress / forward") && !err.contains("panicked"),
        "{err}"
    );
    let v = json(&dir.join("results.json"));
    assert_eq!(v["outcome"]["status"], "failed", "{}", v["outcome"]);
    assert!(v["outcome"]["reason"].as_str().unwrap().contains("forward"));
    let runs = v["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 1);
    assert_eq!(runs[0]["pipeline"], "tiled_deferred");
    assert_eq!(runs[0]["complete"], true);
    let summary = std::fs::read_to_string(dir.join("summary.md")).unwrap();
    assert!(summary.contains("**failed: stress / forward"), "{summary}");
    assert!(
        !dir.join(lightgrid_bench::LOCK_FILE).exists(),
        "lock released"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn scaling_records_a_failing_point_and_goes_on() {
    let dir = temp_dir("scaling-fail");
    // One 64-px tile of one slice at 300,000 lights: its list is longer than lavapipe's
    // loops go (32 slices over the samples' depth range keep every list under the limit).
    let o = lightgrid(&[
        "scaling",
        "--lights",
        "1000,300000",
        "--assign",
        "cpu",
        "--size",
        "64x64",
        "--tile",
        "64",
        "--slices",
        "1",
        "--warmup",
        "0",
        "--out",
        s(&dir),
    ]);
    assert!(!o.status.success());
    let v = json(&dir.join("scaling.json"));
    assert_eq!(v["outcome"]["status"], "failed");
    let points = v["points"].as_array().unwrap();
    assert_eq!(points.len(), 2);
    assert!(
        points[0]["assign_ms"].as_f64().unwrap() > 0.0,
        "1000 lights measured"
    );
    assert!(points[0]["failed"].is_null());
    assert!(
        points[1]["failed"]
            .as_str()
            .unwrap()
            .contains("shader loops"),
        "{}",
        points[1]
    );
    let csv = std::fs::read_to_string(dir.join("scaling.csv")).unwrap();
    assert!(
        csv.lines().nth(2).unwrap().contains("shader loops"),
        "{csv}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn compare_says_when_the_reference_failed() {
    let dir = temp_dir("compare-ref");
    std::fs::create_dir_all(&dir).unwrap();
    // Files of an earlier run: forward.png from it must not stay beside the new table.
    std::fs::write(dir.join("forward.png"), b"earlier").unwrap();
    std::fs::write(dir.join("mine.txt"), b"not lightgrid's").unwrap();
    std::fs::write(
        dir.join(lightgrid_bench::manifest_name("compare")),
        "forward.png\nforward.json\n",
    )
    .unwrap();
    let o = lightgrid(&[
        "compare",
        "--scene",
        "stress",
        "--lights",
        "66000",
        "--size",
        "8x8",
        "--warmup",
        "0",
        "--out-dir",
        s(&dir),
    ]);
    assert!(!o.status.success());
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        !out.lines()
            .any(|l| l.starts_with("tiled_deferred ") && l.contains("reference")),
        "{out}"
    );
    let v = json(&dir.join("compare.json"));
    assert_eq!(v["outcome"]["status"], "failed");
    for row in v["rows"].as_array().unwrap() {
        let id = row["pipeline"].as_str().unwrap();
        if id.starts_with("forward") {
            assert!(row["failed"].is_string(), "{row}");
        } else {
            assert!(row["diff"].is_null(), "{row}");
            assert_eq!(row["diff_note"], "not computed: forward failed", "{row}");
        }
    }
    assert!(
        !dir.join("forward.png").exists(),
        "stale reference image removed"
    );
    assert!(
        dir.join("mine.txt").exists(),
        "files lightgrid did not write stay"
    );
    assert!(dir.join("tiled_deferred.png").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn two_runs_into_one_directory_do_not_mix() {
    let dir = temp_dir("lock");
    let lock = dir.join(lightgrid_bench::LOCK_FILE);
    // A live holder (pid 1 always exists): refused, and the holder's lock is kept.
    std::fs::write(&lock, "1\n").unwrap();
    for args in [
        vec![
            "bench",
            "--preset",
            "quick",
            "--pipelines",
            "forward",
            "--out",
            s(&dir),
        ],
        vec![
            "scaling",
            "--lights",
            "100",
            "--assign",
            "cpu",
            "--out",
            s(&dir),
        ],
        vec!["compare", "--size", "8x8", "--out-dir", s(&dir)],
    ] {
        assert_fails_with(&args, "another lightgrid run (pid 1)");
    }
    assert_eq!(std::fs::read_to_string(&lock).unwrap(), "1\n");
    // A lock left by a process that is gone is taken over.
    std::fs::write(&lock, "999999999\n").unwrap();
    let o = lightgrid(&[
        "scaling",
        "--lights",
        "100",
        "--assign",
        "cpu",
        "--size",
        "32x16",
        "--warmup",
        "0",
        "--out",
        s(&dir),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!lock.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A bench long enough to interrupt: every frame of robots-few, two pipelines, into `dir`.
fn slow_bench(dir: &std::path::Path) -> Vec<&str> {
    vec![
        "bench",
        "--scene",
        "robots-few",
        "--pipelines",
        "forward,deferred",
        "--size",
        "32x18",
        "--frames",
        "0..259:1",
        "--warmup",
        "0",
        "--out",
        s(dir),
    ]
}

#[test]
fn sigterm_stops_a_bench_and_keeps_its_results() {
    let dir = temp_dir("sigterm");
    // Wait until it measures, then SIGTERM.
    let (mut child, mut err) = support::start_measuring(&slow_bench(&dir));
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let killed = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let mut rest = String::new();
    let _ = std::io::Read::read_to_string(&mut err, &mut rest);
    let status = child.wait().unwrap();
    assert!(!status.success(), "an interrupted run exits non-zero");
    assert!(rest.contains("interrupted"), "{rest}");
    let v = json(&dir.join("results.json"));
    assert_eq!(v["outcome"]["status"], "interrupted");
    // The series in progress when the signal came is kept and marked incomplete; any
    // finished before it are complete.
    let runs = v["runs"].as_array().unwrap();
    let last = runs.last().expect("at least the series in progress");
    assert_eq!(last["complete"], false, "{}", last["pipeline"]);
    assert!(!last["frames"].as_array().unwrap().is_empty());
    assert!(runs[..runs.len() - 1].iter().all(|r| r["complete"] == true));
    assert!(dir.join("summary.md").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn counts_and_thresholds_are_bounded_where_parsed() {
    let dir = temp_dir("bounds");
    let d = s(&dir);
    let cases: &[(&[&str], &str)] = &[
        (
            &["render", "--spot-fraction", "NaN"],
            "not a number from 0 to 1",
        ),
        (
            &["render", "--spot-fraction", "-0.5"],
            "not a number from 0 to 1",
        ),
        (
            &["play", "--spot-fraction", "1.5"],
            "not a number from 0 to 1",
        ),
        (
            &["bench", "--spot-fraction", "inf", "--out", d],
            "not a number from 0 to 1",
        ),
        (&["render", "--warmup", "1000000"], "not in 0..=1000"),
        (
            &["compare", "--warmup", "1001", "--out-dir", d],
            "not in 0..=1000",
        ),
        (&["bench", "--repeat", "0", "--out", d], "not in 1..=1000"),
        (
            &["bench", "--warmup", "5000", "--out", d],
            "not in 0..=1000",
        ),
        (&["scaling", "--runs", "0", "--out", d], "not in 1..=1000"),
        (
            &[
                "scaling",
                "--warmup",
                "4294967295",
                "--runs",
                "1",
                "--out",
                d,
            ],
            "not in 0..=1000",
        ),
        (
            &["scaling", "--budget", "NaN", "--out", d],
            "not a finite number",
        ),
        (
            &["scaling", "--budget", "-1", "--out", d],
            "not a finite number",
        ),
        (
            &["scaling", "--budget", "0", "--out", d],
            "positive number of seconds",
        ),
        (
            &["scaling", "--lights", "0", "--out", d],
            "out of range 1 to 1000000",
        ),
        (
            &["scaling", "--lights", "1000,2000000", "--out", d],
            "out of range 1 to 1000000",
        ),
        (
            &["diff", "a.png", "b.png", "--max-mean", "NaN"],
            "not a finite number",
        ),
        (
            &["diff", "a.png", "b.png", "--max-p99", "-1"],
            "not a finite number",
        ),
        (
            &["diff", "a.png", "b.png", "--max-p99", "inf"],
            "not a finite number",
        ),
        (
            &["bench", "--frames", "9..3", "--out", d],
            "ends (3) before it starts (9)",
        ),
        (
            &["bench", "--frames", "0..9:0", "--out", d],
            "the step must be at least 1",
        ),
        (
            &["bench", "--frames", "300..400", "--out", d],
            "no frame of robots-many is in range",
        ),
        (
            &["play", "--frames", "5..1"],
            "ends (1) before it starts (5)",
        ),
        (&["--adapter", "", "render"], "--adapter is empty"),
        (
            &[
                "--adapter",
                "gl",
                "render",
                "--pipeline",
                "tiled_deferred",
                "--size",
                "8x8",
            ],
            "cannot run tiled_deferred",
        ),
        (
            &["--adapter", "nope", "render"],
            "no adapter matches 'nope'",
        ),
        (
            &[
                "bench",
                "--frames",
                "0..10:5",
                "--heatmap-frame",
                "3",
                "--out",
                d,
            ],
            "not one of the measured frames",
        ),
        (&["report", d], "results.json: No such file"),
        // --msaa: zero, a count no adapter has, huge, negative, NaN, one the adapter lacks
        // (lavapipe: 1 and 4 only), and in a list.
        (&["render", "--msaa", "0"], "must be one of 1, 2, 4, 8, 16"),
        (&["render", "--msaa", "3"], "must be one of 1, 2, 4, 8, 16"),
        (
            &["compare", "--msaa", "4294967295", "--out-dir", d],
            "must be one of 1, 2, 4, 8, 16",
        ),
        (&["play", "--msaa", "-4"], "invalid value '-4'"),
        (&["render", "--msaa", "NaN"], "invalid value 'NaN'"),
        (
            &["memory", "--msaa", "1,0"],
            "must be one of 1, 2, 4, 8, 16",
        ),
        (&["render", "--msaa", "16"], "for every target"),
        (&["bench", "--msaa", "1,8", "--out", d], "for every target"),
    ];
    all_refused_leaving_nothing(&dir, cases);
}

#[test]
fn an_option_that_applies_to_nothing_chosen_is_refused_in_every_command() {
    let dir = temp_dir("applies");
    let d = s(&dir);
    let cases: &[(&[&str], &str)] = &[
        (
            &["render", "--scene", "stress", "--headlights"],
            "has no robots",
        ),
        (
            &["bench", "--scene", "stress", "--headlights", "--out", d],
            "has no robots",
        ),
        (
            &["render", "--pipeline", "deferred", "--spot-cull", "sphere"],
            "--spot-cull does not apply to deferred",
        ),
        (
            &["render", "--pipeline", "deferred", "--lists", "shared"],
            "--lists does not apply to deferred",
        ),
        (
            &[
                "render",
                "--pipeline",
                "tiled_deferred",
                "--material-draws",
                "uber",
            ],
            "--material-draws does not apply to tiled_deferred",
        ),
        (
            &["render", "--scene", "stress", "--transparency", "off"],
            "scene stress has no transparent objects",
        ),
        (
            &[
                "bench",
                "--pipelines",
                "forward",
                "--spot-cull",
                "cone",
                "--out",
                d,
            ],
            "--spot-cull does not apply",
        ),
        (
            &["render", "--pipeline", "forward", "--slices", "4"],
            "--slices does not apply to forward",
        ),
        (
            &["render", "--pipeline", "tiled_forward", "--gbuffer", "32"],
            "--gbuffer does not apply",
        ),
        (
            &["render", "--pipeline", "deferred", "--assign", "gather"],
            "--assign does not apply",
        ),
        (
            &["render", "--scene", "robots-many", "--lights", "5"],
            "fixed light count",
        ),
        (
            &["play", "--pipeline", "forward", "--slices", "4"],
            "--slices does not apply",
        ),
        (
            &["play", "--scene", "robots-few", "--lights", "5"],
            "fixed light count",
        ),
        (&["bench", "--lights", "5", "--out", d], "fixed light count"),
        (
            &[
                "bench",
                "--pipelines",
                "forward",
                "--gbuffer",
                "32",
                "--out",
                d,
            ],
            "--gbuffer does not apply",
        ),
        (
            &[
                "bench",
                "--pipelines",
                "forward,deferred",
                "--slices",
                "8",
                "--out",
                d,
            ],
            "--slices does not apply",
        ),
        (
            &[
                "scaling",
                "--pipeline",
                "tiled_deferred",
                "--slices",
                "8",
                "--out",
                d,
            ],
            "--slices does not apply",
        ),
        (
            &[
                "compare",
                "--scene",
                "robots-few",
                "--lights",
                "5",
                "--out-dir",
                d,
            ],
            "fixed light count",
        ),
    ];
    all_refused_leaving_nothing(&dir, cases);
}

#[test]
fn gl_adapters_are_not_offered() {
    // README says why: the count target needs R32Float blending, which GL lacks.
    let o = lightgrid(&["list"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success());
    assert!(out.contains("[vulkan, "), "{out}");
    assert!(!out.contains("[gl, "), "GL listed:\n{out}");
}

#[test]
fn a_closed_stdout_ends_quietly() {
    use std::io::Read;
    // `lightgrid list | head -1`: the reader goes away after one line.
    let mut child = Command::new(env!("CARGO_BIN_EXE_lightgrid"))
        .arg("list")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = [0u8; 8];
    child
        .stdout
        .as_mut()
        .unwrap()
        .read_exact(&mut first)
        .unwrap();
    drop(child.stdout.take());
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    child.wait().unwrap();
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn out_of_memory_at_target_creation_says_so_with_the_size() {
    // A 6 GB address-space limit: the 16384x16384 targets (5 GiB shared, more with the
    // G-buffer) cannot be allocated, as on a GPU with too little memory.
    let o = Command::new("sh")
        .args([
            "-c",
            "ulimit -v 6000000 && exec \"$0\" render --scene robots-few --size 16384x16384 \
             --pipeline tiled_deferred --warmup 0",
            env!("CARGO_BIN_EXE_lightgrid"),
        ])
        .output()
        .unwrap();
    let err = stderr(&o);
    assert!(!o.status.success());
    assert!(
        err.contains("out of memory") && err.contains("16384x16384") && err.contains("MiB"),
        "{err}"
    );
    assert!(
        !err.contains("Validation Error") && !err.contains("panicked"),
        "{err}"
    );
}

/// The files in `dir` (hidden ones too) with their bytes, sorted by name.
fn snapshot(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .map(|p| {
            let bytes = std::fs::read(&p).unwrap();
            (p.file_name().unwrap().to_string_lossy().into_owned(), bytes)
        })
        .collect();
    v.sort();
    v
}

fn names(snapshot: &[(String, Vec<u8>)]) -> Vec<&str> {
    snapshot.iter().map(|(n, _)| n.as_str()).collect()
}

/// A quick bench into `dir` (robots-few, forward, one frame at 32x18).
fn quick_bench(dir: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "bench",
        "--scene",
        "robots-few",
        "--pipelines",
        "forward",
        "--size",
        "32x18",
        "--frames",
        "0",
        "--warmup",
        "0",
        "--out",
        s(dir),
    ];
    args.extend_from_slice(extra);
    lightgrid(&args)
}

/// A quick compare into `dir` (robots-few at 8x8, every pipeline).
fn quick_compare(dir: &Path, extra: &[&str]) -> Vec<String> {
    let mut v: Vec<String> = [
        "compare",
        "--scene",
        "robots-few",
        "--size",
        "8x8",
        "--warmup",
        "0",
        "--out-dir",
        s(dir),
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    v.extend(extra.iter().map(|s| s.to_string()));
    v
}

/// A quick scaling run into `dir`.
fn quick_scaling(dir: &Path) -> Vec<&str> {
    vec![
        "scaling",
        "--lights",
        "100",
        "--assign",
        "cpu",
        "--size",
        "32x16",
        "--warmup",
        "0",
        "--out",
        s(dir),
    ]
}

#[test]
fn a_failed_write_to_stdout_is_a_message_and_exit_1() {
    let dir = temp_dir("stdout-full");
    let (a, b) = (dir.join("a.png"), dir.join("b.png"));
    image::RgbaImage::from_pixel(4, 4, image::Rgba([9, 9, 9, 255]))
        .save(&a)
        .unwrap();
    std::fs::copy(&a, &b).unwrap();
    let png = dir.join("r.png");
    let cases: Vec<Vec<String>> = vec![
        vec!["list".into()],
        vec!["memory".into(), "--size".into(), "64x64".into()],
        vec!["diff".into(), "--json".into(), s(&a).into(), s(&b).into()],
        render(&["--out", s(&png)]),
    ];
    for args in cases {
        // `lightgrid list > /dev/full`: every write fails with ENOSPC.
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let o = Command::new(env!("CARGO_BIN_EXE_lightgrid"))
            .args(&args)
            .stdout(full)
            .output()
            .unwrap();
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains("cannot write to standard output: No space left on device"),
            "{args:?}: {err}"
        );
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn each_command_keeps_to_its_own_files_in_a_shared_directory() {
    let dir = temp_dir("shared-dir");
    let o = quick_bench(&dir, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let bench = snapshot(&dir);
    assert!(names(&bench).contains(&"summary.md"), "{:?}", names(&bench));
    // A compare and a scaling run into the bench's directory: the bench stays whole.
    let o = run(&quick_compare(&dir, &[]));
    assert!(o.status.success(), "{}", stderr(&o));
    let o = lightgrid(&quick_scaling(&dir));
    assert!(o.status.success(), "{}", stderr(&o));
    let after = snapshot(&dir);
    for (name, bytes) in bench.iter().filter(|(n, _)| !n.starts_with(".lightgrid")) {
        let now = after.iter().find(|(n, _)| n == name);
        assert!(
            now.is_some_and(|(_, b)| b == bytes),
            "{name} changed or lost"
        );
    }
    for f in ["compare.json", "forward.png", "scaling.json"] {
        assert!(names(&after).contains(&f), "{f}: {:?}", names(&after));
    }
    // A second bench replaces its own files only.
    let o = quick_bench(&dir, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let again = snapshot(&dir);
    for f in [
        "compare.json",
        "forward.png",
        "scaling.json",
        "results.json",
    ] {
        assert!(names(&again).contains(&f), "{f}: {:?}", names(&again));
    }
    // A file of the user's in a directory lightgrid made is not replaced either: the run is
    // refused and its files kept aside.
    std::fs::remove_file(dir.join("forward.png")).unwrap();
    let mut manifest =
        std::fs::read_to_string(dir.join(lightgrid_bench::manifest_name("compare"))).unwrap();
    manifest = manifest.replace("forward.png\n", "");
    std::fs::write(
        dir.join(lightgrid_bench::manifest_name("compare")),
        manifest,
    )
    .unwrap();
    std::fs::write(dir.join("forward.png"), b"mine").unwrap();
    let o = run(&quick_compare(&dir, &[]));
    let err = stderr(&o);
    assert!(!o.status.success());
    assert!(
        err.contains("already holds forward.png (not written by lightgrid)")
            && err.contains("--force"),
        "{err}"
    );
    assert_eq!(std::fs::read(dir.join("forward.png")).unwrap(), b"mine");
    assert!(
        std::fs::read_dir(&dir).unwrap().any(|e| e
            .unwrap()
            .file_name()
            .to_string_lossy()
            .starts_with("lightgrid-compare-")),
        "the refused run's files are kept aside"
    );
    let o = run(&quick_compare(&dir, &["--force"]));
    assert!(o.status.success(), "{}", stderr(&o));
    assert_ne!(std::fs::read(dir.join("forward.png")).unwrap(), b"mine");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_directory_lightgrid_did_not_make_is_refused_unless_empty_or_forced() {
    let dir = temp_dir("foreign-dir");
    std::fs::write(dir.join("summary.md"), b"my notes").unwrap();
    std::fs::write(dir.join("mine.txt"), b"mine").unwrap();
    let before = snapshot(&dir);
    let compare = quick_compare(&dir, &[]);
    let compare: Vec<&str> = compare.iter().map(String::as_str).collect();
    for args in [
        vec!["bench", "--preset", "quick", "--out", s(&dir)],
        compare,
        quick_scaling(&dir),
    ] {
        assert_fails_with(&args, "is not empty and was not made by lightgrid");
        assert_eq!(snapshot(&dir), before, "{args:?} changed the directory");
    }
    // The default job writes into out/ by the same rule.
    let cwd = temp_dir("foreign-cwd");
    std::fs::create_dir(cwd.join("out")).unwrap();
    std::fs::write(cwd.join("out/results.csv"), b"a,b\n").unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_lightgrid"))
        .current_dir(&cwd)
        .output()
        .unwrap();
    let err = stderr(&o);
    assert!(
        !o.status.success() && err.contains("was not made by lightgrid"),
        "{err}"
    );
    assert_eq!(std::fs::read_dir(cwd.join("out")).unwrap().count(), 1);
    // --force belongs after the command it is for.
    assert_fails_with(&["--force", "list"], "default job only");
    // Forced, a compare writes beside the user's files and leaves them.
    let o = run(&quick_compare(&dir, &["--force"]));
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read(dir.join("summary.md")).unwrap(), b"my notes");
    assert_eq!(std::fs::read(dir.join("mine.txt")).unwrap(), b"mine");
    assert!(dir.join("compare.json").exists());
    // An empty directory needs no --force.
    let empty = temp_dir("empty-dir");
    let o = quick_bench(&empty, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    for d in [dir, cwd, empty] {
        std::fs::remove_dir_all(&d).unwrap();
    }
}

/// Run lightgrid with files limited to `bytes` (RLIMIT_FSIZE, SIGXFSZ ignored): a write past
/// it fails with EFBIG as a full disk fails with ENOSPC, without root or a small file system.
fn with_file_size_limit(args: &[&str], bytes: u64) -> std::process::Output {
    use std::os::unix::process::CommandExt;
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_lightgrid"));
    cmd.args(args);
    // SAFETY: only async-signal-safe calls between fork and exec.
    unsafe {
        cmd.pre_exec(move || {
            libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
            let limit = libc::rlimit {
                rlim_cur: bytes,
                rlim_max: bytes,
            };
            if libc::setrlimit(libc::RLIMIT_FSIZE, &limit) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    cmd.output().unwrap()
}

#[test]
fn a_run_whose_writes_fail_part_way_leaves_the_earlier_run_whole() {
    let dir = temp_dir("fsize");
    let o = run(&quick_compare(&dir, &[]));
    assert!(o.status.success(), "{}", stderr(&o));
    let before = snapshot(&dir);
    // The images and per-pipeline stats fit under 3000 bytes; compare.json (about 5 KB) does
    // not: the run fails after writing most of its files.
    let args = quick_compare(&dir, &[]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = with_file_size_limit(&args, 3000);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("compare.json") && err.contains("File too large"),
        "{err}"
    );
    assert_eq!(
        snapshot(&dir),
        before,
        "the directory is the earlier run's, nothing of the failed one"
    );
    assert!(
        std::fs::read_dir(&dir)
            .unwrap()
            .all(|e| e.unwrap().path().is_file()),
        "no staging directory left"
    );
    // export: the .glb is not there and neither is its temporary file.
    let glb = dir.join("scene.glb");
    let o = with_file_size_limit(&["export", "--scene", "robots-few", "--out", s(&glb)], 3000);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert_eq!(snapshot(&dir), before, "no scene.glb and no temporary file");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn overwriting_an_output_keeps_its_mode() {
    use std::os::unix::fs::PermissionsExt;
    let dir = temp_dir("mode");
    let png = dir.join("private.png");
    std::fs::write(&png, b"old").unwrap();
    std::fs::set_permissions(&png, std::fs::Permissions::from_mode(0o600)).unwrap();
    let o = run(&render(&["--out", s(&png)]));
    assert!(o.status.success(), "{}", stderr(&o));
    let mode = std::fs::metadata(&png).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, 0o600, "{mode:o}");
    assert_ne!(std::fs::read(&png).unwrap(), b"old");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_second_signal_exits_at_once_leaving_no_temporary_files() {
    let dir = temp_dir("sigterm-twice");
    let (mut child, _err) = support::start_measuring(&slow_bench(&dir));
    // Measuring: its staging directory exists.
    let staging = || {
        std::fs::read_dir(&dir)
            .unwrap()
            .filter(|e| {
                let n = e.as_ref().unwrap().file_name();
                let n = n.to_string_lossy();
                n.starts_with(".lightgrid-run-") || n.ends_with(".tmp")
            })
            .count()
    };
    assert_eq!(staging(), 1);
    // Two signals at once, of two kinds so the kernel cannot merge them into one: the
    // second comes before the run could stop and write.
    let pid = child.id();
    let killed = Command::new("sh")
        .args(["-c", &format!("kill -INT {pid}; kill -TERM {pid}")])
        .status()
        .unwrap();
    assert!(killed.success());
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130));
    assert_eq!(staging(), 0, "temporaries removed on the way out");
    assert!(
        !dir.join("results.json").exists(),
        "aborted without writing"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn light_values_out_of_bounds_are_refused_with_the_cause() {
    // A range whose square is no longer a normal f32: named as too small, not "not finite".
    fails_with(
        &render(&["--add-lights", "5", "--light-range", "1e-30"]),
        "--light-range: 1e-30 is outside 1e-6",
    );
    // The exposure: zero, negative, NaN, past what keeps every light's sum finite, below
    // what an f32 keeps: the message states the bounds enforced.
    for bad in ["0", "-1", "nan", "inf", "abc", "5e6", "1e-50"] {
        fails_with(
            &render(&["--exposure", bad]),
            &format!("'{bad}' is not a number from 1e-30 to 1e6"),
        );
    }
    fails_with(
        &render(&["--brdf", "lambert"]),
        "invalid value 'lambert' for '--brdf <brdf>'",
    );
}

#[test]
fn shadow_options_out_of_range_are_refused() {
    // Zero casters (that is --shadows off), negative, NaN, past the light limit, not a number.
    for bad in ["0", "-1", "nan", "2000000", "1e3", "some"] {
        let r = run(&render(&["--shadows", "rays", "--shadow-lights", bad]));
        assert!(!r.status.success(), "--shadow-lights {bad} accepted");
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(err.contains("--shadow-lights"), "{bad}: {err}");
        assert!(!err.contains("panicked"), "{bad}: {err}");
    }
    fails_with(
        &render(&["--shadows", "rays", "--shadow-lights", "0"]),
        "must be between 1 and 1048576, or all (--shadows off for none)",
    );
    // A count without shadows applies to nothing.
    let r = run(&render(&["--shadow-lights", "8"]));
    assert!(!r.status.success());
    assert!(
        String::from_utf8_lossy(&r.stderr).contains("--shadows"),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    fails_with(
        &render(&["--shadows", "sometimes"]),
        "invalid value 'sometimes' for '--shadows <shadows>'",
    );
    // The atlas's budget and a face's size: zero, negative, NaN, past their limits, not a
    // power of two.
    for (flag, bad) in [
        ("--shadow-atlas", "0"),
        ("--shadow-atlas", "-1"),
        ("--shadow-atlas", "nan"),
        ("--shadow-atlas", "5000"),
        ("--shadow-map-size", "0"),
        ("--shadow-map-size", "100"),
        ("--shadow-map-size", "2048"),
        ("--shadow-map-size", "-16"),
    ] {
        let r = run(&render(&["--shadows", "maps", flag, bad]));
        assert!(!r.status.success(), "{flag} {bad} accepted");
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(
            err.contains(flag) && !err.contains("panicked"),
            "{flag} {bad}: {err}"
        );
    }
    // They apply to shadow maps only, as the maps' image does.
    fails_with(
        &render(&["--shadows", "rays", "--shadow-atlas", "8"]),
        "none without --shadows maps",
    );
    let dir = temp_dir("maps-image");
    let image = dir.join("atlas.png");
    let image = image.to_str().unwrap();
    fails_with(
        &render(&["--shadows", "rays", "--shadow-maps-image", image]),
        "--shadow-maps-image needs --shadows maps",
    );
    fails_with(
        &render(&[
            "--shadows",
            "maps",
            "--shadow-maps-image",
            dir.to_str().unwrap(),
        ]),
        "--shadow-maps-image",
    );
    fails_with(
        &render(&[
            "--shadows",
            "maps",
            "--shadow-maps-image",
            &format!("{image}.txt"),
        ]),
        "--shadow-maps-image",
    );
    assert_eq!(
        std::fs::read_dir(&dir).unwrap().count(),
        0,
        "nothing written"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// An atlas too small for the frame's shadowed lights at the smallest face is refused with
/// the numbers and what to change, and writes nothing.
#[test]
fn a_shadow_atlas_too_small_for_the_lights_is_refused() {
    let dir = temp_dir("small-atlas");
    let out = dir.join("s.png");
    let args = [
        "render",
        "--scene",
        "robots-many",
        "--size",
        "64x36",
        "--shadows",
        "maps",
        "--shadow-atlas",
        "1",
        "--out",
        out.to_str().unwrap(),
    ];
    assert_fails_with(
        &args,
        "holds at most 1024 shadow-map faces of 16x16; this frame's shadowed lights need",
    );
    assert!(!out.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// 256 slices of 4-pixel tiles at 2000x1200 is 38 million cells, whose bounds no storage
/// binding of lavapipe holds: refused with the numbers and what to change, not a wgpu
/// validation dump, and no image written.
#[test]
fn a_grid_larger_than_the_device_binds_is_refused() {
    let dir = temp_dir("huge-grid");
    let out = dir.join("g.png");
    let args = [
        "render",
        "--scene",
        "robots-few",
        "--pipeline",
        "clustered_forward",
        "--slices",
        "256",
        "--tile",
        "4",
        "--size",
        "2000x1200",
        "--out",
        s(&out),
    ];
    assert_fails_with(&args, "bytes of per-cell records, more than the");
    assert!(!out.exists(), "an image was written");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn export_refuses_what_its_import_cannot_read() {
    let dir = temp_dir("export-limit");
    let glb = dir.join("many.glb");
    // 200,000 lights: a JSON part of about 90 MB, past the 64 MiB the import reads.
    let o = lightgrid(&[
        "export",
        "--scene",
        "stress",
        "--lights",
        "200000",
        "--out",
        s(&glb),
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("200000 lights")
            && err.contains("more than the 64 MiB")
            && err.contains("own import refuses"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_dir(&dir).unwrap().count(),
        0,
        "nothing written"
    );
    // Below the limit the export is written and reads back.
    let o = lightgrid(&[
        "export",
        "--scene",
        "stress",
        "--lights",
        "20000",
        "--out",
        s(&glb),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = lightgrid(&[
        "render",
        "--scene",
        s(&glb),
        "--size",
        "8x8",
        "--warmup",
        "0",
        "--out",
        s(&dir.join("x.png")),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn report_checks_its_input_before_writing() {
    let dir = temp_dir("report-check");
    let o = quick_bench(&dir, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    // A results.json edited so a scene name would leave the directory.
    let mut v = json(&dir.join("results.json"));
    v["runs"][0]["scene"] = "../../elsewhere".into();
    std::fs::write(dir.join("results.json"), serde_json::to_vec(&v).unwrap()).unwrap();
    let before = snapshot(&dir);
    assert_fails_with(
        &["report", s(&dir)],
        "scene name \"../../elsewhere\" cannot be part of a file name",
    );
    assert_eq!(snapshot(&dir), before, "summary.md and the rest untouched");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Driven by the library's table of settings (`lightgrid::pipelines::AXES`): every option is
/// accepted (and renders) with a pipeline it applies to, refused with one it does not apply
/// to (naming who it applies to), and listed in `--help` with its values. An option added to
/// the table is checked here without a line of this test changing.
#[test]
fn every_setting_of_the_table_is_refused_where_it_does_not_apply_and_accepted_where_it_does() {
    use lightgrid::pipelines::{RenderSettings, AXES, PIPELINES};
    let help = String::from_utf8_lossy(&lightgrid(&["render", "--help"]).stdout).into_owned();
    let dir = temp_dir("axes");
    for axis in AXES {
        assert!(
            help.contains(&axis.option()),
            "render --help lacks {}",
            axis.option()
        );
        for v in (axis.values)() {
            assert!(
                help.contains(v.name),
                "render --help lacks {} {}",
                axis.option(),
                v.name
            );
        }
        // A value other than the default where there is one (the default for numbers: 4
        // samples for --msaa, 8 slices); --msaa-resolve applies only with MSAA.
        let value = match (axis.values)().get(1) {
            Some(v) => v.name.to_string(),
            None if axis.flag == "msaa" => "4".into(),
            None if axis.flag == "shadow-map-size" => "16".into(),
            None => "8".into(),
        };
        // The shadow maps' options apply only with shadows.
        let shadows = axis.flag.starts_with("shadow-");
        let mut settings = RenderSettings::default();
        if shadows {
            settings.shadows = lightgrid::scene::Shadows::Maps;
        }
        (axis.set)(&mut settings, &value).unwrap();
        let msaa = if axis.flag == "msaa-resolve" {
            "4"
        } else {
            "1"
        };
        settings.grid.samples = msaa.parse().unwrap();
        let taker = PIPELINES.iter().find(|p| (axis.applies)(p, &settings));
        let other = PIPELINES.iter().find(|p| !(axis.applies)(p, &settings));
        let taker = taker.unwrap_or_else(|| panic!("{} applies to no pipeline", axis.flag));
        let out = dir.join(format!("{}.png", axis.flag));
        let mut args = render(&["--pipeline", taker.id, "--msaa", msaa]);
        if shadows {
            args.extend(["--shadows".into(), "maps".into()]);
        }
        if axis.flag != "msaa" {
            args.extend([axis.option(), value.clone()]);
        } else {
            let i = args.iter().position(|a| a == "--msaa").unwrap();
            args[i + 1] = value.clone();
        }
        args.extend(["--out".into(), s(&out).into()]);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = lightgrid(&args);
        assert!(o.status.success(), "{args:?} refused: {}", stderr(&o));
        assert!(out.exists(), "{args:?} wrote no image");
        // Every pipeline takes MSAA, the BRDF and shadows: nothing to refuse.
        if let Some(other) = other {
            let needle = format!("{} does not apply to {}", axis.option(), other.id);
            let mut args = render(&["--pipeline", other.id, "--msaa", msaa]);
            args.extend([axis.option(), value.clone()]);
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            assert_fails_with(&args, &needle);
            let o = lightgrid(&args);
            assert!(
                stderr(&o).contains(taker.id),
                "{args:?}: the refusal names no taker"
            );
        } else {
            assert!(
                ["msaa", "brdf"].contains(&axis.flag) || axis.flag.starts_with("shadow"),
                "only --msaa, --brdf and the shadows apply to every pipeline, not {}",
                axis.flag
            );
        }
    }
}
