//! What an agent is handed and what it hands back: a checked mission assignment, and how the
//! mission ended. Both the planning loop (`mission`) and the one-go planners
//! (`one_shot`) use them, so they sit below both.

use std::path::Path;

use shoal_common::distributed::Context;
use shoal_common::scenario::Scenario;
use shoal_common::scenario::ScenarioError;
use shoal_common::wire::{BadContext, BadTrajectory, WireContext};

/// Why an assignment or an execution order from the coordinator cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum Unusable {
    /// The scenario does not parse or validate.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// The scenario has no vehicle of ours.
    #[error("mission {mission} has no vehicle {vehicle:?} (it has {ids:?})")]
    NoVehicle {
        /// The mission.
        mission: String,
        /// Our vehicle.
        vehicle: String,
        /// The vehicles it has.
        ids: Vec<String>,
    },
    /// The context does not fit the fleet.
    #[error(transparent)]
    Context(#[from] BadContext),
    /// The trajectory to drive is unusable.
    #[error(transparent)]
    Trajectory(#[from] BadTrajectory),
    /// The mission clock does not run forward.
    #[error("time scale {0} is not a positive number")]
    TimeScale(f64),
    /// Telemetry would be too slow to see or faster than the link is sized for.
    #[error("telemetry rate {0} Hz is not in (0, 100]")]
    TelemetryRate(f64),
}

/// The scenario of mission `mission` and `vehicle`'s index in it.
pub fn parse_for(
    mission: &str,
    vehicle: &str,
    scenario_toml: &str,
) -> Result<(Scenario, usize), Unusable> {
    let origin = format!("<scenario of mission {mission}>");
    let scenario = Scenario::parse(scenario_toml, Path::new(&origin))?;
    match scenario.vehicles.iter().position(|v| v.id == vehicle) {
        Some(index) => Ok((scenario, index)),
        None => Err(Unusable::NoVehicle {
            mission: mission.to_string(),
            vehicle: vehicle.to_string(),
            ids: scenario.vehicles.iter().map(|v| v.id.clone()).collect(),
        }),
    }
}

/// A mission this agent was assigned, checked.
#[derive(Debug, Clone)]
pub struct Assignment {
    /// Mission id.
    pub mission: String,
    /// Our vehicle's id.
    pub vehicle: String,
    /// Its index in the scenario.
    pub index: usize,
    /// The scenario, overrides applied.
    pub scenario: Scenario,
    /// The first context.
    pub context: Context,
}

impl Assignment {
    /// Reads an `Assign` message; the error says what is wrong in plain words.
    pub fn new(
        mission: &str,
        vehicle: &str,
        scenario_toml: &str,
        context: &WireContext,
    ) -> Result<Assignment, Unusable> {
        let (scenario, index) = parse_for(mission, vehicle, scenario_toml)?;
        let ids: Vec<&str> = scenario.vehicles.iter().map(|v| v.id.as_str()).collect();
        let context = context.to_context(&ids)?;
        Ok(Assignment {
            mission: mission.to_string(),
            vehicle: vehicle.to_string(),
            index,
            scenario,
            context,
        })
    }
}

/// How a mission ended for this agent.
#[derive(Debug, Clone, PartialEq)]
pub struct MissionReport {
    /// Iterations the followers ran.
    pub iterations: u32,
    /// Elite messages sent.
    pub elites_sent: u32,
    /// Why it ended, in plain words.
    pub outcome: String,
}
