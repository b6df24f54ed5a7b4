//! What a stranger on an unsecured network sends during an execution, end to end: a forged
//! fix far from where the vehicle is, a forged `Hold` carrying an order number already used,
//! an obstacle of radius 1e300 and a flood of small ones. The coordinator drops the fix
//! (counted, one event), the huge obstacle and the flood past the rate limit, and the agent
//! the hold; the mission is met as if none had come. The agent is `shoal_agent::run` on a thread driving
//! a simulated vehicle; the stranger is a plain Zenoh client on loopback.

mod common;

use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

use common::{agent, finish, free_endpoint, TestResult};
use serde_json::Value;
use shoal_common::geometry::Vec3;
use shoal_common::scenario::{Obstacle, ObstacleKind, Scenario};
use shoal_common::trajectory::Trajectory;
use shoal_common::wire::codec;
use shoal_common::wire::coordinator_to_agent::CoordinatorToAgent;
use shoal_common::wire::open::Telemetry;
use shoal_common::wire::topics::OpenKey;
use shoal_common::wire::{session, topics, Envelope};
use shoal_coordinator::distributed::{AgentsMode, DistributedOptions};
use shoal_coordinator::execute::{execute_trajectories, ExecOptions};
use zenoh::Wait;

const MISSION: &str = "plausibility";

/// Small obstacles the stranger publishes at once.
const FLOOD: usize = 40;

fn obstacle(id: &str, centre: [f64; 3], radius_m: f64) -> Obstacle {
    Obstacle {
        id: id.into(),
        kind: ObstacleKind::Hard,
        centre,
        radius_m,
        inflation_m: 5.0,
    }
}

/// auv1 from (100, 1000, 200) to (1900, 1000, 200) at 1.5 m/s: 1,200 mission seconds.
fn mission() -> Result<(Scenario, Vec<Trajectory>), Box<dyn std::error::Error>> {
    let text = "name = \"plausibility\"\n[bounds]\nmin = [0.0, 0.0, 0.0]\n\
        max = [2000.0, 2000.0, 400.0]\n[fleet]\nd_min_m = 50.0\nmission_time_s = 1200.0\n\
        [optimizer]\nwaypoints = 8\n[[vehicles]]\nid = \"auv1\"\nkind = \"auv\"\n\
        start = [100.0, 1000.0, 200.0]\ngoal = [1900.0, 1000.0, 200.0]\nspeed_min_mps = 0.5\n\
        speed_max_mps = 2.5\nmax_turn_deg = 35.0\nmax_pitch_deg = 20.0\n";
    let s = Scenario::parse(text, Path::new("plausibility.toml"))?;
    let plan = Trajectory {
        times: vec![0.0, 1200.0],
        points: vec![
            Vec3::new(100.0, 1000.0, 200.0),
            Vec3::new(1900.0, 1000.0, 200.0),
        ],
    };
    Ok((s, vec![plan]))
}

/// What the stranger managed to send: the forged fix's number, the replayed hold's number.
type Sent = anyhow::Result<(u64, u64)>;

/// The stranger: reads auv1's orders and reports like anyone could; once auv1 has reported
/// four times, publishes a copy of its latest report moved 800 m south (numbered two past it,
/// which a receiver checking numbers only would take), and a `Hold` numbered like the first
/// `Execute` it saw (or 1, when it saw none); then an obstacle of radius 1e300 and a flood of
/// [`FLOOD`] small ones off auv1's path.
fn stranger(endpoint: String) -> std::thread::JoinHandle<Sent> {
    std::thread::spawn(move || {
        let e = |what: &str| {
            let what = what.to_string();
            move |err: zenoh::Error| anyhow::anyhow!("{what}: {err}")
        };
        let s = zenoh::open(session::client_config(
            &[endpoint],
            true,
            &Default::default(),
        )?)
        .wait()
        .map_err(e("open"))?;
        let orders = s
            .declare_subscriber(topics::to_agent(MISSION, "auv1")?)
            .wait()
            .map_err(e("orders"))?;
        let reports = s
            .declare_subscriber(topics::telemetry(MISSION, "auv1")?)
            .wait()
            .map_err(e("reports"))?;
        let mut first_order = None;
        let deadline = std::time::Instant::now() + Duration::from_secs(60);
        while std::time::Instant::now() < deadline {
            while let Ok(Some(o)) = orders.try_recv() {
                let bytes = o.payload().to_bytes();
                if let Ok(m) = codec::decode::<CoordinatorToAgent>(&bytes) {
                    first_order.get_or_insert(m.seq);
                }
            }
            let Some(r) = reports
                .recv_timeout(Duration::from_millis(50))
                .map_err(e("recv"))?
            else {
                continue;
            };
            let Ok(mut t) = codec::decode_json::<Telemetry>(&r.payload().to_bytes()) else {
                continue;
            };
            if t.seq < 4 {
                continue;
            }
            // The agent may have had its order before this client could listen: number 1 is
            // older than any the coordinator sends (they count from its start in µs).
            let replayed = first_order.unwrap_or(1);
            t.seq += 2;
            t.state.position[1] -= 800.0;
            let key = topics::telemetry(MISSION, "auv1")?;
            s.put(key, codec::encode_json(&t)?)
                .wait()
                .map_err(e("put"))?;
            let hold = Envelope::sequenced(
                CoordinatorToAgent::Hold {
                    mission: MISSION.into(),
                    vehicle: "auv1".into(),
                    reason: "forged".into(),
                },
                replayed,
            );
            s.put(topics::to_agent(MISSION, "auv1")?, codec::encode(&hold)?)
                .wait()
                .map_err(e("put"))?;
            // One obstacle as large as the ocean, then a flood of small ones off the path.
            let obstacles = topics::open_key(MISSION, OpenKey::Obstacles)?;
            let huge = obstacle("huge", [1000.0, 1000.0, 200.0], 1e300);
            s.put(&obstacles, codec::encode_json(&huge)?)
                .wait()
                .map_err(e("put"))?;
            for k in 0..FLOOD {
                let small = obstacle(&format!("flood-{k}"), [1000.0, 1800.0, 200.0], 1.0);
                s.put(&obstacles, codec::encode_json(&small)?)
                    .wait()
                    .map_err(e("put"))?;
            }
            let _ = s.close().wait();
            return Ok((t.seq, replayed));
        }
        anyhow::bail!("auv1 never reported four times")
    })
}

