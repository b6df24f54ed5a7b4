//! Messages vehicle agents send to the coordinator.

use serde::{Deserialize, Serialize};

use super::WireChromosome;

/// Agent → coordinator. Variants are only ever added at the end: their index is on the wire.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum AgentToCoordinator {
    /// The best chromosome of each of the agent's follower populations after exchange round
    /// `round`'s iterations (seed 004 Fig. 5a), for the leader.
    Elites {
        /// Mission id.
        mission: String,
        /// The vehicle they belong to.
        vehicle: String,
        /// Exchange round.
        round: u32,
        /// Iterations the agent has run.
        iteration: u32,
        /// Cost evaluations its followers have made so far.
        evaluations: u64,
        /// The chromosomes, one per follower population.
        particles: Vec<WireChromosome>,
    },
    /// The agent finished its share of the mission.
    Done {
        /// Mission id.
        mission: String,
        /// The vehicle.
        vehicle: String,
        /// Iterations the agent ran.
        iterations: u32,
        /// Elite messages it sent.
        elites_sent: u32,
        /// Cost evaluations its followers made.
        evaluations: u64,
        /// Messages it dropped (malformed, wrong version, unknown mission or vehicle).
        dropped: u32,
    },
    /// The agent took the assignment and is planning.
    Joined {
        /// Mission id.
        mission: String,
        /// The vehicle.
        vehicle: String,
    },
}

impl AgentToCoordinator {
    /// The mission the message belongs to.
    pub fn mission(&self) -> &str {
        match self {
            AgentToCoordinator::Elites { mission, .. }
            | AgentToCoordinator::Done { mission, .. }
            | AgentToCoordinator::Joined { mission, .. } => mission,
        }
    }

    /// The vehicle the message speaks for.
    pub fn vehicle(&self) -> &str {
        match self {
            AgentToCoordinator::Elites { vehicle, .. }
            | AgentToCoordinator::Done { vehicle, .. }
            | AgentToCoordinator::Joined { vehicle, .. } => vehicle,
        }
    }
}
