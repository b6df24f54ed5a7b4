//! Distributed AMP-PSO (Zhi & Zuo 2024, §3.2–3.3 split over processes), without any transport: the
//! planning loops the vehicle agents and the coordinator run, as plain state machines, so the
//! network code only carries their messages and a test can drive them without a network.
//!
//! - [`follower`]: one vehicle's follower populations. Each particle is that vehicle's
//!   chromosome alone, scored against the other vehicles' trajectories in the current
//!   [`Context`] ([`crate::vehicle_problem::VehicleProblem`]), so the coupling terms (separation
//!   over time, synchronised arrival) are part of its fitness. Runs in the vehicle's agent, or in
//!   the coordinator when that agent is gone (degraded mode).
//! - [`leader`]: the coordinator's leader population of whole-fleet particles. It immigrates the
//!   followers' best chromosomes (Fig. 5a), moves them by eq. (6) with c3 of eq. (8) on the fleet
//!   fitness (Fig. 5b), returns them as migrants (Fig. 5c) and keeps the best fleet plan, which
//!   becomes the agents' next context.
//! - [`lockstep`]: the whole exchange in one process, round by round, exactly as the agents and
//!   the coordinator do it over the network; the reference the distributed runs are tested
//!   against.

pub mod follower;
pub mod leader;
pub mod lockstep;

use crate::cost::FleetEvaluation;
use crate::trajectory::Trajectory;

/// The fleet plan a follower scores its chromosomes against: every vehicle's timed trajectory
/// and the common arrival time they are timed for.
#[derive(Debug, Clone, PartialEq)]
pub struct Context {
    /// Exchange round the plan comes from (0: the leader's initial best).
    pub round: u32,
    /// Common arrival time, seconds.
    pub arrival: f64,
    /// Every vehicle's trajectory, in scenario order.
    pub trajectories: Vec<Trajectory>,
}

impl Context {
    /// The context a fleet evaluation gives.
    pub fn of(round: u32, e: &FleetEvaluation) -> Context {
        Context {
            round,
            arrival: e.common_arrival,
            trajectories: e.trajectories.to_vec(),
        }
    }
}

/// One vehicle's chromosome as it travels between followers and leader: position and velocity.
#[derive(Debug, Clone, PartialEq)]
pub struct Chromosome {
    /// Genes (this vehicle's waypoints, then its leg speeds).
    pub x: Vec<f64>,
    /// Velocity.
    pub v: Vec<f64>,
}

/// Rounds of a run of `iterations` iterations exchanging every `every`: the last round may be
/// shorter.
pub fn rounds(iterations: usize, every: usize) -> usize {
    iterations.div_ceil(every.max(1))
}

/// Iterations in round `round` (0-based).
pub fn round_iterations(iterations: usize, every: usize, round: usize) -> usize {
    let every = every.max(1);
    iterations.saturating_sub(round * every).min(every)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounds_cover_the_budget_exactly() {
        assert_eq!(rounds(200, 1), 200);
        assert_eq!(rounds(200, 3), 67);
        let total: usize = (0..rounds(200, 3))
            .map(|r| round_iterations(200, 3, r))
            .sum();
        assert_eq!(total, 200);
        assert_eq!(round_iterations(200, 3, 66), 2);
        assert_eq!(rounds(0, 5), 0);
        assert_eq!(rounds(7, 0), 7);
    }
}
