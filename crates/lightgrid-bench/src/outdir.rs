//! How a long run ends ([`Outcome`], written into its results) and the directory it writes
//! into ([`OutDir`]): checked before anything is created, locked against a second run, and
//! cleared of the files an earlier run wrote there once the new ones are in place.

use lightgrid::image_io::check_writable;
use lightgrid::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// How a run ended. Results are written on every way out; a run that did not complete says
/// why.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase", tag = "status", content = "reason")]
pub enum Outcome {
    /// Every planned measurement was made.
    #[default]
    Complete,
    /// Stopped by a signal (Ctrl-C or SIGTERM) after the measurement in progress.
    Interrupted(String),
    /// Stopped by an error; what was measured before it is kept.
    Failed(String),
}

impl Outcome {
    pub fn is_complete(&self) -> bool {
        *self == Outcome::Complete
    }

    /// "complete", "interrupted: REASON" or "failed: REASON".
    pub fn describe(&self) -> String {
        match self {
            Outcome::Complete => "complete".into(),
            Outcome::Interrupted(r) => format!("interrupted: {r}"),
            Outcome::Failed(r) => format!("failed: {r}"),
        }
    }
}

/// The reason recorded when the stop flag ends a run.
pub const STOPPED_BY_SIGNAL: &str = "stopped by a signal (Ctrl-C or SIGTERM)";

/// Name of the lock file a run holds in its output directory.
pub const LOCK_FILE: &str = ".lightgrid.lock";
/// Name of the list of files the last run wrote into the directory.
pub const MANIFEST_FILE: &str = ".lightgrid-files";

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> Error + '_ {
    move |cause| Error::Io {
        path: path.display().to_string(),
        cause,
    }
}

/// Check that `dir` can be a run's output directory without creating anything: it is a
/// directory or does not exist yet, and its nearest existing ancestor is a writable directory.
pub fn check_out_dir(dir: &Path) -> Result<()> {
    let invalid = |reason: String| Error::Invalid {
        what: "output directory",
        reason,
    };
    let mut existing = dir.to_path_buf();
    loop {
        match std::fs::metadata(&existing) {
            Ok(m) if m.is_dir() => break,
            Ok(_) => {
                return Err(invalid(format!(
                    "{} is a file, not a directory",
                    existing.display()
                )))
            }
            Err(_) => match existing.parent() {
                Some(p) if !p.as_os_str().is_empty() => existing = p.to_path_buf(),
                _ => {
                    existing = PathBuf::from(".");
                    break;
                }
            },
        }
    }
    check_writable(&existing.join("probe"))
}

/// A run's output directory, created and locked; the lock goes when this is dropped.
pub struct OutDir {
    dir: PathBuf,
    lock: PathBuf,
}

impl OutDir {
    /// Create `dir` (after [`check_out_dir`]) and take its lock. A second run into the same
    /// directory is refused while the first is alive; a lock left by a process that no
    /// longer exists is taken over.
    pub fn claim(dir: &Path) -> Result<OutDir> {
        check_out_dir(dir)?;
        std::fs::create_dir_all(dir).map_err(io(dir))?;
        let lock = dir.join(LOCK_FILE);
        for _ in 0..2 {
            match std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(&lock)
            {
                Ok(mut f) => {
                    use std::io::Write;
                    let _ = writeln!(f, "{}", std::process::id());
                    return Ok(OutDir {
                        dir: dir.to_path_buf(),
                        lock,
                    });
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    let holder = std::fs::read_to_string(&lock).unwrap_or_default();
                    let pid = holder.trim().parse::<u32>().ok();
                    if pid.is_some_and(process_alive) {
                        return Err(Error::Invalid {
                            what: "output directory",
                            reason: format!(
                                "another lightgrid run (pid {}) is writing to {}; wait for it or choose another directory",
                                holder.trim(),
                                dir.display()
                            ),
                        });
                    }
                    // Left by a run that was killed: take it over.
                    let _ = std::fs::remove_file(&lock);
                }
                Err(e) => return Err(io(&lock)(e)),
            }
        }
        Err(Error::Invalid {
            what: "output directory",
            reason: format!("cannot take the lock {}", lock.display()),
        })
    }

    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// After the run's files are written: remove the files the previous run listed that this
    /// one did not write (a pipeline, scene or plot it no longer has), so nothing from an
    /// earlier run sits beside the new files as if it belonged to them; then list this run's.
    pub fn replace_earlier_files(&self, written: &[PathBuf]) -> Result<Vec<PathBuf>> {
        let manifest = self.dir.join(MANIFEST_FILE);
        let names: Vec<String> = written
            .iter()
            .filter_map(|p| p.file_name())
            .map(|n| n.to_string_lossy().into_owned())
            .collect();
        let mut removed = Vec::new();
        if let Ok(old) = std::fs::read_to_string(&manifest) {
            for name in old.lines().map(str::trim).filter(|n| !n.is_empty()) {
                // Only plain names this tool wrote into this directory.
                let plain = !name.contains('/') && !name.contains('\\') && !name.starts_with('.');
                if plain && !names.iter().any(|n| n == name) {
                    let p = self.dir.join(name);
                    if std::fs::symlink_metadata(&p).is_ok_and(|m| m.is_file())
                        && std::fs::remove_file(&p).is_ok()
                    {
                        removed.push(p);
                    }
                }
            }
        }
        lightgrid::image_io::write_atomic(&manifest, (names.join("\n") + "\n").as_bytes())?;
        Ok(removed)
    }
}

impl Drop for OutDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.lock);
    }
}

/// Whether a process with this id exists (on Linux, by /proc; elsewhere assumed alive, so a
/// stale lock there is removed by hand).
fn process_alive(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    if cfg!(target_os = "linux") {
        Path::new(&format!("/proc/{pid}")).exists()
    } else {
        true
    }
}
