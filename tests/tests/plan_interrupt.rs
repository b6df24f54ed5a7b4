//! Ctrl-C during a long plan: the coordinator stops after the current iteration and still writes
//! the best plan so far, saying it was interrupted.

mod common;

use std::error::Error;
use std::fs::File;
use std::process::{Command, Stdio};
use std::thread;
use std::time::{Duration, Instant};

use common::{coordinator, key, root, scenario};

#[test]
fn sigint_writes_the_best_plan_so_far() -> Result<(), Box<dyn Error>> {
    let dir = tempfile::tempdir()?;
    let out = dir.path().join("out");
    let stderr_path = dir.path().join("stderr.log");
    let mut cmd = Command::new(coordinator());
    for (k, _) in std::env::vars_os() {
        if k.to_string_lossy().starts_with("SHOAL_") {
            cmd.env_remove(k);
        }
    }
    // A budget far too large to finish within the test: only the interrupt ends it.
    let mut child = cmd
        .current_dir(root())
        .args(["plan"])
        .arg(scenario("amp-pso-1"))
        .args([
            "--in-process",
            "--iterations",
            "1000000",
            "--populations",
            "2",
            "--particles",
            "10",
        ])
        .arg("--out")
        .arg(&out)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(File::create(&stderr_path)?)
        .spawn()?;
    // Wait for the first progress line, so the handler is installed and planning has begun.
    let started = Instant::now();
    while !std::fs::read_to_string(&stderr_path)?.contains("iteration") {
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
                std::fs::read_to_string(&stderr_path)?
            );
        }
        thread::sleep(Duration::from_millis(50));
    };
    let stderr = std::fs::read_to_string(&stderr_path)?;
    assert!(
        matches!(status.code(), Some(0) | Some(3)),
        "{status}\n{stderr}"
    );
    assert!(stderr.contains("interrupted"), "{stderr}");
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
