//! glTF on the command line, as a user runs it: `export` writes a catalog scene, `render`,
//! `compare`, `play` and `bench` take the file with `--scene`, `--add-lights` fills it,
//! `--camera` chooses its camera; every new option and path is tried with zero, one, huge,
//! negative, NaN, a directory, a device and another output, and refused clearly, touching
//! nothing.

mod support;

use std::path::Path;
use support::{assert_fails_with, lightgrid, stderr, temp_dir, with_animation};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn ok(args: &[&str]) -> String {
    let o = lightgrid(args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn export_then_render_compare_play_and_bench_the_file() {
    let dir = temp_dir("gltf-flow");
    let glb = dir.join("street.glb");
    let out = ok(&[
        "export",
        "--scene",
        "robots-few",
        "--frame",
        "40",
        "--out",
        s(&glb),
    ]);
    assert!(out.contains("written to"), "{out}");
    // The file renders like the catalog scene at that frame.
    let (a, b) = (dir.join("a.png"), dir.join("b.png"));
    let size = ["--size", "96x54", "--warmup", "0"];
    let mut file_args = vec!["render", "--scene", s(&glb), "--out", s(&a)];
    file_args.extend(size);
    ok(&file_args);
    let mut cat_args = vec![
        "render",
        "--scene",
        "robots-few",
        "--frame",
        "40",
        "--out",
        s(&b),
    ];
    cat_args.extend(size);
    ok(&cat_args);
    let diff = ok(&["diff", s(&a), s(&b), "--max-mean", "0.05"]);
    assert!(diff.contains("mean"), "{diff}");
    // Added lights, every pipeline.
    let cmp = dir.join("cmp");
    let table = ok(&[
        "compare",
        "--scene",
        s(&glb),
        "--add-lights",
        "200",
        "--size",
        "64x36",
        "--warmup",
        "0",
        "--out-dir",
        s(&cmp),
    ]);
    assert!(table.contains("211 lights"), "{table}");
    assert!(table.contains("clustered_deferred"), "{table}");
    // The orbit runs in real time and in the benchmark.
    let played = ok(&[
        "play",
        "--scene",
        s(&glb),
        "--frames",
        "0..20:10",
        "--size",
        "32x18",
        "--warmup",
        "0",
        "--pipeline",
        "tiled_deferred",
    ]);
    assert!(played.contains("fps"), "{played}");
    let bench = dir.join("bench");
    ok(&[
        "bench",
        "--scene",
        s(&glb),
        "--add-lights",
        "64",
        "--pipelines",
        "forward,clustered_forward",
        "--frames",
        "0..100:100",
        "--size",
        "32x18",
        "--warmup",
        "0",
        "--out",
        s(&bench),
    ]);
    let summary = std::fs::read_to_string(bench.join("summary.md")).unwrap();
    assert!(summary.contains("## street"), "{summary}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_files_and_options_are_refused_and_touch_nothing() {
    let dir = temp_dir("gltf-bad");
    let d = s(&dir);
    let glb = dir.join("scene.glb");
    ok(&["export", "--scene", "robots-few", "--out", s(&glb)]);
    let before = std::fs::read(&glb).unwrap();
    let junk = dir.join("junk.gltf");
    std::fs::write(&junk, b"{\"asset\": {\"version\": \"2.0\"}, \"nodes\": 7}").unwrap();
    let folder = dir.join("folder.glb");
    std::fs::create_dir(&folder).unwrap();
    let fifo = dir.join("pipe.glb");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    let png = dir.join("out.png");
    let new_glb = dir.join("n.glb");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["render", "--scene", s(&junk)],
            "junk.gltf: malformed JSON",
        ),
        (vec!["render", "--scene", s(&folder)], "not a regular file"),
        (vec!["render", "--scene", "/dev/null.glb"], "/dev/null.glb"),
        (
            vec!["render", "--scene", s(&fifo)],
            "pipe.glb is not a regular file",
        ),
        (
            vec!["export", "--scene", "robots-few", "--out", s(&fifo)],
            "not a regular file",
        ),
        (
            vec!["render", "--scene", "/nonexistent/x.gltf"],
            "No such file",
        ),
        (
            vec!["render", "--scene", s(&glb), "--lights", "5"],
            "does not apply to glTF files",
        ),
        (
            vec!["render", "--scene", s(&glb), "--headlights"],
            "does not apply to glTF files",
        ),
        (
            vec!["render", "--scene", s(&glb), "--camera", "3"],
            "the file has 1 camera",
        ),
        (
            vec!["render", "--scene", s(&glb), "--camera", "-1"],
            "--camera",
        ),
        (
            vec!["render", "--scene", "robots-few", "--camera", "0"],
            "catalog scenes have their own camera",
        ),
        (
            vec!["render", "--scene", s(&glb), "--add-lights", "0"],
            "out of range 1 to 1048576",
        ),
        (
            vec!["render", "--scene", s(&glb), "--add-lights", "-3"],
            "--add-lights",
        ),
        (
            vec!["render", "--scene", s(&glb), "--add-lights", "99999999"],
            "out of range 1 to 1048576",
        ),
        (
            vec![
                "render",
                "--scene",
                s(&glb),
                "--add-lights",
                "5",
                "--light-range",
                "NaN",
            ],
            "not a positive number",
        ),
        (
            vec![
                "render",
                "--scene",
                s(&glb),
                "--add-lights",
                "5",
                "--light-range",
                "0",
            ],
            "not a positive number",
        ),
        (
            vec![
                "render",
                "--scene",
                s(&glb),
                "--add-lights",
                "5",
                "--light-range",
                "-2",
            ],
            "not a positive number",
        ),
        (
            vec!["render", "--scene", s(&glb), "--light-range", "4"],
            "give --add-lights N",
        ),
        (
            vec![
                "bench",
                "--scene",
                s(&glb),
                "--light-range",
                "4",
                "--out",
                d,
            ],
            "give --add-lights N",
        ),
        (
            vec!["render", "--scene", s(&glb), "--out", s(&glb)],
            "name the file *.png",
        ),
        (
            vec!["render", "--scene", s(&glb), "--stats", s(&glb)],
            "an output cannot replace an input",
        ),
        (
            vec!["export", "--scene", "robots-few", "--out", s(&png)],
            "name the file *.glb",
        ),
        (
            vec!["export", "--scene", "robots-few", "--out", s(&folder)],
            "is a directory",
        ),
        (
            vec!["export", "--scene", "robots-few", "--out", "/dev/null"],
            "name the file *.glb",
        ),
        (
            vec!["export", "--scene", s(&glb), "--out", s(&glb)],
            "an output cannot replace an input",
        ),
        (
            vec![
                "export",
                "--scene",
                "robots-few",
                "--frame",
                "999",
                "--out",
                s(&png),
            ],
            "*.glb",
        ),
        (
            vec![
                "export",
                "--scene",
                "robots-few",
                "--frame",
                "999",
                "--out",
                s(&new_glb),
            ],
            "is past the end of robots-few (frames 0..=259)",
        ),
        (
            vec!["export", "--scene", "nope", "--out", s(&new_glb)],
            "unknown scene 'nope'",
        ),
    ];
    for (args, needle) in &cases {
        assert_fails_with(args, needle);
    }
    assert_eq!(
        std::fs::read(&glb).unwrap(),
        before,
        "the scene file was changed"
    );
    let mut left: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(
        left,
        ["folder.glb", "junk.gltf", "pipe.glb", "scene.glb"],
        "something was created"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A GLB with its JSON chunk edited by `edit` (the binary chunk kept).
fn edit_glb(glb: &[u8], edit: impl FnOnce(&mut serde_json::Value)) -> Vec<u8> {
    let len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let mut doc: serde_json::Value = serde_json::from_slice(&glb[20..20 + len]).unwrap();
    edit(&mut doc);
    let mut json = serde_json::to_vec(&doc).unwrap();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let bin = &glb[20 + len..];
    let mut out = b"glTF".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&((12 + 8 + json.len() + bin.len()) as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(bin);
    out
}

#[test]
fn skipped_parts_are_warnings_and_required_ones_errors() {
    let dir = temp_dir("gltf-warn");
    let glb = dir.join("scene.glb");
    ok(&["export", "--scene", "robots-few", "--out", s(&glb)]);
    let bytes = std::fs::read(&glb).unwrap();
    let warned = dir.join("warned.glb");
    std::fs::write(
        &warned,
        edit_glb(&bytes, |d| {
            d["extensionsUsed"] = serde_json::json!(["KHR_lights_punctual", "KHR_materials_sheen"]);
            d["extensions"]["KHR_lights_punctual"]["lights"][0] =
                serde_json::json!({"type": "directional"});
        }),
    )
    .unwrap();
    let o = lightgrid(&[
        "render",
        "--scene",
        s(&warned),
        "--size",
        "32x18",
        "--warmup",
        "0",
    ]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("warning:") && err.contains("KHR_materials_sheen"),
        "{err}"
    );
    assert!(err.contains("directional"), "{err}");
    let required = dir.join("required.glb");
    std::fs::write(
        &required,
        edit_glb(&bytes, |d| {
            d["extensionsRequired"] = serde_json::json!(["KHR_mesh_quantization"])
        }),
    )
    .unwrap();
    assert_fails_with(
        &["render", "--scene", s(&required)],
        "requires extension KHR_mesh_quantization",
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn two_files_with_one_name_are_two_scenes_in_a_bench() {
    let dir = temp_dir("gltf-same-name");
    let (a, b) = (dir.join("a"), dir.join("b"));
    std::fs::create_dir_all(&a).unwrap();
    std::fs::create_dir_all(&b).unwrap();
    let (ga, gb) = (a.join("model.glb"), b.join("model.glb"));
    ok(&["export", "--scene", "robots-few", "--out", s(&ga)]);
    ok(&["export", "--scene", "random-top", "--out", s(&gb)]);
    let bench = dir.join("bench");
    let scenes = format!("{},{}", s(&ga), s(&gb));
    let o = lightgrid(&[
        "bench",
        "--scene",
        &scenes,
        "--pipelines",
        "forward",
        "--frames",
        "0",
        "--size",
        "16x8",
        "--warmup",
        "0",
        "--out",
        s(&bench),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("another scene is named model; this one is model-2"),
        "{}",
        stderr(&o)
    );
    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(bench.join("results.json")).unwrap()).unwrap();
    let mut names: Vec<&str> = v["runs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["scene"].as_str().unwrap())
        .collect();
    names.sort();
    assert_eq!(names, ["model", "model-2"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_files_own_animation_plays_and_benches() {
    let dir = temp_dir("gltf-animated");
    let glb = dir.join("scene.glb");
    ok(&["export", "--scene", "robots-few", "--out", s(&glb)]);
    let animated = dir.join("animated.glb");
    std::fs::write(&animated, with_animation(&std::fs::read(&glb).unwrap())).unwrap();
    // One second at 30 frames per second: 31 frames, played from the file's camera.
    let json = dir.join("play.json");
    let o = lightgrid(&[
        "play",
        "--scene",
        s(&animated),
        "--size",
        "32x18",
        "--json",
        s(&json),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(v["frames"], 31, "{v}");
    // The bench measures its frames; the light moves between them (its pool with it).
    let out = dir.join("bench");
    let o = lightgrid(&[
        "bench",
        "--scene",
        s(&animated),
        "--pipelines",
        "forward,clustered_forward",
        "--frames",
        "0..30:15",
        "--size",
        "48x27",
        "--warmup",
        "0",
        "--out",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("results.json")).unwrap()).unwrap();
    let frames: Vec<u64> = v["runs"][0]["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["frame"].as_u64().unwrap())
        .collect();
    assert_eq!(frames, [0, 15, 30]);
    // The file's frames are rendered as they move: frame 0 and frame 30 differ.
    let (a, b) = (dir.join("a.png"), dir.join("b.png"));
    ok(&[
        "render",
        "--scene",
        s(&animated),
        "--size",
        "64x36",
        "--out",
        s(&a),
    ]);
    ok(&[
        "render",
        "--scene",
        s(&animated),
        "--size",
        "64x36",
        "--frame",
        "30",
        "--out",
        s(&b),
    ]);
    assert_ne!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    std::fs::remove_dir_all(&dir).unwrap();
}
