//! Distributed planning end to end: the real `shoal-coordinator` and `shoal-agent` binaries on
//! free loopback ports, one log per process (printed when a test fails), every wait bounded.
//!
//! CLI contract under test: `shoal-coordinator plan <SCENARIO> --out DIR` without `--in-process`
//! plans over Zenoh with one agent per vehicle, started by the coordinator (`--agents embedded`,
//! logs in `DIR/logs/<vehicle>.log`) or separately (`--agents external --listen tcp/HOST:PORT`,
//! `shoal-agent --vehicle ID --connect tcp/HOST:PORT [--once]`). `plan.json` then has
//! `"mode": "distributed"` and a `distributed` object (mission, exchanges, messages_dropped,
//! agents[], degraded[], rounds: the coordinator's time per round); a vehicle whose agent is lost is planned by the coordinator
//! ("degraded") and a notice says so.

mod common;

use std::error::Error;
use std::process::Command;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc};
use std::thread;
use std::time::{Duration, Instant};

use common::fleet::{endpoint, free_port, Fleet, Handle};
use common::{check_plan_run, coordinator, key, number, without_shoal_env, TestResult};
use serde_json::Value;
use shoal_common::wire::PROTOCOL_VERSION;
use zenoh::Wait;

/// Three AUVs; a distributed plan at the default budget takes about 2 s in a debug build.
const SCENARIO: &str = "amp-pso-2";
const VEHICLES: [&str; 3] = ["auv1", "auv2", "auv3"];

/// Longest a test waits for anything (a plan, a log line); far above what they need.
const LIMIT: Duration = Duration::from_secs(60);

fn deadline() -> Instant {
    Instant::now() + LIMIT
}

/// Starts a coordinator in external mode on `port` for `mission` and waits until its router is
/// up (it says it is waiting for the agents), so agents and test clients connect at once.
fn external_coordinator(
    fleet: &mut Fleet,
    name: &str,
    out: &std::path::Path,
    port: u16,
    mission: &str,
    extra: &[&str],
) -> Handle {
    let listen = endpoint(port);
    let mut args = vec![
        "--agents",
        "external",
        "--listen",
        listen.as_str(),
        "--mission",
        mission,
    ];
    args.extend_from_slice(extra);
    let c = fleet.coordinator(name, SCENARIO, out, &args);
    fleet.wait_for_stderr(c, "waiting up to", deadline());
    c
}

/// Starts `shoal-coordinator router` on `hub` and waits until it listens.
fn start_hub(fleet: &mut Fleet, hub: &str) {
    let mut cmd = Command::new(coordinator());
    without_shoal_env(&mut cmd);
    cmd.args(["router", "--listen", hub]);
    let router = fleet.spawn("router", cmd);
    fleet.wait_for_stderr(router, "router listening", deadline());
}

/// `distributed.agents[]` entry of `vehicle`.
fn agent_figures<'a>(json: &'a Value, vehicle: &str) -> &'a Value {
    let agents = key(json, "distributed.agents");
    let Some(list) = agents.as_array() else {
        panic!("distributed.agents is not an array: {agents}");
    };
    match list.iter().find(|a| a["vehicle"] == vehicle) {
        Some(a) => a,
        None => panic!("distributed.agents has no entry for {vehicle}: {agents}"),
    }
}

/// Vehicles named in `distributed.degraded`.
fn degraded(json: &Value) -> Vec<String> {
    let d = key(json, "distributed.degraded");
    let Some(list) = d.as_array() else {
        panic!("distributed.degraded is not an array: {d}");
    };
    list.iter()
        .map(|x| match x["vehicle"].as_str() {
            Some(v) => v.to_string(),
            None => panic!("a degraded entry has no vehicle: {d}"),
        })
        .collect()
}

/// Notices that say a vehicle was degraded.
fn degraded_notices(json: &Value) -> Vec<String> {
    key(json, "notices")
        .as_array()
        .map(|n| {
            n.iter()
                .filter_map(Value::as_str)
                .filter(|s| s.contains("degraded"))
                .map(str::to_string)
                .collect()
        })
        .unwrap_or_default()
}

