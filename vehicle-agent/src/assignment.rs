//! What an agent is handed and what it hands back: a checked mission assignment, and how the
//! mission ended. Both the planning loop ([`crate::mission`]) and the one-go planners
//! (`one_shot`) use them, so they sit below both.

use std::path::Path;

use shoal_common::distributed::Context;
use shoal_common::scenario::Scenario;
use shoal_common::wire::WireContext;

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
    ) -> Result<Assignment, String> {
        let origin = format!("<scenario of mission {mission}>");
        let scenario =
            Scenario::parse(scenario_toml, Path::new(&origin)).map_err(|e| e.to_string())?;
        let ids: Vec<&str> = scenario.vehicles.iter().map(|v| v.id.as_str()).collect();
        let index = ids.iter().position(|id| *id == vehicle).ok_or_else(|| {
            format!("mission {mission} has no vehicle {vehicle:?} (it has {ids:?})")
        })?;
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
