//! The `[inspection]` table: which net cages an AUV tour inspects and how (seed 003 §II–V).
//!
//! The cages themselves are the scenario's hard obstacles (`[[obstacles]]`, kind `hard`): their
//! `radius_m` is the cage, their `inflation_m` the clearance every leg keeps from it.

use serde::{Deserialize, Serialize};

use super::sizes::over;
use super::{Bad, ObstacleKind, Scenario, ScenarioError, VehicleKind};
use crate::limits;

/// How the first inspection point of each cage is placed (the second mirrors it).
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "kebab-case")]
pub enum FirstPointMode {
    /// Facing the fleet's base (the mean of the vehicles' starts): reproducible without a seed.
    #[default]
    TowardBase,
    /// Seed 003 §II: a random azimuth per cage, from the optimizer's seed.
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
            standoff_m: crate::tour::MONITOR_STANDOFF_M,
            first_point: FirstPointMode::TowardBase,
            order_particles: 100,
            order_iterations: 2000,
        }
    }
}

impl InspectionSettings {
    /// Indices (into `scenario.obstacles`) of the cages to inspect, in scenario order.
    pub fn cage_indices(&self, scenario: &Scenario) -> Vec<usize> {
        scenario
            .obstacles
            .iter()
            .enumerate()
            .filter(|(_, o)| {
                o.kind == ObstacleKind::Hard
                    && (self.cages.is_empty() || self.cages.contains(&o.id))
            })
            .map(|(i, _)| i)
            .collect()
    }

    /// Checks the table against the scenario it belongs to.
    pub fn validate(&self, scenario: &Scenario, bad: Bad) -> Result<(), ScenarioError> {
        for (i, id) in self.cages.iter().enumerate() {
            let found = scenario.obstacles.iter().find(|o| &o.id == id);
            match found {
                None => {
                    return Err(bad(
                        format!("inspection.cages[{i}]"),
                        format!("{id:?}"),
                        "names no obstacle of the scenario",
                    ))
                }
                Some(o) if o.kind != ObstacleKind::Hard => {
                    return Err(bad(
                        format!("inspection.cages[{i}]"),
                        format!("{id:?}"),
                        "is a soft obstacle; cages are hard obstacles",
                    ))
                }
                Some(_) => {}
            }
        }
        let cages = self.cage_indices(scenario);
        if cages.is_empty() {
            return Err(bad(
                "inspection.cages".into(),
                format!("{:?}", self.cages),
                "no hard obstacle to inspect: add [[obstacles]] of kind \"hard\"",
            ));
        }
        if !(self.standoff_m.is_finite() && self.standoff_m > 0.0) {
            return Err(bad(
                "inspection.standoff_m".into(),
                self.standoff_m.to_string(),
                "must be a positive number of metres",
            ));
        }
        for &c in &cages {
            let o = &scenario.obstacles[c];
            if self.standoff_m <= o.inflation_m {
                return Err(bad(
                    "inspection.standoff_m".into(),
                    self.standoff_m.to_string(),
                    &format!(
                        "must exceed the clearance (inflation_m = {}) of cage {}, or its inspection points lie inside the space the legs keep clear",
                        o.inflation_m, o.id
                    ),
                ));
            }
        }
        for (name, v) in [
            ("inspection.order_particles", self.order_particles),
            ("inspection.order_iterations", self.order_iterations),
        ] {
            if v == 0 {
                return Err(bad(name.into(), v.to_string(), "must be at least 1"));
            }
        }
        let (n, i) = (self.order_particles, self.order_iterations);
        if n > limits::MAX_PARTICLES {
            let name = "MAX_PARTICLES";
            return Err(over(
                bad,
                "inspection.order_particles",
                n,
                limits::MAX_PARTICLES,
                name,
            ));
        }
        if i > limits::MAX_ITERATIONS {
            let name = "MAX_ITERATIONS";
            return Err(over(
                bad,
                "inspection.order_iterations",
                i,
                limits::MAX_ITERATIONS,
                name,
            ));
        }
        if (n as u128) * (i as u128) > limits::MAX_EVALUATIONS {
            return Err(bad(
                "inspection.order_iterations".into(),
                i.to_string(),
                &format!(
                    "with {n} order_particles is over the limit {} evaluations (limits::MAX_EVALUATIONS)",
                    limits::MAX_EVALUATIONS
                ),
            ));
        }
        for (i, v) in scenario.vehicles.iter().enumerate() {
            if v.kind != VehicleKind::Auv {
                return Err(bad(
                    format!("vehicles[{i}].kind"),
                    format!("{:?}", v.kind),
                    "inspection tours are flown by AUVs",
                ));
            }
            if v.start != v.goal {
                return Err(bad(
                    format!("vehicles[{i}].goal"),
                    format!("{:?}", v.goal),
                    &format!(
                        "an inspection tour returns to its base: the goal must equal the start {:?}",
                        v.start
                    ),
                ));
            }
        }
        Ok(())
    }
}
