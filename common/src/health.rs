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

/// Whether `path` was rewritten within `max_age`; the error says why not.
pub fn check(path: &Path, max_age: Duration) -> Result<(), String> {
    let modified = std::fs::metadata(path)
        .and_then(|m| m.modified())
        .map_err(|e| format!("unhealthy: no health file {}: {e}", path.display()))?;
    let age = SystemTime::now()
        .duration_since(modified)
        .unwrap_or(Duration::ZERO);
    if age <= max_age {
        Ok(())
    } else {
        Err(format!(
            "unhealthy: {} last written {:.0} s ago (limit {:.0} s)",
            path.display(),
            age.as_secs_f64(),
            max_age.as_secs_f64()
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_beating_file_is_fresh_and_gone_after_drop() -> Result<(), String> {
        let path = std::env::temp_dir().join(format!("shoal-health-{}", std::process::id()));
        assert!(check(&path, BEAT).is_err(), "no file yet");
        let beat = Heartbeat::start(&path);
        std::thread::sleep(Duration::from_millis(200));
        check(&path, BEAT)?;
        drop(beat);
        let e = check(&path, BEAT).err().unwrap_or_default();
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
            .unwrap_or_default();
        std::fs::remove_file(&path)?;
        assert!(e.contains("last written"), "{e}");
        Ok(())
    }
}
