//! Zhang et al.'s single-AUV planners — EPA-PSO and its two baselines — behind the same `plan`
//! contract as the fleet planners: one optimizer run, then a timed trajectory assessed like any
//! other, plus the Zhang et al. 2022 figures.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use shoal_common::energy::problem::{EnergyProblem, Objective};
use shoal_common::plan::{assess, FleetFigures, Plan};
use shoal_common::refine::descent::{self, DescentSettings};
use shoal_common::scenario::{Algorithm, Scenario};
use shoal_common::swarm::catalog::{family, Family};
use shoal_common::swarm::{Executor, IterationReport, Termination};
use shoal_common::trajectory::Trajectory;

use crate::planning::solver::{run_algorithm, RunResult};
use crate::report::energy_gap;

/// The objective an algorithm plans with: the path length alone for Zhang et al.'s length
/// baseline, the full cost of eq. (6) otherwise.
pub fn objective_of(algorithm: Algorithm) -> Objective {
    match family(algorithm) {
        Family::Energy {
            path_length_only: true,
        } => Objective::Length,
        _ => Objective::Full,
    }
}

/// Plans the scenario's one AUV with the energy planner its settings name.
pub fn plan(
    scenario: &Scenario,
    stop: Option<Arc<AtomicBool>>,
    observe: &mut dyn FnMut(&IterationReport),
) -> Plan {
    let o = &scenario.optimizer;
    let problem = match EnergyProblem::new(scenario, 0, objective_of(o.algorithm)) {
        Ok(p) => p,
        Err(why) => return unplannable(scenario, why.to_string()),
    };
    let executor = Executor {
        max_iterations: o.iterations,
        stop,
        ..Executor::default()
    };
    let mut run = run_algorithm(&problem, o, &executor, observe);
    let refined = (o.refine && run.termination != Termination::Interrupted)
        .then(|| refine(&problem, &mut run, executor.stop.as_deref()))
        .flatten();
    let mut plan = to_plan(scenario, &problem, run);
    plan.notices.extend(refined);
    if let Some(terms) = plan.vehicles.first().and_then(|v| v.energy) {
        let id = &scenario.vehicles[0].id;
        plan.notices.push(energy_gap::notice(id, &problem, &terms));
    }
    plan
}

/// The share by which the refinement widens the turning radius it keeps: pressed against R_AUV
/// itself, the simulated AUV swung up to 12 m wide where the surface current crossed its turns
/// (p95 cross-track 9.8 m against 4.4 m on the swarm's plan).
const TURN_RADIUS_MARGIN: f64 = 0.1;

/// Descends from the swarm's best on the same cost ([`descent`]); when that lowers it, the run
/// ends there (its curve gains the last point) and the notice says what changed.
fn refine(
    problem: &EnergyProblem,
    run: &mut RunResult,
    stop: Option<&AtomicBool>,
) -> Option<String> {
    let started = std::time::Instant::now();
    let before = problem.evaluate(&run.best_x);
    // As many evaluations as the swarm made: the refinement at most doubles the plan's work.
    let settings = DescentSettings {
        max_evaluations: usize::try_from(run.evaluations).unwrap_or(usize::MAX),
        ..DescentSettings::default()
    };
    // The descent presses the path against the limits it trades with; on a turn radius of its
    // own a tenth wider, the vehicle keeps room to hold its track in the current.
    let mut margined = problem.clone();
    margined.model.min_turn_radius_m *= 1.0 + TURN_RADIUS_MARGIN;
    let d = descent::descend(&margined, &run.best_x, &settings, stop);
    run.evaluations += d.evaluations as u64;
    run.runtime_s += started.elapsed().as_secs_f64();
    let after = problem.evaluate(&d.x);
    if after.cost >= before.cost {
        return None;
    }
    run.best_x = d.x;
    run.convergence.push(after.cost);
    let (b, a) = (&before.terms, &after.terms);
    Some(format!(
        "refinement: {} local steps after the swarm lowered the cost {:.4} -> {:.4}: energy \
         {:.0} J -> {:.0} J, length {:.1} m -> {:.1} m (--no-refine gives the swarm's plan)",
        d.steps, before.cost, after.cost, b.q_e, a.q_e, b.q_path, a.q_path
    ))
}

