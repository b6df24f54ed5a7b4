//! Messages the coordinator sends to vehicle agents.

use serde::{Deserialize, Serialize};

use super::{WireParticle, WireTrajectory};

/// Coordinator → agent.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum CoordinatorToAgent {
    /// Start planning `vehicle` in `mission`.
    Assign {
        /// Mission id (keeps two missions on one network apart).
        mission: String,
        /// The vehicle this agent plans.
        vehicle: String,
        /// The scenario, as the TOML text the coordinator loaded.
        scenario_toml: String,
        /// Seed of this agent's random streams.
        seed: u64,
    },
    /// The fleet's current best plan: the context the agent scores its particles against.
    Context {
        /// Mission id.
        mission: String,
        /// Coordinator iteration it comes from.
        iteration: u32,
        /// The common arrival time the plan is timed for, seconds.
        arrival_s: f64,
        /// Every vehicle's trajectory.
        trajectories: Vec<WireTrajectory>,
    },
    /// Updated immigrants returning to the agent's followers (seed 004 Fig. 5c).
    Migrants {
        /// Mission id.
        mission: String,
        /// The vehicle they belong to.
        vehicle: String,
        /// Coordinator iteration.
        iteration: u32,
        /// The particles, one vehicle's chromosome each.
        particles: Vec<WireParticle>,
    },
    /// The mission is over (or abandoned): stop planning it.
    Stop {
        /// Mission id.
        mission: String,
        /// Why, in plain words.
        reason: String,
    },
}

impl CoordinatorToAgent {
    /// The mission the message belongs to.
    pub fn mission(&self) -> &str {
        match self {
            CoordinatorToAgent::Assign { mission, .. }
            | CoordinatorToAgent::Context { mission, .. }
            | CoordinatorToAgent::Migrants { mission, .. }
            | CoordinatorToAgent::Stop { mission, .. } => mission,
        }
    }
}
