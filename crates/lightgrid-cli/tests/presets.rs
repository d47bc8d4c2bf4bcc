//! The benchmark presets of issue 17 at smoke size: each runs, measures what it is for and
//! writes its claims with evidence.

mod support;

use support::{assert_fails_with, lightgrid, stderr, temp_dir};

fn bench(args: &[&str]) -> std::path::PathBuf {
    let dir = temp_dir(&format!("preset-{}", args[1]));
    let out = dir.join("b");
    let mut all = vec!["bench"];
    all.extend(args);
    all.extend(["--out", out.to_str().unwrap()]);
    let o = lightgrid(&all);
    assert!(o.status.success(), "{all:?}: {}", stderr(&o));
    out
}

/// The culling preset measures every grid with and without 2.5D depth masks and tight cell
/// boxes, and z-binned, on its four scenes: neither masks nor boxes ever add lighting
/// computations, the boxes take some away over the run, and each claim (Harada's, tight
/// clusters', Drobot's) is judged per scene and pipeline.
#[test]
fn culling_preset_measures_every_grid_with_and_without_masks_and_boxes() {
    let out = bench(&[
        "--preset",
        "culling",
        "--size",
        "96x54",
        "--frames",
        "0..259:130",
    ]);
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|c| *c == name)
            .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
    };
    let (mask, cell_box, pipe, scene, frame, assign) = (
        col("depth_mask"),
        col("cell_box"),
        col("pipeline"),
        col("scene"),
        col("frame"),
        col("assign"),
    );
    let lit = col("lighting_computations");
    let mut counts = std::collections::BTreeMap::new();
    for line in csv.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let key = (
            f[scene].to_string(),
            f[pipe].to_string(),
            f[frame].to_string(),
        );
        let n: u64 = f[lit].parse().unwrap();
        // Z-binning's runs have no masks or boxes (they do not apply to it).
        let variant = match f[assign] {
            "zbin" => ("zbin".to_string(), "zbin".to_string()),
            _ => (f[mask].to_string(), f[cell_box].to_string()),
        };
        counts
            .entry(key)
            .or_insert_with(std::collections::BTreeMap::new)
            .insert(variant, n);
    }
    let scenes: std::collections::BTreeSet<&str> = counts.keys().map(|k| k.0.as_str()).collect();
    // robots-many, robots-few, scattered and stress at 10,000 lights (100,000 only on a
    // hardware GPU), each as it is and all-spot.
    assert_eq!(scenes.len(), 8, "{scenes:?}");
    for s in ["robots-many", "robots-few", "scattered", "stress"] {
        assert!(scenes.contains(s), "{s} not in {scenes:?}");
        let spots = format!("{s}-spots-1");
        assert!(scenes.contains(spots.as_str()), "{spots} not in {scenes:?}");
    }
    for p in [
        "tiled_forward_prez",
        "tiled_deferred",
        "clustered_forward",
        "clustered_deferred",
    ] {
        assert!(counts.keys().any(|k| k.1 == p), "{p} not measured");
    }
    let v = |m: &str, b: &str| (m.to_string(), b.to_string());
    let (mut boxed, mut plain) = (0, 0);
    for (key, by) in &counts {
        assert_eq!(by.len(), 5, "{key:?}: {by:?}");
        let off = by[&v("off", "off")];
        for (variant, n) in by.iter().filter(|(v, _)| v.0 != "zbin") {
            assert!(*n <= off, "{key:?}: {n} with {variant:?}, {off} without");
        }
        assert!(by[&v("zbin", "zbin")] > 0, "{key:?}: {by:?}");
        assert!(by[&v("on", "on")] <= by[&v("off", "on")], "{key:?}: {by:?}");
        boxed += by[&v("off", "on")];
        plain += off;
    }
    assert!(
        boxed < plain,
        "the boxes dropped no light: {boxed} of {plain}"
    );
    // Harada's claim on the two tiled grids and the tight-cluster claim on the two clustered
    // ones, per scene, each with its evidence and a verdict.
    let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
    // Per scene, every grid's assignment share and memory.
    let sections = summary.matches("### Culling: the grids'").count();
    assert_eq!(sections, 8, "{summary}");
    let rows: Vec<&str> = (summary.lines())
        .filter(|l| l.starts_with("| clustered_forward [zbin] |") && l.split('|').count() == 8)
        .collect();
    assert_eq!(rows.len(), 8, "{rows:#?}");
    for row in rows {
        assert!(row.contains("%)"), "no assignment share in {row}");
        let kib: f64 = row.split('|').nth(6).unwrap().trim().parse().unwrap();
        assert!(kib > 0.0, "no grid memory in {row}");
    }
    for (claim, pipelines) in [
        (
            "2.5D culling (a 32-bit mask",
            ["tiled_forward_prez", "tiled_deferred"],
        ),
        (
            "Tight clusters (each cluster",
            ["clustered_forward", "clustered_deferred"],
        ),
        (
            "Z-binning (lights sorted by depth",
            ["clustered_forward", "clustered_deferred"],
        ),
    ] {
        let lines: Vec<&str> = summary.lines().filter(|l| l.contains(claim)).collect();
        assert_eq!(lines.len(), 8 * 2, "'{claim}': {lines:#?}");
        for l in &lines {
            assert!(
                pipelines.iter().any(|p| l.contains(&format!("| {p}: "))),
                "{l}"
            );
            assert!(l.contains("lighting computations with"), "{l}");
            assert!(
                l.contains("**held**") || l.contains("**did not hold**"),
                "{l}"
            );
        }
    }
}

