//! The operator's web view as a person uses it: `run … --view` in a real headless Chromium
//! (Debian's, installed by [`shoal_interop::chromium`] when missing), driven from Python over
//! the DevTools protocol (`tests/python/live_view.py`). What the page drew is compared with the
//! run's own mission log: every vehicle where its report put it, within one telemetry period;
//! the obstacle published mid-mission; the predicted closest approach; the same picture after
//! the socket drops and after a reload. Then `replay … --view` plays the log back. The
//! screenshots stay in `target/tmp/live_view/` (CI artefacts).

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use common::fleet::{free_port, Fleet};
use common::{coordinator, interop_python, root, scenario, without_shoal_env, TestResult};
use serde_json::Value;

const LIMIT: Duration = Duration::from_secs(600);
/// Reports per wall second and vehicle (`run`'s default).
const TELEMETRY_HZ: f64 = 2.0;
/// What the page may lag the coordinator on top of a telemetry period: its push tick (100 ms)
/// and the script's own read.
const SLACK_US: u64 = 300_000;

/// Where the screenshots are kept.
fn artefacts() -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join("live_view")
}

fn browser_steps(
    fleet: &mut Fleet,
    url: &str,
    out: &Path,
    mode: &str,
) -> Result<BTreeMap<String, Value>, Box<dyn std::error::Error>> {
    let python = interop_python()?;
    let chromium = shoal_interop::chromium()?;
    let mut cmd = Command::new(python);
    cmd.arg(root().join("tests/python/live_view.py"))
        .args([chromium.as_str(), url])
        .arg(out)
        .arg(mode);
    let h = fleet.spawn(&format!("browser-{mode}"), cmd);
    let r = fleet.wait(h, Instant::now() + LIMIT);
    assert_eq!(r.code(), Some(0), "{r}");
    let mut steps = BTreeMap::new();
    for line in r.stdout.lines() {
        let v: Value = serde_json::from_str(line)?;
        steps.insert(v["step"].as_str().unwrap_or_default().to_string(), v);
    }
    Ok(steps)
}

/// The log's records of one kind.
fn records<'a>(log: &'a [Value], kind: &str) -> Vec<&'a Value> {
    log.iter().filter(|r| r["record"] == kind).collect()
}

fn read_log(path: &Path) -> Result<Vec<Value>, Box<dyn std::error::Error>> {
    let text = std::fs::read_to_string(path)?;
    Ok(text
        .lines()
        .map(serde_json::from_str)
        .collect::<Result<_, _>>()?)
}

/// Every drawn vehicle is where one of its logged reports put it, and that report is at most
/// one telemetry period older than the newest the coordinator had when the page was read.
fn check_vehicles(step: &Value, log: &[Value], vehicles: usize) {
    let s = &step["summary"];
    let drawn = s["vehicles"].as_array().cloned().unwrap_or_default();
    assert_eq!(drawn.len(), vehicles, "{s}");
    let before = step["before_us"].as_u64().unwrap_or(0);
    let period_us = (1e6 / TELEMETRY_HZ) as u64;
    let reports = records(log, "telemetry");
    for d in &drawn {
        let id = d["id"].as_str().unwrap_or_default();
        let seq = d["seq"].as_u64();
        let logged = reports
            .iter()
            .find(|r| r["telemetry"]["vehicle"] == id && r["telemetry"]["seq"].as_u64() == seq)
            .unwrap_or_else(|| panic!("{id} drawn with report {seq:?}, which is not in the log"));
        let p = &logged["telemetry"]["state"]["position"];
        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
            let (shown, want) = (
                d[axis].as_f64().unwrap_or(f64::NAN),
                p[k].as_f64().unwrap_or(f64::NAN),
            );
            assert!(
                (shown - want).abs() < 1e-6,
                "{id} {axis}: drawn {shown}, logged {want}"
            );
        }
        // Drawn where it says: the top view's circle at (x, -y).
        assert!(
            (d["cx"].as_f64().unwrap_or(f64::NAN) - p[0].as_f64().unwrap_or(0.0)).abs() < 1e-6,
            "{d}"
        );
        assert!(
            (d["cy"].as_f64().unwrap_or(f64::NAN) + p[1].as_f64().unwrap_or(0.0)).abs() < 1e-6,
            "{d}"
        );
        let drawn_at = logged["received_unix_us"].as_u64().unwrap_or(0);
        let newest = reports
            .iter()
            .filter(|r| r["telemetry"]["vehicle"] == id)
            .filter_map(|r| r["received_unix_us"].as_u64())
            .filter(|&t| t + SLACK_US <= before)
            .max()
            .unwrap_or(0);
        assert!(
            drawn_at + period_us >= newest,
            "{id}: drawn report received at {drawn_at} µs, the coordinator had one from {newest} µs (more than one telemetry period newer)"
        );
    }
}

