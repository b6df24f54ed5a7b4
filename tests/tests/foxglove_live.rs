//! The Foxglove WebSocket server end to end: `shoal-coordinator run --foxglove 127.0.0.1:PORT`
//! runs a real mission while an independent client (`tests/python/foxglove_client.py`: the
//! `websockets` package speaking `foxglove.websocket.v1`, `jsonschema` validating every message
//! against its channel's advertised schema) subscribes to every channel. The poses and the
//! WGS-84 fixes it received are the NDJSON log's reports within 1 cm, the scene holds the
//! scenario's obstacles, bounds and paths, a late client gets the latest of each channel at once,
//! and the server refuses what it must. An address beyond loopback is refused without
//! `--insecure`.
//!
//! The interpreter comes from [`shoal_interop::python`] (a venv with the pinned packages).

mod common;

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use common::fleet::{free_port, Fleet};
use common::process::{coordinator, root, run};
use common::{read_json, scenario, without_shoal_env, TestResult};
use serde_json::Value;
use shoal_common::scenario::Scenario;

const LIMIT: Duration = Duration::from_secs(240);
const TOL_M: f64 = 0.01;

/// Each vehicle's reports in the NDJSON log, by their mission time in nanoseconds (as the
/// server stamps them: rounded), and the log's epoch, Unix milliseconds.
type Reports = BTreeMap<String, BTreeMap<u64, Vec<[f64; 3]>>>;

