//! Nothing the user keeps is lost (README "What bad input gets"): outputs are checked against
//! inputs and each other by what the files are (hard links, symlinks, a scene's own buffers
//! and images), a run that fails keeps the last good one, list values that name one series
//! twice are refused, and `report` only reads `results.json` and is bounded for any value in
//! it. Every case checks the files it did not name are byte-identical afterwards.

mod support;

use std::path::{Path, PathBuf};
use support::{assert_fails_with, lightgrid, stderr, temp_dir};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn ok(args: &[&str]) -> String {
    let o = lightgrid(args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Every file under `dir` (recursively, by relative path) with its bytes.
fn snapshot(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                todo.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().display().to_string();
                out.push((rel, std::fs::read(&p).unwrap_or_default()));
            }
        }
    }
    out.sort();
    out
}

/// A link of `target` at `link`: hard or symbolic.
fn link(target: &Path, link: &Path, hard: bool) {
    let _ = std::fs::remove_file(link);
    if hard {
        std::fs::hard_link(target, link).unwrap();
    } else {
        std::os::unix::fs::symlink(target, link).unwrap();
    }
}

#[test]
fn every_command_checks_its_outputs_by_identity() {
    let dir = temp_dir("keep-identity");
    let d = |n: &str| dir.join(n);
    ok(&["export", "--scene", "robots-few", "--out", s(&d("in.glb"))]);
    let png = image::RgbaImage::from_pixel(4, 4, image::Rgba([9, 9, 9, 255]));
    png.save(d("a.png")).unwrap();
    png.save(d("b.png")).unwrap();
    std::fs::write(d("p.png"), b"earlier image").unwrap();
    std::fs::create_dir(d("bench")).unwrap();
    std::fs::create_dir(d("compare")).unwrap();
    // (what a link is made of, the link's name, the command with LINK where it goes, what the
    // refusal says)
    type Case<'a> = (&'a str, &'a str, Vec<&'a str>, &'a str);
    let input = "an output cannot replace an input";
    let twice = "two outputs cannot be the same file";
    let cases: Vec<Case> = vec![
        (
            "in.glb",
            "out.glb",
            vec!["export", "--scene", "IN", "--out", "LINK"],
            input,
        ),
        (
            "p.png",
            "s.png",
            vec!["render", "--size", "8x8", "--out", "P", "--stats", "LINK"],
            twice,
        ),
        (
            "p.png",
            "h.png",
            vec!["render", "--size", "8x8", "--out", "P", "--heatmap", "LINK"],
            twice,
        ),
        (
            "in.glb",
            "o.png",
            vec!["render", "--scene", "IN", "--out", "LINK"],
            input,
        ),
        (
            "a.png",
            "d.png",
            vec!["diff", "A", "B", "--diff-image", "LINK"],
            input,
        ),
        (
            "in.glb",
            "j.json",
            vec!["play", "--scene", "IN", "--json", "LINK"],
            input,
        ),
        (
            "in.glb",
            "j.json",
            vec!["advise", "--scene", "IN", "--budget", "1", "--json", "LINK"],
            input,
        ),
        (
            "in.glb",
            "v.png",
            vec![
                "view",
                "--scene",
                "IN",
                "--screenshot",
                "LINK",
                "--exit-after-frames",
                "1",
            ],
            input,
        ),
        // A directory's outputs (written aside, checked before they are moved into place;
        // --force lets them replace files lightgrid did not write, never an input).
        (
            "in.glb",
            "bench/results.json",
            vec![
                "bench",
                "--scene",
                "IN",
                "--pipelines",
                "forward",
                "--frames",
                "0",
                "--size",
                "8x8",
                "--warmup",
                "0",
                "--out",
                "BENCH",
                "--force",
            ],
            input,
        ),
        (
            "in.glb",
            "compare/forward.png",
            vec![
                "compare",
                "--scene",
                "IN",
                "--size",
                "8x8",
                "--warmup",
                "0",
                "--out-dir",
                "COMPARE",
                "--force",
            ],
            input,
        ),
    ];
    for hard in [true, false] {
        for (target, name, args, needle) in &cases {
            link(&d(target), &d(name), hard);
            let before: Vec<_> = snapshot(&dir)
                .into_iter()
                .filter(|(n, _)| !n.contains("lightgrid-"))
                .collect();
            let args: Vec<String> = args
                .iter()
                .map(|a| match *a {
                    "IN" => s(&d("in.glb")).to_string(),
                    "P" => s(&d("p.png")).to_string(),
                    "A" => s(&d("a.png")).to_string(),
                    "B" => s(&d("b.png")).to_string(),
                    "BENCH" => s(&d("bench")).to_string(),
                    "COMPARE" => s(&d("compare")).to_string(),
                    "LINK" => s(&d(name)).to_string(),
                    a => a.to_string(),
                })
                .collect();
            let refs: Vec<&str> = args.iter().map(String::as_str).collect();
            let what = if hard { "hard link" } else { "symlink" };
            let o = lightgrid(&refs);
            let err = stderr(&o);
            assert!(!o.status.success(), "{what}: {refs:?} succeeded");
            assert!(
                err.contains(needle) && err.contains("both name"),
                "{what}: {refs:?}: {err}"
            );
            let after: Vec<_> = snapshot(&dir)
                .into_iter()
                .filter(|(n, _)| !n.contains("lightgrid-"))
                .collect();
            assert_eq!(after, before, "{what}: {refs:?} changed a file");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A `.gltf` beside its buffer (`robots bin.bin`, named by a %-escaped URI as exporters
/// write spaces) and an image (`tex.png`): robots-few exported, then split.
fn gltf_with_files(dir: &Path) -> PathBuf {
    let glb = dir.join("whole.glb");
    ok(&["export", "--scene", "robots-few", "--out", s(&glb)]);
    let bytes = std::fs::read(&glb).unwrap();
    let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let mut doc: serde_json::Value = serde_json::from_slice(&bytes[20..20 + len]).unwrap();
    let bin = &bytes[20 + len + 8..];
    std::fs::write(dir.join("robots bin.bin"), bin).unwrap();
    doc["buffers"][0]["uri"] = "robots%20bin.bin".into();
    doc["images"] = serde_json::json!([{ "uri": "tex.png" }]);
    doc["textures"] = serde_json::json!([{ "source": 0 }]);
    image::RgbaImage::from_pixel(2, 2, image::Rgba([200, 10, 10, 255]))
        .save(dir.join("tex.png"))
        .unwrap();
    let gltf = dir.join("scene.gltf");
    std::fs::write(&gltf, serde_json::to_vec(&doc).unwrap()).unwrap();
    std::fs::remove_file(&glb).unwrap();
    gltf
}

#[test]
fn a_scenes_own_buffers_and_images_are_inputs() {
    let dir = temp_dir("keep-scene-files");
    let gltf = gltf_with_files(&dir);
    let scene = s(&gltf);
    // It loads as it is.
    ok(&["render", "--scene", scene, "--size", "8x8", "--warmup", "0"]);
    let before = snapshot(&dir);
    let bin = dir.join("robots bin.bin");
    let tex = dir.join("tex.png");
    let sym = dir.join("sym.glb");
    std::os::unix::fs::symlink(&bin, &sym).unwrap();
    let cases: Vec<Vec<&str>> = vec![
        vec![
            "render",
            "--scene",
            scene,
            "--size",
            "8x8",
            "--stats",
            s(&bin),
        ],
        vec![
            "render",
            "--scene",
            scene,
            "--size",
            "8x8",
            "--out",
            s(&tex),
        ],
        vec!["play", "--scene", scene, "--frames", "0", "--json", s(&bin)],
        vec!["export", "--scene", scene, "--out", s(&sym)],
    ];
    for args in &cases {
        assert_fails_with(args, "a file");
        assert_fails_with(args, "an output cannot replace an input");
    }
    std::fs::remove_file(&sym).unwrap();
    assert_eq!(snapshot(&dir), before, "the scene's files are as they were");
    ok(&["render", "--scene", scene, "--size", "8x8", "--warmup", "0"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A quick bench of stress at 70,000 lights into `out`: `forward` among `pipelines` fails
/// part-way (lavapipe cuts its loop over every light short, which lightgrid refuses).
fn stress_bench(out: &Path, pipelines: &str) -> std::process::Output {
    lightgrid(&[
        "bench",
        "--scene",
        "stress",
        "--lights",
        "70000",
        "--pipelines",
        pipelines,
        "--size",
        "32x18",
        "--frames",
        "0",
        "--warmup",
        "0",
        "--out",
        s(out),
    ])
}

#[test]
fn a_bench_that_fails_part_way_keeps_the_earlier_run() {
    let dir = temp_dir("keep-failed-bench");
    let out = dir.join("b");
    let o = stress_bench(&out, "tiled_deferred");
    assert!(o.status.success(), "{}", stderr(&o));
    let before = snapshot(&out);
    assert!(before.iter().any(|(n, _)| n == "results.json"));
    let o = stress_bench(&out, "tiled_deferred,forward");
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(
        err.contains("failed: stress / forward") && err.contains("are kept as they were"),
        "{err}"
    );
    // Every earlier file as it was; the failed run's files beside them, in a directory of
    // their own that the message names.
    let after = snapshot(&out);
    let (aside, kept): (Vec<_>, Vec<_>) = after
        .into_iter()
        .partition(|(n, _)| n.starts_with("lightgrid-bench-incomplete-"));
    assert_eq!(kept, before);
    let results = aside
        .iter()
        .find(|(n, _)| n.ends_with("/results.json"))
        .expect("the failed run's results are kept aside");
    assert!(err.contains(results.0.split('/').next().unwrap()), "{err}");
    let v: serde_json::Value = serde_json::from_slice(&results.1).unwrap();
    assert_eq!(v["outcome"]["status"], "failed");
    // A later complete run replaces the earlier one as before.
    let o = stress_bench(&out, "tiled_deferred");
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn list_values_that_name_one_series_twice_are_refused() {
    let dir = temp_dir("keep-lists");
    let glb = dir.join("robots-few-opaque.glb");
    ok(&["export", "--scene", "robots-few", "--out", s(&glb)]);
    let dot = format!("{}/./robots-few-opaque.glb", s(&dir));
    let out = dir.join("b");
    let bench = |extra: &[&str]| -> Vec<String> {
        let mut v: Vec<String> = ["bench", "--frames", "0", "--size", "8x8", "--out", s(&out)]
            .iter()
            .map(|a| a.to_string())
            .collect();
        v.extend(extra.iter().map(|a| a.to_string()));
        v
    };
    let mut cases: Vec<(Vec<String>, String)> = vec![
        (
            bench(&["--range-scale", "1,1.0"]),
            "--range-scale: 1 is listed twice".into(),
        ),
        (
            bench(&["--scene", "robots-few,robots-few"]),
            "--scene: robots-few is listed twice".into(),
        ),
        (
            bench(&["--scene", &format!("{},{dot}", s(&glb))]),
            "are the same value".into(),
        ),
        (
            bench(&["--pipelines", "forward,deferred,forward"]),
            "--pipelines: forward is listed twice".into(),
        ),
        (
            bench(&["--scene", "stress", "--lights", "5,5"]),
            "--lights: 5 is listed twice".into(),
        ),
        (
            bench(&["--spot-fraction", "0.5,0.50"]),
            "--spot-fraction: 0.5 is listed twice".into(),
        ),
        (
            bench(&["--transparency", "on,on"]),
            "--transparency: on is listed twice".into(),
        ),
        (
            bench(&[
                "--scene",
                &format!("robots-few,{}", s(&glb)),
                "--transparency",
                "on,off",
            ]),
            "would both be measured as robots-few-opaque".into(),
        ),
    ];
    // Every setting of the table, at its default value twice.
    for axis in lightgrid::pipelines::AXES {
        let v = (axis.get)(&lightgrid::RenderSettings::default());
        cases.push((
            bench(&[&axis.option(), &format!("{v},{v}")]),
            format!("{}: {v} is listed twice", axis.option()),
        ));
    }
    for args in [
        vec!["scaling", "--lights", "100,100", "--out", s(&out)],
        vec!["scaling", "--assign", "cpu,cpu", "--out", s(&out)],
        vec!["memory", "--msaa", "4,4"],
    ] {
        let flag = args[1];
        cases.push((
            args.iter().map(|a| a.to_string()).collect(),
            format!("{flag}: "),
        ));
    }
    let before = snapshot(&dir);
    for (args, needle) in &cases {
        let o = lightgrid(&args.iter().map(String::as_str).collect::<Vec<_>>());
        let err = stderr(&o);
        assert!(!o.status.success(), "{args:?} succeeded");
        let advice = needle.contains("would both") || err.contains("give each once");
        assert!(err.contains(needle.as_str()) && advice, "{args:?}: {err}");
    }
    assert!(!out.exists(), "no output directory was made");
    assert_eq!(snapshot(&dir), before);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `f` applied to every number under each key named `key` in `v`.
fn edit_numbers(v: &mut serde_json::Value, key: &str, f: &mut impl FnMut() -> serde_json::Value) {
    match v {
        serde_json::Value::Object(m) => {
            for (k, x) in m.iter_mut() {
                if k == key && x.is_number() {
                    *x = f();
                } else {
                    edit_numbers(x, key, f);
                }
            }
        }
        serde_json::Value::Array(a) => a.iter_mut().for_each(|x| edit_numbers(x, key, f)),
        _ => {}
    }
}

/// `lightgrid report DIR` under a 2 GiB address-space limit, killed after 60 s.
fn bounded_report(dir: &Path) -> (std::process::ExitStatus, String, std::time::Duration) {
    let start = std::time::Instant::now();
    let mut child = std::process::Command::new("sh")
        .args([
            "-c",
            "ulimit -v 2097152 && exec \"$0\" report \"$1\"",
            env!("CARGO_BIN_EXE_lightgrid"),
            s(dir),
        ])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let mut err = String::new();
            std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut err).unwrap();
            return (status, err, start.elapsed());
        }
        if start.elapsed() > std::time::Duration::from_secs(60) {
            let _ = child.kill();
            panic!("report did not finish in 60 s");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

#[test]
fn report_reads_results_and_changes_nothing_unless_it_succeeds() {
    let dir = temp_dir("keep-report");
    let out = dir.join("b");
    ok(&[
        "bench",
        "--scene",
        "robots-few",
        "--pipelines",
        "forward,tiled_forward",
        "--frames",
        "0..2:1",
        "--size",
        "16x8",
        "--warmup",
        "0",
        "--out",
        s(&out),
    ]);
    // Fields the report does not know stay: it does not rewrite results.json.
    let path = out.join("results.json");
    let mut v: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    v["my_note"] = "kept".into();
    v["runs"][0]["my_run_note"] = 7.into();
    std::fs::write(&path, serde_json::to_vec_pretty(&v).unwrap()).unwrap();
    let edited = std::fs::read(&path).unwrap();
    ok(&["report", s(&out)]);
    assert_eq!(std::fs::read(&path).unwrap(), edited);
    // A report that cannot write one file changes none.
    std::fs::remove_file(out.join("summary.md")).unwrap();
    std::fs::create_dir(out.join("summary.md")).unwrap();
    std::fs::remove_file(out.join("results.csv")).unwrap();
    std::fs::write(out.join("results.csv"), b"the user's edit").unwrap();
    let before = snapshot(&out);
    assert_fails_with(&["report", s(&out)], "summary.md is not a regular file");
    assert_eq!(snapshot(&out), before);
    std::fs::remove_dir(out.join("summary.md")).unwrap();
    // Extreme times: the largest and the smallest f64, negative and zero, in every series;
    // the plots' axes and ticks stay bounded.
    let extremes = [1.7e308, 5e-324, -1.0, 0.0, 1e-300, 3.0];
    let mut i = 0;
    edit_numbers(&mut v, "gpu_ms", &mut || {
        i += 1;
        serde_json::json!(extremes[i % extremes.len()])
    });
    std::fs::write(&path, serde_json::to_vec_pretty(&v).unwrap()).unwrap();
    let (status, err, took) = bounded_report(&out);
    assert!(status.success(), "{err}");
    eprintln!("report over extreme values: {took:?}");
    // A value past f64 (or NaN, which JSON cannot hold) is refused on reading.
    let text = String::from_utf8(std::fs::read(&path).unwrap()).unwrap();
    let past = text.replacen("1.7e+308", "1.7e+400", 1);
    assert!(past != text, "results.json holds 1.7e+308");
    std::fs::write(&path, past).unwrap();
    assert_fails_with(&["report", s(&out)], "results.json");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn viewer_script_bounds_are_stated_and_enforced() {
    assert_fails_with(&["view", "--script", "at 1001 pause"], "at most 'at 1000'");
    assert_fails_with(
        &["view", "--script", "resize 16384x16384"],
        "both edges must be 1 to 4096",
    );
}
