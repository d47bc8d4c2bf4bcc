//! What the CLI test files share: running the binary, temporary directories, failure checks.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// `lightgrid args`, started with stderr piped (stdout discarded), handed back once it
/// measures (its first progress line), with the rest of its stderr to read: the moment the
/// signal tests interrupt it.
pub fn start_measuring(
    args: &[&str],
) -> (
    std::process::Child,
    std::io::BufReader<std::process::ChildStderr>,
) {
    use std::io::BufRead;
    let mut child = Command::new(env!("CARGO_BIN_EXE_lightgrid"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = std::io::BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    while err.read_line(&mut line).unwrap() > 0 && !line.contains("% ") {
        line.clear();
    }
    (child, err)
}

pub fn lightgrid(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lightgrid"))
        .args(args)
        .output()
        .expect("run lightgrid")
}

pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("lightgrid-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

pub fn assert_fails_with(args: &[&str], needle: &str) {
    let o = lightgrid(args);
    assert!(!o.status.success(), "{args:?} should fail");
    let err = stderr(&o);
    assert!(
        err.contains(needle),
        "{args:?}: stderr lacks '{needle}':\n{err}"
    );
    assert!(!err.contains("panicked"), "{args:?} panicked:\n{err}");
}

/// Run `cmd` (stdout discarded, stderr kept) with a time limit: its exit code and stderr, or
/// the stderr so far in `Err` when the limit passed (the process is killed).
pub fn run_limited(mut cmd: Command, limit: Duration) -> Result<(Option<i32>, String), String> {
    let mut child = cmd
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run lightgrid");
    let mut err = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = std::io::Read::read_to_string(&mut err, &mut s);
        s
    });
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return Ok((status.code(), reader.join().unwrap()));
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return Err(reader.join().unwrap());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// `glb` with an animation added: its first light's node slides 3 m in x over one second,
/// and its first mesh node turns half a turn (linear).
pub fn with_animation(glb: &[u8]) -> Vec<u8> {
    let len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let mut doc: serde_json::Value = serde_json::from_slice(&glb[20..20 + len]).unwrap();
    let mut bin = glb[20 + len + 8..].to_vec();
    let nodes = doc["nodes"].as_array().unwrap();
    let lit = nodes
        .iter()
        .position(|n| n.get("extensions").is_some())
        .expect("a light node");
    let meshed = nodes.iter().position(|n| n.get("mesh").is_some()).unwrap();
    let from: Vec<f32> = match nodes[lit].get("translation") {
        Some(t) => serde_json::from_value(t.clone()).unwrap(),
        None => {
            let m: Vec<f32> = serde_json::from_value(nodes[lit]["matrix"].clone()).unwrap();
            m[12..15].to_vec()
        }
    };
    let mut add = |values: &[f32], kind: &str, count: usize| {
        while bin.len() % 4 != 0 {
            bin.push(0);
        }
        let offset = bin.len();
        bin.extend(values.iter().flat_map(|v| v.to_le_bytes()));
        let views = doc["bufferViews"].as_array_mut().unwrap();
        views.push(
            serde_json::json!({"buffer": 0, "byteOffset": offset, "byteLength": values.len() * 4}),
        );
        let view = views.len() - 1;
        let accessors = doc["accessors"].as_array_mut().unwrap();
        let mut acc = serde_json::json!({"bufferView": view, "componentType": 5126, "count": count, "type": kind});
        if kind == "SCALAR" {
            acc["min"] = serde_json::json!([values[0]]);
            acc["max"] = serde_json::json!([values[count - 1]]);
        }
        accessors.push(acc);
        accessors.len() - 1
    };
    let times = add(&[0.0, 1.0], "SCALAR", 2);
    let slide = add(
        &[from[0], from[1], from[2], from[0] + 3.0, from[1], from[2]],
        "VEC3",
        2,
    );
    let turn = add(&[0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0], "VEC4", 2);
    doc["animations"] = serde_json::json!([{
        "channels": [
            {"sampler": 0, "target": {"node": lit, "path": "translation"}},
            {"sampler": 1, "target": {"node": meshed, "path": "rotation"}},
        ],
        "samplers": [{"input": times, "output": slide}, {"input": times, "output": turn}],
    }]);
    // Animated nodes hold TRS, not a matrix (§3.11).
    for n in [lit, meshed] {
        let node = doc["nodes"][n].as_object_mut().unwrap();
        if let Some(m) = node.remove("matrix") {
            let m: Vec<f32> = serde_json::from_value(m).unwrap();
            node.insert(
                "translation".into(),
                serde_json::json!([m[12], m[13], m[14]]),
            );
        }
    }
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    doc["buffers"][0]["byteLength"] = serde_json::json!(bin.len());
    let mut json_bytes = serde_json::to_vec(&doc).unwrap();
    while json_bytes.len() % 4 != 0 {
        json_bytes.push(b' ');
    }
    let mut out = b"glTF".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&((12 + 8 + json_bytes.len() + 8 + bin.len()) as u32).to_le_bytes());
    out.extend_from_slice(&(json_bytes.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json_bytes);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}
