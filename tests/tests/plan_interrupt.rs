//! Ctrl-C during a long plan: the coordinator stops after the current iteration and still writes
//! the best plan so far, saying it was interrupted; `run` then does not execute it. A coverage
//! mission cuts its tracking simulation short and still writes its (whole) plan.

mod common;

use std::error::Error;
use std::fs::File;
use std::path::Path;
use std::process::{Command, ExitStatus, Stdio};
use std::thread;
use std::time::{Duration, Instant};

use common::{coordinator, key, root, scenario};

/// Runs `shoal-coordinator COMMAND SCENARIO ARGS… --out OUT` with a budget far too large to
/// finish within the test, sends SIGINT once `started` is on stderr, and returns its exit status
/// and stderr.
fn interrupted(
    command: &str,
    name: &str,
    args: &[&str],
    started: &str,
    out: &Path,
    stderr_path: &Path,
) -> Result<(ExitStatus, String), Box<dyn Error>> {
    let mut cmd = Command::new(coordinator());
    for (k, _) in std::env::vars_os() {
        if k.to_string_lossy().starts_with("SHOAL_") {
            cmd.env_remove(k);
        }
    }
    let mut child = cmd
        .current_dir(root())
        .arg(command)
        .arg(scenario(name))
        .args(args)
        .args(["--iterations", "1000000"])
        .arg("--out")
        .arg(out)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(File::create(stderr_path)?)
        .spawn()?;
    // Wait for the progress line, so the handler is installed and the long work has begun.
    let since = Instant::now();
    while !std::fs::read_to_string(stderr_path)?.contains(started) {
        assert!(
            since.elapsed() < Duration::from_secs(60),
            "no {started:?} on stderr"
        );
        thread::sleep(Duration::from_millis(50));
    }
    let pid = child.id().to_string();
    let killed = Command::new("kill").args(["-INT", &pid]).status()?;
    assert!(killed.success(), "kill -INT {pid} failed");
    let status = loop {
        if let Some(s) = child.try_wait()? {
            break s;
        }
        if since.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!(
                "still running after SIGINT:\n{}",
                std::fs::read_to_string(stderr_path)?
            );
        }
        thread::sleep(Duration::from_millis(50));
    };
    Ok((status, std::fs::read_to_string(stderr_path)?))
}

/// The plan written after the interrupt says so.
fn check_interrupted_plan(out: &Path) -> Result<(), Box<dyn Error>> {
    let plan: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("plan.json"))?)?;
    assert_eq!(key(&plan, "termination"), "Interrupted");
    let iterations = key(&plan, "iterations").as_u64().unwrap_or(u64::MAX);
    assert!(iterations < 1_000_000, "{iterations}");
    let notices = key(&plan, "notices").to_string();
    assert!(notices.contains("interrupted after"), "{notices}");
    assert!(out.join("plan.svg").is_file());
    Ok(())
}

#[test]
fn sigint_writes_the_best_plan_so_far() -> Result<(), Box<dyn Error>> {
    let dir = tempfile::tempdir()?;
    let out = dir.path().join("out");
    let (status, stderr) = interrupted(
        "plan",
        "amp-pso-1",
        &["--in-process", "--populations", "2", "--particles", "10"],
        "iteration",
        &out,
        &dir.path().join("stderr.log"),
    )?;
    assert!(
        matches!(status.code(), Some(0) | Some(3)),
        "{status}\n{stderr}"
    );
    assert!(stderr.contains("interrupted"), "{stderr}");
    check_interrupted_plan(&out)
}

#[test]
fn sigint_while_run_plans_writes_the_plan_and_executes_nothing() -> Result<(), Box<dyn Error>> {
    let dir = tempfile::tempdir()?;
    let out = dir.path().join("out");
    let (status, stderr) = interrupted(
        "run",
        "amp-pso-2",
        &["--in-process", "--populations", "2", "--particles", "10"],
        "iteration",
        &out,
        &dir.path().join("stderr.log"),
    )?;
    assert_eq!(status.code(), Some(3), "{status}\n{stderr}");
    assert!(
        stderr
            .contains("interrupted while planning: the plan so far is written, it is not executed"),
        "{stderr}"
    );
    check_interrupted_plan(&out)?;
    // No execution was started: no agents, no mission log, no execution report.
    assert!(!stderr.contains("executing mission"), "{stderr}");
    assert!(!out.join("execution.json").exists());
    assert!(!out.join("mission.ndjson").exists());
    Ok(())
}

#[test]
fn sigint_cuts_a_coverage_missions_tracking_short() -> Result<(), Box<dyn Error>> {
    // Tracking the whole seabed takes seconds; the signal comes as it starts.
    let dir = tempfile::tempdir()?;
    let out = dir.path().join("out");
    let (status, stderr) = interrupted(
        "plan",
        "cpp-seabed",
        &["--in-process"],
        "coverage: tracking",
        &out,
        &dir.path().join("stderr.log"),
    )?;
    assert_eq!(status.code(), Some(0), "{status}\n{stderr}");
    let plan: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("plan.json"))?)?;
    assert_eq!(key(&plan, "kind"), "coverage");
    assert_eq!(key(&plan, "termination"), "Interrupted");
    assert_eq!(key(&plan, "coverage.tracking.interrupted"), true);
    assert_eq!(key(&plan, "coverage.tracking.reached_end"), false);
    let notices = key(&plan, "notices").to_string();
    assert!(
        notices.contains("tracking was interrupted after"),
        "{notices}"
    );
    assert!(!notices.contains("did not reach the end"), "{notices}");
    // The plan itself is whole: its path covers the area (86 % on this map, seed 1) and the
    // tracking drove only the start of it.
    let ratio = key(&plan, "coverage.coverage.ratio")
        .as_f64()
        .unwrap_or(0.0);
    assert!(ratio > 0.8, "{ratio}");
    let planned = key(&plan, "coverage.path_length_m").as_f64().unwrap_or(0.0);
    assert!(planned > 10_000.0, "{planned}");
    // The crawler tracks at under 1 m/s: it drove fewer metres than seconds simulated.
    let simulated = key(&plan, "coverage.tracking.sim_time_s")
        .as_f64()
        .unwrap_or(f64::NAN);
    assert!(
        simulated < planned / 2.0,
        "{simulated} s simulated for {planned} m"
    );
    assert!(out.join("plan.svg").is_file());
    Ok(())
}
