//! A headless browser showing the web view, for `bench-telemetry --view`: Debian's `chromium`
//! started on the page's address with a profile of its own, killed when dropped.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use anyhow::Context as _;

use crate::view::ViewStats;

/// A running headless browser.
pub struct Headless {
    /// The browser process.
    child: Child,
    /// Its profile and log directory.
    dir: PathBuf,
}

impl Headless {
    /// Starts `browser` headless on `url`, its profile and log in `dir`. `--no-sandbox`: it
    /// shows only our own page, and Chromium refuses to start as root (containers, CI) without
    /// it. The DevTools port keeps a headless Chromium open on the page until it is killed.
    pub fn open(browser: &Path, url: &str, dir: &Path) -> anyhow::Result<Headless> {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let log = std::fs::File::create(dir.join("browser.log"))?;
        let child = Command::new(browser)
            .args([
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--no-first-run",
                "--remote-debugging-port=0",
                "--window-size=1400,1000",
            ])
            .arg(format!("--user-data-dir={}", dir.join("profile").display()))
            .arg(url)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(log)
            .spawn()
            .with_context(|| {
                format!(
                    "cannot start {} (install Debian's chromium, or name a browser with --browser)",
                    browser.display()
                )
            })?;
        Ok(Headless {
            child,
            dir: dir.to_path_buf(),
        })
    }

    /// Waits until the page has connected to the view.
    pub fn wait_for_page(&self, stats: &ViewStats, timeout: Duration) -> anyhow::Result<()> {
        let end = Instant::now() + timeout;
        while stats.clients.load(Ordering::SeqCst) == 0 {
            if Instant::now() > end {
                anyhow::bail!(
                    "the headless browser did not open the view within {timeout:?} (see {})",
                    self.dir.join("browser.log").display()
                );
            }
            std::thread::sleep(Duration::from_millis(100));
        }
        Ok(())
    }
}

impl Drop for Headless {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
