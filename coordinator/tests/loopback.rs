//! The coordinator and its agents over real Zenoh sessions on loopback, all in this process:
//! the agents are `shoal_agent::run` on threads, the coordinator `plan_distributed` in external
//! mode. Every wait is bounded.

mod common;

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::sync::Arc;
use std::time::Duration;

use common::{agent, finish, free_endpoint, Agent, TestResult};
use shoal_common::distributed::lockstep;
use shoal_common::plan::Plan;
use shoal_common::scenario::Scenario;
use shoal_coordinator::distributed::{
    plan_distributed, plan_strips_distributed, AgentsMode, DistributedOptions,
};

/// Longest any test waits for a plan.
const LIMIT: Duration = Duration::from_secs(90);

/// Scenario 2 (three AUVs) with a budget small enough for a debug build.
fn scenario() -> Result<Scenario, Box<dyn std::error::Error>> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenarios/amp-pso-2.toml");
    let mut s = Scenario::load(&path)?;
    s.optimizer.iterations = 16;
    s.optimizer.particles = 12;
    s.optimizer.leader_particles = 4;
    s.optimizer.distributed.agent_populations = 3;
    s.optimizer.distributed.context_every = 2;
    // Rounds of 3, 3, 3, 3, 3 and 1 iterations.
    s.optimizer.distributed.exchange_every = 3;
    // The plans are compared with the lockstep reference's best, which is the swarm's own: no
    // touch-up or refinement after it (this small budget leaves violations the touch-up would
    // work on, and paths the refinement would pull tight).
    s.optimizer.touch_up = false;
    s.optimizer.refine = false;
    Ok(s)
}

fn options(mission: &str, endpoint: &str, join_s: u64) -> DistributedOptions {
    DistributedOptions {
        mission: mission.into(),
        agents: AgentsMode::External,
        listen: vec![endpoint.into()],
        routers: vec![],
        security: Default::default(),
        join_timeout: Duration::from_secs(join_s),
        round_timeout: Duration::from_secs(10),
        agent_bin: None,
        log_dir: std::env::temp_dir(),
        health_file: None,
        agent_args: Vec::new(),
    }
}

/// One agent per vehicle of scenario 2.
fn fleet_agents(endpoint: &str) -> Vec<Agent> {
    ["auv1", "auv2", "auv3"]
        .iter()
        .map(|v| agent(v, endpoint))
        .collect()
}

/// Runs the coordinator on a thread and waits for it at most [`LIMIT`]; `on_iteration` sees
/// every round's iteration count.
fn coordinate(
    s: &Scenario,
    o: DistributedOptions,
    on_iteration: impl Fn(usize) + Send + 'static,
) -> Result<anyhow::Result<Plan>, String> {
    let (tx, rx) = mpsc::channel();
    let s = s.clone();
    std::thread::spawn(move || {
        let stop = Arc::new(AtomicBool::new(false));
        let plan = plan_distributed(&s, &o, &stop, &mut |st| on_iteration(st.iteration));
        let _ = tx.send(plan);
    });
    rx.recv_timeout(LIMIT)
        .map_err(|_| format!("no plan within {LIMIT:?}"))
}

#[test]
fn agents_over_loopback_give_the_lockstep_plan() -> TestResult {
    let s = scenario()?;
    let endpoint = free_endpoint()?;
    // Agents first: they wait for the coordinator's router.
    let agents = fleet_agents(&endpoint);
    let plan = coordinate(&s, options("loopback-same", &endpoint, 30), |_| {})??;
    finish(agents)?;
    let reference = lockstep::run(&s, None, &mut |_| {});
    assert!(
        (plan.fitness - reference.best_cost).abs() < 1e-12,
        "distributed {} vs lockstep {}",
        plan.fitness,
        reference.best_cost
    );
    assert_eq!(plan.mode, "distributed");
    assert_eq!(plan.convergence, reference.convergence);
    let d = plan.distributed.ok_or("no distributed figures")?;
    assert_eq!(d.mission, "loopback-same");
    assert_eq!(d.exchanges, 6);
    assert_eq!(d.messages_dropped, 0);
    assert!(d.degraded.is_empty(), "{:?}", d.degraded);
    for a in &d.agents {
        assert_eq!((a.iterations, a.elites_sent), (16, 6), "{a:?}");
        assert_eq!(a.messages_dropped, Some(0), "{a:?}");
        assert!(!a.degraded);
    }
    Ok(())
}

