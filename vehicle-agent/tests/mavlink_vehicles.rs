//! The `mavlink` link driving vehicles nobody here wrote: MAVSDK 4.1 as the autopilot, and an
//! ArduSub-style vehicle written with pymavlink (see `vehicles/mod.rs`). Each vehicle moves along
//! its mission in real time, so the link's positions are checked against the plan itself.
//!
//! What the vehicles do with each command was measured on MAVSDK 4.1.0 (no COMMAND_ACK at all for
//! MISSION_START or DO_PAUSE_CONTINUE: no handler; DO_SET_MODE to PX4 Hold refused with
//! MAV_RESULT_TEMPORARILY_REJECTED whatever the allowable modes); the vehicles' module docs say
//! how each behaviour is played.

mod vehicles;

use std::time::{Duration, Instant};

use serde_json::Value;
use shoal_agent::link::mavlink::MavlinkLink;
use shoal_agent::link::{LinkOutcome, VehicleLink};
use shoal_common::execution::{CommandState, VehicleCommand, VehicleStatus};
use shoal_common::trajectory::Trajectory;
use vehicles::{connect, distance, follow, home_arg, num, worst_error, Kind, TestResult, Vehicle};

/// A 15 s plan about 2 km from the origin: 12 m east at 3 m/s, 10 m north and 1 m down in
/// 5 s, a 2 s wait, 12 m west at 3 m/s.
fn short_plan() -> Trajectory {
    Trajectory::from_samples(&[
        [0.0, 1400.0, 1400.0, -10.0],
        [4.0, 1412.0, 1400.0, -10.0],
        [9.0, 1412.0, 1410.0, -11.0],
        [11.0, 1412.0, 1410.0, -11.0],
        [15.0, 1400.0, 1410.0, -11.0],
    ])
}

/// How far the link's positions may stray from the plan: telemetry is up to ~0.2 s old.
const TRACK_TOLERANCE_M: f64 = 2.0;

/// Spawns `kind` at the plan's start with `args`.
fn at_start(kind: Kind, plan: &Trajectory, args: &[&str]) -> Result<Vehicle, String> {
    let home = home_arg(plan.points[0].into());
    let mut all = vec!["--home", &home, "--timeout", "90"];
    all.extend_from_slice(args);
    Vehicle::spawn(kind, &all).map_err(|e| e.to_string())
}

/// The vehicle's legs as it planned them when the mission started: (speed, speed_from, end s).
fn legs(started: &Value) -> Vec<(f64, Option<u64>, f64)> {
    let Some(legs) = started["legs"].as_array() else {
        return Vec::new();
    };
    legs.iter()
        .map(|l| {
            let end = ["depart_s", "travel_s", "hold_s"].map(|k| num(l, k).unwrap_or(f64::NAN));
            let speed = num(l, "speed").unwrap_or(f64::NAN);
            (speed, l["speed_from"].as_u64(), end.iter().sum())
        })
        .collect()
}

/// Uploads `plan` and waits until the vehicle confirmed it: mission time 0 is then.
fn start(link: &mut MavlinkLink, plan: &Trajectory) -> Result<Instant, String> {
    let asked = Instant::now();
    link.upload(plan).map_err(|e| e.to_string())?;
    let outcomes = vehicles::settle(link, VehicleCommand::Upload, asked)?;
    let last = outcomes.last().map(|(_, o)| o.clone());
    match last {
        Some(o) if o.state == CommandState::Confirmed => Ok(Instant::now()),
        other => Err(format!("the upload was not confirmed: {other:?}")),
    }
}