/// `--lights` as a list measures each scene that takes a light count once per count, named
/// by it, and the other scenes once.
#[test]
fn a_light_count_list_measures_each_count() {
    let out = bench(&[
        "--scene",
        "stress,robots-few",
        "--lights",
        "50,80",
        "--pipelines",
        "forward",
        "--size",
        "64x36",
        "--frames",
        "0..0:1",
    ]);
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let scene = header.iter().position(|c| *c == "scene").unwrap();
    let mut names: Vec<&str> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(scene).unwrap())
        .collect();
    names.sort();
    names.dedup();
    assert_eq!(
        names,
        ["robots-few", "stress-50-lights", "stress-80-lights"]
    );
    // Each with its own light count (the frames' records).
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    let text = json.to_string();
    assert!(
        text.contains("\"lights\":50") && text.contains("\"lights\":80"),
        "{text:.400}"
    );
}

#[test]
fn depth_bounds_preset_measures_every_step_and_checks_its_claims() {
    let out = bench(&[
        "--preset",
        "depth-bounds",
        "--size",
        "96x54",
        "--frames",
        "0..259:130",
    ]);
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|c| *c == "depth_bounds").unwrap();
    let pipe = header.iter().position(|c| *c == "pipeline").unwrap();
    let mut seen = std::collections::BTreeSet::new();
    for line in csv.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        seen.insert((f[pipe].to_string(), f[col].to_string()));
    }
    for p in ["tiled_forward_prez", "clustered_forward"] {
        for b in ["both", "min", "max", "none"] {
            assert!(
                seen.contains(&(p.to_string(), b.to_string())),
                "{p} {b}: {seen:?}"
            );
        }
    }
    assert!(seen.contains(&("tiled_forward".to_string(), String::new())));
    let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
    for claim in [
        "A depth pre-pass alone makes tiled forward shading faster",
        "Depth bounds after the pre-pass make it faster again",
        "One side of the depth bounds (min or max only) is enough",
        "With clusters too, one side of the depth bounds",
    ] {
        let line = summary
            .lines()
            .find(|l| l.contains(claim))
            .unwrap_or_else(|| panic!("no claim '{claim}' in summary.md"));
        assert!(line.contains("avg ms"), "{line}");
        assert!(
            line.contains("**held**") || line.contains("**did not hold**"),
            "{line}"
        );
    }
    assert!(
        summary.contains("tiled_forward_prez [bounds min]"),
        "series rows are labelled"
    );
}

