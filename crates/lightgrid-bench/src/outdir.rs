//! How a long run ends ([`Outcome`], written into its results) and the directory it writes
//! into ([`OutDir`]): checked before anything is created, locked against a second run, and
//! cleared of the files an earlier run wrote there once the new ones are in place.

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
/// Start of the names of the lists of files each command's last run wrote into a directory
/// ([`manifest_name`]); a directory holding one was made by lightgrid.
pub const MANIFEST_FILE: &str = ".lightgrid-files";
/// Start of the name of the directory a run writes its files into before they are moved into
/// place together ([`OutDir::commit`]), followed by the process id.
const STAGING_PREFIX: &str = ".lightgrid-run-";

/// The list of the files `command`'s last run wrote: one per command, so a command removes
/// only its own earlier files (a compare never removes a bench's results).
pub fn manifest_name(command: &str) -> String {
    format!("{MANIFEST_FILE}-{command}")
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> Error + '_ {
    move |cause| Error::Io {
        path: path.display().to_string(),
        cause,
    }
}

fn invalid(reason: String) -> Error {
    Error::Invalid {
        what: "output directory",
        reason,
    }
}

/// Names lightgrid keeps for itself in an output directory (manifests, the lock, temporary
/// files and staging directories): not a user's files.
fn own_name(name: &str) -> bool {
    name.starts_with(".lightgrid")
}

/// Check that `dir` can be a run's output directory without creating anything: it is a
/// directory or does not exist yet, its nearest existing ancestor is a writable directory,
/// and, unless `force`, an existing `dir` is empty or was made by lightgrid (it holds a
/// manifest), so no file of the user's is replaced by a run they did not mean to put there.
/// `force` true checks writability only.
pub fn check_out_dir(dir: &Path, force: bool) -> Result<()> {
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
    let probe = lightgrid::image_io::Temporary::new(
        existing.join(format!(".lightgrid-{}.probe", std::process::id())),
    );
    std::fs::write(probe.path(), b"").map_err(|cause| Error::Io {
        path: format!(
            "cannot create the output directory {} ({} refuses new files)",
            dir.display(),
            existing.display()
        ),
        cause,
    })?;
    drop(probe);
    if existing == dir && !force {
        check_not_foreign(dir)?;
    }
    Ok(())
}

/// Refuse an existing directory that holds files and no manifest of lightgrid's.
fn check_not_foreign(dir: &Path) -> Result<()> {
    let mut foreign = Vec::new();
    let mut made_here = false;
    for entry in std::fs::read_dir(dir).map_err(io(dir))? {
        let name = entry.map_err(io(dir))?.file_name();
        let name = name.to_string_lossy();
        if name.starts_with(MANIFEST_FILE) {
            made_here = true;
        } else if !own_name(&name) {
            foreign.push(name.into_owned());
        }
    }
    if made_here || foreign.is_empty() {
        return Ok(());
    }
    foreign.sort();
    let more = if foreign.len() > 3 { ", ..." } else { "" };
    foreign.truncate(3);
    Err(invalid(format!(
        "{} is not empty and was not made by lightgrid (it holds {}{more}); name a new or empty directory, or give --force to write into it (files of the same names are replaced)",
        dir.display(),
        foreign.join(", ")
    )))
}

/// A run's output directory, created and locked; the lock goes when this is dropped. Files
/// are written into [`OutDir::staging`] and moved into place together by [`OutDir::commit`],
/// so a run that fails part-way (a full disk) leaves the directory as the last run left it.
pub struct OutDir {
    dir: PathBuf,
    lock: PathBuf,
    command: String,
    force: bool,
    staging: lightgrid::image_io::Temporary,
}

/// What [`OutDir::commit`] does with the files of the command's earlier run that this one did
/// not write.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Earlier {
    /// Remove them: nothing from an earlier run sits beside the new files as if it belonged
    /// to them (a pipeline that failed this time).
    Remove,
    /// Keep them (`report` rewrites part of a bench's files and keeps its heatmaps).
    Keep,
}

