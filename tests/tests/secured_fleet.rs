//! A secured fleet end to end: `shoal-coordinator keys` makes the CA, the members' certificates
//! and configurations; the coordinator listens on mutual TLS and enforces the generated access
//! control; the agents join with their vehicles' certificates. An independent client (the Python
//! `eclipse-zenoh` package, `tests/python/secured_client.py`) then tries what a stranger and a
//! misbehaving vehicle would, and what an operator must be able to do.
//!
//! The interpreter is found as for the other interop tests ([`common::interop_python`]).

mod common;

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use common::fleet::{free_port, Fleet};
use common::process::{coordinator, root};
use common::{interop_python, scenario, without_shoal_env, TestResult};
use shoal_agent::network::coordinator_present;
use shoal_common::wire::security::Security;
use shoal_common::wire::{session, topics};
use zenoh::Wait;

fn deadline(s: u64) -> Instant {
    Instant::now() + Duration::from_secs(s)
}

/// The Python interpreter, a fleet with scenario 2's keys in `<dir>/keys`, and a free TLS
/// endpoint.
fn secured_setup() -> Result<(String, Fleet, std::path::PathBuf, String), String> {
    let py = interop_python()?;
    let mut fleet = Fleet::new();
    let keys = fleet.dir().join("keys");
    make_keys(&mut fleet, &keys);
    let endpoint = format!("tls/127.0.0.1:{}", free_port());
    Ok((py, fleet, keys, endpoint))
}

/// `keys` for scenario 2's vehicles and one operator, into `dir`.
fn make_keys(fleet: &mut Fleet, dir: &Path) {
    let mut cmd = Command::new(coordinator());
    without_shoal_env(&mut cmd);
    cmd.current_dir(root())
        .arg("keys")
        .arg("--out")
        .arg(dir)
        .arg("--scenario")
        .arg(scenario("amp-pso-2"));
    let k = fleet.spawn("keys", cmd);
    let k = fleet.wait(k, deadline(30));
    assert_eq!(k.code(), Some(0), "{}", k.stderr);
}

fn coordinator_cmd(keys: &Path, args: &[&str]) -> Command {
    let mut cmd = Command::new(coordinator());
    without_shoal_env(&mut cmd);
    cmd.current_dir(root())
        .args(args)
        .arg("--zenoh-config")
        .arg(keys.join("coordinator.json5"));
    cmd
}

fn python_client(py: &str, endpoint: &str, keys: &Path, mission: &str) -> Command {
    let mut cmd = Command::new(py);
    cmd.current_dir(root())
        .arg(root().join("tests/python/secured_client.py"))
        .arg(endpoint)
        .arg(keys)
        .arg(mission);
    cmd
}

#[test]
fn strangers_and_a_vehicle_forging_for_another_are_kept_out_and_the_mission_is_met() -> TestResult {
    let (py, mut fleet, keys, endpoint) = secured_setup()?;
    let out = fleet.dir().join("out");
    let mut run = coordinator_cmd(&keys, &["run"]);
    run.arg(scenario("amp-pso-2"))
        .args(["--agents", "external", "--listen", &endpoint])
        .args(["--mission", "secured", "--time-scale", "100"])
        .args(["--iterations", "40", "--quiet", "--out"])
        .arg(&out);
    let c = fleet.spawn("coordinator", run);
    fleet.wait_for_stderr(c, "waiting up to", deadline(60));
    let mut agents = Vec::new();
    for v in ["auv1", "auv2", "auv3"] {
        let config = keys.join(format!("{v}.json5"));
        let config = config.to_string_lossy();
        // Not --once: `run` plans one mission with them, then executes another.
        agents.push(fleet.agent(v, &endpoint, &["--zenoh-config", &config]));
    }
    let client = fleet.spawn(
        "python-client",
        python_client(&py, &endpoint, &keys, "secured"),
    );
    let client = fleet.wait(client, deadline(240));
    assert_eq!(
        client.code(),
        Some(0),
        "{}\n{}",
        client.stdout,
        client.stderr
    );
    let summary: serde_json::Value = serde_json::from_str(client.stdout.trim())?;
    assert_eq!(summary["forgeries_delivered"], serde_json::json!([]));
    let c = fleet.wait(c, deadline(240));
    assert_eq!(c.code(), Some(0), "{}", c.stderr);
    for a in agents {
        assert!(fleet.running(a), "an agent died:\n{}", fleet.stderr(a));
    }
    let report = common::read_json(&out.join("execution.json"))?;
    // auv1's ten reports naming auv2 on auv1's own key (which access control allows).
    let dropped = report["dropped"].as_u64().unwrap_or(0);
    assert!(dropped >= 10, "dropped {dropped}: {report}");
    let min = report["figures"]["min_separation_m"]
        .as_f64()
        .unwrap_or(0.0);
    assert!(min >= 50.0, "separation {min} m under d_min: {report}");
    fleet.passed();
    Ok(())
}

