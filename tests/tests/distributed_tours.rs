//! Inspection tours planned by the agents (Hu et al. 2023 with several AUVs): each agent derives its
//! share of the inspection points from the scenario and plans its own tour; the coordinator
//! assembles, times and checks the fleet's plan, and plans a lost agent's tour itself.

mod common;

use std::time::{Duration, Instant};

use common::fleet::{endpoint, free_port, Fleet};
use common::{check_plan_run, key, plan, scenario, TestResult};
use serde_json::Value;

const SCENARIO: &str = "cages-fleet";
const LIMIT: Duration = Duration::from_secs(90);

fn degraded(json: &Value) -> Vec<String> {
    key(json, "distributed.degraded")
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|d| d["vehicle"].as_str().map(str::to_string))
        .collect()
}

#[test]
fn agents_plan_their_own_tours_and_match_the_in_process_plan() -> TestResult {
    let budget = ["--iterations", "60", "--particles", "20", "--seed", "2"];
    let mut fleet = Fleet::new();
    let out = fleet.dir().join("out");
    let c = fleet.coordinator("coordinator", SCENARIO, &out, &budget);
    let r = fleet.wait(c, Instant::now() + LIMIT);
    let json = check_plan_run(SCENARIO, &out, &r)?;
    assert_eq!(key(&json, "mode"), "distributed");
    assert_eq!(key(&json, "feasible").as_bool(), Some(true));
    assert!(degraded(&json).is_empty(), "{}", key(&json, "distributed"));
    assert_eq!(key(&json, "distributed.messages_dropped").as_u64(), Some(0));
    // The shares and seeds follow from the scenario: the agents' tours are the ones this
    // process would plan.
    let dir = tempfile::tempdir()?;
    let local = plan(&scenario(SCENARIO), dir.path(), &budget);
    let local = check_plan_run(SCENARIO, dir.path(), &local)?;
    for k in 0..2 {
        assert_eq!(
            json["vehicles"][k]["trajectory"], local["vehicles"][k]["trajectory"],
            "vehicle {k}"
        );
        assert_eq!(json["vehicles"][k]["tour"], local["vehicles"][k]["tour"]);
    }
    // The agents' evaluations come up with their tours: the same count as planning here.
    assert!(key(&json, "evaluations").as_u64().is_some_and(|n| n > 0));
    assert_eq!(key(&json, "evaluations"), key(&local, "evaluations"));
    // The convergence curve comes up with them too: one entry per leg-swarm iteration, and one
    // for the legs' refinement.
    assert_eq!(key(&json, "convergence").as_array().map(Vec::len), Some(61));
    assert_eq!(key(&json, "convergence"), key(&local, "convergence"));
    fleet.passed();
    Ok(())
}

#[test]
fn a_lost_agents_tour_is_planned_by_the_coordinator() -> TestResult {
    let mut fleet = Fleet::new();
    let out = fleet.dir().join("out");
    let port = free_port();
    let listen = endpoint(port);
    // A budget that keeps auv2's agent busy for seconds, so it can be killed mid-tour.
    let c = fleet.coordinator(
        "coordinator",
        SCENARIO,
        &out,
        &[
            "--agents",
            "external",
            "--listen",
            listen.as_str(),
            "--mission",
            "e2e-tours",
            "--iterations",
            "1500",
            "--particles",
            "40",
        ],
    );
    fleet.wait_for_stderr(c, "waiting up to", Instant::now() + LIMIT);
    let _a1 = fleet.agent("auv1", &listen, &["--once"]);
    let a2 = fleet.agent("auv2", &listen, &["--once"]);
    fleet.wait_for_stderr(a2, "planning auv2", Instant::now() + LIMIT);
    fleet.kill(a2);
    let r = fleet.wait(c, Instant::now() + Duration::from_secs(240));
    let json = check_plan_run(SCENARIO, &out, &r)?;
    assert_eq!(key(&json, "mode"), "distributed");
    assert_eq!(degraded(&json), ["auv2"], "{}", key(&json, "distributed"));
    let notices = key(&json, "notices").to_string();
    assert!(
        notices.contains("auv2's tour was planned by the coordinator"),
        "{notices}"
    );
    // The plan is still whole: every cage point is visited (the checker checks coverage).
    assert_eq!(key(&json, "feasible").as_bool(), Some(true));
    fleet.passed();
    Ok(())
}
