//! Claiming a file output before the work that makes it. A command that writes one large
//! file (a field) claims it first, so that what would make it fail at the end fails at
//! once instead, and nothing of its own is left behind from earlier runs:
//!
//! - a directory at the output's path is refused before any work (it used to be found
//!   only at the final rename, after minutes of work, leaving a full-size temporary file);
//! - the output is locked while the command runs: a lock file `.NAME.lock` beside it,
//!   held with an advisory lock (`flock`) that the system releases when the process ends,
//!   however it ends; a second writer of the same output is refused by name;
//! - under the lock, temporary files of the same output left by earlier runs that were
//!   interrupted (`.NAME.*.tmp`, see [`crate::atomic`]) are removed: no live writer
//!   can own them any more.

use std::fs::{File, OpenOptions, TryLockError};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::error::{CoreError, Result};

/// The outputs claimed and not yet released, for [`abandon_live_claims`]: each one's lock
/// file, and the directory and prefix (`NAME.`) of its temporaries.
static LIVE: Mutex<Vec<(PathBuf, PathBuf, String)>> = Mutex::new(Vec::new());

/// What an interrupted process does with its claims before it exits (the binary calls
/// it from its interrupt handler): removes their lock files and the temporaries of their
/// outputs, so that an interrupt leaves nothing behind. (A process killed outright leaves
/// them; the next claim of the same output clears its temporaries.)
pub fn abandon_live_claims() {
    let live = LIVE.lock().unwrap_or_else(|e| e.into_inner());
    for (lock, dir, prefix) in live.iter() {
        remove_temporaries(dir, prefix);
        let _ = std::fs::remove_file(lock);
    }
}

/// A claimed output; the lock is released (and its file removed) when it is dropped.
#[derive(Debug)]
pub struct OutputClaim {
    lock_path: PathBuf,
    lock: Option<File>,
    removed: Vec<PathBuf>,
}

impl OutputClaim {
    /// What was removed, for a person: `None` when nothing was.
    pub fn removed_note(&self) -> Option<String> {
        if self.removed.is_empty() {
            return None;
        }
        let names: Vec<String> = self
            .removed
            .iter()
            .map(|p| p.display().to_string())
            .collect();
        Some(format!(
            "removed {} temporary file(s) an interrupted run left: {}",
            names.len(),
            names.join(", ")
        ))
    }

    /// Temporary files of earlier, interrupted runs that the claim removed.
    pub fn removed(&self) -> &[PathBuf] {
        &self.removed
    }

    /// Removes every temporary file (`.*.tmp`) in `dir`, a directory only this output's
    /// writer uses (e.g. the per-pose parts of an ingest), and counts them in
    /// [`OutputClaim::removed`].
    pub fn clear_temporaries_in(&mut self, dir: &Path) {
        self.removed.extend(remove_temporaries(dir, ""));
    }
}

impl Drop for OutputClaim {
    fn drop(&mut self) {
        // Removed while still held, so that no other process can take the lock on a file
        // that is about to disappear unnoticed (they check the name after locking).
        let _ = std::fs::remove_file(&self.lock_path);
        drop(self.lock.take());
        LIVE.lock()
            .unwrap_or_else(|e| e.into_inner())
            .retain(|(lock, _, _)| lock != &self.lock_path);
    }
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Removes the temporaries `.PREFIX*.tmp` in `dir`; returns what it removed.
fn remove_temporaries(dir: &Path, prefix: &str) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let start = format!(".{prefix}");
    entries
        .flatten()
        .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
        .map(|e| e.path())
        .filter(|p| {
            let name = file_name(p);
            name.starts_with(&start) && name.ends_with(".tmp")
        })
        .filter(|p| std::fs::remove_file(p).is_ok())
        .collect()
}

/// Whether `file` (open) is still the file at `path` (not removed or replaced since).
fn same_file(file: &File, path: &Path) -> bool {
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => crate::atomic::same_inode(&a, &b),
        _ => false,
    }
}

/// Claims the file output `path` (see the module text): refuses a directory there, creates
/// its parent directories, locks it against a second writer and removes the temporaries
/// earlier runs left. Errors name `path`.
pub fn claim_output(path: &Path) -> Result<OutputClaim> {
    if path.is_dir() {
        return Err(CoreError::BadOutput {
            path: path.to_path_buf(),
            problem: "a directory is there: give the path of the file to write".into(),
        });
    }
    let name = file_name(path);
    if name.is_empty() {
        return Err(CoreError::BadOutput {
            path: path.to_path_buf(),
            problem: "names no file".into(),
        });
    }
    let parent = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).map_err(|e| CoreError::io(parent, e))?;
    let lock_path = parent.join(format!(".{name}.lock"));
    // Held from before the lock file exists until the claim is listed live: an interrupt
    // in between waits for the listing in `abandon_live_claims`, which then removes the
    // file (an interrupt there once left the lock file behind).
    let mut live = LIVE.lock().unwrap_or_else(|e| e.into_inner());
    let lock = loop {
        let file = OpenOptions::new()
            .create(true)
            .truncate(false)
            .write(true)
            .open(&lock_path)
            // Named by the output asked for (e.g. a directory one may not write).
            .map_err(|e| CoreError::io(path, e))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) => {
                return Err(CoreError::Busy {
                    path: path.to_path_buf(),
                    lock: lock_path,
                });
            }
            Err(TryLockError::Error(e)) => return Err(CoreError::io(&lock_path, e)),
        }
        // The holder before us may have removed the file between our open and our lock:
        // then ours is a lock on nothing, and we take the new one.
        if same_file(&file, &lock_path) {
            break file;
        }
    };
    let _ = std::fs::write(&lock_path, format!("{}\n", std::process::id()));
    let prefix = format!("{name}.");
    let removed = remove_temporaries(parent, &prefix);
    live.push((lock_path.clone(), parent.to_path_buf(), prefix));
    drop(live);
    Ok(OutputClaim {
        lock_path,
        lock: Some(lock),
        removed,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn claims_abandoned_on_an_interrupt_leave_no_lock_or_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("f.frf");
        let claim = claim_output(&out).unwrap();
        let lock = out.with_file_name(".f.frf.lock");
        let half = out.with_file_name(".f.frf.77.tmp");
        std::fs::write(&half, b"half a field").unwrap();
        assert!(lock.exists());
        abandon_live_claims();
        assert!(!lock.exists() && !half.exists());
        drop(claim);
        // Released claims are not abandoned again.
        assert!(LIVE.lock().unwrap().iter().all(|(p, _, _)| p != &lock));
    }

    #[test]
    fn a_claim_refuses_a_second_writer_and_a_directory_and_clears_old_temporaries() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("sub").join("f.frf");
        std::fs::create_dir_all(out.parent().unwrap()).unwrap();
        let stale = out.with_file_name(".f.frf.4242.tmp");
        let other = out.with_file_name(".g.frf.4242.tmp");
        std::fs::write(&stale, b"half a field").unwrap();
        std::fs::write(&other, b"another output's").unwrap();
        let claim = claim_output(&out).unwrap();
        assert_eq!(claim.removed(), std::slice::from_ref(&stale));
        assert!(!stale.exists() && other.exists());
        let again = claim_output(&out).unwrap_err().to_string();
        assert!(again.contains("another process is writing it"), "{again}");
        assert!(again.contains("f.frf"), "{again}");
        drop(claim);
        assert!(!out.with_file_name(".f.frf.lock").exists());
        let claim = claim_output(&out).unwrap();
        drop(claim);
        let e = claim_output(dir.path()).unwrap_err().to_string();
        assert!(e.contains("a directory is there"), "{e}");
    }
}
