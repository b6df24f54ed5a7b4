//! The `[inspection]` table: which net cages an AUV tour inspects and how (Hu et al. 2023, §II–V).
//!
//! The cages themselves are the scenario's hard obstacles (`[[obstacles]]`, kind `hard`): their
//! `radius_m` is the cage, their `inflation_m` the clearance every leg keeps from it.

use serde::{Deserialize, Serialize};

/// How the first inspection point of each cage is placed (the second mirrors it).
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "kebab-case")]
pub enum FirstPointMode {
    /// Facing the fleet's base (the mean of the vehicles' starts): reproducible without a seed.
    #[default]
    TowardBase,
    /// Hu et al. 2023, §II: a random azimuth per cage, from the optimizer's seed.
    Random,
}

/// `[inspection]`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct InspectionSettings {
    /// Ids of the hard obstacles to inspect; empty: every hard obstacle.
    pub cages: Vec<String>,
    /// How far outside the cage the monitoring sphere lies, metres (§II: "slightly greater").
    pub standoff_m: f64,
    /// Placement of each cage's first point.
    pub first_point: FirstPointMode,
    /// Swap-operator PSO swarm size (Table 3: 100).
    pub order_particles: usize,
    /// Swap-operator PSO iterations (Table 3: 2000).
    pub order_iterations: usize,
}

impl Default for InspectionSettings {
    fn default() -> Self {
        InspectionSettings {
            cages: Vec::new(),
            standoff_m: crate::tour::cages::MONITOR_STANDOFF_M,
            first_point: FirstPointMode::TowardBase,
            order_particles: 100,
            order_iterations: 2000,
        }
    }
}