impl OutDir {
    /// Create `dir` (after [`check_out_dir`]) and take its lock for `command` (`bench`,
    /// `compare`, `scaling`: whose manifest the run's files go into). A second run into the
    /// same directory is refused while the first is alive; a lock left by a process that no
    /// longer exists is taken over, and its staging directories removed.
    pub fn claim(dir: &Path, command: &str, force: bool) -> Result<OutDir> {
        check_out_dir(dir, force)?;
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
                    let out = OutDir {
                        dir: dir.to_path_buf(),
                        lock,
                        command: command.to_string(),
                        force,
                        staging: lightgrid::image_io::Temporary::new(
                            dir.join(format!("{STAGING_PREFIX}{}", std::process::id())),
                        ),
                    };
                    out.remove_stale_staging();
                    std::fs::create_dir(out.staging()).map_err(io(out.staging()))?;
                    return Ok(out);
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    let holder = std::fs::read_to_string(&lock).unwrap_or_default();
                    let pid = holder.trim().parse::<u32>().ok();
                    if pid.is_some_and(process_alive) {
                        return Err(invalid(format!(
                            "another lightgrid run (pid {}) is writing to {}; wait for it or choose another directory",
                            holder.trim(),
                            dir.display()
                        )));
                    }
                    // Left by a run that was killed: take it over.
                    let _ = std::fs::remove_file(&lock);
                }
                Err(e) => return Err(io(&lock)(e)),
            }
        }
        Err(invalid(format!("cannot take the lock {}", lock.display())))
    }

    /// Staging directories of runs that were killed (they hold the lock, so none is alive).
    fn remove_stale_staging(&self) {
        let Ok(entries) = std::fs::read_dir(&self.dir) else {
            return;
        };
        for e in entries.flatten() {
            let name = e.file_name();
            let stale = name
                .to_str()
                .and_then(|n| n.strip_prefix(STAGING_PREFIX))
                .and_then(|pid| pid.parse::<u32>().ok())
                .is_some_and(|pid| !process_alive(pid));
            if stale {
                let _ = std::fs::remove_dir_all(e.path());
            }
        }
    }

    /// The directory the run names.
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// Where the run writes its files (inside [`OutDir::path`], on the same file system); they
    /// reach the directory only through [`OutDir::commit`].
    pub fn staging(&self) -> &Path {
        self.staging.path()
    }

    /// The names listed in `manifest` (plain names only: nothing outside the directory).
    fn listed(&self, manifest: &str) -> Vec<String> {
        std::fs::read_to_string(self.dir.join(manifest))
            .unwrap_or_default()
            .lines()
            .map(str::trim)
            .filter(|n| !n.is_empty() && !n.contains(['/', '\\']) && !own_name(n))
            .map(String::from)
            .collect()
    }

    /// Other commands' manifests and what each lists: their files are not replaced, and the
    /// names a forced run took are handed over.
    fn other_manifests(&self, own: &str) -> Result<Vec<(String, Vec<String>)>> {
        let mut others = Vec::new();
        for e in std::fs::read_dir(&self.dir)
            .map_err(io(&self.dir))?
            .flatten()
        {
            let m = e.file_name().to_string_lossy().into_owned();
            if m.starts_with(MANIFEST_FILE) && m != own {
                let list = self.listed(&m);
                others.push((m, list));
            }
        }
        Ok(others)
    }

    /// The refusal of a run whose files would replace `taken` (another command's, or not
    /// lightgrid's): a few named with their owner, this run's files set aside.
    fn refuse_taken(&self, taken: &[&String], others: &[(String, Vec<String>)]) -> Error {
        let owner = |n: &String| {
            others
                .iter()
                .find(|(_, l)| l.contains(n))
                .and_then(|(m, _)| m.strip_prefix(MANIFEST_FILE)?.strip_prefix('-'))
                .map_or("not written by lightgrid".to_string(), |c| {
                    format!("written by `lightgrid {c}`")
                })
        };
        let list: Vec<String> = taken
            .iter()
            .take(3)
            .map(|n| format!("{n} ({})", owner(n)))
            .collect();
        let kept_note = match self.set_aside("refused") {
            Ok(kept) => format!("this run's files are in {}", kept.display()),
            Err(e) => format!("this run's files could not be kept: {e}"),
        };
        invalid(format!(
            "{} already holds {}{}; nothing there was replaced ({kept_note}); give --force to replace them, or choose another directory",
            self.dir.display(),
            list.join(", "),
            if taken.len() > 3 { ", ..." } else { "" }
        ))
    }

    /// After every file of the run is written into [`OutDir::staging`] (`written`): move them
    /// into the directory, then deal with the command's earlier files as `earlier` says, and
    /// list this run's files in the command's manifest. A file that another command's run
    /// wrote, or that lightgrid did not write, is never replaced unless `--force` was given:
    /// the run is refused before anything moves and its files are kept in a directory of their
    /// own that the error names. A run that did not `complete` (failed or interrupted) does not
    /// replace an earlier run of the command: its files are set aside in a directory of their
    /// own ([`Committed::set_aside`]) and the earlier ones stay as they were; with no earlier
    /// run it is placed as a complete one is. Everything that could stop the move part-way (a
    /// name given twice, a staged file missing, a directory or other non-file where a file
    /// goes) is checked before anything moves.
    pub fn commit(
        &self,
        written: &[PathBuf],
        earlier: Earlier,
        complete: bool,
    ) -> Result<Committed> {
        let own = manifest_name(&self.command);
        let old = self.listed(&own);
        let names: Vec<String> = written
            .iter()
            .filter_map(|p| p.file_name())
            .map(|n| n.to_string_lossy().into_owned())
            .collect();
        self.check_movable(written, &names)?;
        let earlier_run = old
            .iter()
            .any(|n| std::fs::symlink_metadata(self.dir.join(n)).is_ok());
        if !complete && earlier_run {
            let aside = self.set_aside("incomplete")?;
            return Ok(Committed {
                placed: Vec::new(),
                removed: Vec::new(),
                set_aside: Some(aside),
            });
        }
        // Other commands' manifests, to refuse replacing their files and to hand over the
        // names a forced run took.
        let others = self.other_manifests(&own)?;
        // Files an earlier version listed in its one shared manifest are anyone's to replace.
        let legacy = self.listed(MANIFEST_FILE);
        let taken: Vec<&String> = names
            .iter()
            .filter(|n| !old.contains(n) && !legacy.contains(n))
            .filter(|n| std::fs::symlink_metadata(self.dir.join(n)).is_ok())
            .collect();
        if !self.force && !taken.is_empty() {
            return Err(self.refuse_taken(&taken, &others));
        }
        // Listed first with the old files too: a run stopped while files move leaves them all
        // listed, and the next run of the command removes what it does not write again.
        let mut both = old.clone();
        both.extend(names.iter().filter(|n| !old.contains(n)).cloned());
        self.write_manifest(&own, &both)?;
        let mut placed = Vec::new();
        for (from, name) in written.iter().zip(&names) {
            let to = self.dir.join(name);
            std::fs::rename(from, &to).map_err(io(&to))?;
            placed.push(to);
        }
        for (m, list) in &others {
            if list.iter().any(|n| names.contains(n)) {
                let rest: Vec<String> = list
                    .iter()
                    .filter(|n| !names.contains(n))
                    .cloned()
                    .collect();
                self.write_manifest(m, &rest)?;
            }
        }
        let mut removed = Vec::new();
        let mut listed = names.clone();
        for name in old.iter().filter(|n| !names.contains(n)) {
            let p = self.dir.join(name);
            let file = std::fs::symlink_metadata(&p).is_ok_and(|m| m.is_file());
            if earlier == Earlier::Remove && file && std::fs::remove_file(&p).is_ok() {
                removed.push(p);
            } else if file {
                listed.push(name.clone());
            }
        }
        self.write_manifest(&own, &listed)?;
        Ok(Committed {
            placed,
            removed,
            set_aside: None,
        })
    }

    /// Refuse, before anything moves, a commit that would stop part-way: a name given twice
    /// (two files of the run would be one), a staged file that is not there, or a name whose
    /// place in the directory holds a directory or another non-file.
    fn check_movable(&self, written: &[PathBuf], names: &[String]) -> Result<()> {
        if names.len() != written.len() {
            return Err(invalid("a file of the run has no name".into()));
        }
        for (i, (path, name)) in written.iter().zip(names).enumerate() {
            if names[..i].contains(name) {
                return Err(invalid(format!(
                    "two files of this run are both named {name}; nothing was moved into {}",
                    self.dir.display()
                )));
            }
            if !std::fs::symlink_metadata(path).is_ok_and(|m| m.is_file()) {
                return Err(invalid(format!(
                    "{} was not written; nothing was moved into {}",
                    path.display(),
                    self.dir.display()
                )));
            }
            let to = self.dir.join(name);
            if std::fs::symlink_metadata(&to)
                .is_ok_and(|m| m.is_dir() || !m.is_file() && !m.file_type().is_symlink())
            {
                return Err(invalid(format!(
                    "{} is not a regular file and cannot be replaced; nothing was changed",
                    to.display()
                )));
            }
        }
        Ok(())
    }

    /// Move the staging directory, with this run's files, to `lightgrid-COMMAND-WHY-PID` in
    /// the directory (it is no longer removed on drop), and return its path.
    fn set_aside(&self, why: &str) -> Result<PathBuf> {
        let kept = self.dir.join(format!(
            "lightgrid-{}-{why}-{}",
            self.command,
            std::process::id()
        ));
        std::fs::rename(self.staging(), &kept).map_err(io(&kept))?;
        Ok(kept)
    }

    fn write_manifest(&self, manifest: &str, names: &[String]) -> Result<()> {
        let text: String = names.iter().map(|n| format!("{n}\n")).collect();
        lightgrid::image_io::write_atomic(&self.dir.join(manifest), text.as_bytes())
    }
}

