//! The `mavlink` link against vehicles on loopback UDP: a mock vehicle written with the mavlink
//! crate ([`mock_vehicle`]: it drops messages so the retries must work, refuses, or stays
//! silent), and pymavlink as an independent peer (`tests/python/mavlink_peer.py`).
//!
//! The peer's interpreter comes from [`shoal_interop::python`] (a venv with the pinned packages).

mod mock_vehicle;

use std::io::{BufRead, BufReader};
use std::net::UdpSocket;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use clap::Parser;
use mavlink::dialects::common::{self as mav, MavCmd, MavMessage as M};
use mavlink::{MavConnection, MavHeader};
use shoal_agent::link::mavlink::{mission_items, AutopilotChoice, MavlinkLink, Placement, Profile};
use shoal_agent::link::{GeoOrigin, LinkError, LinkOutcome, MavlinkSettings, VehicleLink};
use shoal_agent::AgentArgs;
use shoal_common::execution::{CommandState, VehicleCommand, VehicleStatus};
use shoal_common::geometry::Vec3;
use shoal_common::trajectory::Trajectory;

use mock_vehicle::{Behaviour, Mock, VEHICLE};

type TestResult = Result<(), Box<dyn std::error::Error>>;

const ORIGIN: GeoOrigin = GeoOrigin::new(43.1, 5.9, 0.0);

/// A free UDP port on loopback (bound, read, released).
fn free_port() -> Result<u16, std::io::Error> {
    Ok(UdpSocket::bind("127.0.0.1:0")?.local_addr()?.port())
}

/// Three samples: 150 m east in 100 s, then 200 m north and 20 m down in 200 s.
fn plan() -> Trajectory {
    let points = [
        [0.0, 0.0, -10.0],
        [150.0, 0.0, -10.0],
        [150.0, 200.0, -30.0],
    ];
    Trajectory {
        times: vec![0.0, 100.0, 300.0],
        points: points.map(Vec3::from).to_vec(),
    }
}

/// A generic autopilot (these vehicles send no HEARTBEAT before a mission) at `port`.
fn settings(port: u16, timeout_ms: u64, retries: u32) -> MavlinkSettings {
    let mut s = MavlinkSettings::new(format!("udpout:127.0.0.1:{port}"), Some(ORIGIN));
    (s.timeout, s.retries) = (Duration::from_millis(timeout_ms), retries);
    s.autopilot = AutopilotChoice::Generic;
    s
}

/// The link to the vehicle at `port`, without a geofence.
fn connect(settings: &MavlinkSettings) -> Result<MavlinkLink, LinkError> {
    MavlinkLink::connect(settings, Placement::at(ORIGIN))
}

