//! `lightgrid advise` as a user runs it: a tiny budget still measures and recommends, the
//! ranking is ordered by what was measured, the JSON says the same as the table, and bad
//! budgets and outputs are refused.

mod support;

use support::{assert_fails_with, lightgrid, stderr, temp_dir};

#[test]
fn a_small_budget_ranks_what_it_measured_and_recommends_the_fastest() {
    let dir = temp_dir("advise");
    let json = dir.join("advice.json");
    let o = lightgrid(&[
        "advise",
        "--scene",
        "robots-few",
        "--size",
        "64x36",
        "--budget",
        "20",
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let table = String::from_utf8_lossy(&o.stdout).into_owned();
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let ranking = v["ranking"].as_array().unwrap();
    // Every pipeline that reproduces forward's image was at least tried.
    for p in lightgrid::pipelines::PIPELINES
        .iter()
        .filter(|p| p.reference == "forward")
    {
        assert!(
            ranking.iter().any(|m| m["pipeline"] == p.id),
            "{} missing from the ranking",
            p.id
        );
    }
    let measured: Vec<f64> = ranking
        .iter()
        .take_while(|m| m["status"] == "measured" && m["wrong_frames"] == 0)
        .map(|m| m["frame_ms"].as_f64().unwrap())
        .collect();
    assert!(!measured.is_empty(), "nothing measured in 20 s:\n{table}");
    assert!(measured.windows(2).all(|w| w[0] <= w[1]), "{measured:?}");
    for m in ranking.iter().filter(|m| m["status"] != "measured") {
        assert!(m["reason"].as_str().is_some_and(|r| !r.is_empty()), "{m}");
    }
    let rec = &v["recommendation"];
    assert_eq!(rec["pipeline"], ranking[0]["pipeline"]);
    assert_eq!(rec["tile"], ranking[0]["tile"]);
    let options = rec["options"].as_str().unwrap();
    assert!(
        table.contains(&format!("recommended: {options}")),
        "{table}"
    );
    assert!(rec["reasons"].as_array().unwrap().len() >= 3, "{rec}");
    // The recommended options render.
    let mut args = vec!["render", "--scene", "robots-few", "--size", "64x36"];
    args.extend(options.split_whitespace());
    let r = lightgrid(&args);
    assert!(r.status.success(), "{args:?}: {}", stderr(&r));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn json_to_stdout_is_the_whole_document() {
    let o = lightgrid(&[
        "advise",
        "--scene",
        "robots-few",
        "--size",
        "32x18",
        "--budget",
        "8",
        "--json",
        "-",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("stdout is JSON");
    assert_eq!(v["width"], 32);
    assert!(v["recommendation"]["options"].is_string());
}

#[test]
fn a_budget_too_small_for_anything_fails_saying_so() {
    let dir = temp_dir("advise-none");
    let json = dir.join("a.json");
    let o = lightgrid(&[
        "advise",
        "--scene",
        "robots-few",
        "--size",
        "32x18",
        "--budget",
        "0.000001",
        "--json",
        json.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("no configuration was measured"),
        "{}",
        stderr(&o)
    );
    // The skipped candidates are still written, each with its reason.
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert!(v["recommendation"].is_null());
    assert!(v["ranking"]
        .as_array()
        .unwrap()
        .iter()
        .all(|m| m["status"] == "skipped" && m["reason"] == "the budget was spent"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_advise_options_are_refused() {
    let dir = temp_dir("advise-bad");
    let d = dir.to_str().unwrap();
    for b in ["0", "-1", "NaN", "inf", "abc", "100000"] {
        assert_fails_with(&["advise", "--budget", b], "--budget");
    }
    assert_fails_with(&["advise", "--json", d], "--json");
    assert_fails_with(&["advise", "--json", "/dev/null"], "--json");
    assert_fails_with(&["advise", "--size", "0x5"], "--size");
    assert_fails_with(&["advise", "--scene", "nope"], "nope");
    assert!(std::fs::read_dir(&dir).unwrap().next().is_none());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_interrupted_advice_exits_1_and_says_so() {
    let dir = temp_dir("advise-interrupted");
    let json = dir.join("advice.json");
    // Once it measures, one SIGTERM: stop, not abort.
    let (mut child, mut err) = support::start_measuring(&[
        "advise",
        "--scene",
        "robots-few",
        "--size",
        "64x36",
        "--budget",
        "60",
        "--json",
        json.to_str().unwrap(),
    ]);
    let killed = std::process::Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let mut rest = String::new();
    std::io::Read::read_to_string(&mut err, &mut rest).unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(1), "{rest}");
    assert!(
        rest.contains("interrupted by a signal") && !rest.contains("panicked"),
        "{rest}"
    );
    // What was measured is written, marked interrupted.
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(v["interrupted"], true);
    std::fs::remove_dir_all(&dir).unwrap();
}
