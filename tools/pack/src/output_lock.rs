//! One pack per output. Two runs writing the same `-o` would truncate each other's `<output>.part`
//! (and a `--resume` of one would move the other's file away), so a run holds an exclusive lock
//! on `<output>.lock` from before it looks for a run to resume until its output is in place.
//!
//! The lock is the operating system's (flock on Unix): it dies with the process, so a killed
//! run leaves at most a stale `.lock` file, which the next run simply locks again. A run that
//! ends normally removes the file while it still holds the lock.

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context};

/// The held lock of one output; released (and its file removed) on drop.
pub struct OutputLock {
    path: PathBuf,
    _file: File,
}

impl OutputLock {
    /// Locks `<output>.lock`, or says which run holds it. Special outputs (`/dev/null`, a FIFO)
    /// are not locked: their part file is private to the run (see `TrajectoryWriter::create`).
    pub fn acquire(output: &str) -> anyhow::Result<Option<Self>> {
        if pellet_io::is_special_file(Path::new(output)) {
            return Ok(None);
        }
        let path = PathBuf::from(format!("{output}.lock"));
        loop {
            let mut file = OpenOptions::new()
                .create(true)
                .read(true)
                .write(true)
                .truncate(false)
                .open(&path)
                .with_context(|| format!("cannot create the lock file {}", path.display()))?;
            match file.try_lock() {
                Ok(()) => {}
                Err(std::fs::TryLockError::WouldBlock) => {
                    let mut holder = String::new();
                    let _ = file.read_to_string(&mut holder);
                    let who = match holder.trim() {
                        "" => "another pack".to_string(),
                        pid => format!("another pack (pid {pid})"),
                    };
                    bail!(
                        "{who} is writing {output} (it holds {}); wait for it to finish, stop it, or give another -o",
                        path.display()
                    );
                }
                Err(std::fs::TryLockError::Error(e)) => {
                    return Err(e).with_context(|| format!("cannot lock {}", path.display()));
                }
            }
            // The run that held it may have removed the file between our open and our lock: then
            // we hold a lock nobody else can see, and must lock the file now at that path.
            if same_file(&file, &path) {
                file.set_len(0)?;
                file.rewind()?;
                write!(file, "{}", std::process::id())?;
                return Ok(Some(Self { path, _file: file }));
            }
        }
    }
}

#[cfg(unix)]
fn same_file(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_file(_: &File, path: &Path) -> bool {
    // Elsewhere an open file cannot be removed: the path still names it.
    path.exists()
}

impl Drop for OutputLock {
    fn drop(&mut self) {
        // Removed while still locked: a run that opened it meanwhile sees it gone and retries.
        let _ = std::fs::remove_file(&self.path);
    }
}
