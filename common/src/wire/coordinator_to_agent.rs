//! Messages the coordinator sends to vehicle agents.

use serde::{Deserialize, Serialize};

use super::{WireChromosome, WireContext, WireTrajectory};

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
    /// Updated immigrants returning to the agent's followers (Zhi & Zuo 2024, Fig. 5c), one per
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
    /// Drive `vehicle` along its timed trajectory; repeated until its telemetry comes.
    /// Mission time `t` runs as `(unix_now − epoch) × time_scale`, so the whole fleet shares one
    /// clock (agents on other machines need synchronised clocks, e.g. NTP).
    Execute {
        /// Mission id (an execution is a mission of its own).
        mission: String,
        /// The vehicle.
        vehicle: String,
        /// The scenario as TOML (vehicle limits, terrain, currents for a simulated vehicle).
        scenario_toml: String,
        /// The trajectory, mission-timed.
        trajectory: WireTrajectory,
        /// Unix time of mission time 0, milliseconds.
        epoch_unix_ms: u64,
        /// Mission seconds per wall second (1 = real time).
        time_scale: f64,
        /// Telemetry reports per wall second.
        telemetry_hz: f64,
        /// Seed of the simulated vehicle's noise.
        seed: u64,
    },
    /// A replanned trajectory (mission-timed, from the vehicle's current position on): follow it
    /// from now on, leaving a hold if it was holding.
    Update {
        /// Mission id.
        mission: String,
        /// The vehicle.
        vehicle: String,
        /// Plan revision (0 = the first plan), echoed in its telemetry.
        revision: u32,
        /// The trajectory.
        trajectory: WireTrajectory,
    },
    /// Hold where it is (no replan could be made in time).
    Hold {
        /// Mission id.
        mission: String,
        /// The vehicle.
        vehicle: String,
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
            | CoordinatorToAgent::Stop { mission, .. }
            | CoordinatorToAgent::Execute { mission, .. }
            | CoordinatorToAgent::Update { mission, .. }
            | CoordinatorToAgent::Hold { mission, .. } => mission,
        }
    }
}