#[test]
fn a_lost_agent_is_planned_by_the_coordinator() -> TestResult {
    let s = scenario()?;
    let endpoint = free_endpoint()?;
    let agents = fleet_agents(&endpoint);
    // auv2's agent shuts down once the coordinator reports iteration 5 (the end of round 1).
    let auv2 = Arc::clone(&agents[1].stop);
    let plan = coordinate(&s, options("loopback-lost", &endpoint, 30), move |it| {
        if it >= 5 {
            auv2.store(true, Ordering::Relaxed);
        }
    })??;
    finish(agents)?;
    let d = plan.distributed.as_ref().ok_or("no distributed figures")?;
    let names: Vec<&str> = d.degraded.iter().map(|x| x.vehicle.as_str()).collect();
    assert_eq!(names, ["auv2"], "{:?}", d.degraded);
    assert!(d.degraded[0].from_round >= 2, "{:?}", d.degraded);
    assert!(
        plan.notices
            .iter()
            .any(|n| n.contains("auv2") && n.contains("degraded")),
        "{:?}",
        plan.notices
    );
    // Every vehicle still has a whole plan and every iteration ran.
    assert_eq!(plan.vehicles.len(), 3);
    assert!(
        d.agents.iter().all(|a| a.iterations == 16),
        "{:?}",
        d.agents
    );
    assert_eq!(plan.convergence.len(), 16);
    assert!(plan.fitness.is_finite());
    Ok(())
}

/// The leader keeps its best after every sweep of the adaptive schedule and the coordinator
/// finishes each (touch-up and refinement, as a plan ends): two sweeps never end worse than
/// one, whose run they repeat before going on.
#[test]
fn a_longer_distributed_budget_never_finishes_worse() -> TestResult {
    let mut s = scenario()?;
    (s.optimizer.touch_up, s.optimizer.refine) = (true, true);
    s.optimizer.distributed.exchange_every = 25;
    let sweep = shoal_coordinator::planning::finish::CHECKPOINT_EVERY;
    let mut fitness = Vec::new();
    for (k, iterations) in [sweep, 2 * sweep].into_iter().enumerate() {
        s.optimizer.iterations = iterations;
        let endpoint = free_endpoint()?;
        let agents = fleet_agents(&endpoint);
        let mission = format!("loopback-sweeps-{k}");
        let plan = coordinate(&s, options(&mission, &endpoint, 30), |_| {})??;
        finish(agents)?;
        assert_eq!(plan.convergence.last(), Some(&plan.fitness));
        fitness.push(plan.fitness);
    }
    assert!(fitness[1] <= fitness[0] + 1e-12, "{fitness:?}");
    Ok(())
}

#[test]
fn agents_that_never_join_are_named() -> TestResult {
    let s = scenario()?;
    let endpoint = free_endpoint()?;
    let agents = vec![agent("auv1", &endpoint)];
    let outcome = coordinate(&s, options("loopback-missing", &endpoint, 2), |_| {})?;
    finish(agents)?;
    let e = match outcome {
        Ok(_) => return Err("planned without agents".into()),
        Err(e) => e.to_string(),
    };
    assert!(e.contains("auv2") && e.contains("auv3"), "{e}");
    assert!(!e.contains("auv1,") && !e.contains("auv1 "), "{e}");
    assert!(e.contains(&endpoint), "{e}");
    Ok(())
}

/// The cages fleet's inspection tours (two AUVs, a one-shot mission) with a debug-build budget.
fn tours() -> Result<Scenario, Box<dyn std::error::Error>> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenarios/cages-fleet.toml");
    let mut s = Scenario::load(&path)?;
    s.optimizer.iterations = 60;
    s.optimizer.particles = 20;
    Ok(s)
}

