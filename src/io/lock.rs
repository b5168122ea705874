//! A run's claim on its output directory: an advisory lock (`flock`) on a lock file in it,
//! taken before the run touches anything there, so that a second run into the same
//! directory is refused without changing a byte of the first one's output.
//!
//! The kernel holds the lock for the process: it goes when the process ends however it
//! ends (a kill -9 too), so a lock file left behind is free for the next run, and a process
//! id written in it that now belongs to another process does not matter. The id is there
//! for the message only.

use std::fs::{File, OpenOptions, TryLockError};
use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

/// The name of the lock file a running run keeps in its output directory.
pub const LOCK: &str = ".tinydem.lock";

/// The lock of one output directory, held while this value lives.
#[derive(Debug)]
pub struct Lock {
    path: PathBuf,
    /// The open lock file: closing it releases the lock.
    _file: File,
}

impl Lock {
    /// Takes the lock of `dir` (which must exist), or says which process holds it.
    pub fn take(dir: &Path) -> Result<Lock> {
        let path = dir.join(LOCK);
        // A run that ends removes the file while it holds the lock; one that opened the
        // file just before then gets the lock of a removed file, sees that and tries again.
        for _ in 0..100 {
            let mut file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&path)
                .with_context(|| format!("cannot create {}", path.display()))?;
            match file.try_lock() {
                Ok(()) => {}
                Err(TryLockError::WouldBlock) => {
                    let holder = std::fs::read_to_string(&path).unwrap_or_default();
                    let holder = match holder.trim() {
                        "" => String::new(),
                        pid => format!(" (process {pid})"),
                    };
                    bail!(
                        "another tinydem run{holder} is writing into {}: wait for it, or choose another directory with --output",
                        dir.display()
                    );
                }
                Err(TryLockError::Error(e)) => {
                    return Err(e).with_context(|| format!("cannot lock {}", path.display()));
                }
            }
            if !same_file(&file, &path) {
                continue;
            }
            file.set_len(0)
                .and_then(|()| writeln!(file, "{}", std::process::id()))
                .with_context(|| format!("cannot write {}", path.display()))?;
            return Ok(Lock { path, _file: file });
        }
        bail!("cannot take the lock {}", path.display())
    }
}

/// Whether `path` still names the open `file`.
fn same_file(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

impl Drop for Lock {
    fn drop(&mut self) {
        // Removed while held; the lock goes when the file closes, after this.
        let _ = std::fs::remove_file(&self.path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_held_lock_refuses_a_second_taker_and_a_left_file_is_free() {
        let dir = tempfile::tempdir().unwrap();
        let first = Lock::take(dir.path()).unwrap();
        let err = Lock::take(dir.path()).unwrap_err().to_string();
        let me = std::process::id();
        assert!(
            err.contains(&format!("another tinydem run (process {me})")),
            "{err}"
        );
        drop(first);
        assert!(
            !dir.path().join(LOCK).exists(),
            "the lock file goes with the lock"
        );
        // A file left by a killed run, naming a live process (this one): free to take.
        std::fs::write(dir.path().join(LOCK), format!("{me}\n")).unwrap();
        let again = Lock::take(dir.path()).unwrap();
        drop(again);
    }

    #[test]
    fn of_threads_taking_the_lock_together_exactly_one_gets_it() {
        for _ in 0..20 {
            let dir = tempfile::tempdir().unwrap();
            let barrier = std::sync::Barrier::new(4);
            let taken = std::thread::scope(|s| {
                let handles: Vec<_> = (0..4)
                    .map(|_| {
                        s.spawn(|| {
                            barrier.wait();
                            let lock = Lock::take(dir.path());
                            barrier.wait(); // all have tried before any lets go
                            lock.is_ok()
                        })
                    })
                    .collect();
                handles
                    .into_iter()
                    .map(|h| h.join().unwrap())
                    .filter(|&ok| ok)
                    .count()
            });
            assert_eq!(taken, 1);
        }
    }
}