/// The published obstacle is drawn where the log says it was put.
fn check_obstacle(s: &Value, log: &[Value]) {
    let published = records(log, "obstacle");
    assert!(!published.is_empty(), "the run published no obstacle");
    let drawn: Vec<&Value> = s["obstacles"]
        .as_array()
        .map(|a| a.iter().filter(|o| o["published"] == true).collect())
        .unwrap_or_default();
    assert!(!drawn.is_empty(), "no published obstacle drawn: {s}");
    for d in drawn {
        let o = published
            .iter()
            .find(|o| o["id"] == d["id"])
            .unwrap_or_else(|| panic!("drawn {d}, not in the log"));
        assert!(
            (d["cx"].as_f64().unwrap_or(f64::NAN) - o["centre"][0].as_f64().unwrap_or(0.0)).abs()
                < 1e-6
        );
        assert!(
            (d["cy"].as_f64().unwrap_or(f64::NAN) + o["centre"][1].as_f64().unwrap_or(0.0)).abs()
                < 1e-6
        );
        assert!(
            (d["r"].as_f64().unwrap_or(f64::NAN) - o["radius_m"].as_f64().unwrap_or(0.0)).abs()
                < 1e-6
        );
    }
}

/// The predicted closest approach is drawn between the status's pair, marked a conflict
/// exactly when it is under d_min.
fn check_predicted(s: &Value, d_min: f64) {
    let line = &s["predicted"];
    let status = &s["status_predicted"];
    assert!(line.is_object() && status.is_object(), "{s}");
    let distance = status["min_distance_m"].as_f64().unwrap_or(f64::NAN);
    assert_eq!(line["conflict"].as_bool(), Some(distance < d_min), "{s}");
    assert_eq!(line["vehicles"].as_array().map(Vec::len), Some(2), "{s}");
    for k in ["x1", "x2"] {
        let x = line[k].as_f64().unwrap_or(f64::NAN);
        assert!(
            (0.0..=2000.0).contains(&x),
            "{k} = {x} is outside the box: {s}"
        );
    }
}

/// Starts `replay LOG --view` on a free loopback port; returns it and the page's address.
fn replay_view(fleet: &mut Fleet, log: &Path) -> (common::fleet::Handle, String) {
    let addr = format!("127.0.0.1:{}", free_port());
    let mut cmd = Command::new(coordinator());
    without_shoal_env(&mut cmd);
    cmd.current_dir(root())
        .arg("replay")
        .arg(log)
        .args(["--view", &addr]);
    let replay = fleet.spawn("replay", cmd);
    fleet.wait_for_stderr(
        replay,
        "replay view: http://",
        Instant::now() + Duration::from_secs(60),
    );
    (replay, format!("http://{addr}/"))
}