/// The plan of the best particle: the path flown at the constant ground speed of §2.2.
pub fn to_plan(scenario: &Scenario, problem: &EnergyProblem, run: RunResult) -> Plan {
    let o = &scenario.optimizer;
    let eval = problem.evaluate(&run.best_x);
    let speed = problem.model.ground_speed_mps;
    let mut times = Vec::with_capacity(eval.path.len());
    let mut t = 0.0;
    for (k, p) in eval.path.iter().enumerate() {
        if k > 0 {
            t += (p - eval.path[k - 1]).norm() / speed;
        }
        times.push(t);
    }
    let trajectory = Trajectory {
        times,
        points: eval.path.clone(),
    };
    let mut assessment = assess(scenario, std::slice::from_ref(&trajectory));
    let id = scenario.vehicles[0].id.clone();
    let m = &problem.model;
    let terms = eval.terms;
    if terms.min_turn_radius_m < m.min_turn_radius_m {
        assessment.violations.push(format!(
            "{id} turns on a {:.2} m radius, tighter than its {:.1} m turning radius (Zhang et al. 2022, eq. (5))",
            terms.min_turn_radius_m, m.min_turn_radius_m
        ));
    }
    if terms.terrain_violations > 0 {
        assessment.violations.push(format!(
            "{id} passes {:.2} m closer to the seabed than its {:.1} m clearance at {} path points",
            -terms.terrain_margin_m, m.terrain_clearance_m, terms.terrain_violations
        ));
    }
    // The plan holds the ground speed of §2.2 whatever the current; the vehicle must make the
    // difference through the water, and cannot beyond its top speed.
    let top = scenario.vehicles[0].speed_max_mps;
    if terms.max_water_speed_mps > top + 1e-9 {
        assessment.violations.push(format!(
            "{id} must make up to {:.2} m/s through the water to hold {speed:.2} m/s over ground against the current, over its top speed of {top:.2} m/s (vehicles[0].speed_max_mps)",
            terms.max_water_speed_mps
        ));
    }
    if let Some(v) = assessment.vehicles.first_mut() {
        v.energy = Some(terms);
    }
    let mut notices = Vec::new();
    if scenario.currents.is_some() {
        notices.push(format!(
            "{id} flies at a constant {speed:.2} m/s over ground (Zhang et al. 2022, §2.2); through the water that takes up to {:.2} m/s against the current",
            terms.max_water_speed_mps
        ));
    }
    if run.termination == Termination::Interrupted {
        notices.push(format!(
            "planning was interrupted after {} of {} iterations: this is the best plan found so far",
            run.convergence.len(),
            o.iterations
        ));
    }
    let arrival = trajectory.arrival();
    Plan {
        scenario: scenario.name.clone(),
        algorithm: o.algorithm.as_str().to_string(),
        mode: "in-process".to_string(),
        seed: o.seed,
        runtime_s: run.runtime_s,
        fitness: eval.cost,
        objective: eval.cost - problem.penalty_weight * eval.penalty,
        penalty: eval.penalty,
        feasible: assessment.violations.is_empty(),
        violations: assessment.violations,
        notices,
        mission_time_s: scenario.fleet.mission_time_s,
        common_arrival_s: arrival,
        d_min_m: scenario.fleet.d_min_m,
        iterations: run.convergence.len(),
        evaluations: run.evaluations,
        termination: format!("{:?}", run.termination),
        vehicles: assessment.vehicles,
        fleet: assessment.fleet,
        convergence: run.convergence,
        distributed: None,
        origin: scenario.origin,
    }
}

/// A plan that names why nothing could be planned (the scenario validation rules this out; kept
/// so that a library caller with a hand-built scenario gets words, not a panic).
pub(crate) fn unplannable(scenario: &Scenario, why: String) -> Plan {
    let o = &scenario.optimizer;
    Plan {
        scenario: scenario.name.clone(),
        algorithm: o.algorithm.as_str().to_string(),
        mode: "in-process".to_string(),
        seed: o.seed,
        runtime_s: 0.0,
        fitness: 0.0,
        objective: 0.0,
        penalty: 0.0,
        feasible: false,
        violations: vec![why],
        notices: Vec::new(),
        mission_time_s: scenario.fleet.mission_time_s,
        common_arrival_s: 0.0,
        d_min_m: scenario.fleet.d_min_m,
        iterations: 0,
        evaluations: 0,
        termination: "NotStarted".to_string(),
        vehicles: Vec::new(),
        fleet: FleetFigures {
            min_separation_m: None,
            min_separation_pair: None,
            min_separation_time_s: None,
            separation_breach_s: 0.0,
            hard_collisions: 0,
            arrival_spread_s: 0.0,
        },
        convergence: Vec::new(),
        distributed: None,
        origin: scenario.origin,
    }
}