/// The figures of a distributed plan of [`SCENARIO`] for `mission` where every agent planned
/// its vehicle to the end: three agents, an elite message per exchange from each, none degraded.
fn assert_every_agent_planned(json: &Value, mission: Option<&str>) {
    assert_eq!(key(json, "mode"), "distributed");
    let m = key(json, "distributed.mission");
    match mission {
        Some(id) => assert_eq!(m, id, "mission id"),
        None => assert!(m.as_str().is_some_and(|s| !s.is_empty()), "mission id {m}"),
    }
    // First, as the degraded entries say why an agent was lost.
    assert!(
        degraded(json).is_empty(),
        "vehicles were degraded: {}",
        key(json, "distributed")
    );
    assert!(
        degraded_notices(json).is_empty(),
        "{:?}",
        key(json, "notices")
    );
    let exchanges = number(json, "distributed.exchanges");
    assert!(
        exchanges > 0.0,
        "no exchanges: {}",
        key(json, "distributed")
    );
    // Every exchange is a round the coordinator timed: waiting for the elites, and its step.
    assert_eq!(number(json, "distributed.rounds.rounds"), exchanges);
    let collect = number(json, "distributed.rounds.collect_s");
    let leader = number(json, "distributed.rounds.leader_s");
    let cpu = number(json, "distributed.rounds.coordinator_cpu_s");
    assert!(
        collect > 0.0 && leader > 0.0 && cpu >= 0.0,
        "{}",
        key(json, "distributed.rounds")
    );
    let agents = key(json, "distributed.agents");
    assert_eq!(
        agents.as_array().map(Vec::len),
        Some(VEHICLES.len()),
        "{agents}"
    );
    for v in VEHICLES {
        let a = agent_figures(json, v);
        assert_eq!(a["elites_sent"].as_f64(), Some(exchanges), "{v}: {a}");
        assert_eq!(a["degraded"], false, "{v}: {a}");
        assert!(
            a["messages_dropped"].is_u64(),
            "{v}: its agent must report its dropped messages: {a}"
        );
    }
}

/// The default: `plan` without `--in-process` starts one agent per vehicle itself.
#[test]
fn embedded_agents_plan_scenario_2() -> TestResult {
    let mut fleet = Fleet::new();
    let out = fleet.dir().join("out");
    for v in VEHICLES {
        fleet.watch(out.join("logs").join(format!("{v}.log")));
    }
    let c = fleet.coordinator("coordinator", SCENARIO, &out, &["--seed", "1"]);
    let r = fleet.wait(c, deadline());
    let json = check_plan_run(SCENARIO, &out, &r)?;
    assert_every_agent_planned(&json, None);
    assert_eq!(
        number(&json, "distributed.messages_dropped"),
        0.0,
        "{}",
        key(&json, "distributed")
    );
    for v in VEHICLES {
        let a = agent_figures(&json, v);
        assert_eq!(a["messages_dropped"], 0, "{v}: {a}");
        assert_eq!(
            a["iterations"],
            key(&json, "iterations").clone(),
            "{v}: {a}"
        );
        let log = out.join("logs").join(format!("{v}.log"));
        assert!(log.is_file(), "no agent log {}", log.display());
    }
    fleet.passed();
    Ok(())
}