/// Drives the whole plan: the vehicle's legs end when the plan's samples say, the link's
/// positions follow the plan, and arrival comes on time at the goal.
fn drive_and_check(vehicle: &mut Vehicle, plan: &Trajectory) -> TestResult {
    let mut link = connect(vehicle, 500, 3)?;
    let t0 = start(&mut link, plan)?;
    let started = vehicle.wait_for("started", Duration::from_secs(2))?;
    let ends: Vec<f64> = legs(&started).iter().map(|l| l.2).collect();
    assert_eq!(ends.len(), plan.times.len() - 1, "{started}");
    for (end, t) in ends.iter().zip(&plan.times[1..]) {
        assert!(
            (end - t).abs() < 0.15,
            "a leg ends at {end:.2} s, not {t} s: {started}"
        );
    }
    let within = Duration::from_secs_f64(plan.arrival() + 8.0);
    let states = follow(&mut link, t0, within, |s| {
        s.status == VehicleStatus::Arrived
    })?;
    let (err, at) = worst_error(plan, &states).ok_or("no states")?;
    assert!(err < TRACK_TOLERANCE_M, "{err:.2} m off the plan at {at:?}");
    let last = states.last().ok_or("no states")?;
    let goal = plan.points[plan.points.len() - 1].into();
    assert!(distance(last.position, goal) < 0.5, "{last:?}");
    let arrived = last.arrived_s.ok_or("arrived without a time")?;
    assert!(
        (arrived - plan.arrival()).abs() < 1.0,
        "arrived at {arrived:.2} s"
    );
    vehicle.wait_for("arrived", Duration::from_secs(2))?;
    Ok(())
}

#[test]
fn mavsdk_drives_the_plan_on_time_and_its_arrival_is_seen() -> TestResult {
    let plan = short_plan();
    let mut vehicle = at_start(Kind::Mavsdk, &plan, &[])?;
    drive_and_check(&mut vehicle, &plan)?;
    let mission = vehicle.wait_for("mission", Duration::ZERO)?;
    let commands: Vec<u64> = mission["items"]
        .as_array()
        .ok_or("no items")?
        .iter()
        .filter_map(|i| i["command"].as_u64())
        .collect();
    assert_eq!(commands, [178, 16, 178, 16, 16, 178, 16], "{mission}");
    // MISSION_START is answered by the vehicle script: MAVSDK 4.1 has no handler for it.
    let start = vehicle.events("command");
    assert!(
        start
            .iter()
            .any(|c| c["command"] == 300 && c["result"] == 0),
        "{start:?}"
    );
    vehicle.wait_for_nth("item_reached", 7, Duration::from_secs(2))?;
    let reached = vehicle.events("item_reached");
    let last = reached.last().and_then(|r| r["seq"].as_u64());
    assert_eq!((reached.len(), last), (7, Some(6)), "{reached:?}");
    let (status, _) = vehicle.finish()?;
    assert!(status.success(), "{status}");
    Ok(())
}

#[test]
fn ardupilot_keeps_the_first_legs_speed() -> TestResult {
    let plan = short_plan();
    let mut vehicle = at_start(Kind::ArduPilot, &plan, &[])?;
    drive_and_check(&mut vehicle, &plan)?;
    // Item 0 is the vehicle's home, so the first leg's speed must come from item 1 on.
    let started = vehicle.wait_for("started", Duration::ZERO)?;
    let first = legs(&started).first().copied();
    assert!(
        first.is_some_and(|(speed, from, _)| (speed - 3.0).abs() < 0.01 && from >= Some(1)),
        "the first leg: {first:?} in {started}"
    );
    // Every waypoint relative to home, as ArduSub runs them.
    assert!(
        vehicle.events("warning").is_empty(),
        "{:?}",
        vehicle.events("warning")
    );
    Ok(())
}

/// A vehicle that takes a geofence gets the scenario bounds as an inclusion polygon and the
/// hard obstacle beside the plan as an exclusion circle, before the mission, which it then flies.
#[test]
fn ardupilot_takes_the_geofence_then_flies_the_mission() -> TestResult {
    use shoal_agent::link::mavlink::{FenceSource, Placement};
    use shoal_common::scenario::{Bounds, Obstacle, ObstacleKind};
    let plan = short_plan();
    let mut vehicle = at_start(Kind::ArduPilot, &plan, &[])?;
    let beside = Obstacle {
        id: "HObs#1".into(),
        kind: ObstacleKind::Hard,
        centre: [1406.0, 1440.0, -20.0],
        radius_m: 15.0,
        inflation_m: 5.0,
    };
    let fence = FenceSource {
        bounds: Bounds {
            min: [1300.0, 1300.0, -100.0],
            max: [1500.0, 1500.0, 0.0],
        },
        obstacles: vec![beside],
    };
    let mut place = Placement::at(vehicles::ORIGIN);
    place.fence = Some(fence);
    let mut link = vehicles::connect_placed(&vehicle, 500, 3, place)?;
    start(&mut link, &plan)?;
    let fence = vehicle.wait_for("fence", Duration::from_secs(2))?;
    let commands: Vec<u64> = fence["items"]
        .as_array()
        .ok_or("no fence items")?
        .iter()
        .filter_map(|i| i["command"].as_u64())
        .collect();
    assert_eq!(commands, [5001, 5001, 5001, 5001, 5004], "{fence}");
    vehicle.wait_for("arrived", Duration::from_secs(25))?;
    Ok(())
}

