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