/// What [`OutDir::commit`] did.
#[derive(Debug)]
pub struct Committed {
    /// The run's files, in the directory.
    pub placed: Vec<PathBuf>,
    /// Files of the command's earlier run that this one did not write, removed.
    pub removed: Vec<PathBuf>,
    /// Where the files of a run that did not complete went, when an earlier run's files stay
    /// in the directory in their place.
    pub set_aside: Option<PathBuf>,
}

impl Committed {
    /// A sentence for the user when the run's files were set aside.
    pub fn note(&self, dir: &Path) -> Option<String> {
        self.set_aside.as_ref().map(|aside| {
            format!(
                "the earlier run's files in {} are kept as they were; this run's are in {}",
                dir.display(),
                aside.display()
            )
        })
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

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("lightgrid-outdir-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    /// One run of `command` writing `files` (name, content) and committing them.
    fn run(dir: &Path, command: &str, files: &[(&str, &str)], earlier: Earlier) -> Result<()> {
        let out = OutDir::claim(dir, command, false)?;
        let written: Vec<PathBuf> = files
            .iter()
            .map(|(n, c)| {
                let p = out.staging().join(n);
                std::fs::write(&p, c).unwrap();
                p
            })
            .collect();
        out.commit(&written, earlier, true).map(drop)
    }

    #[test]
    fn each_command_replaces_and_removes_only_its_own_files() {
        let dir = scratch("own");
        run(
            &dir,
            "bench",
            &[("results.json", "b1"), ("old.png", "b1")],
            Earlier::Remove,
        )
        .unwrap();
        run(&dir, "compare", &[("forward.png", "c1")], Earlier::Remove).unwrap();
        // bench again without old.png: its own old.png goes, compare's file stays.
        run(&dir, "bench", &[("results.json", "b2")], Earlier::Remove).unwrap();
        assert_eq!(
            names(&dir),
            [
                ".lightgrid-files-bench",
                ".lightgrid-files-compare",
                "forward.png",
                "results.json"
            ]
        );
        assert_eq!(
            std::fs::read_to_string(dir.join("results.json")).unwrap(),
            "b2"
        );
        // Keep (report): earlier files stay listed and in place.
        run(&dir, "compare", &[("compare.json", "c2")], Earlier::Keep).unwrap();
        assert!(dir.join("forward.png").exists());
        let listed = std::fs::read_to_string(dir.join(manifest_name("compare"))).unwrap();
        assert!(
            listed.contains("forward.png") && listed.contains("compare.json"),
            "{listed}"
        );
        // Another command's file is not replaced: refused, the file as it was, the run's
        // files kept aside.
        let e = run(&dir, "scaling", &[("results.json", "s1")], Earlier::Remove)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("results.json (written by `lightgrid bench`)"),
            "{e}"
        );
        assert_eq!(
            std::fs::read_to_string(dir.join("results.json")).unwrap(),
            "b2"
        );
        let aside = names(&dir)
            .into_iter()
            .find(|n| n.starts_with("lightgrid-scaling-"));
        assert!(aside.is_some(), "{:?}", names(&dir));
        // No staging directory or lock stays after a run, whatever its end.
        assert!(!names(&dir)
            .iter()
            .any(|n| n.starts_with(STAGING_PREFIX) || n == LOCK_FILE));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_run_that_fails_before_committing_changes_nothing() {
        let dir = scratch("fail");
        run(&dir, "bench", &[("results.json", "b1")], Earlier::Remove).unwrap();
        let before = names(&dir);
        {
            let out = OutDir::claim(&dir, "bench", false).unwrap();
            std::fs::write(out.staging().join("results.json"), "half").unwrap();
            // Dropped without commit: a write failed part-way.
        }
        assert_eq!(names(&dir), before);
        assert_eq!(
            std::fs::read_to_string(dir.join("results.json")).unwrap(),
            "b1"
        );
        // A staging directory of a killed run is removed by the next claim.
        std::fs::create_dir(dir.join(format!("{STAGING_PREFIX}999999999"))).unwrap();
        drop(OutDir::claim(&dir, "bench", false).unwrap());
        assert_eq!(names(&dir), before);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_foreign_directory_needs_force() {
        let dir = scratch("foreign");
        std::fs::create_dir_all(&dir).unwrap();
        check_out_dir(&dir, false).unwrap();
        std::fs::write(dir.join("notes.txt"), "mine").unwrap();
        let e = check_out_dir(&dir, false).unwrap_err().to_string();
        assert!(
            e.contains("not made by lightgrid (it holds notes.txt)"),
            "{e}"
        );
        check_out_dir(&dir, true).unwrap();
        assert!(OutDir::claim(&dir, "bench", false).is_err());
        drop(OutDir::claim(&dir, "bench", true).unwrap());
        assert_eq!(names(&dir), ["notes.txt"]);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