/// Uploads the plan, waits until mission time `at`, asks for a hold, and checks: the vehicle's
/// first answer (a confirmation, or a refusal or silence reported as failed) comes within 1 s;
/// the hold is confirmed in the end (however many steps and fallbacks that took); the link's
/// reports never stop meanwhile (no gap over 0.5 s); the vehicle stopped on the plan between
/// `at` and the confirmation, and stays there (under 0.3 m over 2 s), Holding.
fn hold_mid_leg(
    vehicle: &mut Vehicle,
    plan: &Trajectory,
    at: f64,
) -> Result<shoal_agent::link::mavlink::MavlinkLink, Box<dyn std::error::Error>> {
    let mut link = connect(vehicle, 400, 2)?;
    let t0 = start(&mut link, plan)?;
    std::thread::sleep(Duration::from_secs_f64(at));
    let asked = Instant::now();
    link.hold(t0.elapsed().as_secs_f64())?;
    // The reports go on while the hold is worked out: the link's state never waits.
    let mut gaps = Vec::new();
    let mut outcomes = Vec::new();
    let mut last = Instant::now();
    let is_hold = |o: &LinkOutcome| o.command == VehicleCommand::Hold;
    while !outcomes
        .iter()
        .any(|(_, o): &(f64, LinkOutcome)| o.is_final())
    {
        link.state(t0.elapsed().as_secs_f64())?;
        gaps.push(last.elapsed().as_secs_f64());
        last = Instant::now();
        outcomes.extend(
            settle_once(&mut link, asked)
                .into_iter()
                .filter(|(_, o)| is_hold(o)),
        );
        if asked.elapsed() > Duration::from_secs(10) {
            return Err(format!("no final outcome of the hold: {outcomes:?}").into());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let worst_gap = gaps.iter().copied().fold(0.0, f64::max);
    assert!(worst_gap < 0.5, "the link's state waited {worst_gap:.2} s");
    let (first_s, first) = &outcomes[0];
    assert!(
        *first_s < 1.0,
        "the first answer came {first_s:.2} s after: {first:?}"
    );
    let (answered, done) = outcomes[outcomes.len() - 1].clone();
    assert_eq!(done.state, CommandState::Confirmed, "{outcomes:?}");
    let answered = at + answered;
    std::thread::sleep(Duration::from_millis(1500)); // at its hold point, telemetry caught up
    let held = link.state(t0.elapsed().as_secs_f64())?;
    std::thread::sleep(Duration::from_secs(2));
    let later = link.state(t0.elapsed().as_secs_f64())?;
    assert_eq!(later.status, VehicleStatus::Holding, "{later:?}");
    let drift = distance(held.position, later.position);
    assert!(
        drift < 0.3,
        "moved {drift:.2} m while holding: {held:?} -> {later:?}"
    );
    let steps = ((answered - at) / 0.05).ceil().max(1.0) as usize;
    let off_plan = (0..=steps)
        .map(|k| at + (answered - at) * k as f64 / steps as f64)
        .map(|t| distance(held.position, plan.position_at(t).into()))
        .fold(f64::INFINITY, f64::min);
    assert!(
        off_plan < 1.0,
        "held {off_plan:.2} m off the plan between {at} and {answered:.2} s: {held:?}"
    );
    let past = distance(held.position, plan.position_at(at).into());
    eprintln!(
        "hold: first answer {first_s:.2} s ({:?}), confirmed {:.2} s after ({}); stopped {past:.2} m along the plan past where it was asked",
        first.state,
        answered - at,
        done.detail
    );
    Ok(link)
}

/// The outcomes collected now, stamped with the seconds since `asked`.
fn settle_once(link: &mut MavlinkLink, asked: Instant) -> Vec<(f64, LinkOutcome)> {
    let now = asked.elapsed().as_secs_f64();
    link.outcomes().into_iter().map(|o| (now, o)).collect()
}

/// The command events for `command`, as (params, result).
fn commands(vehicle: &mut Vehicle, command: u64) -> Result<Vec<(Value, Value)>, String> {
    vehicle.poll()?;
    let all = vehicle.events("command");
    let these = all.iter().filter(|c| c["command"] == command);
    Ok(these
        .map(|c| (c["params"].clone(), c["result"].clone()))
        .collect())
}

#[test]
fn mavsdk_accepting_the_pause_stops_mid_leg_and_a_new_upload_drives_on() -> TestResult {
    let plan = short_plan();
    let mut vehicle = at_start(Kind::Mavsdk, &plan, &["--hold", "accept"])?;
    let mut link = hold_mid_leg(&mut vehicle, &plan, 6.0)?;
    let pauses = commands(&mut vehicle, 193)?;
    assert_eq!(pauses.len(), 1, "{pauses:?}");
    assert_eq!(
        (&pauses[0].0[0], &pauses[0].1),
        (&Value::from(0.0), &Value::from(0))
    );
    vehicle.wait_for("holding", Duration::ZERO)?;

    // The rest of the plan, uploaded again: the vehicle drives on from where it holds.
    link.upload(&plan)?;
    let t0 = Instant::now();
    let states = follow(&mut link, t0, Duration::from_secs(20), |s| {
        s.status == VehicleStatus::Arrived
    })?;
    let last = states.last().ok_or("no states")?;
    assert!(
        distance(last.position, [1400.0, 1410.0, -11.0]) < 0.5,
        "{last:?}"
    );
    vehicle.wait_for("arrived", Duration::from_secs(2))?;
    assert_eq!(vehicle.events("mission").len(), 2);
    Ok(())
}

#[test]
fn mavsdk_ignoring_the_pause_still_holds_through_the_fallback_mission() -> TestResult {
    let plan = short_plan();
    let mut vehicle = at_start(Kind::Mavsdk, &plan, &["--hold", "ignore"])?;
    hold_mid_leg(&mut vehicle, &plan, 6.0)?;
    // MAVSDK 4.1 sends no COMMAND_ACK to DO_PAUSE_CONTINUE (no handler)…
    let pauses = commands(&mut vehicle, 193)?;
    assert!(pauses.iter().all(|(_, r)| r.is_null()), "{pauses:?}");
    assert_fallback_mission(&mut vehicle, 0)
}

/// The hold fallback: a second mission whose only waypoint (after `placeholders` items) waits a
/// long time where the vehicle was, started by MISSION_START.
fn assert_fallback_mission(vehicle: &mut Vehicle, placeholders: usize) -> TestResult {
    vehicle.poll()?;
    let missions = vehicle.events("mission");
    let fallback = missions.get(1).ok_or("no second mission")?;
    let items = fallback["items"].as_array().ok_or("no items")?;
    let waypoints: Vec<&Value> = items[placeholders..]
        .iter()
        .filter(|i| i["command"] == 16)
        .collect();
    assert_eq!(waypoints.len(), 1, "{fallback}");
    let hold_s = num(waypoints[0], "param1").unwrap_or(0.0);
    assert!(hold_s >= 60.0, "a short hold: {fallback}");
    assert!(
        vehicle.events("started").len() >= 2,
        "the fallback was not started"
    );
    Ok(())
}

#[test]
fn mavsdk_px4_refusing_hold_falls_back_to_a_mission() -> TestResult {
    let plan = short_plan();
    let args = ["--autopilot", "px4", "--hold", "refuse"];
    let mut vehicle = at_start(Kind::Mavsdk, &plan, &args)?;
    hold_mid_leg(&mut vehicle, &plan, 6.0)?;
    // PX4 profile: DO_SET_MODE custom, AUTO (4), LOITER (3); MAVSDK's ActionServer refuses it
    // with MAV_RESULT_TEMPORARILY_REJECTED (1).
    let modes = commands(&mut vehicle, 176)?;
    assert!(
        modes
            .iter()
            .any(|(p, r)| p[0] == 1.0 && p[1] == 4.0 && p[2] == 3.0 && *r == 1),
        "no DO_SET_MODE answered as expected: {modes:?}"
    );
    assert!(commands(&mut vehicle, 193)?.is_empty(), "no pause for PX4");
    assert_fallback_mission(&mut vehicle, 0)
}

#[test]
fn mavsdk_px4_accepting_hold_stops() -> TestResult {
    let plan = short_plan();
    let args = ["--autopilot", "px4", "--hold", "accept"];
    let mut vehicle = at_start(Kind::Mavsdk, &plan, &args)?;
    hold_mid_leg(&mut vehicle, &plan, 6.0)?;
    held_by_mode(&mut vehicle, [4.0, 3.0]) // PX4 AUTO.LOITER
}

/// The hold was a DO_SET_MODE to custom mode `mode` (main, sub) that the vehicle accepted, and
/// no fallback mission followed.
fn held_by_mode(vehicle: &mut Vehicle, mode: [f64; 2]) -> TestResult {
    let modes = commands(vehicle, 176)?;
    assert!(
        modes
            .iter()
            .any(|(p, r)| p[1] == mode[0] && p[2] == mode[1] && *r == 0),
        "no DO_SET_MODE {mode:?} accepted: {modes:?}"
    );
    assert_eq!(
        vehicle.events("mission").len(),
        1,
        "held without a fallback mission"
    );
    Ok(())
}

#[test]
fn ardupilot_refusing_the_pause_holds_in_poshold() -> TestResult {
    let plan = short_plan();
    let args = ["--pause", "refuse", "--mode", "accept"];
    let mut vehicle = at_start(Kind::ArduPilot, &plan, &args)?;
    hold_mid_leg(&mut vehicle, &plan, 6.0)?;
    let pauses = commands(&mut vehicle, 193)?;
    assert!(pauses.iter().all(|(_, r)| *r == 4), "FAILED: {pauses:?}");
    held_by_mode(&mut vehicle, [16.0, 0.0]) // ArduSub POSHOLD
}

#[test]
fn ardupilot_refusing_every_hold_falls_back_to_a_mission() -> TestResult {
    let plan = short_plan();
    let args = ["--pause", "ignore", "--mode", "refuse"];
    let mut vehicle = at_start(Kind::ArduPilot, &plan, &args)?;
    hold_mid_leg(&mut vehicle, &plan, 6.0)?;
    assert!(commands(&mut vehicle, 193)?
        .iter()
        .all(|(_, r)| r.is_null()));
    assert!(commands(&mut vehicle, 176)?.iter().all(|(_, r)| *r == 4));
    assert_fallback_mission(&mut vehicle, 1) // item 0: the placeholder for home
}

#[test]
fn ardupilot_arrival_is_seen_without_the_last_item_reached() -> TestResult {
    let plan = short_plan();
    let mut vehicle = at_start(Kind::ArduPilot, &plan, &["--drop-last-reached"])?;
    drive_and_check(&mut vehicle, &plan)?;
    let last = vehicle
        .events("item_reached")
        .last()
        .map(|r| r["sent"].clone());
    assert_eq!(last, Some(Value::Bool(false)), "the last one is not sent");
    Ok(())
}

#[test]
fn ardupilot_refusing_the_fence_does_not_stop_the_mission() -> TestResult {
    let plan = short_plan();
    let mut vehicle = at_start(Kind::ArduPilot, &plan, &["--no-fence"])?;
    let mut link = connect(&vehicle, 500, 3)?;
    link.upload(&plan)?;
    // Without the ArduPilot profile the first leg goes at the vehicle's default 1 m/s.
    let states = follow(&mut link, Instant::now(), Duration::from_secs(40), |s| {
        s.status == VehicleStatus::Arrived
    })?;
    let last = states.last().ok_or("no states")?;
    assert!(
        distance(last.position, [1400.0, 1410.0, -11.0]) < 0.5,
        "{last:?}"
    );
    vehicle.wait_for("arrived", Duration::from_secs(2))?;
    let refused = vehicle.events("fence_refused").len();
    assert!(vehicle.events("fence").is_empty() && refused <= 1);
    Ok(())
}

#[test]
fn the_vehicles_kinematics_pass_their_self_test() -> TestResult {
    let py = shoal_interop::python()?;
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/python/vehicle_kinematics.py"
    );
    let out = std::process::Command::new(&py).arg(script).output()?;
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("ok"), "{text}");
    Ok(())
}

