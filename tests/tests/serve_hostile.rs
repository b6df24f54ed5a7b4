//! `shoal-coordinator serve` against a stranger: about seventy hostile submissions
//! (`tests/python/hostile_submissions.py`) sent by the independent Python `eclipse-zenoh`
//! client to a real `serve` process. Each must be refused with its reason (or accepted where it
//! is valid), no reply may quote `/etc/passwd`, `serve` must stay up with its resident memory
//! bounded, and at exit it must name the missions it never ran.
//!
//! The interpreter comes from [`shoal_interop::python`] (a venv with the pinned packages).

mod common;

use std::fs::File;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use common::fleet::{endpoint, free_port};
use common::process::{coordinator, root};
use common::{interop_python as python, scenario, without_shoal_env, TestResult};

/// Largest resident set `serve` may reach while it is attacked (it idles at tens of MB; a
/// submission reading /dev/zero took it to 4.2 GB).
const MAX_RSS_KB: u64 = 1 << 20;

/// A child killed on drop, whose stderr file is printed if the test fails.
struct Guard {
    child: Child,
    stderr: std::path::PathBuf,
}

impl Drop for Guard {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        if std::thread::panicking() {
            let log = std::fs::read_to_string(&self.stderr).unwrap_or_default();
            eprintln!("--- serve stderr ---\n{log}");
        }
    }
}

/// `VmRSS` of process `pid`, kB (0 once it is gone).
fn rss_kb(pid: u32) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .unwrap_or(0)
}

/// Whether scenario validation bounds the sizes only it checks (then those cases are sent too).
fn validation_bounds_waypoints() -> bool {
    let text = std::fs::read_to_string(scenario("amp-pso-2")).unwrap_or_default();
    let huge = text.replace("waypoints = 30", "waypoints = 1000000");
    shoal_common::scenario::Scenario::parse(&huge, Path::new("x.toml")).is_err()
}

/// Waits for `needle` in the file at `path`, up to `deadline`.
fn wait_for(path: &Path, needle: &str, deadline: Instant) -> bool {
    while Instant::now() < deadline {
        if std::fs::read_to_string(path).is_ok_and(|t| t.contains(needle)) {
            return true;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    false
}

#[test]
fn hostile_submissions_are_refused_and_serve_stays_up_with_bounded_memory() -> TestResult {
    let py = python()?;
    let tmp = tempfile::tempdir()?;
    let (data, out, log) = (
        tmp.path().join("data"),
        tmp.path().join("missions"),
        tmp.path().join("serve.err"),
    );
    std::fs::create_dir(&data)?;
    let port = free_port();
    let mut cmd = Command::new(coordinator());
    without_shoal_env(&mut cmd);
    cmd.current_dir(root())
        .args(["serve", "--listen", &endpoint(port)])
        .arg("--out")
        .arg(&out)
        .arg("--data-dir")
        .arg(&data)
        .stdout(Stdio::null())
        .stderr(File::create(&log)?);
    let mut serve = Guard {
        child: cmd.spawn()?,
        stderr: log.clone(),
    };
    let pid = serve.child.id();
    assert!(
        wait_for(
            &log,
            "serving missions",
            Instant::now() + Duration::from_secs(30)
        ),
        "serve did not start"
    );
    let started = Instant::now();

    // Sample serve's resident memory while it is attacked.
    let (max_rss, stop) = (
        Arc::new(AtomicU64::new(0)),
        Arc::new(AtomicBool::new(false)),
    );
    let sampler = {
        let (max_rss, stop) = (Arc::clone(&max_rss), Arc::clone(&stop));
        std::thread::spawn(move || {
            while !stop.load(Ordering::Relaxed) {
                max_rss.fetch_max(rss_kb(pid), Ordering::Relaxed);
                std::thread::sleep(Duration::from_millis(20));
            }
        })
    };
    let limits = validation_bounds_waypoints();
    let mut client = Command::new(py);
    client
        .current_dir(root())
        .arg(root().join("tests/python/hostile_submissions.py"))
        .arg(endpoint(port))
        .arg(&data)
        .arg(scenario("amp-pso-2"));
    if limits {
        client.arg("--scenario-limits");
    } else {
        eprintln!("scenario-size cases not sent: Scenario::parse does not bound waypoints here");
    }
    let c = client.output()?;
    let alive = serve.child.try_wait()?.is_none();
    stop.store(true, Ordering::Relaxed);
    let _ = sampler.join();
    let stdout = String::from_utf8_lossy(&c.stdout);
    let stderr = String::from_utf8_lossy(&c.stderr);
    let summary: serde_json::Value = serde_json::from_str(stdout.trim())
        .map_err(|e| format!("client summary {stdout:?}: {e}\n{stderr}"))?;
    let max_rss_kb = max_rss.load(Ordering::Relaxed);
    eprintln!(
        "corpus in {:.1} s: {summary}; serve alive: {alive}; max RSS {max_rss_kb} kB",
        started.elapsed().as_secs_f64()
    );
    assert!(c.status.success(), "{stderr}");
    assert!(alive, "serve died under the corpus");
    assert!(
        max_rss_kb > 0 && max_rss_kb < MAX_RSS_KB,
        "max RSS {max_rss_kb} kB"
    );
    let n = summary["n"].as_u64().unwrap_or(0);
    assert!(n >= 50, "{summary}");
    // Nothing was written beside `--out` (a mission id `..` once wrote there).
    let mut beside: Vec<String> = std::fs::read_dir(tmp.path())?
        .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
        .collect();
    beside.sort();
    assert_eq!(beside, ["data", "missions", "serve.err"]);

    // Stopped, serve names the missions it accepted and never ran, and counts every refusal.
    let _ = Command::new("kill")
        .args(["-TERM", &pid.to_string()])
        .status();
    let deadline = Instant::now() + Duration::from_secs(30);
    while serve.child.try_wait()?.is_none() && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(50));
    }
    let status = serve.child.try_wait()?;
    let text = std::fs::read_to_string(&log)?;
    assert_eq!(status.and_then(|s| s.code()), Some(0), "{text}");
    assert!(text.contains("still queued, not run: "), "{text}");
    let refused = summary["refused"].as_u64().unwrap_or(0);
    assert!(
        text.contains(&format!("refused {refused} submission(s)")),
        "{text}"
    );
    assert!(!text.contains("panicked"), "{text}");
    assert!(
        started.elapsed() < Duration::from_secs(60),
        "{:?}",
        started.elapsed()
    );
    Ok(())
}
