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
