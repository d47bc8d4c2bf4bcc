//! No panic is reachable from the command line: every command run over generated option
//! values (numbers out of range, NaN, words, sizes, paths that are directories, devices,
//! missing or badly named) exits 0 or with a clear error, never with Rust's panic status 101
//! or "panicked" on stderr.

mod support;

use proptest::prelude::*;
use std::process::Command;
use std::time::Duration;

/// Values any option may get: numbers at and past every bound, non-numbers, sizes.
const VALUES: &[&str] = &[
    "0",
    "1",
    "-1",
    "7",
    "255",
    "257",
    "1000",
    "1001",
    "65536",
    "4294967295",
    "4294967296",
    "-4294967296",
    "NaN",
    "inf",
    "-0",
    "1e3",
    "abc",
    "",
    " ",
    "0x0",
    "1x1",
    "8x8",
    "17x3",
    "64x36",
    "3x2x1",
    "x",
    "-5x10",
    "99999x1",
    "4294967295x4294967295",
    "0..3",
    "3..0",
    "0..9:0",
    "0..259:100",
    "16",
    "32",
    "24",
];

/// Names: scenes, pipelines, strategies, adapters, valid and not.
const NAMES: &[&str] = &[
    "robots-many",
    "robots-few",
    "scattered",
    "random-top",
    "stress",
    "nope",
    "missing.glb",
    "/dev/null.gltf",
    "forward",
    "tiled_deferred",
    "tiled_deferred_single",
    "clustered_forward",
    "deferred_stencil",
    "light_prepass",
    "all",
    "forward,deferred",
    "cpu",
    "gather",
    "scatter",
    "bvh",
    "bvh-gpu",
    "auto",
    "vulkan",
    "gl",
    "0",
    "9",
    "sphere",
    "cone",
    "sphere,cone",
    "0.5",
    "on",
    "off",
    "separate",
    "shared",
    "separate,shared",
    "per-material",
    "uber",
    "4",
    "1,4",
    "16",
];

/// Options per command, with the safe values that keep a valid run short (tiny frames, one
/// frame, one pipeline) where the case does not set them itself.
struct Cmd {
    name: &'static str,
    flags: &'static [&'static str],
    /// Flags that take a path.
    paths: &'static [&'static str],
    safe: &'static [(&'static str, &'static str)],
}

const CMDS: &[Cmd] = &[
    Cmd {
        name: "render",
        flags: &[
            "--spot-fraction",
            "--spot-cull",
            "--transparency",
            "--material-shaders",
            "--lists",
            "--material-draws",
            "--msaa",
            "--scene",
            "--camera",
            "--add-lights",
            "--light-range",
            "--exposure",
            "--shadows",
            "--shadow-lights",
            "--frame",
            "--size",
            "--lights",
            "--seed",
            "--tile",
            "--slices",
            "--assign",
            "--gbuffer",
            "--warmup",
            "--pipeline",
        ],
        paths: &["--out", "--stats", "--heatmap", "--shadow-maps-image"],
        safe: &[
            ("--size", "8x8"),
            ("--warmup", "0"),
            ("--scene", "robots-few"),
        ],
    },
    Cmd {
        name: "play",
        flags: &[
            "--spot-fraction",
            "--spot-cull",
            "--transparency",
            "--material-shaders",
            "--lists",
            "--material-draws",
            "--msaa",
            "--scene",
            "--add-lights",
            "--exposure",
            "--shadows",
            "--shadow-lights",
            "--camera",
            "--pipeline",
            "--assign",
            "--frames",
            "--size",
            "--loops",
            "--warmup",
            "--tile",
            "--slices",
            "--gbuffer",
            "--lights",
            "--seed",
        ],
        paths: &["--json"],
        safe: &[
            ("--size", "8x8"),
            ("--frames", "0..2"),
            ("--warmup", "0"),
            ("--scene", "robots-few"),
        ],
    },
    Cmd {
        name: "view",
        flags: &[
            "--spot-fraction",
            "--transparency",
            "--msaa",
            "--scene",
            "--add-lights",
            "--exposure",
            "--pipeline",
            "--assign",
            "--frame",
            "--size",
            "--view",
            "--script",
            "--exit-after-frames",
            "--tile",
            "--slices",
            "--gbuffer",
            "--lights",
        ],
        paths: &["--screenshot"],
        safe: &[
            ("--size", "8x8"),
            ("--exit-after-frames", "2"),
            ("--scene", "robots-few"),
        ],
    },
    Cmd {
        name: "advise",
        flags: &[
            "--scene",
            "--size",
            "--budget",
            "--add-lights",
            "--exposure",
            "--spot-fraction",
            "--lights",
        ],
        paths: &["--json"],
        safe: &[
            ("--size", "8x8"),
            ("--budget", "1"),
            ("--scene", "robots-few"),
        ],
    },
    Cmd {
        name: "compare",
        flags: &[
            "--spot-fraction",
            "--transparency",
            "--material-shaders",
            "--scene",
            "--add-lights",
            "--exposure",
            "--shadows",
            "--shadow-lights",
            "--frame",
            "--size",
            "--lights",
            "--tile",
            "--slices",
            "--warmup",
        ],
        paths: &["--out-dir"],
        safe: &[
            ("--size", "8x8"),
            ("--warmup", "0"),
            ("--scene", "robots-few"),
            ("--out-dir", "@dir/c"),
        ],
    },
    Cmd {
        name: "bench",
        flags: &[
            "--spot-fraction",
            "--spot-cull",
            "--transparency",
            "--material-shaders",
            "--lists",
            "--material-draws",
            "--scene",
            "--add-lights",
            "--light-range",
            "--pipelines",
            "--frames",
            "--size",
            "--tile",
            "--slices",
            "--assign",
            "--msaa",
            "--gbuffer",
            "--repeat",
            "--warmup",
            "--lights",
            "--seed",
            "--heatmap-frame",
        ],
        paths: &["--out"],
        safe: &[
            ("--size", "8x8"),
            ("--frames", "0"),
            ("--pipelines", "forward"),
            ("--warmup", "0"),
            ("--scene", "robots-few"),
            ("--out", "@dir/b"),
        ],
    },
    Cmd {
        name: "scaling",
        flags: &[
            "--lights",
            "--assign",
            "--pipeline",
            "--scene",
            "--size",
            "--tile",
            "--slices",
            "--seed",
            "--runs",
            "--warmup",
            "--budget",
        ],
        paths: &["--out"],
        safe: &[
            ("--size", "8x8"),
            ("--lights", "100"),
            ("--assign", "cpu"),
            ("--warmup", "0"),
            ("--out", "@dir/s"),
        ],
    },
    Cmd {
        name: "diff",
        flags: &["--max-mean", "--max-p99"],
        paths: &["--diff-image"],
        safe: &[],
    },
    Cmd {
        name: "export",
        flags: &[
            "--scene",
            "--frame",
            "--size",
            "--add-lights",
            "--light-range",
            "--exposure",
            "--spot-fraction",
            "--camera",
            "--seed",
        ],
        paths: &["--out"],
        safe: &[("--scene", "robots-few"), ("--out", "@dir/e.glb")],
    },
    Cmd {
        name: "memory",
        flags: &["--size", "--gbuffer", "--msaa"],
        paths: &[],
        safe: &[],
    },
];

