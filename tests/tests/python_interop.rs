//! The open interface from an independent client: the Python `eclipse-zenoh` package (1.10.2)
//! submits scenario 2 to `shoal-coordinator serve` on `shoal/submit`, then reads back the plan,
//! the telemetry, the fleet status (a query) and the events from their JSON keys
//! (`tests/python/submit_and_watch.py`).
//!
//! The interpreter comes from [`shoal_interop::python`] (a venv with the pinned packages).

mod common;

use std::process::Command;
use std::time::{Duration, Instant};

use common::fleet::{endpoint, free_port, Fleet};
use common::process::{coordinator, root};
use common::{interop_python as python, scenario, without_shoal_env, TestResult};

#[test]
fn a_python_client_submits_scenario_2_and_reads_plan_telemetry_and_status() -> TestResult {
    let py = python()?;
    let mut fleet = Fleet::new();
    let port = free_port();
    let mut serve = Command::new(coordinator());
    without_shoal_env(&mut serve);
    serve
        .current_dir(root())
        .args([
            "serve",
            "--listen",
            &format!("tcp/127.0.0.1:{port}"),
            "--missions",
            "1",
        ])
        .arg("--out")
        .arg(fleet.dir().join("missions"));
    let server = fleet.spawn("serve", serve);
    fleet.wait_for_stderr(
        server,
        "serving missions",
        Instant::now() + Duration::from_secs(30),
    );
    let mut client = Command::new(py);
    client
        .current_dir(root())
        .arg(root().join("tests/python/submit_and_watch.py"))
        .arg(endpoint(port))
        .arg(scenario("amp-pso-2"))
        .args(["--time-scale", "100", "--iterations", "40"]);
    let c = fleet.spawn("python-client", client);
    let c = fleet.wait(c, Instant::now() + Duration::from_secs(300));
    assert_eq!(c.code(), Some(0), "{}\n{}", c.stdout, c.stderr);
    let summary: serde_json::Value = serde_json::from_str(c.stdout.trim())?;
    assert_eq!(
        summary["plan_vehicles"],
        serde_json::json!(["auv1", "auv2", "auv3"])
    );
    assert!(summary["reports"].as_u64().unwrap_or(0) >= 30, "{summary}");
    let s = fleet.wait(server, Instant::now() + Duration::from_secs(60));
    assert_eq!(s.code(), Some(0), "{}\n{}", s.stdout, s.stderr);
    assert!(s.stderr.contains("refused 1 submission"), "{}", s.stderr);
    let execution = fleet.dir().join("missions/py-interop/execution.json");
    let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(execution)?)?;
    assert!(
        report["figures"]["min_separation_m"]
            .as_f64()
            .unwrap_or(0.0)
            >= 50.0
    );
    fleet.passed();
    Ok(())
}
