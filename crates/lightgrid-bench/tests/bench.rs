//! The benchmark: a small run produces every file, results.json has the documented layout,
//! summaries agree with the per-frame series, the ideal never exceeds any actual count, and a
//! stopped run keeps what it measured.

#[path = "../../lightgrid/tests/common/mod.rs"]
mod common;

use lightgrid_bench::{
    evaluate_claims, run, write_report, AxisValues, BenchConfig, FrameRange, TimesFrom, Verdict,
};
use serde_json::Value;
use std::sync::atomic::{AtomicBool, Ordering};

fn config() -> BenchConfig {
    BenchConfig {
        scenes: vec!["robots-many".into()],
        pipelines: [
            "forward",
            "tiled_forward",
            "tiled_forward_prez",
            "tiled_deferred",
            "deferred",
            "deferred_stencil",
            "light_prepass",
        ]
        .map(String::from)
        .to_vec(),
        frames: FrameRange::parse("0..259:129").unwrap(),
        size: Some((96, 54)),
        tile_size: 16,
        settings: vec![AxisValues {
            flag: "gbuffer".into(),
            values: vec!["16".into(), "32".into()],
        }],
        repeat: 2,
        warmup: 1,
        seed: 1,
        lights: Vec::new(),
        heatmap_frame: None,
        spot_fractions: Vec::new(),
        add_lights: None,
        heatmap_max: None,
        range_scales: vec![],
        headlights: false,
        transparency: true,
        opaque_variants: false,
        material_shaders: true,
    }
}

fn num(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("{key} is not a number in {v}"))
}