#[test]
fn an_operator_submits_to_a_secured_serve_and_a_vehicle_cannot() -> TestResult {
    let (py, mut fleet, keys, endpoint) = secured_setup()?;
    let missions = fleet.dir().join("missions");
    let mut serve = coordinator_cmd(&keys, &["serve", "--missions", "1"]);
    serve.args(["--listen", &endpoint, "--out"]).arg(&missions);
    let s = fleet.spawn("serve", serve);
    fleet.wait_for_stderr(s, "serving missions", deadline(60));
    let mut cmd = python_client(&py, &endpoint, &keys, "secured-submit");
    cmd.arg("--submit")
        .arg("--scenario")
        .arg(scenario("amp-pso-2"));
    let client = fleet.spawn("python-client", cmd);
    let client = fleet.wait(client, deadline(120));
    assert_eq!(
        client.code(),
        Some(0),
        "{}\n{}",
        client.stdout,
        client.stderr
    );
    let s = fleet.wait(s, deadline(240));
    assert_eq!(s.code(), Some(0), "{}", s.stderr);
    let report = common::read_json(&missions.join("secured-submit/execution.json"))?;
    assert!(report["figures"].is_object(), "{report}");
    fleet.passed();
    Ok(())
}

/// Zenoh's boxed error as a test failure.
fn z<T>(r: zenoh::Result<T>) -> Result<T, String> {
    r.map_err(|e| e.to_string())
}

/// After its coordinator's liveliness token goes, an agent asks the network whether it is really
/// gone before it abandons the mission. Through the secured router and the access control
/// `keys` writes, that question must find a token that is declared and none that is not.
#[test]
fn a_vehicle_asks_through_the_access_control_whether_its_coordinator_is_there() -> TestResult {
    let mut fleet = Fleet::new();
    let keys = fleet.dir().join("keys");
    make_keys(&mut fleet, &keys);
    let endpoint = format!("tls/127.0.0.1:{}", free_port());
    let member = |name: &str| Security {
        config_file: Some(keys.join(format!("{name}.json5"))),
        ..Security::default()
    };
    let config =
        session::router_config(std::slice::from_ref(&endpoint), &[], &member("coordinator"))?;
    let router = z(zenoh::open(config).wait())?;
    let key = topics::coordinator_liveliness("alpha")?;
    let token = z(router.liveliness().declare_token(key.as_str()).wait())?;
    let config = session::client_config(&[endpoint], false, &member("auv1"))?;
    let vehicle = z(zenoh::open(config).wait())?;
    let wait = Duration::from_secs(2);
    assert!(coordinator_present(&vehicle, "alpha", wait));
    assert!(!coordinator_present(&vehicle, "beta", wait));
    z(token.undeclare().wait())?;
    let end = deadline(10);
    while coordinator_present(&vehicle, "alpha", wait) {
        assert!(Instant::now() < end, "the undeclared token is still found");
        std::thread::sleep(Duration::from_millis(100));
    }
    z(vehicle.close().wait())?;
    z(router.close().wait())?;
    fleet.passed();
    Ok(())
}

#[test]
fn a_router_beyond_loopback_without_authentication_is_refused_and_says_how() {
    let mut fleet = Fleet::new();
    let mut cmd = Command::new(coordinator());
    without_shoal_env(&mut cmd);
    cmd.args([
        "router",
        "--listen",
        &format!("tcp/0.0.0.0:{}", free_port()),
    ]);
    let r = fleet.spawn("router", cmd);
    let r = fleet.wait(r, deadline(30));
    assert_eq!(r.code(), Some(1), "{}", r.stderr);
    for needle in ["refusing to listen", "shoal-coordinator keys", "--insecure"] {
        assert!(r.stderr.contains(needle), "{needle:?} not in {}", r.stderr);
    }
    fleet.passed();
}