#[test]
fn the_live_view_shows_the_mission_in_a_real_browser_and_replays_it() -> TestResult {
    let mut fleet = Fleet::new();
    let shots = artefacts();
    let _ = std::fs::remove_dir_all(&shots);
    std::fs::create_dir_all(&shots)?;
    let out = fleet.dir().join("run");
    let port = free_port();
    let addr = format!("127.0.0.1:{port}");
    // Scenario 3's five AUVs, planned briefly, run at 50× (about a minute); an obstacle put on
    // auv2's path at t = 600 s.
    let mut cmd = Command::new(coordinator());
    without_shoal_env(&mut cmd);
    cmd.current_dir(root())
        .arg("run")
        .arg(scenario("amp-pso-3"))
        .args(["--in-process", "-q", "--time-scale", "50"])
        .args([
            "--iterations",
            "30",
            "--populations",
            "4",
            "--particles",
            "20",
        ])
        .args(["--inject-obstacle", "600:auv2,40", "--view", &addr, "--out"])
        .arg(&out);
    let run = fleet.spawn("coordinator", cmd);
    fleet.wait_for_stderr(
        run,
        "live view: http://",
        Instant::now() + Duration::from_secs(60),
    );
    let steps = browser_steps(
        &mut fleet,
        &format!("http://{addr}/"),
        &shots.join("live"),
        "live",
    )?;
    let r = fleet.wait(run, Instant::now() + LIMIT);
    assert!(matches!(r.code(), Some(0 | 3)), "{r}");

    let log = read_log(&out.join("mission.ndjson"))?;
    let step = |name: &str| {
        steps
            .get(name)
            .unwrap_or_else(|| panic!("no step {name}: {steps:?}"))
    };
    check_vehicles(step("vehicles"), &log, 5);
    check_predicted(&step("predicted")["summary"], 50.0);
    check_obstacle(&step("obstacle")["summary"], &log);
    for again in ["reconnected", "reloaded"] {
        let s = &step(again)["summary"];
        check_obstacle(s, &log);
        assert_eq!(
            s["vehicles"].as_array().map(Vec::len),
            Some(5),
            "{again}: {s}"
        );
        assert!(
            s["caughtUp"] == true && s["mission"].is_string(),
            "{again}: {s}"
        );
    }
    assert!(step("reconnected")["summary"]["connections"].as_u64() >= Some(2));
    assert_eq!(step("reloaded")["summary"]["connections"].as_u64(), Some(1));

    // The finished log, played back.
    let (replay, url) = replay_view(&mut fleet, &out.join("mission.ndjson"));
    let steps = browser_steps(&mut fleet, &url, &shots.join("replay"), "replay")?;
    let end = &steps["replay-end"]["summary"];
    assert_eq!(end["vehicles"].as_array().map(Vec::len), Some(5), "{end}");
    check_obstacle(end, &log);
    assert_eq!(end["ended"], true, "{end}");
    let middle = &steps["replay-middle"]["summary"];
    let t = middle["t_s"].as_f64().unwrap_or(f64::NAN);
    for d in middle["vehicles"].as_array().cloned().unwrap_or_default() {
        assert!(
            d["t_s"].as_f64().is_some_and(|f| f <= t),
            "{d} drawn after the slider's {t}"
        );
    }
    fleet.kill(replay);
    for shot in [
        "live/vehicles.png",
        "live/obstacle.png",
        "live/reloaded.png",
        "replay/replay-middle.png",
    ] {
        let bytes = std::fs::read(shots.join(shot))?;
        assert!(
            bytes.starts_with(b"\x89PNG\r\n\x1a\n"),
            "{shot} is not a PNG"
        );
    }
    fleet.passed();
    Ok(())
}

/// Two AUVs: auv1 from (1000, 1000, 1000) 300 m south, auv2 300 m from the west to
/// (960, 1000, 1000), 40 m from auv1's start, arriving at the mission time (300 s) when auv1 is
/// far away (the plan keeps them at least 240 m apart).
const CONFLICT_SCENARIO: &str = r#"
name = "lost-beside-arrived"
description = "auv2 arrives 40 m from where auv1 starts"

[bounds]
min = [0.0, 0.0, 0.0]
max = [2000.0, 2000.0, 2000.0]

[fleet]
d_min_m = 50.0
mission_time_s = 300.0

[optimizer]
algorithm = "amp-pso"
populations = 4
particles = 20
leader_particles = 10
iterations = 30
waypoints = 10
seed = 1

[[obstacles]]
id = "far"
kind = "hard"
centre = [1800.0, 1800.0, 200.0]
radius_m = 50.0
inflation_m = 10.0