/// An agent killed mid-plan (SIGKILL: no goodbye) is planned by the coordinator from then on;
/// the plan is still whole and says so.
#[test]
fn a_killed_agent_is_planned_by_the_coordinator() -> TestResult {
    let mut fleet = Fleet::new();
    let out = fleet.dir().join("out");
    let port = free_port();
    let c = external_coordinator(
        &mut fleet,
        "coordinator",
        &out,
        port,
        "e2e-kill",
        &["--seed", "1", "--iterations", "400", "--round-timeout", "3"],
    );
    let agents: Vec<Handle> = VEHICLES
        .iter()
        .map(|v| fleet.agent(v, &endpoint(port), &["--once"]))
        .collect();
    // Planning has begun once a progress line is out.
    fleet.wait_for_stderr(c, "iteration ", deadline());
    fleet.kill(agents[1]);
    let r = fleet.wait(c, deadline());
    let json = check_plan_run(SCENARIO, &out, &r)?;
    assert_eq!(key(&json, "mode"), "distributed");
    assert_eq!(key(&json, "distributed.mission"), "e2e-kill");
    assert_eq!(
        degraded(&json),
        ["auv2"],
        "{}",
        key(&json, "distributed.degraded")
    );
    for v in VEHICLES {
        let a = agent_figures(&json, v);
        assert_eq!(a["degraded"], v == "auv2", "{v}: {a}");
    }
    let notices = degraded_notices(&json);
    assert!(
        notices.iter().any(|n| n.contains("auv2")),
        "no notice says auv2 was degraded: {:?}",
        key(&json, "notices")
    );
    assert!(
        notices
            .iter()
            .all(|n| !n.contains("auv1") && !n.contains("auv3")),
        "only auv2 was degraded: {notices:?}"
    );
    let vehicles = key(&json, "vehicles");
    for v in VEHICLES {
        let trajectory = vehicles
            .as_array()
            .and_then(|vs| vs.iter().find(|x| x["id"] == v))
            .and_then(|x| x["trajectory"].as_array());
        assert!(
            trajectory.is_some_and(|t| t.len() >= 2),
            "{v} has no trajectory: {vehicles}"
        );
    }
    fleet.passed();
    Ok(())
}

/// Bytes that are not a message: a fixed pseudo-random stream (xorshift), so a failure can be
/// replayed; 1 to 64 bytes.
fn random_bytes(state: &mut u64) -> Vec<u8> {
    let mut next = || {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        *state
    };
    let n = 1 + (next() % 64) as usize;
    (0..n).map(|_| (next() & 0xff) as u8).collect()
}

/// bincode 1.3.3 (fixint, little endian) of a string: u64 length, then the bytes.
fn bincode_str(s: &str) -> Vec<u8> {
    [&(s.len() as u64).to_le_bytes()[..], s.as_bytes()].concat()
}

/// A well-formed message of the next protocol version: were its version this build's, it would
/// be a `CoordinatorToAgent::Stop` of `mission` (variant 3) — a receiver that ignored the
/// version would end the mission early — and on an agent's `out` key it would read as a
/// `AgentToCoordinator::Joined` (variant 2) claiming `vehicle`.
fn wrong_version(mission: &str, to_agent: bool, vehicle: &str) -> Vec<u8> {
    let mut m = (PROTOCOL_VERSION + 1).to_le_bytes().to_vec();
    m.extend_from_slice(&1u64.to_le_bytes());
    if to_agent {
        m.extend_from_slice(&3u32.to_le_bytes());
        m.extend(bincode_str(mission));
        m.extend(bincode_str("from a future protocol"));
    } else {
        m.extend_from_slice(&2u32.to_le_bytes());
        m.extend(bincode_str(mission));
        m.extend(bincode_str(vehicle));
    }
    m
}

/// This build's version and an order number, then an enum variant no message has: malformed
/// for any reader of this version.
fn malformed_this_version(state: &mut u64) -> Vec<u8> {
    [
        &PROTOCOL_VERSION.to_le_bytes()[..],
        &[1, 0, 0, 0, 0, 0, 0, 0],
        &[0xff, 0xff, 0xff, 0xff],
        &random_bytes(state),
    ]
    .concat()
}