/// An agent of `vehicle` that is up for `hold` and gone again before it accepts anything: its
/// liveliness token only, as left behind by an agent killed just after it started planning,
/// before its `Joined` went out.
fn fleeting_agent(
    vehicle: &str,
    endpoint: &str,
    hold: Duration,
) -> std::thread::JoinHandle<anyhow::Result<()>> {
    use zenoh::Wait;
    let (vehicle, endpoint) = (vehicle.to_string(), endpoint.to_string());
    std::thread::spawn(move || {
        let config =
            shoal_common::wire::session::client_config(&[endpoint], true, &Default::default())?;
        let session = zenoh::open(config)
            .wait()
            .map_err(|e| anyhow::anyhow!("open: {e}"))?;
        let key = shoal_common::wire::topics::liveliness(&vehicle)?;
        let token = session
            .liveliness()
            .declare_token(key.as_str())
            .wait()
            .map_err(|e| anyhow::anyhow!("token: {e}"))?;
        std::thread::sleep(hold);
        drop(token);
        session
            .close()
            .wait()
            .map_err(|e| anyhow::anyhow!("close: {e}"))?;
        Ok(())
    })
}

#[test]
fn a_tour_agent_gone_before_it_joined_is_planned_by_the_coordinator() -> TestResult {
    let s = tours()?;
    let endpoint = free_endpoint()?;
    let agents = vec![agent("auv1", &endpoint)];
    let fleeting = fleeting_agent("auv2", &endpoint, Duration::from_secs(2));
    // Before the fix the fleet waited for auv2 to come back and failed after the join timeout.
    let plan = coordinate(&s, options("loopback-fleeting", &endpoint, 20), |_| {})??;
    finish(agents)?;
    match fleeting.join() {
        Ok(r) => r?,
        Err(_) => return Err("the fleeting agent's thread panicked".into()),
    }
    let d = plan.distributed.as_ref().ok_or("no distributed figures")?;
    let names: Vec<&str> = d.degraded.iter().map(|x| x.vehicle.as_str()).collect();
    assert_eq!(names, ["auv2"], "{:?}", d.degraded);
    assert!(
        plan.notices
            .iter()
            .any(|n| n.contains("auv2's tour was planned by the coordinator")),
        "{:?}",
        plan.notices
    );
    assert_eq!(plan.vehicles.len(), 2);
    assert!(plan.fitness.is_finite());
    Ok(())
}