/// Paths an output or input may name (`@dir` is the case's temporary directory).
const PATHS: &[&str] = &[
    "@dir/x.png",
    "@dir/x.jpg",
    "@dir",
    "/dev/null",
    "/nonexistent/x.png",
    "@dir/a.png",
    "@dir/long",
    "@dir/sub/deeper/x.png",
    "",
    "@dir/x.json",
    "@dir/x.glb",
    "@dir/x.gltf",
];

fn expand(v: &str, dir: &str) -> String {
    if v == "@dir/long" {
        format!("{dir}/{}.png", "n".repeat(251))
    } else {
        v.replace("@dir", dir)
    }
}

/// A generated case: the command, (flag index, value index) pairs, and whether the adapter
/// flag comes first.
fn case() -> impl Strategy<Value = (usize, Vec<(usize, usize, bool)>, Option<usize>)> {
    (
        0..CMDS.len(),
        prop::collection::vec((0usize..64, 0usize..64, any::<bool>()), 0..4),
        prop::option::weighted(0.15, 0..NAMES.len()),
    )
}

fn args_of(
    cmd: &Cmd,
    opts: &[(usize, usize, bool)],
    adapter: Option<usize>,
    dir: &str,
) -> Vec<String> {
    let mut args = Vec::new();
    if let Some(a) = adapter {
        args.extend(["--adapter".to_string(), NAMES[a].to_string()]);
    }
    args.push(cmd.name.to_string());
    if cmd.name == "diff" {
        args.extend([format!("{dir}/a.png"), format!("{dir}/b.png")]);
    }
    let mut given = Vec::new();
    for &(f, v, name) in opts {
        let all = cmd.flags.len() + cmd.paths.len();
        if all == 0 {
            break;
        }
        let f = f % all;
        let (flag, value) = if f < cmd.flags.len() {
            let pool = if name { NAMES } else { VALUES };
            (cmd.flags[f], pool[v % pool.len()].to_string())
        } else {
            let flag = cmd.paths[f - cmd.flags.len()];
            (flag, expand(PATHS[v % PATHS.len()], dir))
        };
        given.push(flag);
        args.extend([flag.to_string(), value]);
    }
    for (flag, value) in cmd.safe {
        if !given.contains(flag) {
            args.extend([flag.to_string(), expand(value, dir)]);
        }
    }
    args
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 96,
        failure_persistence: None,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x11),
        ..ProptestConfig::default()
    })]

    #[test]
    fn no_command_panics_on_generated_options((c, opts, adapter) in case()) {
        let dir = support::temp_dir("prop");
        let d = dir.to_str().unwrap().to_string();
        image::RgbaImage::from_pixel(8, 8, image::Rgba([1, 2, 3, 255]))
            .save(dir.join("a.png"))
            .unwrap();
        std::fs::copy(dir.join("a.png"), dir.join("b.png")).unwrap();
        let args = args_of(&CMDS[c], &opts, adapter, &d);
        // A valid run of these sizes takes seconds; one still going after this is reported
        // as a hang.
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_lightgrid"));
        cmd.args(&args);
        let outcome = support::run_limited(cmd, Duration::from_secs(120)).ok();
        std::fs::remove_dir_all(&dir).unwrap();
        let (code, err) = outcome.unwrap_or_else(|| panic!("{args:?} still running after 120 s"));
        // Shown with --nocapture: which cases ran and which were refused, and why.
        eprintln!("{code:?} {args:?}: {}", err.lines().last().unwrap_or(""));
        prop_assert!(code != Some(101) && !err.contains("panicked"), "{:?} panicked:\n{}", args, err);
        prop_assert!(code.is_some(), "{:?} was killed by a signal:\n{}", args, err);
        if code != Some(0) {
            prop_assert!(err.contains("error"), "{:?} failed without an error message:\n{}", args, err);
        }
    }
}
