//! Messages the coordinator sends to vehicle agents.

use serde::{Deserialize, Serialize};

use super::{WireChromosome, WireContext};

/// Coordinator → agent. Variants are only ever added at the end: their index is on the wire.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum CoordinatorToAgent {
    /// Plan `vehicle` in `mission`; repeated until the agent answers `Joined`.
    Assign {
        /// Mission id (keeps two missions on one network apart).
        mission: String,
        /// The vehicle this agent plans.
        vehicle: String,
        /// The scenario with every override applied, as TOML.
        scenario_toml: String,
        /// The first context (the leader's initial best plan).
        context: WireContext,
    },
    /// The fleet's current best plan, broadcast on the mission's fleet key: the context the
    /// agents score their particles against.
    Context {
        /// Mission id.
        mission: String,
        /// The plan.
        context: WireContext,
    },
    /// Updated immigrants returning to the agent's followers (seed 004 Fig. 5c), one per
    /// follower population, after exchange `round`.
    Migrants {
        /// Mission id.
        mission: String,
        /// The vehicle they belong to.
        vehicle: String,
        /// Exchange round they answer.
        round: u32,
        /// Round of the context the agent must be using before it takes them in.
        context_round: u32,
        /// The chromosomes.
        particles: Vec<WireChromosome>,
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