/// The agent's whole execution loop against MAVSDK ignoring the pause: its reports never stop
/// (the coordinator declares a vehicle lost after 3 s of silence), the hold's failure is in a
/// report within 1 s of the order, and a later report says the fallback holds the vehicle.
#[test]
fn the_agent_reports_an_ignored_hold_within_a_second_and_never_goes_silent() -> TestResult {
    use shoal_agent::execute::{self, Order};
    use shoal_common::wire::coordinator_to_agent::CoordinatorToAgent;
    use shoal_common::wire::open::Telemetry;
    use shoal_common::wire::WireTrajectory;
    use std::sync::atomic::AtomicBool;
    use std::sync::{mpsc, Mutex};

    let plan = short_plan();
    let vehicle = at_start(Kind::Mavsdk, &plan, &["--hold", "ignore"])?;
    let mut link = connect(&vehicle, 400, 2)?;
    let scenario = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenarios/amp-pso-1.toml"
    ))?;
    let wire = WireTrajectory::new("auv1", &plan);
    let epoch = shoal_common::execution::unix_us() / 1000;
    let order = Order::new("m", "auv1", &scenario, &wire, epoch, 1.0, 5.0, 1)?;
    let (tx, inbox) = mpsc::channel();
    let reports = Mutex::new(Vec::<(Instant, Telemetry)>::new());
    let publish = |t: &Telemetry| {
        if let Ok(mut r) = reports.lock() {
            r.push((Instant::now(), t.clone()));
        }
    };
    let (stop, idle) = (AtomicBool::new(false), Duration::from_secs(60));
    let ordered = std::thread::scope(|s| {
        let feeder = s.spawn(move || {
            std::thread::sleep(Duration::from_secs(6));
            let at = Instant::now();
            let hold = CoordinatorToAgent::Hold {
                mission: "m".into(),
                vehicle: "auv1".into(),
                reason: "test".into(),
            };
            let _ = tx.send(hold);
            std::thread::sleep(Duration::from_secs(4));
            let end = CoordinatorToAgent::Stop {
                mission: "m".into(),
                reason: "test over".into(),
            };
            let _ = tx.send(end);
            at
        });
        let report = execute::run(order, &mut link, &inbox, &publish, &stop, idle);
        eprintln!("execution: {}", report.outcome);
        feeder.join()
    });
    let ordered = ordered.map_err(|_| "the feeder panicked")?;
    let reports = reports.into_inner().map_err(|e| e.to_string())?;
    let gaps = reports.windows(2).map(|w| (w[1].0 - w[0].0).as_secs_f64());
    let worst = gaps.fold(0.0, f64::max);
    assert!(worst < 1.0, "a report gap of {worst:.2} s");
    let failed_at = reports.iter().find_map(|(at, t)| {
        let c = t.command.as_ref()?;
        (c.command == VehicleCommand::Hold && c.state == CommandState::Failed).then_some(*at)
    });
    let failed_after = failed_at.map(|at| (at - ordered).as_secs_f64());
    assert!(
        failed_after.is_some_and(|s| s < 1.0),
        "hold failure reported after {failed_after:?} s"
    );
    let held = reports.iter().any(|(_, t)| {
        t.state.status == VehicleStatus::Holding
            && t.command
                .as_ref()
                .is_some_and(|c| c.state == CommandState::Confirmed)
    });
    assert!(held, "no report of the fallback holding the vehicle");
    eprintln!(
        "agent: {} reports, worst gap {worst:.2} s, hold failure reported {:.2} s after the order",
        reports.len(),
        failed_after.unwrap_or(f64::NAN)
    );
    Ok(())
}
