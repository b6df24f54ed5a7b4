//! Ctrl-C during a long plan: the coordinator stops after the current iteration and still writes
//! the best plan so far, saying it was interrupted; `run` then does not execute it.

mod common;

use std::error::Error;
use std::fs::File;
use std::path::Path;
use std::process::{Command, ExitStatus, Stdio};
use std::thread;
use std::time::{Duration, Instant};

use common::{coordinator, key, root, scenario};

/// Runs `shoal-coordinator COMMAND SCENARIO ARGS… --out OUT` with a budget far too large to
/// finish within the test, sends SIGINT once the first progress line is on stderr, and returns
/// its exit status and stderr.
fn interrupted(
    command: &str,
    name: &str,
    args: &[&str],
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
    // Wait for the first progress line, so the handler is installed and planning has begun.
    let started = Instant::now();
    while !std::fs::read_to_string(stderr_path)?.contains("iteration") {
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "no progress on stderr"
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
        if started.elapsed() > Duration::from_secs(120) {
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
