//! Messages vehicle agents send to the coordinator.

use serde::{Deserialize, Serialize};

use super::WireParticle;

/// Agent → coordinator.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum AgentToCoordinator {
    /// The best particles of the agent's followers (seed 004 Fig. 5a), for the leader.
    Elites {
        /// Mission id.
        mission: String,
        /// The vehicle they belong to.
        vehicle: String,
        /// Agent iteration.
        iteration: u32,
        /// The particles, this vehicle's chromosome each.
        particles: Vec<WireParticle>,
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
        /// Messages it dropped (malformed, wrong version, unknown mission or vehicle).
        dropped: u32,
    },
}

impl AgentToCoordinator {
    /// The mission the message belongs to.
    pub fn mission(&self) -> &str {
        match self {
            AgentToCoordinator::Elites { mission, .. }
            | AgentToCoordinator::Done { mission, .. } => mission,
        }
    }

    /// The vehicle the message speaks for.
    pub fn vehicle(&self) -> &str {
        match self {
            AgentToCoordinator::Elites { vehicle, .. }
            | AgentToCoordinator::Done { vehicle, .. } => vehicle,
        }
    }
}
