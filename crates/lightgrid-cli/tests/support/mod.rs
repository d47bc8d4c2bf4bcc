//! What the CLI test files share: running the binary, temporary directories, failure checks.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Output};

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