[[vehicles]]
id = "auv1"
kind = "auv"
start = [1000.0, 1000.0, 1000.0]
goal = [1000.0, 700.0, 1000.0]
speed_min_mps = 0.5
speed_max_mps = 1.5
max_turn_deg = 35.0
max_pitch_deg = 20.0

[[vehicles]]
id = "auv2"
kind = "auv"
start = [660.0, 1000.0, 1000.0]
goal = [960.0, 1000.0, 1000.0]
speed_min_mps = 0.5
speed_max_mps = 1.5
max_turn_deg = 35.0
max_pitch_deg = 20.0
"#;

/// A predicted conflict, drawn red: auv1's agent never connects, so auv1 stands at its start,
/// lost 2 + 5 wall seconds into the mission (560 mission seconds at 80×); auv2 has arrived by
/// then (300 mission seconds: under 4 s), 40 m from it, and the mission is given up only at
/// 930 s (the window and 600 s past it). Neither can give way, so the mission ends with the two
/// predicted under d_min, and its last status shows it. The replayed log's page draws that
/// closest approach as a conflict, between auv1's start and auv2's finish.
#[test]
fn the_view_draws_a_predicted_conflict_under_d_min_in_red() -> TestResult {
    let mut fleet = Fleet::new();
    let shots = artefacts().join("conflict");
    std::fs::create_dir_all(&shots)?;
    let file = fleet.dir().join("lost-beside-arrived.toml");
    std::fs::write(&file, CONFLICT_SCENARIO)?;
    let out = fleet.dir().join("run");
    let port = free_port();
    let mut cmd = Command::new(coordinator());
    without_shoal_env(&mut cmd);
    cmd.current_dir(root())
        .arg("run")
        .arg(&file)
        .args([
            "--in-process",
            "-q",
            "--time-scale",
            "80",
            "--agents",
            "external",
        ])
        .args([
            "--lost-after",
            "2",
            "--listen",
            &common::fleet::endpoint(port),
        ])
        .arg("--out")
        .arg(&out);
    let run = fleet.spawn("coordinator", cmd);
    fleet.agent(
        "auv2",
        &common::fleet::endpoint(port),
        &["--idle-timeout", "5"],
    );
    let r = fleet.wait(run, Instant::now() + LIMIT);
    assert_eq!(r.code(), Some(3), "{r}");
    assert!(r.stdout.contains("auv1 never arrived"), "{r}");

    let (replay, url) = replay_view(&mut fleet, &out.join("mission.ndjson"));
    let steps = browser_steps(&mut fleet, &url, &shots, "conflict")?;
    fleet.kill(replay);
    let s = &steps["conflict"]["summary"];
    check_predicted(s, 50.0);
    let line = &s["predicted"];
    assert_eq!(line["conflict"], true, "{s}");
    let mut pair: Vec<&str> = (line["vehicles"].as_array().into_iter().flatten())
        .filter_map(Value::as_str)
        .collect();
    pair.sort_unstable();
    assert_eq!(pair, ["auv1", "auv2"], "{s}");
    // Hand value: |(1000, 1000) − (960, 1000)| = 40 m, auv2 within its arrival tolerance.
    let d = s["status_predicted"]["min_distance_m"]
        .as_f64()
        .unwrap_or(f64::NAN);
    assert!((d - 40.0).abs() < 10.0, "{s}");
    // Drawn between the two places, in the top view's (x, −y).
    let ends = [
        (line["x1"].as_f64(), line["y1"].as_f64()),
        (line["x2"].as_f64(), line["y2"].as_f64()),
    ];
    let near = |x: f64, y: f64| {
        ends.iter().any(|e| match e {
            (Some(ex), Some(ey)) => (ex - x).hypot(ey - y) < 10.0,
            _ => false,
        })
    };
    assert!(near(1000.0, -1000.0) && near(960.0, -1000.0), "{s}");
    // Painted in the conflict colour (#e0245e), not the grey of a safe approach.
    assert_eq!(s["predicted_stroke"], "rgb(224, 36, 94)", "{s}");
    let shot = std::fs::read(shots.join("conflict.png"))?;
    assert!(shot.starts_with(b"\x89PNG\r\n\x1a\n"), "not a PNG");
    fleet.passed();
    Ok(())
}