/// Publishes garbage on `keys` every 50 ms from an independent Zenoh client of `endpoint` until
/// `stop`; sends back how many messages went out (or why it failed).
fn publish_garbage(
    endpoint: String,
    mission: String,
    keys: Vec<(String, bool)>,
    stop: Arc<AtomicBool>,
) -> mpsc::Receiver<Result<u64, String>> {
    let (tx, rx) = mpsc::channel();
    thread::spawn(move || {
        let run = || -> Result<u64, Box<dyn Error + Send + Sync>> {
            let mut c = zenoh::Config::default();
            c.insert_json5("mode", "\"client\"")?;
            c.insert_json5("connect/endpoints", &format!("[\"{endpoint}\"]"))?;
            c.insert_json5("scouting/multicast/enabled", "false")?;
            let session = zenoh::open(c).wait()?;
            let mut state = 0x9e37_79b9_7f4a_7c15_u64;
            let mut sent = 0u64;
            while !stop.load(Ordering::Relaxed) {
                for (k, to_agent) in &keys {
                    for bytes in [
                        random_bytes(&mut state),
                        malformed_this_version(&mut state),
                        wrong_version(&mission, *to_agent, "auv1"),
                    ] {
                        session.put(k.as_str(), bytes).wait()?;
                        sent += 1;
                    }
                }
                thread::sleep(Duration::from_millis(50));
            }
            session.close().wait()?;
            Ok(sent)
        };
        let _ = tx.send(run().map_err(|e| e.to_string()));
    });
    rx
}

/// Raises its flag when dropped.
struct StopOnDrop(Arc<AtomicBool>);

impl Drop for StopOnDrop {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Relaxed);
    }
}

/// Random bytes and another protocol version's messages on the mission's keys, in both
/// directions and on the fleet key, all through the plan: dropped and counted on both sides,
/// and the plan is as if they never came.
#[test]
fn garbage_and_wrong_versions_are_dropped_and_counted() -> TestResult {
    let mission = "e2e-garbage";
    let mut fleet = Fleet::new();
    let out = fleet.dir().join("out");
    let port = free_port();
    let c = external_coordinator(
        &mut fleet,
        "coordinator",
        &out,
        port,
        mission,
        &["--seed", "2"],
    );
    let stop = Arc::new(AtomicBool::new(false));
    // Stops the publisher however this test ends.
    let _stop = StopOnDrop(Arc::clone(&stop));
    let published = publish_garbage(
        endpoint(port),
        mission.to_string(),
        vec![
            (format!("shoal/{mission}/vehicle/auv1/out"), false),
            (format!("shoal/{mission}/vehicle/auv1/in"), true),
            (format!("shoal/{mission}/fleet"), true),
        ],
        Arc::clone(&stop),
    );
    for v in VEHICLES {
        fleet.agent(v, &endpoint(port), &["--once"]);
    }
    let r = fleet.wait(c, deadline());
    stop.store(true, Ordering::Relaxed);
    let sent = match published.recv_timeout(Duration::from_secs(10)) {
        Ok(Ok(n)) => n,
        Ok(Err(e)) => panic!("the test's Zenoh client failed: {e}\n{r}"),
        Err(_) => panic!("the test's Zenoh client did not stop within 10 s\n{r}"),
    };
    assert!(sent > 0, "no garbage went out");
    let json = check_plan_run(SCENARIO, &out, &r)?;
    assert_every_agent_planned(&json, Some(mission));
    let dropped = number(&json, "distributed.messages_dropped");
    assert!(
        dropped > 0.0,
        "the coordinator counted no dropped message ({sent} sent): {}",
        key(&json, "distributed")
    );
    // auv1's inbox and the fleet key reached auv1; the fleet key reached every agent.
    for v in VEHICLES {
        let a = agent_figures(&json, v);
        assert!(
            a["messages_dropped"].as_u64().is_some_and(|n| n > 0),
            "the agent of {v} counted no dropped message ({sent} sent): {a}"
        );
    }
    fleet.passed();
    Ok(())
}

