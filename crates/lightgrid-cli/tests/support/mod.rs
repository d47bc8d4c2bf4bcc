//! What the CLI test files share: running the binary, temporary directories, failure checks.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

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