#[test]
fn a_forged_far_fix_and_a_replayed_hold_leave_the_mission_met_and_are_counted() -> TestResult {
    let (s, plans) = mission()?;
    let endpoint = free_endpoint()?;
    let dir = tempfile::tempdir()?;
    let agents = vec![agent("auv1", &endpoint)];
    let spy = stranger(endpoint.clone());
    let distributed = DistributedOptions {
        mission: MISSION.into(),
        agents: AgentsMode::External,
        listen: vec![endpoint],
        routers: Vec::new(),
        security: Default::default(),
        join_timeout: Duration::from_secs(30),
        round_timeout: Duration::from_secs(10),
        agent_bin: None,
        log_dir: dir.path().to_path_buf(),
        health_file: None,
        agent_args: Vec::new(),
    };
    let options = ExecOptions {
        time_scale: 60.0,
        telemetry_hz: 2.0,
        horizon_s: 180.0,
        deviation_m: 25.0,
        separation_buffer_m: 10.0,
        lost_after: Duration::from_secs(10),
        replan_budget: Duration::from_secs(1),
        arrival_window_s: 60.0,
        log: dir.path().join("mission.ndjson"),
        inject: Vec::new(),
        quiet: true,
        seed: 1,
        live: None,
    };
    let report = execute_trajectories(
        &s,
        &plans,
        1200.0,
        &distributed,
        &options,
        &AtomicBool::new(false),
    )?;
    finish(agents)?;
    let (forged, replayed) = spy.join().map_err(|_| "the stranger's thread panicked")??;
    let log: Vec<Value> = std::fs::read_to_string(dir.path().join("mission.ndjson"))?
        .lines()
        .filter_map(|l| serde_json::from_str(l).ok())
        .collect();
    let kinds = |k: &str| log.iter().filter(|r| r["kind"] == k).count();
    // The fix: refused as a jump, counted once, told once; never a replan, never logged as a
    // report (replay would draw it).
    assert_eq!(report.implausible.jump, 1, "{:?}", report.implausible);
    assert_eq!(kinds("implausible_report"), 1);
    assert_eq!(report.replans, 0, "replanned toward the forged fix");
    let far = log.iter().any(|r| {
        r["record"] == "telemetry" && r["telemetry"]["state"]["position"][1].as_f64() < Some(500.0)
    });
    assert!(!far, "the forged fix {forged} was logged as a report");
    // The hold: numbered {replayed}, already used, so auv1 never held.
    let held = log
        .iter()
        .any(|r| r["record"] == "telemetry" && r["telemetry"]["state"]["status"] == "holding");
    assert!(!held, "auv1 obeyed a replayed hold numbered {replayed}");
    // The obstacles: the huge one dropped; of the flood, about a second's worth (5) taken and
    // the rest dropped by the rate limit, each reason told once.
    let r = &report.implausible;
    assert_eq!(r.obstacle_out_of_scale, 1, "{r:?}");
    let taken = log.iter().filter(|x| x["record"] == "obstacle").count() as u64;
    assert_eq!(taken + r.obstacle_rate, FLOOD as u64, "{r:?}");
    assert!((5..=8).contains(&taken), "{taken} of {FLOOD} taken at once");
    assert_eq!(kinds("obstacle_dropped"), 2);
    assert_eq!(r.total(), 1 + 1 + r.obstacle_rate, "{r:?}");
    assert!(
        shoal_coordinator::mission::run::execution_ok(&report),
        "{}",
        shoal_coordinator::mission::run::execution_summary(&report)
    );
    Ok(())
}
