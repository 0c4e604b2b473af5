//! One run per output folder, and each folder owned by one run.
//!
//! A run holds `DIR/.mote.lock` while it writes there: an advisory lock
//! (`flock`) on that file, which the kernel releases when the process ends
//! however it ends, so a lock is never judged stale by its contents (an
//! empty file, a reused process id). The file holds the process id, for the
//! message a second run gets.
//!
//! A run also marks the folder as its own: `DIR/.mote-run` names the run
//! (a random run id, the input's hash and label). Checkpoints record the
//! same identity, and `--resume` continues only in a folder whose mark is
//! the checkpoint's run: it never trims or appends to another run's files.

use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

use mote_io::checkpoint::Checkpoint;
use mote_io::IoError;

use crate::error::{refuse, FrontError};

/// The lock of an output folder, released when dropped.
#[derive(Debug)]
pub struct FolderLock {
    path: PathBuf,
    /// Holds the advisory lock for as long as it is open.
    _file: File,
}

impl FolderLock {
    /// Takes the lock of `dir` (which must exist), or refuses if another
    /// run holds it.
    pub fn take(dir: &Path) -> Result<FolderLock, FrontError> {
        let path = dir.join(".mote.lock");
        let os = |e| FrontError::from(IoError::os(&path, e));
        // A holder that releases between our open and our lock may have
        // removed the file: the lock we got is then on a name no longer in
        // the folder, and we try again on the new one.
        for _ in 0..8 {
            let mut file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&path)
                .map_err(os)?;
            match file.try_lock() {
                Ok(()) => {}
                Err(TryLockError::WouldBlock) => {
                    // The holder writes its process id just after locking.
                    let mut holder = String::new();
                    for _ in 0..20 {
                        holder.clear();
                        let _ = file
                            .rewind()
                            .and_then(|()| file.read_to_string(&mut holder));
                        if !holder.is_empty() {
                            break;
                        }
                        std::thread::sleep(std::time::Duration::from_millis(5));
                    }
                    let who = match holder.trim().parse::<u32>() {
                        Ok(pid) => format!("another mote run (process {pid})"),
                        Err(_) => "another mote run".to_string(),
                    };
                    refuse!(
                        "{}: {who} is writing into this folder; wait for it or give another with -o",
                        dir.display()
                    );
                }
                Err(TryLockError::Error(e)) => return Err(os(e)),
            }
            if !same_file(&file, &path) {
                continue;
            }
            file.set_len(0).map_err(os)?;
            file.rewind().map_err(os)?;
            write!(file, "{}", std::process::id()).map_err(os)?;
            return Ok(FolderLock { path, _file: file });
        }
        refuse!("{}: cannot take the output folder's lock", path.display())
    }
}

impl Drop for FolderLock {
    fn drop(&mut self) {
        // Removed while still held; the lock goes with the file handle.
        let _ = std::fs::remove_file(&self.path);
    }
}

/// Whether the open `file` is still the one named `path`.
#[cfg(unix)]
fn same_file(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_file(_file: &File, path: &Path) -> bool {
    path.exists()
}

/// Who a run is: written into its folder and into its checkpoints.
#[derive(Debug, Clone, PartialEq)]
pub struct RunIdentity {
    /// Random, 16 hexadecimal digits.
    pub run_id: String,
    /// FNV-1a of the input's text, 16 hexadecimal digits.
    pub input_hash: String,
    /// What the input was called.
    pub input_label: String,
}

impl RunIdentity {
    /// A new run of the input `label` with text `text`.
    pub fn fresh(label: &str, text: &str) -> RunIdentity {
        RunIdentity {
            run_id: format!("{:016x}", rand::random::<u64>()),
            input_hash: input_hash(text),
            input_label: label.to_string(),
        }
    }

    /// The run a checkpoint came from, if it records one (checkpoints of
    /// mote before run ids do not).
    pub fn of_checkpoint(cp: &Checkpoint) -> Option<RunIdentity> {
        Some(RunIdentity {
            run_id: cp.option("run-id")?.to_string(),
            input_hash: input_hash(&cp.input_text),
            input_label: cp.input_label.clone(),
        })
    }

    /// The identity a folder's mark names, if it has one.
    fn of_folder(dir: &Path) -> Option<RunIdentity> {
        let text = std::fs::read_to_string(dir.join(MARK)).ok()?;
        let mut lines = text.lines();
        if lines.next()? != "mote-run 1" {
            return None;
        }
        let mut get = |key: &str| {
            lines
                .next()
                .and_then(|l| l.strip_prefix(key))
                .map(|v| v.trim().to_string())
        };
        Some(RunIdentity {
            run_id: get("run-id ")?,
            input_hash: get("input-hash ")?,
            input_label: get("input ").unwrap_or_default(),
        })
    }

    /// Writes the mark of `dir` (atomically: a reader sees the old mark
    /// or the new one).
    fn mark(&self, dir: &Path) -> Result<(), FrontError> {
        let path = dir.join(MARK);
        let tmp = dir.join(".mote-run.tmp");
        let text = format!(
            "mote-run 1\nrun-id {}\ninput-hash {}\ninput {}\n",
            self.run_id,
            self.input_hash,
            self.input_label.replace('\n', " ")
        );
        std::fs::write(&tmp, text)
            .and_then(|()| std::fs::rename(&tmp, &path))
            .map_err(|e| IoError::os(&path, e).into())
    }
}

/// The name of a folder's mark.
const MARK: &str = ".mote-run";

/// The files a run writes into its folder, by name or by stem.
fn holds_run_files(dir: &Path) -> bool {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return false;
    };
    entries.flatten().any(|e| {
        let name = e.file_name();
        let name = name.to_string_lossy();
        name == "observables.csv"
            || name == "nip.csv"
            || name == "packing.xyz"
            || name.starts_with("trajectory.")
    })
}

