//! Health files for container healthchecks. The images are `FROM scratch` (no shell, no curl),
//! so a healthy process proves it is alive by rewriting a file every [`BEAT`], and the same
//! binary, run as the healthcheck, says whether the file is fresh.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, SystemTime};

/// How often a [`Heartbeat`] rewrites its file.
pub const BEAT: Duration = Duration::from_secs(2);

/// Rewrites a file every [`BEAT`] until dropped; the file is removed on drop.
#[derive(Debug)]
pub struct Heartbeat {
    path: PathBuf,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl Heartbeat {
    /// Starts beating `path` (the first beat is immediate; a write error is logged once).
    pub fn start(path: &Path) -> Heartbeat {
        let stop = Arc::new(AtomicBool::new(false));
        let (flag, file) = (Arc::clone(&stop), path.to_path_buf());
        let thread = std::thread::spawn(move || {
            let mut warned = false;
            while !flag.load(Ordering::Relaxed) {
                if let Err(e) = std::fs::write(&file, b"ok\n") {
                    if !warned {
                        tracing::warn!("cannot write the health file {}: {e}", file.display());
                        warned = true;
                    }
                }
                for _ in 0..20 {
                    if flag.load(Ordering::Relaxed) {
                        break;
                    }
                    std::thread::sleep(BEAT / 20);
                }
            }
        });
        Heartbeat {
            path: path.to_path_buf(),
            stop,
            thread: Some(thread),
        }
    }
}

impl Drop for Heartbeat {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
        let _ = std::fs::remove_file(&self.path);
    }
}

/// Why a process is not healthy.
#[derive(Debug, thiserror::Error)]
pub enum Unhealthy {
    /// The health file cannot be read: the process never started beating, or stopped.
    #[error("unhealthy: no health file {}: {source}", path.display())]
    NoFile {
        /// The health file.
        path: PathBuf,
        /// What the file system said.
        source: std::io::Error,
    },
    /// The file is older than the limit: the process is alive no more, or hangs.
    #[error(
        "unhealthy: {} last written {:.0} s ago (limit {:.0} s)",
        path.display(),
        age.as_secs_f64(),
        limit.as_secs_f64()
    )]
    Stale {
        /// The health file.
        path: PathBuf,
        /// Time since it was last written.
        age: Duration,
        /// The limit it broke.
        limit: Duration,
    },
}

/// Whether `path` was rewritten within `max_age`; the error says why not.
pub fn check(path: &Path, max_age: Duration) -> Result<(), Unhealthy> {
    let modified = std::fs::metadata(path)
        .and_then(|m| m.modified())
        .map_err(|source| Unhealthy::NoFile {
            path: path.to_path_buf(),
            source,
        })?;
    let age = SystemTime::now()
        .duration_since(modified)
        .unwrap_or(Duration::ZERO);
    if age <= max_age {
        Ok(())
    } else {
        Err(Unhealthy::Stale {
            path: path.to_path_buf(),
            age,
            limit: max_age,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_beating_file_is_fresh_and_gone_after_drop() -> Result<(), Unhealthy> {
        let path = std::env::temp_dir().join(format!("shoal-health-{}", std::process::id()));
        assert!(check(&path, BEAT).is_err(), "no file yet");
        let beat = Heartbeat::start(&path);
        std::thread::sleep(Duration::from_millis(200));
        check(&path, BEAT)?;
        drop(beat);
        let e = check(&path, BEAT)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("no health file"), "{e}");
        Ok(())
    }

    #[test]
    fn a_stale_file_is_unhealthy() -> Result<(), Box<dyn std::error::Error>> {
        let path = std::env::temp_dir().join(format!("shoal-stale-{}", std::process::id()));
        std::fs::write(&path, b"ok\n")?;
        std::thread::sleep(Duration::from_millis(50));
        let e = check(&path, Duration::from_millis(1))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        std::fs::remove_file(&path)?;
        assert!(e.contains("last written"), "{e}");
        Ok(())
    }
}