#[test]
fn a_run_writes_every_file_with_consistent_summaries() {
    // The sweep includes `--gbuffer 32`, whose 64 colour bytes per sample are beyond WebGPU's
    // default limits: the adapter's limits, as the bench command asks for natively.
    let ctx = common::gpu_with(lightgrid::gpu::DeviceLimits::Adapter);
    let cfg = config();
    let stop = AtomicBool::new(false);
    let mut calls = 0;
    let results = run(&ctx, &cfg, &stop, &mut |p| {
        calls += 1;
        assert!(p.done <= p.total);
    })
    .unwrap();
    assert!(calls > 0 && results.outcome.is_complete());
    let dir = std::env::temp_dir().join(format!("lightgrid-bench-test-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let written = write_report(&dir, &results).unwrap();
    for f in [
        "results.json",
        "results.csv",
        "summary.md",
        "frame_time_robots-many_g16.png",
        "frame_time_robots-many_g16.svg",
        "frame_time_robots-many_g32.png",
        "frame_time_robots-many_g32.svg",
        "lighting_robots-many.png",
        "lighting_robots-many.svg",
        "passes_robots-many_g16.png",
        "passes_robots-many_g32.svg",
        "heatmap_robots-many_tiled_deferred_f129.png",
    ] {
        assert!(dir.join(f).exists(), "{f} missing");
        assert!(
            written.contains(&dir.join(f)),
            "{f} not reported as written"
        );
    }

    // Pipelines without a G-buffer are measured once, the others once per precision.
    let runs_of = |p: &str| results.runs.iter().filter(|r| r.pipeline == p).count();
    assert_eq!(
        (
            runs_of("forward"),
            runs_of("tiled_forward_prez"),
            runs_of("light_prepass")
        ),
        (1, 1, 1)
    );
    assert_eq!(
        (
            runs_of("tiled_deferred"),
            runs_of("deferred"),
            runs_of("deferred_stencil")
        ),
        (2, 2, 2)
    );

    // results.json: the documented layout.
    let json: Value =
        serde_json::from_slice(&std::fs::read(dir.join("results.json")).unwrap()).unwrap();
    assert_eq!(json["schema_version"], 4);
    assert!(json["adapter"].is_string() && json["command"].is_string());
    assert_eq!(json["outcome"]["status"], "complete");
    assert_eq!(json["config"]["repeat"], 2);
    // Which figure came from where: times from the real-time path, counts from analysis.
    let sources = json["sources"].as_array().unwrap();
    let source = |key: &str| {
        sources
            .iter()
            .find(|s| s[0] == key)
            .and_then(|s| s[1].as_str())
            .unwrap_or_else(|| panic!("no source for {key}"))
            .to_string()
    };
    assert!(source("gpu_ms").starts_with("real-time path"));
    assert!(source("frame_ms").starts_with("real-time path"));
    assert!(source("lighting_computations").starts_with("analysis"));
    let runs = json["runs"].as_array().unwrap();
    assert_eq!(runs.len(), results.runs.len());
    let mut csv_rows = 0;
    for r in runs {
        for key in ["scene", "pipeline", "timing"] {
            assert!(r[key].is_string(), "{key} in {r}");
        }
        assert!(r["gbuffer_bits"].is_null() || r["gbuffer_bits"] == 16 || r["gbuffer_bits"] == 32);
        assert_eq!(
            (
                r["width"].as_u64(),
                r["height"].as_u64(),
                r["tile_size"].as_u64()
            ),
            (Some(96), Some(54), Some(16))
        );
        assert_eq!(r["complete"], true);
        assert_eq!(r["times_from"], "real-time");
        assert_eq!(r["overflow_frames"], 0);
        for f in r["frames"].as_array().unwrap() {
            assert!(f["frame_ms"].as_f64().unwrap() > 0.0, "{f}");
            assert!(f["analysis_gpu_ms"].as_f64().unwrap() > 0.0, "{f}");
            assert_eq!(
                f["gpu_ms_repeats"].as_array().unwrap().len(),
                2,
                "--repeat 2"
            );
        }
        let frames = r["frames"].as_array().unwrap();
        assert_eq!(
            frames
                .iter()
                .map(|f| f["frame"].as_u64().unwrap())
                .collect::<Vec<_>>(),
            vec![0, 129, 258]
        );
        csv_rows += frames.len();
        let mut times = Vec::new();
        let mut counts = Vec::new();
        for f in frames {
            let repeats: Vec<f64> = f["gpu_ms_repeats"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            assert_eq!(repeats.len(), 2);
            assert!(
                repeats.contains(&num(f, "gpu_ms")),
                "gpu_ms is one of the repeats (the median)"
            );
            assert!(f["passes"]
                .as_array()
                .unwrap()
                .iter()
                .all(|p| p["label"].is_string() && p["ms"].is_number()));
            let actual = num(f, "lighting_computations");
            let ideal = num(f, "ideal_lighting_computations");
            assert!(
                ideal > 0.0 && ideal <= actual,
                "{} frame {}: ideal {ideal} > actual {actual}",
                r["pipeline"],
                f["frame"]
            );
            times.push(num(f, "gpu_ms"));
            counts.push(actual);
        }
        // Summaries agree with the series.
        let s = &r["summary"];
        let check = |stat: &Value, v: &[f64]| {
            let avg = v.iter().sum::<f64>() / v.len() as f64;
            assert!(
                (num(stat, "mean") - avg).abs() <= 1e-9 * avg.max(1.0),
                "{stat} vs {v:?}"
            );
            assert_eq!(
                num(stat, "min"),
                v.iter().copied().fold(f64::INFINITY, f64::min)
            );
            assert_eq!(
                num(stat, "max"),
                v.iter().copied().fold(f64::NEG_INFINITY, f64::max)
            );
        };
        check(&s["gpu_ms"], &times);
        check(&s["lighting_computations"], &counts);
        let eff = num(s, "efficiency");
        assert!(eff > 0.0 && eff <= 1.0, "{eff}");
        assert!(num(s, "bytes_per_pixel") >= 12.0);
    }
    // results.json reads back to the same runs (what `lightgrid report` rebuilds from).
    let back = lightgrid_bench::read_results(&dir.join("results.json")).unwrap();
    assert_eq!(back.runs, results.runs);
    assert_eq!(back.config, results.config);
    let csv = std::fs::read_to_string(dir.join("results.csv")).unwrap();
    assert_eq!(
        csv.lines().count(),
        csv_rows + 1,
        "one CSV row per frame plus the header"
    );

    let summary = std::fs::read_to_string(dir.join("summary.md")).unwrap();
    for p in &cfg.pipelines {
        assert!(summary.contains(&format!("| {p}")), "summary lacks {p}");
    }
    let claims = evaluate_claims(&results);
    assert!(claims.len() >= 8);
    // The G-buffer claim is measurable with both precisions; every verdict is in summary.md.
    assert!(claims
        .iter()
        .any(|c| c.statement.contains("fatter G-buffer") && c.verdict != Verdict::NotMeasured));
    for c in &claims {
        assert!(
            summary.contains(c.statement),
            "summary lacks claim {}",
            c.statement
        );
        // A checked claim is a row of the table; one this run cannot check is listed once
        // below it, with every scene, instead of a table row per scene.
        let row = format!("| {} | {} |", c.scene, c.statement);
        let listed = format!("- {} (", c.statement);
        match c.verdict {
            Verdict::NotMeasured => {
                assert!(
                    !summary.contains(&row) && summary.matches(&listed).count() == 1,
                    "{row}"
                )
            }
            _ => assert!(summary.contains(&row), "{row}"),
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Per run the progress callback sees 1 warm-up, 3 analysis renders and 3 real-time frames
/// (frames 0, 129, 258): a stop at call `at` lands in the analysis renders of the second run
/// (10) or in the real-time pass of the first (6).
fn stopped_at(at: u32) -> lightgrid_bench::BenchResults {
    let ctx = common::gpu();
    let mut cfg = config();
    cfg.set("gbuffer", vec!["16".into()]);
    cfg.repeat = 1;
    let stop = AtomicBool::new(false);
    let mut calls = 0;
    let results = run(&ctx, &cfg, &stop, &mut |_| {
        calls += 1;
        if calls == at {
            stop.store(true, Ordering::Relaxed);
        }
    })
    .unwrap();
    assert!(matches!(
        results.outcome,
        lightgrid_bench::Outcome::Interrupted(_)
    ));
    assert!(!results.runs.is_empty() && results.runs.len() < cfg.pipelines.len());
    assert!(results
        .runs
        .last()
        .is_some_and(|r| !r.complete && r.summary.is_some()));
    results
}

#[test]
fn a_stopped_run_keeps_what_it_measured() {
    let results = stopped_at(10);
    assert_eq!(results.runs.len(), 2);
    let last = results.runs.last().unwrap();
    assert_eq!(
        last.times_from,
        TimesFrom::Analysis,
        "stopped before its real-time pass"
    );
    assert_eq!(last.frames.len(), 2);
    assert_eq!(results.runs[0].times_from, TimesFrom::RealTime);
    let dir = std::env::temp_dir().join(format!("lightgrid-bench-stop-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    write_report(&dir, &results).unwrap();
    let summary = std::fs::read_to_string(dir.join("summary.md")).unwrap();
    assert!(summary.contains("interrupted") && summary.contains("(incomplete; analysis times)"));
    std::fs::remove_dir_all(&dir).unwrap();

    // Stopped in the real-time pass: the frames it timed keep their real-time figures.
    let results = stopped_at(6);
    assert_eq!(results.runs.len(), 1);
    let r = &results.runs[0];
    assert_eq!(r.times_from, TimesFrom::RealTime);
    assert_eq!(r.frames.len(), 2);
    assert!(r
        .frames
        .iter()
        .all(|f| f.frame_ms > 0.0 && f.gpu_ms_repeats.len() == 1));
}

#[test]
fn frame_ranges_parse_and_reject_nonsense() {
    assert_eq!(FrameRange::parse("0..259:5").unwrap().frames(260).len(), 52);
    assert_eq!(
        FrameRange::parse("10..12").unwrap().frames(260),
        vec![10, 11, 12]
    );
    assert_eq!(FrameRange::parse("7").unwrap().frames(260), vec![7]);
    assert_eq!(
        FrameRange::parse("0..1000:100").unwrap().frames(260).last(),
        Some(&200)
    );
    for bad in ["5..1", "0..10:0", "a..b", "1..2:x", ""] {
        assert!(FrameRange::parse(bad).is_err(), "{bad}");
    }
}

#[test]
fn scaling_growth_reports_slopes_and_the_fastest_strategy() {
    use lightgrid_bench::{
        scaling_growth, scaling_table, ScalingConfig, ScalingPoint, ScalingResults,
    };
    let point = |lights: u32, assign: &str, ms: Option<f64>| ScalingPoint {
        lights,
        assign: assign.into(),
        skipped: ms.is_none().then(|| "over budget".into()),
        failed: None,
        assign_ms: ms,
        assign_ms_runs: ms.into_iter().collect(),
        assign_gpu_ms: None,
        assign_cpu_ms: None,
        frame_gpu_ms: None,
        grid_indices: ms.map(|_| 10),
        grid_bytes: None,
        grid_cells: None,
        grid_cells_occupied: None,
        lights_per_cell_max: None,
        lighting_computations: Some(200),
        ideal_lighting_computations: Some(100),
    };
    let r = ScalingResults {
        command: "lightgrid scaling".into(),
        adapter: "test".into(),
        software_adapter: true,
        config: ScalingConfig::default(),
        outcome: lightgrid_bench::Outcome::Complete,
        points: vec![
            point(1000, "linear", Some(10.0)),
            point(1000, "cheap", Some(5.0)),
            point(1000, "slow", Some(20.0)),
            point(1_000_000, "linear", Some(10_000.0)),
            point(1_000_000, "cheap", Some(50.0)),
            point(1_000_000, "slow", None),
        ],
    };
    let g = scaling_growth(&r);
    assert!(g.contains("- linear: 10.0 ms at 1000 lights to 10000.0 ms at 1000000 (1000x for 1000x the lights; log-log slope 1.00)"), "{g}");
    assert!(g.contains("log-log slope 0.33"), "{g}");
    assert!(
        !g.contains("- slow"),
        "one measured point has no growth: {g}"
    );
    assert!(
        g.contains("1000: cheap (5.0 ms); 1000000: cheap (50.0 ms)"),
        "{g}"
    );
    let t = scaling_table(&r);
    assert!(
        t.contains("| 1000000 | slow | skipped: over budget |"),
        "{t}"
    );
    assert!(t.contains("| 1000 | linear | 10.0 |"), "{t}");
}

/// With spots, each grid pipeline is measured once per spot culling and the report keeps them
/// apart: cone culling never lists more than sphere culling, the ideal is the same, and the
/// pipelines without a grid run once.
#[test]
fn spot_culls_are_measured_side_by_side() {
    use lightgrid::pipelines::SpotCull;
    let ctx = common::gpu();
    let cfg = BenchConfig {
        pipelines: vec!["forward".into(), "clustered_deferred".into()],
        frames: FrameRange::parse("0..259:200").unwrap(),
        repeat: 1,
        spot_fractions: vec![1.0],
        settings: vec![AxisValues {
            flag: "spot-cull".into(),
            values: vec!["sphere".into(), "cone".into()],
        }],
        ..config()
    };
    let results = run(&ctx, &cfg, &AtomicBool::new(false), &mut |_| {}).unwrap();
    let runs: Vec<(&str, Option<SpotCull>)> = results
        .runs
        .iter()
        .map(|r| (r.pipeline.as_str(), r.varied::<SpotCull>()))
        .collect();
    assert_eq!(
        runs,
        vec![
            ("forward", None),
            ("clustered_deferred", Some(SpotCull::Sphere)),
            ("clustered_deferred", Some(SpotCull::Cone)),
        ]
    );
    let (sphere, cone) = (&results.runs[1], &results.runs[2]);
    for (a, b) in sphere.frames.iter().zip(&cone.frames) {
        assert_eq!(
            a.stats.ideal_lighting_computations,
            b.stats.ideal_lighting_computations
        );
        let (a, b) = (
            a.stats.lighting_computations.unwrap(),
            b.stats.lighting_computations.unwrap(),
        );
        assert!(b < a, "cone {b} not below sphere {a}");
    }
    let dir = std::env::temp_dir().join(format!("lightgrid-bench-spots-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    write_report(&dir, &results).unwrap();
    let summary = std::fs::read_to_string(dir.join("summary.md")).unwrap();
    assert!(
        summary.contains("clustered_deferred [sphere]")
            && summary.contains("clustered_deferred [cone]")
    );
    assert!(summary.contains("spot lights: 100%"), "{summary}");
    // Test (b) measured once per frame, never listing fewer than the ideal for what it keeps.
    assert_eq!(results.spot_ray_tests.len(), sphere.frames.len());
    for t in &results.spot_ray_tests {
        assert!(
            t.count.lit_pairs > 0 && t.count.missed_pairs <= t.count.lit_pairs,
            "{t:?}"
        );
        assert!(t.count.lighting_computations > 0);
    }
    assert!(summary.contains("Spot test (b)"), "{summary}");
    let csv = std::fs::read_to_string(dir.join("results.csv")).unwrap();
    assert!(csv.lines().next().unwrap().contains("spot_cull"));
    assert_eq!(
        csv.lines().filter(|l| l.contains(",sphere,")).count(),
        sphere.frames.len()
    );
    let back = lightgrid_bench::read_results(&dir.join("results.json")).unwrap();
    assert_eq!(back.runs, results.runs);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A spot-fraction list measures every scene once per fraction, named for the fractions above
/// 0 (the culling preset's all-spot scenes); the all-spot scene's lights are all spots and the
/// other's none; a fraction listed twice is refused; a results file written when the fraction
/// was one number reads as a list of one.
#[test]
fn spot_fraction_lists_measure_each_scene_once_per_fraction() {
    let cfg = BenchConfig {
        scenes: vec!["robots-few".into(), "stress".into()],
        lights: vec![50],
        spot_fractions: vec![0.0, 1.0],
        ..config()
    };
    let prepared = lightgrid_bench::prepare(&cfg).unwrap();
    let names: Vec<&str> = prepared.scenes().iter().map(|s| s.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "robots-few",
            "robots-few-spots-1",
            "stress",
            "stress-spots-1"
        ]
    );
    for s in prepared.scenes() {
        let spots = s.lights.iter().filter(|l| l.light.spot.is_some()).count();
        assert!(!s.lights.is_empty(), "{}", s.name);
        match s.name.contains(lightgrid_bench::SPOTS_SUFFIX) {
            true => assert_eq!(spots, s.lights.len(), "{}", s.name),
            false => assert_eq!(spots, 0, "{}", s.name),
        }
    }
    let twice = BenchConfig {
        spot_fractions: vec![1.0, 0.0, 1.0],
        ..cfg.clone()
    };
    let e = lightgrid_bench::prepare(&twice).err().expect("refused");
    assert!(e.to_string().contains("listed twice"), "{e}");
    let mut old = serde_json::to_value(&cfg).unwrap();
    let fields = old.as_object_mut().unwrap();
    fields
        .remove("spot_fractions")
        .expect("the list is written");
    fields.insert("spot_fraction".into(), serde_json::json!(0.5));
    let read: BenchConfig = serde_json::from_value(old).unwrap();
    assert_eq!(read.spot_fractions, vec![0.5]);
}