fn log_reports(ndjson: &Path) -> Result<(u64, Reports), Box<dyn std::error::Error>> {
    let mut epoch_ms = None;
    let mut reports = Reports::new();
    for line in std::fs::read_to_string(ndjson)?.lines() {
        let r: Value = serde_json::from_str(line)?;
        match r["record"].as_str() {
            Some("start") => epoch_ms = r["epoch_unix_ms"].as_u64(),
            Some("telemetry") => {
                let t = &r["telemetry"];
                let s = &t["state"];
                let p = |i: usize| s["position"][i].as_f64().unwrap_or(f64::NAN);
                let t_ns = (s["t_s"].as_f64().unwrap_or(-1.0) * 1e9).round() as u64;
                let vehicle = t["vehicle"].as_str().unwrap_or("").to_string();
                reports
                    .entry(vehicle)
                    .or_default()
                    .entry(t_ns)
                    .or_default()
                    .push([p(0), p(1), p(2)]);
            }
            _ => {}
        }
    }
    Ok((epoch_ms.ok_or("the log has no start record")?, reports))
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The received `[stamp_ns, a, b, c]` rows of each vehicle, each matched to its report: the
/// report's position and the row's three numbers (as `to_position` turns them into one).
fn matched(
    received: &Value,
    reports: &Reports,
    epoch_ms: u64,
    to_position: &dyn Fn([f64; 3]) -> [f64; 3],
) -> Result<BTreeMap<String, usize>, Box<dyn std::error::Error>> {
    let mut counts = BTreeMap::new();
    let rows = received.as_object().ok_or("no received rows")?;
    for (vehicle, rows) in rows {
        let log = reports
            .get(vehicle)
            .ok_or(format!("{vehicle}: not in the log"))?;
        for row in rows.as_array().ok_or("rows are not a list")? {
            let n = |i: usize| row[i].as_f64().unwrap_or(f64::NAN);
            let stamp = row[0].as_u64().ok_or("a row without a stamp")?;
            let t_ns = stamp - epoch_ms * 1_000_000;
            let Some(at) = log.get(&t_ns) else {
                return Err(format!("{vehicle}: no report at mission time {t_ns} ns").into());
            };
            let got = to_position([n(1), n(2), n(3)]);
            // Several reports can share a time (before the mission clock starts): the nearest.
            let d = at
                .iter()
                .map(|a| distance(got, *a))
                .fold(f64::INFINITY, f64::min);
            assert!(
                d <= TOL_M,
                "{vehicle} at {t_ns} ns: {got:?} vs the log's {at:?} ({d} m)"
            );
            *counts.entry(vehicle.clone()).or_insert(0) += 1;
        }
    }
    Ok(counts)
}

#[test]
fn a_foxglove_client_sees_the_logged_positions_the_scene_and_the_bounds() -> TestResult {
    let python = common::interop_python()?;
    let mut fleet = Fleet::new();
    let out = fleet.dir().join("out");
    let port = free_port();
    // Scenario 3's five AUVs (it has a geodetic origin), planned briefly and run at 200× real
    // time (about 14 s).
    let text = std::fs::read_to_string(scenario("amp-pso-3"))?;
    let sc = Scenario::parse(&text, &scenario("amp-pso-3"))?;
    let vehicles: Vec<&str> = sc.vehicles.iter().map(|v| v.id.as_str()).collect();
    let mut cmd = Command::new(coordinator());
    without_shoal_env(&mut cmd);
    cmd.current_dir(root())
        .arg("run")
        .arg(scenario("amp-pso-3"))
        .args(["--in-process", "-q", "--time-scale", "200"])
        .args([
            "--iterations",
            "40",
            "--foxglove",
            &format!("127.0.0.1:{port}"),
        ])
        .arg("--out")
        .arg(&out);
    let c = fleet.spawn("coordinator", cmd);
    let received = fleet.dir().join("foxglove.json");
    let mut client = Command::new(python);
    client
        .arg(root().join("tests/python/foxglove_client.py"))
        .arg(format!("ws://127.0.0.1:{port}"))
        .arg(&received)
        .args(["--timeout", "200"]);
    let r = run(client, LIMIT);
    let coord = fleet.wait(c, Instant::now() + LIMIT);
    assert_eq!(coord.code(), Some(0), "{}\n{}", coord.stdout, coord.stderr);
    assert_eq!(r.code(), Some(0), "{r}");
    let got = read_json(&received)?;

    // Every channel, with Foxglove's schemas for what its panels draw.
    let channels = &got["channels"];
    for v in &vehicles {
        assert_eq!(
            channels[format!("/shoal/pose/{v}")],
            "foxglove.PoseInFrame",
            "{channels}"
        );
        assert_eq!(
            channels[format!("/shoal/location/{v}")],
            "foxglove.LocationFix",
            "{channels}"
        );
    }
    assert_eq!(channels["/shoal/scene"], "foxglove.SceneUpdate");
    assert_eq!(channels["/shoal/status"], "shoal.status");
    assert_eq!(channels["/shoal/events"], "shoal.event");

    // The poses and fixes are the log's reports, within 1 cm; almost all of them arrived.
    let (epoch_ms, reports) = log_reports(&out.join("mission.ndjson"))?;
    let poses = matched(&got["poses"], &reports, epoch_ms, &|p| p)?;
    let origin = sc.origin.ok_or("amp-pso-3 has no origin")?;
    let fixes = matched(&got["locations"], &reports, epoch_ms, &|[lat, lon, alt]| {
        origin.to_local(lat, lon, alt)
    })?;
    let execution = read_json(&out.join("execution.json"))?;
    let count = |m: &BTreeMap<u64, Vec<[f64; 3]>>| m.values().map(Vec::len).sum::<usize>();
    let logged: usize = reports.values().map(count).sum();
    assert_eq!(
        execution["figures"]["reports"].as_u64(),
        Some(logged as u64),
        "{execution}"
    );
    for v in &vehicles {
        let in_log = reports.get(*v).map_or(0, count);
        assert!(in_log >= 10, "{v}: {in_log} reports in the log");
        for (what, counts) in [("poses", &poses), ("fixes", &fixes)] {
            let n = counts.get(*v).copied().unwrap_or(0);
            assert!(10 * n >= 9 * in_log, "{v}: {n} {what} of {in_log} reports");
        }
    }

    // The scene: the bounds, every obstacle of the scenario with its kind, each planned path.
    let ids: Vec<&str> = got["scene_entities"]
        .as_array()
        .map(|a| a.iter().filter_map(|e| e["id"].as_str()).collect())
        .unwrap_or_default();
    assert!(ids.contains(&"bounds"), "{ids:?}");
    for v in &vehicles {
        assert!(ids.contains(&format!("path/{v}").as_str()), "{ids:?}");
    }
    for o in &sc.obstacles {
        let id = format!("obstacle/{}", o.id);
        let e = got["scene_entities"]
            .as_array()
            .and_then(|a| a.iter().find(|e| e["id"] == id.as_str()))
            .ok_or(format!("{id} is not in the scene"))?;
        let kind = serde_json::to_value(o.kind)?;
        assert_eq!(e["metadata"]["kind"], kind, "{e}");
        assert_eq!(e["metadata"]["published"], "false", "{e}");
    }
    assert!(got["statuses"].as_u64().is_some_and(|n| n >= 3), "{got}");

    // A late client gets each channel's latest message at once.
    let late = &got["checks"]["late"];
    let topics: Vec<&str> = late["topics"]
        .as_array()
        .map(|a| a.iter().filter_map(Value::as_str).collect())
        .unwrap_or_default();
    for t in [
        "/shoal/scene",
        "/shoal/status",
        "/shoal/pose/auv1",
        "/shoal/location/auv5",
    ] {
        assert!(topics.contains(&t), "the late client lacks {t}: {late}");
    }
    let late_obstacles = late["scene_entities"].as_array().map_or(0, |a| {
        a.iter()
            .filter(|e| e.as_str().is_some_and(|e| e.starts_with("obstacle/")))
            .count()
    });
    assert_eq!(late_obstacles, sc.obstacles.len(), "{late}");

    // Refusals: no subprotocol, a malformed message, an unknown channel, a message too large.
    let refusals = &got["checks"]["refusals"];
    assert_eq!(refusals["no_subprotocol"], 400, "{refusals}");
    assert_eq!(
        refusals["warnings"].as_array().map(Vec::len),
        Some(2),
        "{refusals}"
    );
    assert_eq!(refusals["oversize_close_code"], 1009, "{refusals}");

    // The finished log played back, four times as fast: the same poses, and the statuses
    // rebuilt from the records (the log has none), one per wall second of the run and the last.
    let port = free_port();
    let mut cmd = Command::new(coordinator());
    without_shoal_env(&mut cmd);
    cmd.current_dir(root())
        .arg("replay")
        .arg(out.join("mission.ndjson"))
        .args(["--foxglove", &format!("127.0.0.1:{port}"), "--speed", "4"]);
    let replay = fleet.spawn("replay", cmd);
    let replayed = fleet.dir().join("foxglove-replay.json");
    let mut client = Command::new(common::interop_python()?);
    client
        .arg(root().join("tests/python/foxglove_client.py"))
        .arg(format!("ws://127.0.0.1:{port}"))
        .arg(&replayed)
        .args(["--timeout", "200", "--watch-only"]);
    let r = run(client, LIMIT);
    assert_eq!(r.code(), Some(0), "{r}");
    let played = fleet.wait(replay, Instant::now() + LIMIT);
    assert!(matches!(played.code(), Some(0 | 3)), "{played}");
    let got = read_json(&replayed)?;
    let poses = matched(&got["poses"], &reports, epoch_ms, &|p| p)?;
    for v in &vehicles {
        let in_log = reports.get(*v).map_or(0, count);
        let n = poses.get(*v).copied().unwrap_or(0);
        assert!(
            10 * n >= 9 * in_log,
            "{v}: {n} replayed poses of {in_log} reports"
        );
    }
    assert!(got["statuses"].as_u64().is_some_and(|n| n >= 3), "{got}");
    fleet.passed();
    Ok(())
}

#[test]
fn an_address_beyond_loopback_is_refused_without_insecure() {
    let mut fleet = Fleet::new();
    let out = fleet.dir().join("out");
    let mut cmd = Command::new(coordinator());
    without_shoal_env(&mut cmd);
    cmd.current_dir(root())
        .arg("run")
        .arg(scenario("amp-pso-3"))
        .args([
            "--in-process",
            "-q",
            "--iterations",
            "1",
            "--foxglove",
            "0.0.0.0:0",
        ])
        .arg("--out")
        .arg(&out);
    let r = run(cmd, Duration::from_secs(60));
    assert_eq!(r.code(), Some(1), "{r}");
    assert!(
        r.stderr.contains("--foxglove 0.0.0.0:0: beyond loopback")
            && r.stderr.contains("--insecure"),
        "{r}"
    );
    assert!(!out.join("mission.ndjson").exists(), "the mission ran: {r}");
    fleet.passed();
}
