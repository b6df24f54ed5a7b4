//! The `[coverage]` table: area coverage by a mining crawler (CPP-DSMV). Its presence makes
//! `plan` run the coverage pipeline — 2.5D map, Boustrophedon planner, closed-loop tracking —
//! instead of a swarm.

use serde::{Deserialize, Serialize};

use super::error::{in_range, over};
use super::error::{Bad, ScenarioError};
use crate::coverage::params::CoverageParams;
use crate::coverage::tracking::TrackingParams;
use crate::coverage::{Terrain25Error, TerrainSpec, TraversalLimits};
use crate::limits;

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
    /// Checks every sub-table against the horizontal `area` `[x0, y0, x1, y1]` it covers (the
    /// scenario's bounds); errors name `coverage.<table>.<field>`.
    pub fn validate(&self, area: [f64; 4], bad: Bad) -> Result<(), ScenarioError> {
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
        if self.heightmap.is_none() {
            self.validate_map_cells(bad)?;
        }
        self.validate_width(area, bad)?;
        self.validate_work(area, bad)?;
        for (name, v) in [
            ("speed_mps", self.tracking.speed_mps),
            ("min_speed_mps", self.tracking.min_speed_mps),
            ("max_speed_mps", self.tracking.max_speed_mps),
        ] {
            let field = format!("coverage.tracking.{name}");
            in_range(bad, &field, v, limits::SPEED_MPS, "m/s (limits::SPEED_MPS)")?;
        }
        Ok(())
    }

    /// The synthetic terrain's cells (its size over its cell, each axis rounded up) within
    /// [`limits::MAX_MAP_CELLS`], before the map is sampled.
    fn validate_map_cells(&self, bad: Bad) -> Result<(), ScenarioError> {
        let t = &self.terrain;
        let cells = (t.size_m[0] / t.cell_m).ceil() * (t.size_m[1] / t.cell_m).ceil();
        if cells > limits::MAX_MAP_CELLS as f64 {
            return Err(bad(
                "coverage.terrain.cell_m".into(),
                t.cell_m.to_string(),
                &format!(
                    "makes a {} × {} m map of {cells:.3e} cells, over the limit {} (limits::MAX_MAP_CELLS)",
                    t.size_m[0],
                    t.size_m[1],
                    limits::MAX_MAP_CELLS
                ),
            ));
        }
        Ok(())
    }

    /// The crawler's width: a real crawler's, narrower than the area, and inside the clearance
    /// the planner keeps. The planner keeps `planner.safety_clearance_m` between the vehicle's
    /// centre line and impassable ground whatever the width (the width only dilates the no-go
    /// map): a clearance under half the width would plan the vehicle's side over that ground.
    fn validate_width(&self, area: [f64; 4], bad: Bad) -> Result<(), ScenarioError> {
        let w = self.limits.vehicle_width_m;
        let field = "coverage.limits.vehicle_width_m";
        if !(w > 0.0 && w <= limits::MAX_VEHICLE_WIDTH_M) {
            return Err(bad(
                field.into(),
                w.to_string(),
                &format!(
                    "must be in (0, {}] m (limits::MAX_VEHICLE_WIDTH_M: the widest seabed crawler)",
                    limits::MAX_VEHICLE_WIDTH_M
                ),
            ));
        }
        let narrower = (area[2] - area[0]).min(area[3] - area[1]);
        if w >= narrower {
            return Err(bad(
                field.into(),
                w.to_string(),
                &format!("is not narrower than the area to cover ({narrower} m across)"),
            ));
        }
        let clearance = self.planner.safety_clearance_m;
        if clearance < w / 2.0 {
            return Err(bad(
                "coverage.planner.safety_clearance_m".into(),
                clearance.to_string(),
                &format!(
                    "is less than half the vehicle's width ({field} = {w}): the planner keeps this clearance from the centre line, so the vehicle's side would be over impassable ground"
                ),
            ));
        }
        Ok(())
    }

    /// The planner's work: its check and rollback steps at least [`limits::MIN_CHECK_STEP_M`],
    /// the samples it checks along its rows (area / row spacing / step) within
    /// [`limits::MAX_COVERAGE_CHECKS`], and its search budgets within
    /// [`limits::MAX_SEARCH_EXPANSIONS`].
    fn validate_work(&self, area: [f64; 4], bad: Bad) -> Result<(), ScenarioError> {
        let p = &self.planner;
        for (name, v) in [
            ("check_step_m", p.check_step_m),
            ("rollback_step_m", p.rollback_step_m),
        ] {
            if v < limits::MIN_CHECK_STEP_M {
                return Err(bad(
                    format!("coverage.planner.{name}"),
                    v.to_string(),
                    &format!(
                        "is under the limit {} m (limits::MIN_CHECK_STEP_M)",
                        limits::MIN_CHECK_STEP_M
                    ),
                ));
            }
        }
        let path_m = (area[2] - area[0]) * (area[3] - area[1]) / p.row_spacing();
        let checks = path_m / p.check_step_m;
        if checks.is_nan() || checks > limits::MAX_COVERAGE_CHECKS {
            return Err(bad(
                "coverage.planner.check_step_m".into(),
                p.check_step_m.to_string(),
                &format!(
                    "with rows {} m apart (2 × min_turn_radius_m) asks for {checks:.3e} checks along about {path_m:.0} m of rows, over the limit {:e} (limits::MAX_COVERAGE_CHECKS)",
                    p.row_spacing(),
                    limits::MAX_COVERAGE_CHECKS
                ),
            ));
        }
        for (name, v) in [
            ("transit_expansions", p.transit_expansions),
            ("transit_budget", p.transit_budget),
        ] {
            if v > limits::MAX_SEARCH_EXPANSIONS {
                let field = format!("coverage.planner.{name}");
                let bound = limits::MAX_SEARCH_EXPANSIONS;
                return Err(over(bad, &field, v, bound, "MAX_SEARCH_EXPANSIONS"));
            }
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
