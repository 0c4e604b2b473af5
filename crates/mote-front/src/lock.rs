//! One run per output folder: a run holds `DIR/.mote.lock` (its process
//! id) while it writes there, so a second run into the same folder is
//! refused instead of interleaving its rows with the first one's. A lock
//! left by a run that no longer exists (killed with SIGKILL) is taken over.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::{refuse, FrontError};

/// The lock of an output folder, released when dropped.
#[derive(Debug)]
pub struct FolderLock {
    path: PathBuf,
}

impl FolderLock {
    /// Takes the lock of `dir` (which must exist).
    pub fn take(dir: &Path) -> Result<FolderLock, FrontError> {
        let path = dir.join(".mote.lock");
        for _ in 0..3 {
            match std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(&path)
            {
                Ok(mut file) => {
                    write!(file, "{}", std::process::id())
                        .map_err(|e| mote_io::IoError::os(&path, e))?;
                    return Ok(FolderLock { path });
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    let holder = std::fs::read_to_string(&path)
                        .ok()
                        .and_then(|s| s.trim().parse::<u32>().ok());
                    if let Some(pid) = holder.filter(|p| is_running(*p)) {
                        refuse!(
                            "{}: another mote run (process {pid}) is writing into this folder; wait for it or give another with -o",
                            dir.display()
                        );
                    }
                    // A lock its run left behind: take it over.
                    let _ = std::fs::remove_file(&path);
                }
                Err(e) => return Err(mote_io::IoError::os(&path, e).into()),
            }
        }
        refuse!("{}: cannot take the output folder's lock", path.display())
    }
}

impl Drop for FolderLock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// Whether process `pid` exists (Linux: /proc/PID; elsewhere every lock
/// counts as left behind).
fn is_running(pid: u32) -> bool {
    pid != std::process::id() && Path::new(&format!("/proc/{pid}")).exists()
}
