//! A measurement, not part of the suite (`#[ignore]`): replan the crossing of
//! `reactions.rs`'s predicted-conflict test (auv2 gives way to auv1 at (1000, 1000)) for many
//! seeds under a short budget, and fly each answer with the simulator, as auv2's agent would.
//! Every answer must be flown to an arrival within 10 s of its planned 1200 s. Run with
//! `cargo test -p shoal-coordinator --test replans_flown -- --ignored --nocapture`;
//! `SHOAL_REPLANS` (default 100) and `SHOAL_REPLAN_BUDGET_MS` (default 50) set the count and
//! the budget. Before the simulator's capture radius, seed 23 at 50 ms circled its end point.

use std::path::Path;
use std::time::Duration;

use shoal_common::execution::sim::{SimModel, SimSettings, Simulator};
use shoal_common::execution::VehicleStatus;
use shoal_common::geometry::Vec3;
use shoal_common::scenario::Scenario;
use shoal_common::trajectory::Trajectory;
use shoal_coordinator::execute::replan::{replan, Request};

type TestResult = Result<(), Box<dyn std::error::Error>>;

fn env_or(name: &str, default: u64) -> Result<u64, String> {
    std::env::var(name).map_or(Ok(default), |v| {
        v.parse().map_err(|e| format!("{name}={v:?}: {e}"))
    })
}

#[test]
#[ignore = "a measurement: cargo test --test replans_flown -- --ignored --nocapture"]
fn every_replanned_crossing_is_flown_to_an_arrival_on_time() -> TestResult {
    let mut text = String::from(
        "name = \"reactions\"\n[bounds]\nmin = [0.0, 0.0, 0.0]\nmax = [2000.0, 2000.0, 400.0]\n\
         [fleet]\nd_min_m = 50.0\nmission_time_s = 1200.0\n[optimizer]\nwaypoints = 8\n",
    );
    let legs = [
        ("auv1", [100.0, 1000.0, 200.0], [1900.0, 1000.0, 200.0]),
        ("auv2", [1000.0, 100.0, 200.0], [1000.0, 1900.0, 200.0]),
    ];
    for (id, start, goal) in legs {
        text.push_str(&format!(
            "[[vehicles]]\nid = \"{id}\"\nkind = \"auv\"\nstart = {start:?}\ngoal = {goal:?}\n\
             speed_min_mps = 0.5\nspeed_max_mps = 2.5\nmax_turn_deg = 35.0\nmax_pitch_deg = 20.0\n"
        ));
    }
    let s = Scenario::parse(&text, Path::new("crossing.toml"))?;
    // 1800 m at 1.5 m/s: both reach (1000, 1000) at t = 600 s.
    let plans: Vec<Trajectory> = legs
        .iter()
        .map(|(_, a, b)| Trajectory {
            times: vec![0.0, 1200.0],
            points: vec![Vec3::from(*a), Vec3::from(*b)],
        })
        .collect();
    let (n, budget) = (
        env_or("SHOAL_REPLANS", 100)?,
        env_or("SHOAL_REPLAN_BUDGET_MS", 50)?,
    );
    let mut late = Vec::new();
    for seed in 0..n {
        // The update starts 50 s after the conflict is seen at t ≈ 396–399 s (reactions.rs).
        let t0 = 446.0 + (seed % 5) as f64;
        let out = replan(&Request {
            scenario: &s,
            vehicle: 1,
            t0,
            p0: plans[1].position_at(t0),
            heading: Some(Vec3::new(0.0, 1.0, 0.0)),
            current: &plans[1],
            resume_s: None,
            others: &plans,
            arrival_s: 1200.0,
            budget: Duration::from_millis(budget),
            separation_buffer_m: 10.0,
            seed,
            ground: None,
            stop: None,
        });
        let plan = plans[1].followed_by(&out.trajectory);
        let model = SimModel::Auv {
            current: None,
            surface_z: 400.0,
        };
        let mut sim = Simulator::new(&s.vehicles[1], model, SimSettings::default());
        sim.load(plan);
        let mut t = 0.0;
        while t < 1500.0 && sim.status() != VehicleStatus::Arrived {
            t += 1.0;
            sim.advance_to(t);
        }
        let arrived = sim.state().arrived_s;
        if !arrived.is_some_and(|a| a <= 1210.0) {
            late.push((seed, arrived, out.trajectory.points));
        }
    }
    eprintln!(
        "{} of {n} replans ({budget} ms) flown late or never",
        late.len()
    );
    assert!(late.is_empty(), "{late:?}");
    Ok(())
}
