//! The `[coverage]` table: area coverage by a mining crawler (seed 002). Its presence makes
//! `plan` run the coverage pipeline — 2.5D map, Boustrophedon planner, closed-loop tracking —
//! instead of a swarm.

use serde::{Deserialize, Serialize};

use super::{Bad, ScenarioError};
use crate::coverage::params::CoverageParams;
use crate::coverage::tracking::TrackingParams;
use crate::coverage::{Terrain25Error, TerrainSpec, TraversalLimits};

/// `[coverage]`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct CoverageSettings {
    /// Seed of the synthetic seabed; absent: `optimizer.seed`.
    pub terrain_seed: Option<u64>,
    /// `[coverage.terrain]`: the seeded synthetic seabed (ignored with `heightmap`).
    pub terrain: TerrainSpec,
    /// A measured heightmap (CSV or ESRI ASCII grid, relative to the scenario file) instead.
    pub heightmap: Option<std::path::PathBuf>,
    /// `[coverage.limits]`: critical slope and vehicle width.
    pub limits: TraversalLimits,
    /// Vehicle length, metres (reported; the planner works with the width and `R_min`).
    pub vehicle_length_m: f64,
    /// `[coverage.planner]`.
    pub planner: CoverageParams,
    /// `[coverage.tracking]`; `min_turn_radius_m` is taken from the planner.
    pub tracking: TrackingParams,
    /// Whether to simulate the closed-loop tracking of the planned path.
    pub track: bool,
}

impl Default for CoverageSettings {
    fn default() -> Self {
        Self {
            terrain_seed: None,
            terrain: TerrainSpec::default(),
            heightmap: None,
            limits: TraversalLimits::default(),
            vehicle_length_m: 12.0,
            planner: CoverageParams::default(),
            tracking: TrackingParams::default(),
            track: true,
        }
    }
}

impl CoverageSettings {
    /// Checks every sub-table; errors name `coverage.<table>.<field>`.
    pub fn validate(&self, bad: Bad) -> Result<(), ScenarioError> {
        let wrap = |table: &str, e: Terrain25Error| match e {
            Terrain25Error::InvalidSpec { field, what }
            | Terrain25Error::InvalidParam { field, what } => {
                bad(format!("coverage.{table}.{field}"), what, "is out of range")
            }
            other => bad(format!("coverage.{table}"), other.to_string(), "is invalid"),
        };
        if self.heightmap.is_none() {
            self.terrain.validate().map_err(|e| wrap("terrain", e))?;
        }
        self.limits.validate().map_err(|e| wrap("limits", e))?;
        self.planner.validate().map_err(|e| wrap("planner", e))?;
        self.tracking
            .validate()
            .map_err(|e| bad("coverage.tracking".into(), e.to_string(), "is out of range"))?;
        if !(self.vehicle_length_m.is_finite() && self.vehicle_length_m > 0.0) {
            return Err(bad(
                "coverage.vehicle_length_m".into(),
                self.vehicle_length_m.to_string(),
                "must be a positive length in metres",
            ));
        }
        Ok(())
    }

    /// The tracking settings with the planner's turning radius.
    pub fn tracking_params(&self) -> TrackingParams {
        TrackingParams {
            min_turn_radius_m: self.planner.min_turn_radius_m,
            ..self.tracking.clone()
        }
    }
}