/// Collects outcomes until `command`'s final one (10 s at most); returns them all.
fn settle(link: &mut MavlinkLink, command: VehicleCommand) -> Result<Vec<LinkOutcome>, String> {
    let (deadline, mut seen) = (Instant::now() + Duration::from_secs(10), Vec::new());
    loop {
        seen.extend(link.outcomes());
        if seen.iter().any(|o| o.command == command && o.is_final()) {
            return Ok(seen);
        }
        if Instant::now() > deadline {
            return Err(format!("no final outcome of {command:?}: {seen:?}"));
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// The final state of `command` and its detail.
fn final_of(outcomes: &[LinkOutcome], command: VehicleCommand) -> (CommandState, String) {
    outcomes
        .iter()
        .rfind(|o| o.command == command && o.is_final())
        .map_or((CommandState::Pending, String::new()), |o| {
            (o.state, o.detail.clone())
        })
}

/// Polls `state` until `done` holds (or 3 s pass).
fn wait_state(
    link: &mut MavlinkLink,
    done: impl Fn(&shoal_common::execution::VehicleState) -> bool,
) -> Result<shoal_common::execution::VehicleState, String> {
    let deadline = Instant::now() + Duration::from_secs(3);
    loop {
        let state = link.state(42.0);
        match state {
            Ok(s) if done(&s) => return Ok(s),
            _ if Instant::now() > deadline => {
                return Err(format!("gave up waiting; last: {state:?}"))
            }
            _ => std::thread::sleep(Duration::from_millis(20)),
        }
    }
}

/// GLOBAL_POSITION_INT at scenario point `p`.
fn position_at(p: [f64; 3], v_ned_cm: [i16; 3], hdg_cdeg: u16) -> mav::GLOBAL_POSITION_INT_DATA {
    let [lat, lon, alt] = ORIGIN.to_geodetic(p);
    let mut g = mav::GLOBAL_POSITION_INT_DATA::default();
    (g.lat, g.lon, g.alt) = (
        (lat * 1e7).round() as i32,
        (lon * 1e7).round() as i32,
        (alt * 1e3).round() as i32,
    );
    ([g.vx, g.vy, g.vz], g.hdg) = (v_ned_cm, hdg_cdeg);
    g
}

#[test]
fn upload_survives_lost_messages_then_position_arrival_and_hold_come_through() -> TestResult {
    let mock = Mock::start(Behaviour::Lossy)?;
    let mut place = Placement::at(ORIGIN);
    place.surface_z = Some(0.0);
    let mut link = MavlinkLink::connect(&settings(mock.port, 200, 5), place)?;
    let early = link.state(0.0);
    assert!(matches!(early, Err(LinkError::Timeout(_))), "{early:?}");

    let started = Instant::now();
    link.upload(&plan())?;
    let upload = settle(&mut link, VehicleCommand::Upload)?;
    assert_eq!(
        final_of(&upload, VehicleCommand::Upload).0,
        CommandState::Confirmed
    );
    assert!(
        started.elapsed() >= Duration::from_millis(400),
        "two timeouts before the retries"
    );
    {
        let b = mock.board();
        assert_eq!(
            b.counts, 2,
            "MISSION_COUNT sent again after the first was not answered"
        );
        let want = mission_items(&plan(), &ORIGIN, None, (1, 1), (Profile::Generic, 0.0)).items;
        assert_eq!(b.items.len(), 4);
        for (got, want) in b.items.iter().zip(&want) {
            assert_eq!(
                (got.seq, got.command, got.frame),
                (want.seq, want.command, want.frame)
            );
            assert_eq!(
                (got.x, got.y, got.z, got.param2),
                (want.x, want.y, want.z, want.param2)
            );
        }
        let end = ORIGIN.to_geodetic([150.0, 200.0, -30.0]);
        assert_eq!(
            (b.items[3].x, b.items[3].y),
            ((end[0] * 1e7).round() as i32, (end[1] * 1e7).round() as i32)
        );
        assert_eq!(b.commands, [MavCmd::MAV_CMD_MISSION_START]);
    }

    // 1 m/s north, 0.5 m/s east, 0.1 m/s up; heading 45° (north-east) is 45° ccw from east.
    mock.board().position = Some(position_at([120.0, -35.5, -12.0], [100, 50, -10], 4500));
    let s = wait_state(&mut link, |s| s.t_s == 42.0)?;
    let want = [120.0, -35.5, -12.0];
    assert!(
        (0..3).all(|i| (s.position[i] - want[i]).abs() < 0.1),
        "{:?}",
        s.position
    );
    assert!(
        (0..3).all(|i| (s.velocity[i] - [0.5, 1.0, 0.1][i]).abs() < 1e-9),
        "{:?}",
        s.velocity
    );
    let depth_ok = s.depth_m.is_some_and(|d| (d - 12.0).abs() < 1e-3);
    assert!((s.heading_deg - 45.0).abs() < 1e-9 && depth_ok, "{s:?}");
    assert_eq!(
        (s.status, s.battery, s.arrived_s),
        (VehicleStatus::Underway, 1.0, None)
    );

    mock.board().reached = Some(3);
    let s = wait_state(&mut link, |s| s.status == VehicleStatus::Arrived)?;
    assert!(s.arrived_s.is_some_and(|t| t <= 42.0));

    link.hold(0.0)?;
    let held = settle(&mut link, VehicleCommand::Hold)?;
    assert_eq!(
        final_of(&held, VehicleCommand::Hold).0,
        CommandState::Confirmed
    );
    assert_eq!(link.state(43.0)?.status, VehicleStatus::Holding);
    assert_eq!(
        mock.board().commands.last(),
        Some(&MavCmd::MAV_CMD_DO_PAUSE_CONTINUE)
    );
    assert_eq!(link.skipped(), 0);
    Ok(())
}

#[test]
fn a_silent_vehicle_times_out_after_the_retries() -> TestResult {
    let mock = Mock::start(Behaviour::Silent)?;
    let mut link = connect(&settings(mock.port, 100, 2))?;
    let started = Instant::now();
    link.upload(&plan())?;
    let upload = settle(&mut link, VehicleCommand::Upload)?;
    let took = started.elapsed();
    let (state, why) = final_of(&upload, VehicleCommand::Upload);
    assert!(
        state == CommandState::GaveUp && why.contains("MISSION_REQUEST 0"),
        "{why}"
    );
    assert!(
        took >= Duration::from_millis(300) && took < Duration::from_secs(2),
        "{took:?}"
    );
    assert_eq!(
        mock.board().counts,
        3,
        "the first MISSION_COUNT and two resends"
    );
    // The hold: unanswered, reported within a second, and no fallback without a position.
    let asked = Instant::now();
    link.hold(0.0)?;
    let held = settle(&mut link, VehicleCommand::Hold)?;
    let failed = held.iter().position(|o| o.state == CommandState::Failed);
    assert!(failed.is_some(), "{held:?}");
    let (state, why) = final_of(&held, VehicleCommand::Hold);
    assert!(
        state == CommandState::GaveUp && why.contains("no position"),
        "{why}"
    );
    assert!(
        asked.elapsed() < Duration::from_secs(2),
        "{:?}",
        asked.elapsed()
    );
    assert_eq!(
        link.state(1.0).ok().map(|s| s.status),
        None,
        "no fix, no state"
    );
    Ok(())
}

#[test]
fn an_exchange_a_newer_command_supersedes_is_answered_given_up() -> TestResult {
    // The silent vehicle keeps the upload waiting for its first MISSION_REQUEST; the hold given
    // meanwhile supersedes it. Both commands are answered: the upload given up as superseded,
    // the hold given up (no position to hold at), each under its own serial.
    let mock = Mock::start(Behaviour::Silent)?;
    let mut link = connect(&settings(mock.port, 300, 5))?;
    let upload = link.upload(&plan())?;
    std::thread::sleep(Duration::from_millis(100));
    let hold = link.hold(0.0)?;
    assert_ne!(upload, hold);
    let seen = settle(&mut link, VehicleCommand::Hold)?;
    let answer = |serial| seen.iter().find(|o| o.serial == serial && o.is_final());
    let superseded = answer(upload).ok_or(format!("the upload is not answered: {seen:?}"))?;
    assert_eq!(superseded.command, VehicleCommand::Upload);
    assert_eq!(superseded.state, CommandState::GaveUp);
    assert!(superseded.detail.contains("superseded"), "{superseded:?}");
    let held = answer(hold).ok_or(format!("the hold is not answered: {seen:?}"))?;
    assert!(
        held.state == CommandState::GaveUp && held.detail.contains("no position"),
        "{held:?}"
    );
    assert_eq!(
        mock.board().counts,
        1,
        "the upload stopped at its first try"
    );
    Ok(())
}

#[test]
fn a_refused_mission_is_refused() -> TestResult {
    let mock = Mock::start(Behaviour::Refuses)?;
    let mut link = connect(&settings(mock.port, 200, 5))?;
    link.upload(&plan())?;
    let upload = settle(&mut link, VehicleCommand::Upload)?;
    let (state, why) = final_of(&upload, VehicleCommand::Upload);
    assert!(
        state == CommandState::GaveUp && why.contains("MAV_MISSION_ERROR"),
        "{why}"
    );
    Ok(())
}

#[test]
fn a_listening_link_skips_garbage_and_strangers() -> TestResult {
    let port = free_port()?;
    let mut link = connect(&MavlinkSettings::new(
        format!("udpin:127.0.0.1:{port}"),
        Some(ORIGIN),
    ))?;
    let raw = UdpSocket::bind("127.0.0.1:0")?;
    raw.send_to(
        &[0xfd, 9, 0, 0, 1, 1, 1, 0, 0, 0, 1, 2, 3],
        ("127.0.0.1", port),
    )?; // a torn frame
    raw.send_to(b"not mavlink at all", ("127.0.0.1", port))?;
    let vehicle = mavlink::connect::<M>(&format!("udpout:127.0.0.1:{port}"))?;
    let stranger = MavHeader {
        system_id: 9,
        ..VEHICLE
    };
    vehicle.send(
        &stranger,
        &M::GLOBAL_POSITION_INT(position_at([5.0; 3], [0; 3], 0)),
    )?;
    vehicle.send(
        &VEHICLE,
        &M::GLOBAL_POSITION_INT(position_at([-20.0, 30.0, -4.0], [0; 3], u16::MAX)),
    )?;
    let s = wait_state(&mut link, |_| true)?;
    assert!(
        (s.position[0] + 20.0).abs() < 0.1 && (s.position[1] - 30.0).abs() < 0.1,
        "{s:?}"
    );
    assert_eq!((s.status, s.heading_deg), (VehicleStatus::Idle, 0.0));
    assert!(link.skipped() >= 1, "the stranger's message is counted");
    Ok(())
}

#[test]
fn the_agent_flags_build_the_settings_and_bad_values_name_the_flag() -> TestResult {
    let base = ["shoal-agent", "--vehicle", "auv1", "--link", "mavlink"];
    let args = AgentArgs::try_parse_from(base.iter().chain(&[
        "--mavlink-address",
        "udpout:127.0.0.1:14550",
        "--mavlink-origin",
        "43.1,5.9,-2",
        "--mavlink-target",
        "2,1",
    ]))?;
    let origin = Some(GeoOrigin::new(43.1, 5.9, -2.0));
    let mut want = MavlinkSettings::new("udpout:127.0.0.1:14550", origin);
    (want.target_system, want.target_component) = (2, 1);
    assert_eq!(args.link_settings().mavlink, Some(want));
    for (flag, bad) in [
        ("--mavlink-origin", "91,0,0"),
        ("--mavlink-address", "tcp:x:1"),
        ("--mavlink-target", "0,1"),
    ] {
        let err = AgentArgs::try_parse_from(base.iter().chain(&[flag, bad]))
            .err()
            .map(|e| e.to_string());
        assert!(
            err.as_ref()
                .is_some_and(|e| e.contains(flag) && e.contains(bad)),
            "{flag} {bad}: {err:?}"
        );
    }
    let without = AgentArgs::try_parse_from(base)?;
    let err = without.config().err().map(|e| e.to_string());
    assert!(err.is_some_and(|e| e.contains("--mavlink-address")));
    Ok(())
}

/// Kills the peer if the test ends early.
struct Peer(Child);

impl Drop for Peer {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// A number field of a flat JSON line (`"key": 1.5`), as the peer prints them.
fn field(line: &str, key: &str) -> Option<f64> {
    let rest = &line[line.find(&format!("\"{key}\": "))? + key.len() + 4..];
    rest[..rest.find([',', '}'])?].trim().parse().ok()
}

#[test]
fn pymavlink_as_the_vehicle_takes_the_mission_reports_arrival_and_stops() -> TestResult {
    let py = shoal_interop::python()?;
    let port = free_port()?;
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/python/mavlink_peer.py"
    );
    let mut child = Command::new(&py)
        .args([script, &port.to_string(), "--timeout", "20"])
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| format!("{py}: {e}"))?;
    let stdout = child.stdout.take().ok_or("no stdout")?;
    let mut peer = Peer(child);
    let (tx, lines) = mpsc::channel();
    std::thread::spawn(move || {
        BufReader::new(stdout)
            .lines()
            .map_while(Result::ok)
            .try_for_each(|l| tx.send(l))
    });
    let first = lines.recv_timeout(Duration::from_secs(15))?;
    assert!(first.contains("listening"), "{first}");

    let mut link = connect(&settings(port, 500, 5))?;
    link.upload(&plan())?;
    let s = wait_state(&mut link, |s| s.status == VehicleStatus::Arrived)?;
    assert!(
        (0..3).all(|i| (s.position[i] - [150.0, 200.0, -30.0][i]).abs() < 0.1),
        "{s:?}"
    );
    assert!(
        (s.heading_deg - 0.0).abs() < 1e-9,
        "heading 90° from north is east: {s:?}"
    );
    link.stop()?;
    let stopped = settle(&mut link, VehicleCommand::Stop)?;
    assert_eq!(
        final_of(&stopped, VehicleCommand::Stop).0,
        CommandState::Confirmed
    );
    assert_eq!(link.state(50.0)?.status, VehicleStatus::Stopped);

    let deadline = Instant::now() + Duration::from_secs(10);
    let status = loop {
        match peer.0.try_wait()? {
            Some(status) => break status,
            None if Instant::now() > deadline => {
                return Err("the peer did not exit after the stop".into())
            }
            None => std::thread::sleep(Duration::from_millis(20)),
        }
    };
    let out: Vec<String> = lines.iter().collect(); // up to the end of its stdout
    assert!(status.success(), "peer: {status}; stdout: {out:#?}");
    let items: Vec<&String> = out.iter().filter(|l| l.contains("\"item\"")).collect();
    let want = mission_items(&plan(), &ORIGIN, None, (1, 1), (Profile::Generic, 0.0)).items;
    assert_eq!(items.len(), want.len(), "{out:#?}");
    for (line, w) in items.iter().zip(&want) {
        let got = ["seq", "command", "x", "y", "z", "param2"].map(|k| field(line, k));
        let expect = [
            w.seq as f64,
            w.command as u32 as f64,
            w.x.into(),
            w.y.into(),
            w.z.into(),
            w.param2.into(),
        ];
        assert!(
            got.iter()
                .zip(expect)
                .all(|(g, e)| g.is_some_and(|g| (g - e).abs() <= 1e-6 * e.abs().max(1.0))),
            "{line} vs {w:?}"
        );
    }
    let commands: Vec<Option<f64>> = out
        .iter()
        .filter(|l| l.contains("\"command\", "))
        .map(|l| field(l, "command"))
        .collect();
    let (start, pause) = (
        MavCmd::MAV_CMD_MISSION_START as u32 as f64,
        MavCmd::MAV_CMD_DO_PAUSE_CONTINUE as u32 as f64,
    );
    assert_eq!(commands, [Some(start), Some(pause)], "{out:#?}");
    Ok(())
}