#[test]
fn ctrl_c_in_a_tour_mission_ends_it_at_once_with_complete_tours() -> TestResult {
    // A budget that would take hours: the test ends only if the stop reaches every swarm, the
    // coordinator's and the agents'.
    let mut s = tours()?;
    s.optimizer.iterations = 1_000_000;
    if let Some(inspection) = s.inspection.as_mut() {
        inspection.order_iterations = 1_000_000;
    }
    let endpoint = free_endpoint()?;
    let agents = vec![agent("auv1", &endpoint), agent("auv2", &endpoint)];
    let o = options("loopback-tour-stop", &endpoint, 30);
    let (tx, rx) = mpsc::channel();
    let scenario = s.clone();
    std::thread::spawn(move || {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&stop);
        // The first status comes once both agents have joined and are planning: Ctrl-C then.
        let plan = plan_distributed(&scenario, &o, &stop, &mut |_| {
            flag.store(true, Ordering::Relaxed)
        });
        let _ = tx.send(plan);
    });
    let plan = rx
        .recv_timeout(LIMIT)
        .map_err(|_| format!("no plan within {LIMIT:?}"))??;
    assert_eq!(plan.termination, "Interrupted");
    assert!(
        plan.notices
            .iter()
            .any(|n| n.contains("planning was interrupted") && n.contains("auv1, auv2")),
        "{:?}",
        plan.notices
    );
    // The tours are the agents', cut short by the coordinator's Stop and sent as they stood:
    // none had to be planned by the coordinator.
    let d = plan.distributed.as_ref().ok_or("no distributed figures")?;
    assert!(d.degraded.is_empty(), "{:?}", d.degraded);
    assert!(plan.evaluations > 0);
    // Every inspection point is still visited by one of the two tours.
    let visited: usize = plan
        .vehicles
        .iter()
        .filter_map(|v| v.tour.as_ref())
        .map(|t| t.order.len())
        .sum();
    let points = 2 * s
        .inspection
        .as_ref()
        .map_or(0, |i| i.cage_indices(&s).len());
    assert!(points > 0);
    assert_eq!(visited, points);
    // The agents (one mission each) end by themselves: the coordinator's Stop cut their tours.
    let deadline = std::time::Instant::now() + Duration::from_secs(30);
    while agents.iter().any(|a| !a.handle.is_finished()) {
        if std::time::Instant::now() > deadline {
            finish(agents)?;
            return Err("an agent still planned its tour 30 s after the coordinator's Stop".into());
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    finish(agents)?;
    Ok(())
}

#[test]
fn ctrl_c_in_a_coverage_fleet_mission_cuts_the_agents_tracking_short() -> TestResult {
    // Three crawlers on a flat 600 m × 600 m, tracked. Untouched, each strip's tracking takes
    // seconds (a 300 m map takes 1.6 s for all three), far longer than the Stop needs to come:
    // the tracking must come back interrupted.
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenarios/cpp-fleet.toml");
    let mut s = Scenario::load(&path)?;
    s.bounds.max[0] = 600.0;
    s.bounds.max[1] = 600.0;
    // Each crawler from the west end of its 200 m strip to the east end.
    for (k, v) in s.vehicles.iter_mut().enumerate() {
        let y = 200.0 * k as f64;
        v.start = [5.0, y + 5.0, v.start[2]];
        v.goal = [595.0, y + 195.0, v.goal[2]];
    }
    let coverage = s.coverage.as_mut().ok_or("no [coverage]")?;
    coverage.terrain.size_m = [600.0, 600.0];
    // No seamounts or trenches: 8 of them on this small map leave some strips no row.
    coverage.terrain.random_peaks.count = 0;
    coverage.terrain.random_pits.count = 0;
    assert!(coverage.track);
    s.validate(&path)?;
    let job = shoal_common::coverage::fleet::FleetCoverage::new(&s)?;
    let map = job.map(std::path::Path::new("."))?;
    let endpoint = free_endpoint()?;
    let agents: Vec<Agent> = ["crawler1", "crawler2", "crawler3"]
        .iter()
        .map(|v| agent(v, &endpoint))
        .collect();
    let o = options("loopback-strip-stop", &endpoint, 30);
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&stop);
        // The first status comes once every agent has joined: Ctrl-C then.
        let plans = plan_strips_distributed(&s, job, map, &o, &stop, &mut |_| {
            flag.store(true, Ordering::Relaxed)
        });
        let _ = tx.send(plans);
    });
    let (plans, figures) = rx
        .recv_timeout(LIMIT)
        .map_err(|_| format!("no plan within {LIMIT:?}"))??;
    // The strips are the agents', planned whole, their tracking cut short by the Stop.
    assert!(figures.degraded.is_empty(), "{:?}", figures.degraded);
    assert_eq!(plans.len(), 3);
    for p in &plans {
        let t = p.report.tracking.as_ref().ok_or("not tracked")?;
        assert!(t.interrupted && !t.reached_end, "{t:?}");
        assert!(p.path.length() > 1000.0, "{}", p.path.length());
    }
    let deadline = std::time::Instant::now() + Duration::from_secs(30);
    while agents.iter().any(|a| !a.handle.is_finished()) {
        if std::time::Instant::now() > deadline {
            finish(agents)?;
            return Err(
                "an agent still tracked its strip 30 s after the coordinator's Stop".into(),
            );
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    finish(agents)?;
    Ok(())
}