/// 64-bit FNV-1a of `text`, as 16 hexadecimal digits.
pub fn input_hash(text: &str) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("{h:016x}")
}

/// An output folder held by one run: locked, and marked as that run's.
#[derive(Debug)]
pub struct RunFolder {
    pub dir: PathBuf,
    pub identity: RunIdentity,
    _lock: FolderLock,
}

impl RunFolder {
    /// Creates `dir` if needed, takes its lock and marks it as a new run's.
    pub fn fresh(dir: &Path, label: &str, text: &str) -> Result<RunFolder, FrontError> {
        std::fs::create_dir_all(dir).map_err(|e| IoError::os(dir, e))?;
        let lock = FolderLock::take(dir)?;
        let identity = RunIdentity::fresh(label, text);
        identity.mark(dir)?;
        Ok(RunFolder {
            dir: dir.to_path_buf(),
            identity,
            _lock: lock,
        })
    }

    /// Takes `dir` to continue the run checkpoint `cp` (read from `path`)
    /// came from, refusing a folder that holds another run's files: its
    /// mark names another run, or it holds files but no mark of this run.
    pub fn resumed(dir: &Path, cp: &Checkpoint, path: &Path) -> Result<RunFolder, FrontError> {
        std::fs::create_dir_all(dir).map_err(|e| IoError::os(dir, e))?;
        let lock = FolderLock::take(dir)?;
        let ours = RunIdentity::of_checkpoint(cp);
        let theirs = RunIdentity::of_folder(dir);
        let why = |what: String| -> FrontError {
            FrontError::request(format!(
                "{}: cannot resume into {}: {what}; resuming would trim that run's files and splice \
                 two runs into one. Run afresh, or resume from a checkpoint of the run the folder holds",
                path.display(),
                dir.display()
            ))
        };
        let identity = match (ours, theirs) {
            (Some(ours), Some(theirs)) if ours.run_id == theirs.run_id => ours,
            (Some(ours), Some(theirs)) => {
                return Err(why(format!(
                "the checkpoint is of run {} ({}), the folder now holds the files of run {} ({})",
                ours.run_id, ours.input_label, theirs.run_id, theirs.input_label
            )))
            }
            (None, Some(theirs)) => {
                return Err(why(format!(
                "the folder holds the files of run {} ({}), written after this checkpoint's run",
                theirs.run_id, theirs.input_label
            )))
            }
            (Some(ours), None) if holds_run_files(dir) => {
                return Err(why(format!(
                    "the checkpoint is of run {} ({}), the folder holds files no run of it wrote",
                    ours.run_id, ours.input_label
                )))
            }
            (Some(ours), None) => ours,
            // A checkpoint of a mote before run ids, in a folder of that
            // time: continued as then, and marked from now on.
            (None, None) => RunIdentity::fresh(&cp.input_label, &cp.input_text),
        };
        identity.mark(dir)?;
        Ok(RunFolder {
            dir: dir.to_path_buf(),
            identity,
            _lock: lock,
        })
    }

    /// Takes `dir` for a fresh run or for the checkpoint `resumed`
    /// (read from `path`).
    pub fn claim(
        dir: &Path,
        label: &str,
        text: &str,
        resumed: Option<(&Checkpoint, &Path)>,
    ) -> Result<RunFolder, FrontError> {
        match resumed {
            Some((cp, path)) => RunFolder::resumed(dir, cp, path),
            None => RunFolder::fresh(dir, label, text),
        }
    }

    /// What a checkpoint of this run records of it: the run id, the
    /// input's hash and the folder (absolute, so a resume from another
    /// working directory finds it).
    pub fn checkpoint_options(&self) -> Vec<(String, String)> {
        let folder = std::path::absolute(&self.dir).unwrap_or_else(|_| self.dir.clone());
        vec![
            ("run-id".into(), self.identity.run_id.clone()),
            ("input-hash".into(), self.identity.input_hash.clone()),
            ("folder".into(), folder.display().to_string()),
        ]
    }
}

