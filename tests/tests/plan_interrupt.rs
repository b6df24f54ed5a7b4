//! Ctrl-C during a long plan: the coordinator stops after the current iteration and still writes
//! the best plan so far, saying it was interrupted; `run` then does not execute it. A coverage
//! mission cuts its tracking simulation short and still writes its (whole) plan. A coordinator
//! killed outright (SIGKILL), which can neither write nor stop anything, leaves no agent behind:
//! each watches its parent (`--parent-pid`).

mod common;

use std::error::Error;
use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::thread;
use std::time::{Duration, Instant};

use common::{agent, coordinator, key, root, scenario};

/// Starts `shoal-coordinator COMMAND SCENARIO ARGS… --out OUT` with a budget far too large to
/// finish within the test, and returns it once `started` is on its stderr (written to
/// `stderr_path`), with the time it was started.
fn started(
    command: &str,
    name: &str,
    args: &[&str],
    started: &str,
    out: &Path,
    stderr_path: &Path,
) -> Result<(Child, Instant), Box<dyn Error>> {
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
        if since.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("no {started:?} on stderr");
        }
        thread::sleep(Duration::from_millis(50));
    }
    Ok((child, since))
}

/// Runs [`started`]'s command, sends SIGINT once `started` is on stderr, and returns its exit
/// status and stderr.
fn interrupted(
    command: &str,
    name: &str,
    args: &[&str],
    started_on: &str,
    out: &Path,
    stderr_path: &Path,
) -> Result<(ExitStatus, String), Box<dyn Error>> {
    let (mut child, since) = started(command, name, args, started_on, out, stderr_path)?;
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

/// Process `pid`'s parent, if it runs (not gone, not a zombie): the state and the parent's pid
/// follow the command name in `/proc/PID/stat`.
fn running_parent(pid: u32) -> Option<u32> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    let mut fields = stat.rsplit_once(')')?.1.split_whitespace();
    let state = fields.next()?;
    (state != "Z" && state != "X")
        .then(|| fields.next()?.parse().ok())
        .flatten()
}

/// Whether process `pid` runs.
fn running(pid: u32) -> bool {
    running_parent(pid).is_some()
}

/// The running processes whose parent is `parent`.
fn running_children(parent: u32) -> Vec<u32> {
    let Ok(entries) = std::fs::read_dir("/proc") else {
        return Vec::new();
    };
    entries
        .filter_map(|e| e.ok()?.file_name().to_str()?.parse::<u32>().ok())
        .filter(|&pid| running_parent(pid) == Some(parent))
        .collect()
}

/// Whether every process of `pids` stops running within `limit`; those still running then are
/// killed, so a failing test leaves nothing behind.
fn all_stop_within(pids: &[u32], limit: Duration) -> bool {
    let since = Instant::now();
    while pids.iter().any(|&pid| running(pid)) {
        if since.elapsed() > limit {
            for pid in pids {
                let _ = Command::new("kill").args(["-9", &pid.to_string()]).status();
            }
            return false;
        }
        thread::sleep(Duration::from_millis(50));
    }
    true
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

#[test]
fn sigkill_of_a_distributed_plan_leaves_no_agent_behind() -> Result<(), Box<dyn Error>> {
    let dir = tempfile::tempdir()?;
    let out = dir.path().join("out");
    let stderr_path = dir.path().join("stderr.log");
    // The progress line of a distributed plan comes once every agent has joined.
    let (mut child, _) = started(
        "plan",
        "amp-pso-2",
        &["--populations", "2", "--particles", "10"],
        "iteration",
        &out,
        &stderr_path,
    )?;
    let agents = running_children(child.id());
    child.kill()?;
    child.wait()?;
    let stderr = std::fs::read_to_string(&stderr_path)?;
    // Scenario 2 has three vehicles, one embedded agent each.
    assert_eq!(agents.len(), 3, "{agents:?}\n{stderr}");
    assert!(
        all_stop_within(&agents, Duration::from_secs(10)),
        "agents {agents:?} outlived their killed coordinator by 10 s\n{stderr}"
    );
    Ok(())
}

#[test]
fn an_agent_leaves_when_its_parent_is_killed_and_not_before() -> Result<(), Box<dyn Error>> {
    // A shell starts the agent in the background, watching the shell, prints the agent's pid
    // and waits. Nothing listens on the endpoint: the agent waits for its router.
    let mut shell = Command::new("sh")
        .args(["-c", r#""$0" --vehicle auv1 --connect tcp/127.0.0.1:9 --parent-pid $$ >/dev/null 2>&1 & echo $!; wait"#])
        .arg(agent())
        .stdout(Stdio::piped())
        .spawn()?;
    let mut line = String::new();
    BufReader::new(shell.stdout.take().ok_or("no stdout")?).read_line(&mut line)?;
    let pid: u32 = line.trim().parse()?;
    // The control: while the shell lives, the agent stays.
    thread::sleep(Duration::from_millis(1500));
    let stayed = running(pid);
    shell.kill()?;
    shell.wait()?;
    let left = all_stop_within(&[pid], Duration::from_secs(10));
    assert!(stayed, "the agent left while its parent was alive");
    assert!(left, "the agent outlived its parent by 10 s");
    Ok(())
}

#[test]
fn a_parent_pid_that_is_not_the_parent_is_refused() -> Result<(), Box<dyn Error>> {
    let out = Command::new(agent())
        .args(["--vehicle", "auv1", "--connect", "tcp/127.0.0.1:9"])
        .args(["--parent-pid", &u32::MAX.to_string()])
        .output()?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    let expected = format!(
        "--parent-pid {}: this agent's parent is process {}",
        u32::MAX,
        std::process::id()
    );
    assert!(stderr.contains(&expected), "{stderr}");
    Ok(())
}