#[test]
fn forward_plus_preset_draws_the_heatmap_on_the_papers_scale() {
    let out = bench(&[
        "--preset",
        "forward-plus",
        "--size",
        "96x54",
        "--frames",
        "0..259:259",
    ]);
    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("results.json")).unwrap()).unwrap();
    assert_eq!(v["config"]["heatmap_max"], 50);
    // Forward+'s 14,400 tiles: 8x8 at 1280x720, 4x4 at a software adapter's 640x360 (the
    // preset's size; `--size` here only makes the test quick).
    let tile = if v["software_adapter"] == true { 4 } else { 8 };
    assert_eq!(v["config"]["tile_size"], tile);
    assert_eq!(v["config"]["scenes"][0], "scattered");
    // Its claims name the paper's conditions and how this small run differs from them.
    let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(
        summary.contains("- **forward-plus** measured on an AMD Radeon HD 6970 at 1280x720 with 8-px tiles (14400 tiles); this run differs in the adapter")
            && summary.contains("the frame size (96x54)"),
        "{summary}"
    );
    let runs = v["runs"].as_array().unwrap();
    assert!(runs.iter().any(|r| r["pipeline"] == "tiled_forward_prez"));
    let heatmap = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| {
            p.file_name()
                .unwrap()
                .to_str()
                .unwrap()
                .starts_with("heatmap_scattered")
        })
        .expect("a heatmap");
    let img = image::open(heatmap).unwrap().to_rgba8();
    assert_eq!(img.width(), 96, "the frame's width (the legend fits)");
    // Fig. 3's stages: every pass of both pipelines has its stage (a renamed pass would make
    // the claim unmeasured, naming the pass).
    let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
    let line = measured_claim(
        &summary,
        "scattered",
        "Forward+ is faster in total than compute-based deferred lighting",
    );
    assert!(
        line.contains("pre-pass + culling and lighting + final shading"),
        "{line}"
    );
}

#[test]
fn a_fixed_heatmap_scale_changes_the_colours_and_is_checked() {
    let dir = temp_dir("heatmap-max");
    let (a, b) = (dir.join("a.png"), dir.join("b.png"));
    for (path, max) in [(&a, None), (&b, Some("5"))] {
        let mut args = vec![
            "render",
            "--scene",
            "robots-few",
            "--pipeline",
            "tiled_deferred",
            "--size",
            "64x36",
            "--heatmap",
            path.to_str().unwrap(),
        ];
        if let Some(m) = max {
            args.extend(["--heatmap-max", m]);
        }
        let o = lightgrid(&args);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    assert_ne!(
        image::open(&a).unwrap().to_rgba8(),
        image::open(&b).unwrap().to_rgba8(),
        "a scale of 5 saturates what the frame's own maximum does not"
    );
    for bad in ["0", "-1", "NaN", "1000001"] {
        assert_fails_with(
            &[
                "render",
                "--heatmap",
                a.to_str().unwrap(),
                "--heatmap-max",
                bad,
            ],
            "--heatmap-max",
        );
    }
    assert_fails_with(&["render", "--heatmap-max", "50"], "--heatmap");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn light_range_preset_sweeps_the_ranges_and_checks_fig_4_2a() {
    let out = bench(&[
        "--preset",
        "light-range",
        "--size",
        "64x36",
        "--frames",
        "0..259:259",
    ]);
    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("results.json")).unwrap()).unwrap();
    // Fig. 4.2(a)'s tile count: 32-px tiles at 1920x1080, 5-px at a software adapter's
    // 320x180 (21 at a hardware one's 1280x720).
    let tile = if v["software_adapter"] == true { 5 } else { 21 };
    assert_eq!(v["config"]["tile_size"], tile);
    let scenes: std::collections::BTreeSet<&str> = v["runs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["scene"].as_str().unwrap())
        .collect();
    // Every factor without the robots' glass (the paper's scene has none).
    assert_eq!(v["config"]["transparency"], false);
    assert!(v["runs"]
        .as_array()
        .unwrap()
        .iter()
        .all(|r| r["frames"][0]["transparent_fragments"].as_u64().unwrap() == 0));
    for f in ["0.5", "1", "2", "4", "8", "16"] {
        assert!(
            scenes.contains(format!("robots-many-range-x{f}").as_str()),
            "{scenes:?}"
        );
    }
    // Lights per tile grow with the range (the same lights, larger spheres).
    let per_tile = |f: &str| {
        v["runs"]
            .as_array()
            .unwrap()
            .iter()
            .find(|r| {
                r["scene"] == format!("robots-many-range-x{f}") && r["pipeline"] == "tiled_deferred"
            })
            .unwrap()["summary"]["lights_per_tile_avg"]
            .as_f64()
            .unwrap()
    };
    assert!(per_tile("0.5") < per_tile("4") && per_tile("4") < per_tile("16"));
    let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
    for claim in [
        "Lights too large leave nothing to cull",
        "The gain of tiled shading over brute force shrinks",
    ] {
        let line = summary.lines().find(|l| l.contains(claim)).expect(claim);
        assert!(
            line.contains("**held**") || line.contains("**did not hold**"),
            "{line}"
        );
    }
    let fresh = out.with_file_name("never");
    for bad in ["0", "-1", "NaN", "1001"] {
        assert_fails_with(
            &[
                "bench",
                "--range-scale",
                bad,
                "--out",
                fresh.to_str().unwrap(),
            ],
            "--range-scale",
        );
    }
    assert!(!fresh.exists(), "a refused run creates nothing");
}

#[test]
fn both_depth_reductions_are_measured_side_by_side() {
    let out = bench(&[
        "--pipelines",
        "tiled_deferred,forward",
        "--depth-reduction",
        "atomics,subgroup",
        "--size",
        "64x36",
        "--frames",
        "0..259:130",
    ]);
    let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(
        summary.contains("tiled_deferred [subgroup reduction]"),
        "series rows are labelled"
    );
    let line = summary
        .lines()
        .find(|l| l.contains("A subgroup (warp-level) min/max reduction"))
        .expect("the claim");
    assert!(line.contains("cell-bounds pass avg ms: atomics"), "{line}");
    // results.csv tells the two series apart.
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = header
        .iter()
        .position(|c| *c == "depth_reduction")
        .expect("a depth_reduction column");
    let seen: std::collections::BTreeSet<&str> = csv
        .lines()
        .skip(1)
        .filter(|l| l.contains(",tiled_deferred,"))
        .map(|l| l.split(',').nth(col).unwrap())
        .collect();
    assert_eq!(seen, ["atomics", "subgroup"].into_iter().collect());
    assert_fails_with(
        &[
            "render",
            "--pipeline",
            "forward",
            "--depth-reduction",
            "subgroup",
        ],
        "--depth-reduction does not apply to forward",
    );
}

/// The line of `claim` on `scene` in summary.md, which must have a verdict.
fn measured_claim<'a>(summary: &'a str, scene: &str, claim: &str) -> &'a str {
    let line = summary
        .lines()
        .find(|l| l.starts_with(&format!("| {scene} |")) && l.contains(claim))
        .unwrap_or_else(|| panic!("no claim '{claim}' on {scene} in summary.md"));
    assert!(
        line.contains("**held**") || line.contains("**did not hold**"),
        "{line}"
    );
    line
}

