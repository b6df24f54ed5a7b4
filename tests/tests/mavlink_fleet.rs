//! A real vehicle link end to end: `shoal-coordinator run` plans a lone AUV placed on the Earth
//! by its scenario's `[origin]` (`tests/fixtures/field-auv.toml`, 2 km from the origin), and an
//! external `shoal-agent --link mavlink`, given no origin of its own, drives MAVSDK 4.1 playing
//! the autopilot (`tests/python/mavsdk_vehicle.py`, moving in real time along the mission it is
//! given) to the goal. The coordinator's picture comes only from what the vehicle reports.

mod common;

use std::net::UdpSocket;
use std::process::Command;
use std::time::{Duration, Instant};

use common::fleet::{endpoint, free_port, Fleet};
use common::process::{coordinator, root};
use common::{interop_python, read_json, without_shoal_env, TestResult};
use serde_json::Value;
use shoal_common::geo::GeoOrigin;

/// The fixture's origin and auv1's start.
const ORIGIN: GeoOrigin = GeoOrigin::new(43.1, 5.9, 0.0);
const START: [f64; 3] = [2000.0, 2000.0, -20.0];
const GOAL: [f64; 3] = [2060.0, 2035.0, -24.0];

fn free_udp_port() -> Result<u16, std::io::Error> {
    Ok(UdpSocket::bind("127.0.0.1:0")?.local_addr()?.port())
}

#[test]
fn run_drives_a_mavsdk_vehicle_on_the_scenarios_origin_to_its_goal() -> TestResult {
    let py = interop_python()?;
    let mut fleet = Fleet::new();
    let out = fleet.dir().join("out");
    let vport = free_udp_port()?;
    let [lat, lon, alt] = ORIGIN.to_geodetic(START);
    let mut vehicle = Command::new(&py);
    vehicle
        .arg(root().join("tests/python/mavsdk_vehicle.py"))
        .arg(vport.to_string())
        .args(["--home", &format!("{lat:.9},{lon:.9},{alt:.3}")])
        .args(["--ignore-stdin", "--timeout", "150"]);
    fleet.spawn("mavsdk-vehicle", vehicle);
    let port = free_port();
    let mut run = Command::new(coordinator());
    without_shoal_env(&mut run);
    run.current_dir(root())
        .arg("run")
        .arg(root().join("tests/fixtures/field-auv.toml"))
        .args([
            "--in-process",
            "-q",
            "--time-scale",
            "1",
            "--agents",
            "external",
        ])
        .args(["--listen", &format!("tcp/127.0.0.1:{port}")])
        .arg("--out")
        .arg(&out);
    let c = fleet.spawn("coordinator", run);
    let address = format!("udpout:127.0.0.1:{vport}");
    let link = ["--link", "mavlink", "--mavlink-address", &address, "--once"];
    fleet.agent("auv1", &endpoint(port), &link);
    let r = fleet.wait(c, Instant::now() + Duration::from_secs(180));
    assert_eq!(r.code(), Some(0), "{}\n{}", r.stdout, r.stderr);
    assert!(r.stdout.contains("MET"), "{}", r.stdout);

    let report = read_json(&out.join("execution.json"))?;
    let v = &report["figures"]["vehicles"][0];
    assert_eq!(v["in_window"], Value::Bool(true), "{v}");
    assert_eq!(v["lost"], Value::Bool(false), "{v}");
    let log = std::fs::read_to_string(out.join("mission.ndjson"))?;
    for kind in ["vehicle_lost", "hold_failed", "upload_failed"] {
        let needle = format!("\"kind\":\"{kind}\"");
        assert!(!log.contains(&needle), "a {kind} event in the log");
    }
    // The last fix it reported, through MAVLink and WGS-84 back to scenario metres: at the goal.
    let last = log
        .lines()
        .filter(|l| l.contains("\"telemetry\""))
        .filter_map(|l| serde_json::from_str::<Value>(l).ok())
        .filter_map(|t| {
            let p = t["telemetry"]["state"]["position"].as_array()?.clone();
            let p: Vec<f64> = p.iter().filter_map(Value::as_f64).collect();
            <[f64; 3]>::try_from(p).ok()
        })
        .next_back()
        .ok_or("no telemetry in the log")?;
    let off = (0..3)
        .map(|i| (last[i] - GOAL[i]).powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(
        off < 0.5,
        "the last fix {last:?} is {off:.2} m from the goal"
    );
    fleet.passed();
    Ok(())
}
