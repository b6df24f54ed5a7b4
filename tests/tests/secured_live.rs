//! The web view and the Foxglove server beyond loopback, end to end: `shoal-coordinator keys`
//! makes a fleet's keys; `shoal-coordinator serve` listens on mutual TLS with the coordinator's
//! configuration and serves `--view 0.0.0.0:PORT` and `--foxglove 0.0.0.0:PORT`, which must then
//! speak HTTPS/WSS with client certificates. An independent client
//! (`tests/python/secured_watch.py`: Python's `ssl`, `http.client`, `websockets` and
//! `eclipse-zenoh`) submits a mission as the operator, watches it on both servers, and checks
//! that a client without a certificate, a vehicle's certificate and plain HTTP/ws are refused
//! while the operator is still served afterwards. Without keys or `--insecure` the same
//! addresses are refused at start.
//!
//! The interpreter comes from [`shoal_interop::python`] (a venv with the pinned packages).

mod common;

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use common::fleet::{free_port, Fleet};
use common::process::{coordinator, root};
use common::{interop_python, read_json, scenario, without_shoal_env, TestResult};

fn deadline(s: u64) -> Instant {
    Instant::now() + Duration::from_secs(s)
}

/// `keys` for scenario 2's vehicles and the operator `operator`, into `dir`.
fn make_keys(fleet: &mut Fleet, dir: &Path) {
    let mut cmd = Command::new(coordinator());
    without_shoal_env(&mut cmd);
    cmd.current_dir(root())
        .arg("keys")
        .arg("--out")
        .arg(dir)
        .arg("--scenario")
        .arg(scenario("amp-pso-2"))
        .args(["--operators", "operator"])
        .args(["--coordinator-hosts", "localhost,127.0.0.1"]);
    let k = fleet.spawn("keys", cmd);
    let k = fleet.wait(k, deadline(30));
    assert_eq!(k.code(), Some(0), "{}", k.stderr);
}

#[test]
fn an_operator_watches_over_https_and_wss_and_others_are_refused() -> TestResult {
    let py = interop_python()?;
    let mut fleet = Fleet::new();
    let keys = fleet.dir().join("keys");
    make_keys(&mut fleet, &keys);
    let endpoint = format!("tls/127.0.0.1:{}", free_port());
    let (view, foxglove) = (free_port(), free_port());
    let mut serve = Command::new(coordinator());
    without_shoal_env(&mut serve);
    serve
        .current_dir(root())
        .arg("serve")
        .arg("--zenoh-config")
        .arg(keys.join("coordinator.json5"))
        .args(["--listen", &endpoint])
        .args(["--view", &format!("0.0.0.0:{view}")])
        .args(["--foxglove", &format!("0.0.0.0:{foxglove}")])
        .arg("--out")
        .arg(fleet.dir().join("missions"));
    let s = fleet.spawn("serve", serve);
    fleet.wait_for_stderr(s, "serving missions", deadline(60));
    let stderr = fleet.stderr(s);
    assert!(
        stderr.contains(&format!("live view: https://0.0.0.0:{view}/"))
            && stderr.contains(&format!("wss://0.0.0.0:{foxglove}")),
        "{stderr}"
    );
    let seen = fleet.dir().join("watch.json");
    let mut client = Command::new(py);
    client
        .current_dir(root())
        .arg(root().join("tests/python/secured_watch.py"))
        .arg(&keys)
        .arg(&endpoint)
        .arg(view.to_string())
        .arg(foxglove.to_string())
        .arg(scenario("amp-pso-2"))
        .arg(&seen);
    let c = fleet.spawn("python-watch", client);
    let c = fleet.wait(c, deadline(300));
    assert_eq!(c.code(), Some(0), "{}\n{}", c.stdout, c.stderr);
    let got = read_json(&seen)?;
    assert_eq!(got["page_status"], 200, "{got}");
    assert_eq!(got["page_status_after"], 200, "{got}");
    assert_eq!(got["foxglove_pose"], true, "{got}");
    assert_eq!(
        got["refusals"].as_object().map(|r| r.len()),
        Some(7),
        "{got}"
    );
    assert!(fleet.running(s), "serve died:\n{}", fleet.stderr(s));
    fleet.kill(s);
    fleet.passed();
    Ok(())
}

#[test]
fn the_view_beyond_loopback_without_keys_or_insecure_is_refused_at_start() {
    let mut fleet = Fleet::new();
    let mut cmd = Command::new(coordinator());
    without_shoal_env(&mut cmd);
    cmd.current_dir(root())
        .arg("serve")
        .args(["--listen", &format!("tcp/127.0.0.1:{}", free_port())])
        .args(["--view", "0.0.0.0:0"])
        .arg("--out")
        .arg(fleet.dir().join("missions"));
    let r = fleet.spawn("serve", cmd);
    let r = fleet.wait(r, deadline(30));
    assert_eq!(r.code(), Some(1), "{}", r.stderr);
    for needle in [
        "--view 0.0.0.0:0: beyond loopback",
        "shoal-coordinator keys",
        "ssh -L",
        "--insecure",
    ] {
        assert!(
            r.stderr.contains(needle),
            "{needle:?} missing: {}",
            r.stderr
        );
    }
    fleet.passed();
}