#[test]
fn paper_preset_measures_every_pipeline_and_checks_the_papers_claims() {
    let out = bench(&[
        "--preset",
        "paper",
        "--size",
        "96x54",
        "--frames",
        "0..259:100",
    ]);
    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("results.json")).unwrap()).unwrap();
    let runs = v["runs"].as_array().unwrap();
    // Every pipeline but the mono-specular references, on both scenes, at the papers' tiles.
    for p in lightgrid::pipelines::PIPELINES {
        let only_a_reference = p.reference == p.id && p.id != lightgrid::pipelines::REFERENCE;
        for scene in ["robots-many", "robots-few"] {
            let n = runs
                .iter()
                .filter(|r| r["scene"] == scene && r["pipeline"] == p.id)
                .count();
            let expected = if only_a_reference {
                0
            } else if p.uses_gbuffer() {
                2
            } else {
                1
            };
            assert_eq!(n, expected, "{scene} {}", p.id);
        }
    }
    // The papers' tile count: 32-px tiles at 1920x1080, 11-px tiles at a software
    // adapter's 640x360 (the preset's size; `--size` here only makes the test quick).
    let tile = if v["software_adapter"] == true {
        11
    } else {
        32
    };
    assert!(
        runs.iter().all(|r| r["tile_size"] == tile),
        "{tile}-pixel tiles"
    );
    // Without the robots' glass, which the papers' scenes do not have.
    assert_eq!(v["config"]["transparency"], false);
    let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(summary.contains("transparent objects off"), "{summary}");
    assert!(summary.contains("the papers': 2040 for 32-px tiles at 1920x1080"));
    // Where the run's conditions differ from each paper's, said once per paper.
    assert!(
        summary.contains("- **tiled-shading** measured on an NVIDIA GTX 280 or GTX 480 at 1920x1080 with 32-px tiles (2040 tiles); this run differs in the adapter"),
        "{summary}"
    );
    // Each claim's paper wording, threshold and verdict; the model verdicts labelled.
    assert!(summary.contains(
        "| scene | claim (the paper's words) | source | threshold | measured | verdict |"
    ));
    assert!(
        summary
            .contains("\"by about 25%\": tiled_forward_prez ÷ tiled_deferred avg ms 1.15 to 1.35"),
        "{summary}"
    );
    assert!(summary.contains(" (model) |"), "{summary}");
    for (scene, claim) in [
        ("robots-many", "Tiled deferred has the fastest worst case"),
        (
            "robots-few",
            "With few lights, tiled forward shading is competitive",
        ),
        (
            "robots-many",
            "tiled forward with pre-Z is about four times slower",
        ),
        ("robots-many", "Deferred-Stencil is competitive"),
        (
            "robots-many",
            "Forward+ is faster in total than compute-based deferred lighting",
        ),
    ] {
        measured_claim(&summary, scene, claim);
    }
    // The blog's break-evens, with the layouts' budgets and crossing as the reason.
    for scene in ["robots-many", "robots-few"] {
        for claim in [
            "writes more than deferred shading once more than 0.5 lights",
            "With monochrome specular on both sides, deferred lighting writes as much",
            "With monochrome specular on both sides, deferred lighting reads less",
        ] {
            let line = measured_claim(&summary, scene, claim);
            assert!(line.contains("bytes per pixel + per lit pixel"), "{line}");
        }
        let line = measured_claim(
            &summary,
            scene,
            "deferred lighting needs less render-target memory",
        );
        // The memory model's bytes per pixel at the preset's settings (the light-volume
        // pipelines' float depth + stencil copy included).
        let bytes = |id: &str| {
            lightgrid::pipelines::find(id)
                .unwrap()
                .memory_model(&lightgrid::RenderSettings::default())
                .bytes_per_pixel()
        };
        let want = format!(
            "light_prepass_mono {} B, deferred_mono {} B",
            bytes("light_prepass_mono"),
            bytes("deferred_mono")
        );
        assert!(line.contains(&want), "{line} (wanted {want})");
    }
}