/// The folder a checkpoint's run continues in: the checkpoint's own folder
/// where that holds the run (a folder moved as a whole), else the folder
/// the run recorded (`folder`, absolute; `output` in older checkpoints).
/// The second flag says the folder is not the one the checkpoint lies in,
/// so the caller shows where the run goes on.
pub fn resume_folder(cp: &Checkpoint, path: &Path) -> (PathBuf, bool) {
    let own = path
        .parent()
        .map(|p| {
            if p.as_os_str().is_empty() {
                PathBuf::from(".")
            } else {
                p.to_path_buf()
            }
        })
        .unwrap_or_else(|| PathBuf::from("."));
    let ours = RunIdentity::of_checkpoint(cp);
    if let (Some(ours), Some(there)) = (&ours, RunIdentity::of_folder(&own)) {
        if ours.run_id == there.run_id {
            return (own, false);
        }
    }
    let recorded = cp
        .option("folder")
        .or_else(|| cp.option("output"))
        .map(PathBuf::from)
        .unwrap_or_else(|| own.clone());
    let elsewhere = !same_place(&recorded, &own);
    (recorded, elsewhere)
}

/// Whether two paths name one folder.
fn same_place(a: &Path, b: &Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::{Arc, Barrier};

    #[test]
    fn two_takers_at_once_never_both_hold_the_lock() {
        for _ in 0..100 {
            let dir = tempfile::tempdir().unwrap();
            let dir = Arc::new(dir.path().to_path_buf());
            // Both try together, and both have tried before either lets go.
            let tried = Arc::new(Barrier::new(2));
            let start = Arc::new(Barrier::new(2));
            let takers: Vec<_> = (0..2)
                .map(|_| {
                    let (dir, tried, start) = (dir.clone(), tried.clone(), start.clone());
                    std::thread::spawn(move || {
                        start.wait();
                        let lock = FolderLock::take(&dir);
                        tried.wait();
                        lock.is_ok()
                    })
                })
                .collect();
            let held = takers
                .into_iter()
                .map(|t| t.join().unwrap())
                .filter(|ok| *ok)
                .count();
            assert_eq!(
                held, 1,
                "exactly one of two simultaneous runs holds the folder"
            );
        }
    }

    #[test]
    fn a_lock_file_left_behind_is_taken_whatever_it_holds() {
        let dir = tempfile::tempdir().unwrap();
        for left in ["", "1", "not a pid"] {
            std::fs::write(dir.path().join(".mote.lock"), left).unwrap();
            let lock = FolderLock::take(dir.path()).expect("no process holds it");
            let again = FolderLock::take(dir.path()).unwrap_err().to_string();
            assert!(
                again.contains(&format!("process {}", std::process::id())),
                "{again}"
            );
            drop(lock);
            assert!(!dir.path().join(".mote.lock").exists());
        }
    }

    #[test]
    fn a_checkpoint_of_another_run_is_refused_by_the_folder() {
        let dir = tempfile::tempdir().unwrap();
        let first = RunFolder::fresh(dir.path(), "a.toml", "seed = 1").unwrap();
        let cp = Checkpoint {
            input_label: "a.toml".into(),
            input_text: "seed = 1".into(),
            options: first.checkpoint_options(),
            ..Checkpoint::default()
        };
        drop(first);
        let cp_path = dir.path().join("checkpoint.mote");
        // The same run continues.
        drop(RunFolder::resumed(dir.path(), &cp, &cp_path).unwrap());
        // A newer run takes the folder: the old checkpoint is refused.
        drop(RunFolder::fresh(dir.path(), "a.toml", "seed = 2").unwrap());
        let e = RunFolder::resumed(dir.path(), &cp, &cp_path)
            .unwrap_err()
            .to_string();
        assert!(e.contains("holds the files of run"), "{e}");
        // A checkpoint of a mote before run ids is refused there too.
        let old = Checkpoint {
            options: vec![],
            ..cp.clone()
        };
        assert!(RunFolder::resumed(dir.path(), &old, &cp_path).is_err());
        // Files without any mark are not taken for the checkpoint's run's.
        let bare = tempfile::tempdir().unwrap();
        std::fs::write(bare.path().join("observables.csv"), "step\n").unwrap();
        assert!(RunFolder::resumed(bare.path(), &cp, &cp_path).is_err());
    }

    #[test]
    fn a_moved_folder_resumes_where_its_checkpoint_lies() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a");
        let run = RunFolder::fresh(&a, "a.toml", "x").unwrap();
        let cp = Checkpoint {
            input_text: "x".into(),
            options: run.checkpoint_options(),
            ..Checkpoint::default()
        };
        drop(run);
        let b = dir.path().join("b");
        std::fs::rename(&a, &b).unwrap();
        assert_eq!(
            resume_folder(&cp, &b.join("checkpoint.mote")),
            (b.clone(), false)
        );
        // A copy of the checkpoint elsewhere goes to the recorded folder,
        // and says so.
        let (to, elsewhere) = resume_folder(&cp, &dir.path().join("cp.mote"));
        assert_eq!(to, std::path::absolute(&a).unwrap());
        assert!(elsewhere);
    }
}
