//! What `run` hands to the execution once a plan is made, fleet or coverage alike, and whether
//! it is executed at all.

use std::sync::atomic::{AtomicBool, Ordering};

use shoal_common::scenario::Scenario;
use shoal_common::trajectory::Trajectory;

/// What `run` executes: the scenario the agents get (a coverage mission's starts moved to its
/// paths), every vehicle's timed trajectory (scenario order) and the time they are timed to end.
pub struct Executable {
    /// The scenario sent to the agents.
    pub scenario: Scenario,
    /// Per vehicle, mission-timed.
    pub trajectories: Vec<Trajectory>,
    /// The common arrival (a coverage fleet: the last crawler's finish).
    pub common_arrival_s: f64,
}

/// Whether a plan that is `feasible` or not is executed; says why not on stderr. Ctrl-C while
/// planning (`shutdown`) asks for the plan so far, not for a mission started and stopped at
/// once.
pub fn executable(feasible: bool, shutdown: &AtomicBool) -> bool {
    if shutdown.load(Ordering::Relaxed) {
        eprintln!("interrupted while planning: the plan so far is written, it is not executed");
        false
    } else if !feasible {
        eprintln!("the plan is not feasible: it is not executed (see plan.json)");
        false
    } else {
        true
    }
}

/// The scenario a fleet to be executed is planned with: d_min plus the separation buffer, so
/// that a plan pressed against its d_min (the refinement pulls paths tight) still keeps the
/// scenario's d_min while the vehicles track it with errors of their own; planned at d_min
/// itself, the executor's predictions from noisy fixes see a conflict at the first close pass.
/// The execution keeps the scenario's d_min.
pub fn with_tracking_room(scenario: &Scenario, separation_buffer_m: f64) -> Scenario {
    let mut planning = scenario.clone();
    if scenario.vehicles.len() > 1 && separation_buffer_m > 0.0 {
        planning.fleet.d_min_m += separation_buffer_m;
        eprintln!(
            "note: the vehicles are planned {:.0} m apart, d_min {:.0} m plus the --separation-buffer {:.0} m for the tracking error of both (plan.json's d_min is that sum)",
            planning.fleet.d_min_m, scenario.fleet.d_min_m, separation_buffer_m
        );
    }
    planning
}