#[test]
fn clustered_preset_checks_fig_4_6_on_both_views() {
    let out = bench(&[
        "--preset",
        "clustered",
        "--size",
        "96x54",
        "--frames",
        "0..119:60",
    ]);
    // Fig. 4.6's tile count: 32-px tiles at 1920x1080, 11-px at a software adapter's
    // 640x360.
    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("results.json")).unwrap()).unwrap();
    let tile = if v["software_adapter"] == true {
        11
    } else {
        32
    };
    assert_eq!(v["config"]["tile_size"], tile);
    let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
    measured_claim(
        &summary,
        "random-top",
        "In the top-down view tiled forward outperforms",
    );
    measured_claim(
        &summary,
        "random-fps",
        "In the first-person view tiled forward becomes slower",
    );
    measured_claim(
        &summary,
        "random-top vs random-fps",
        "Clustered shading depends much less on the view",
    );
}

/// The grid-storage preset measures tiled forward with and without pre-Z with the grid in
/// buffers (CPU and GPU assignment) and in textures (CPU only: `--assign` does not apply to
/// it, so no series is doubled): the texture grid lists exactly what `--assign cpu` lists
/// (the same CPU assignment), and every run is timed.
#[test]
fn grid_storage_preset_measures_buffers_and_textures_side_by_side() {
    let out = bench(&[
        "--preset",
        "grid-storage",
        "--size",
        "96x54",
        "--frames",
        "0..259:130",
    ]);
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|c| *c == name).unwrap();
    let (scene, pipe, frame, storage, assign, lit, gpu) = (
        col("scene"),
        col("pipeline"),
        col("frame"),
        col("grid_storage"),
        col("assign"),
        col("lighting_computations"),
        col("gpu_ms"),
    );
    let mut counts = std::collections::BTreeMap::new();
    for line in csv.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let series = format!("{}/{}", f[storage], f[assign]);
        let n: u64 = f[lit].parse().unwrap();
        assert!(f[gpu].parse::<f64>().unwrap() > 0.0, "{line}: untimed");
        let key = (
            f[scene].to_string(),
            f[pipe].to_string(),
            f[frame].to_string(),
        );
        counts
            .entry(key)
            .or_insert_with(std::collections::BTreeMap::new)
            .insert(series, n);
    }
    assert!(!counts.is_empty());
    for (key, series) in &counts {
        let names: Vec<&str> = series.keys().map(String::as_str).collect();
        assert_eq!(
            names,
            ["buffers/cpu", "buffers/gather", "textures/"],
            "{key:?}: the series"
        );
        assert_eq!(
            series["textures/"], series["buffers/cpu"],
            "{key:?}: the texture grid is the CPU grid"
        );
    }
}