/// Two coordinators plan two missions at once through one Zenoh router (`shoal-coordinator
/// router`, a hub that outlives missions) with the same three agents, which connect to the hub
/// only. Each coordinator's own router links to the hub.
#[test]
fn two_missions_share_one_router_and_its_agents() -> TestResult {
    let mut fleet = Fleet::new();
    let (out_a, out_b) = (fleet.dir().join("out-a"), fleet.dir().join("out-b"));
    let (hub, p, q) = (free_port(), free_port(), free_port());
    let hub = endpoint(hub);
    start_hub(&mut fleet, &hub);
    let a = external_coordinator(
        &mut fleet,
        "coordinator-a",
        &out_a,
        p,
        "e2e-a",
        &["--seed", "1", "--router", hub.as_str()],
    );
    let b = external_coordinator(
        &mut fleet,
        "coordinator-b",
        &out_b,
        q,
        "e2e-b",
        &["--seed", "2", "--router", hub.as_str()],
    );
    let agents: Vec<Handle> = VEHICLES.iter().map(|v| fleet.agent(v, &hub, &[])).collect();
    let until = deadline();
    let ra = fleet.wait(a, until);
    let rb = fleet.wait(b, until);
    for (name, mission, out, r) in [("A", "e2e-a", &out_a, &ra), ("B", "e2e-b", &out_b, &rb)] {
        let json = check_plan_run(SCENARIO, out, r)?;
        assert_every_agent_planned(&json, Some(mission));
        assert_eq!(
            number(&json, "distributed.messages_dropped"),
            0.0,
            "coordinator {name}: {}",
            key(&json, "distributed")
        );
        for v in VEHICLES {
            let f = agent_figures(&json, v);
            assert_eq!(f["messages_dropped"], 0, "coordinator {name}, {v}: {f}");
        }
    }
    // Without --once the agents serve on after both missions.
    for (v, h) in VEHICLES.iter().zip(agents) {
        assert!(fleet.running(h), "the agent of {v} exited");
    }
    fleet.passed();
    Ok(())
}

/// External mode with agents missing: an error naming the vehicles without one, and no plan.
#[test]
fn missing_agents_are_named() -> TestResult {
    let mut fleet = Fleet::new();
    let out = fleet.dir().join("out");
    let port = free_port();
    let c = external_coordinator(
        &mut fleet,
        "coordinator",
        &out,
        port,
        "e2e-missing",
        &["--join-timeout", "3"],
    );
    fleet.agent("auv1", &endpoint(port), &["--once"]);
    let r = fleet.wait(c, deadline());
    assert_eq!(r.code(), Some(1), "expected exit 1 (error):\n{r}");
    let error = r
        .stderr
        .lines()
        .find(|l| l.starts_with("error:"))
        .unwrap_or_else(|| panic!("no error line on stderr:\n{r}"));
    assert!(
        error.contains("auv2") && error.contains("auv3"),
        "the error must name auv2 and auv3:\n{r}"
    );
    assert!(
        !error.contains("auv1"),
        "auv1's agent was there; the error must not blame it:\n{r}"
    );
    assert!(
        !out.join("plan.json").exists(),
        "a plan was written without agents:\n{r}"
    );
    fleet.passed();
    Ok(())
}

/// A coordinator killed mid-plan: its agents, connected through a hub router, abandon the
/// mission at once (the hub tells them the coordinator's liveliness token is gone) instead of
/// waiting out their idle timeout, and keep serving. (Agents connected to the killed
/// coordinator's own router lose their router with it and fall back on `--idle-timeout`.)
#[test]
fn agents_abandon_the_mission_of_a_killed_coordinator() -> TestResult {
    let mut fleet = Fleet::new();
    let out = fleet.dir().join("out");
    let (hub, port) = (endpoint(free_port()), free_port());
    start_hub(&mut fleet, &hub);
    let c = external_coordinator(
        &mut fleet,
        "coordinator",
        &out,
        port,
        "e2e-orphan",
        &["--iterations", "4000", "--router", hub.as_str()],
    );
    let agents: Vec<Handle> = VEHICLES
        .iter()
        .map(|v| fleet.agent(v, &hub, &["--idle-timeout", "60"]))
        .collect();
    fleet.wait_for_stderr(c, "iteration ", deadline());
    fleet.kill(c);
    // Well before the 60 s idle timeout.
    let soon = Instant::now() + Duration::from_secs(15);
    for &a in &agents {
        fleet.wait_for_stderr(a, "its coordinator left the network", soon);
    }
    for (v, &a) in VEHICLES.iter().zip(&agents) {
        assert!(fleet.running(a), "the agent of {v} exited");
    }
    fleet.passed();
    Ok(())
}
