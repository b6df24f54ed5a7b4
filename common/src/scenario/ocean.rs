//! The `[currents]` and `[energy]` tables: the water an AUV flies through and the constants of
//! Zhang et al.'s energy-saving planner.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use super::error::{in_range, over};
use super::error::{Bad, ScenarioError};
use crate::current::{CurrentField, DepthDecayCurrent, StillWater};
use crate::current_grid::GridCurrent;
use crate::energy::Weights;
use crate::limits;

/// Which current model a scenario uses.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "kebab-case")]
pub enum CurrentModel {
    /// Zhang et al. 2022, eq. (2): horizontal, strongest at the surface, zero at the map's greatest depth.
    #[default]
    DepthDecay,
    /// A gridded field (a forecast or a survey) read from `file`, interpolated trilinearly and
    /// clamped to the grid's box outside it; the format is in [`crate::current_grid`].
    Grid,
}

/// `[currents]`: the current field.
///
/// ```toml
/// [currents]
/// model = "depth-decay"                # Zhang et al. 2022, eq. (2)
/// surface_velocity_mps = [-1.0, -1.0]
/// ```
///
/// or
///
/// ```toml
/// [currents]
/// model = "grid"
/// file = "currents.csv"                # x,y,z,u,v,w; relative to the scenario file
/// ```
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Currents {
    /// The model (default `depth-decay`).
    #[serde(default)]
    pub model: CurrentModel,
    /// `depth-decay` only (and required there): `(u, v)` at the surface, m/s (Zhang et al. 2022, eq. (2):
    /// −1.0 each).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface_velocity_mps: Option<[f64; 2]>,
    /// `grid` only (and required there): the CSV file of the field. A relative path is taken
    /// from the scenario file's directory, and is stored absolute once loaded, so agents on the
    /// same file system find it too.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<PathBuf>,
    /// The grid read from `file` when the scenario was loaded ([`Currents::resolve`]); equal
    /// grids compare equal.
    #[serde(skip)]
    pub grid: Option<Arc<GridCurrent>>,
}

impl Currents {
    /// The field over a scenario box whose top is the surface and whose floor is ζ_bd (the
    /// bounds are only used by `depth-decay`; a grid carries its own positions).
    ///
    /// A `grid` that was never loaded (a scenario deserialised without [`Currents::resolve`])
    /// gives still water, with a warning; [`super::Scenario::load`] and
    /// [`super::Scenario::parse`] always load it.
    pub fn field(&self, bounds_min_z: f64, bounds_max_z: f64) -> Arc<dyn CurrentField> {
        match self.model {
            CurrentModel::DepthDecay => Arc::new(DepthDecayCurrent {
                surface_mps: self.surface_velocity_mps.unwrap_or([0.0, 0.0]),
                surface_z: bounds_max_z,
                max_depth_m: bounds_max_z - bounds_min_z,
            }),
            CurrentModel::Grid => match &self.grid {
                Some(grid) => grid.clone(),
                None => {
                    tracing::warn!(
                        "the current grid {:?} was not loaded: planning in still water",
                        self.file
                    );
                    Arc::new(StillWater)
                }
            },
        }
    }

    /// Checks that the keys fit the model and the values are usable.
    pub fn validate(&self, bad: Bad) -> Result<(), ScenarioError> {
        let missing = || "(missing)".to_string();
        match self.model {
            CurrentModel::DepthDecay => {
                if let Some(file) = &self.file {
                    return Err(bad(
                        "currents.file".into(),
                        format!("{:?}", file.display().to_string()),
                        "belongs to model = \"grid\"; the depth-decay model takes surface_velocity_mps",
                    ));
                }
                let Some(surface) = self.surface_velocity_mps else {
                    return Err(bad(
                        "currents.surface_velocity_mps".into(),
                        missing(),
                        "model = \"depth-decay\" needs the surface current [u, v] in m/s",
                    ));
                };
                let speed = surface[0].hypot(surface[1]);
                if !(speed.is_finite() && speed <= limits::MAX_CURRENT_MPS) {
                    return Err(bad(
                        "currents.surface_velocity_mps".into(),
                        format!("{surface:?}"),
                        &format!(
                            "must be finite, at most {} m/s in all (limits::MAX_CURRENT_MPS)",
                            limits::MAX_CURRENT_MPS
                        ),
                    ));
                }
            }
            CurrentModel::Grid => {
                if let Some(surface) = self.surface_velocity_mps {
                    return Err(bad(
                        "currents.surface_velocity_mps".into(),
                        format!("{surface:?}"),
                        "belongs to model = \"depth-decay\"; a grid gives the velocity at its nodes",
                    ));
                }
                if self.file.is_none() {
                    return Err(bad(
                        "currents.file".into(),
                        missing(),
                        "model = \"grid\" needs the CSV file of the field (header x,y,z,u,v,w)",
                    ));
                }
            }
        }
        Ok(())
    }

    /// Loads the grid of a `grid` model: a relative `file` is made absolute against `dir` (the
    /// scenario file's directory) and read; its errors are reported against field
    /// `currents.file` of the scenario `file`. Does nothing for `depth-decay`.
    /// (`_file` is named by `bad` already; it is kept for symmetry with `Seabed::resolve`.)
    pub fn resolve(&mut self, dir: &Path, _file: &Path, bad: Bad) -> Result<(), ScenarioError> {
        self.grid = None;
        if self.model != CurrentModel::Grid {
            return Ok(());
        }
        let Some(path) = &mut self.file else {
            return Err(bad(
                "currents.file".into(),
                "(missing)".into(),
                "model = \"grid\" needs the CSV file of the field (header x,y,z,u,v,w)",
            ));
        };
        let written = format!("{:?}", path.display().to_string());
        if !path.is_absolute() {
            *path = dir.join(&*path);
        }
        super::error::check_data_file(path, "currents.file", bad)?;
        let grid = GridCurrent::load(path)
            .map_err(|e| bad("currents.file".into(), written, &e.to_string()))?;
        let nodes = grid
            .axes()
            .iter()
            .fold(1usize, |n, a| n.saturating_mul(a.count));
        if nodes > limits::MAX_MAP_CELLS {
            let bound = limits::MAX_MAP_CELLS;
            return Err(over(bad, "currents.file", nodes, bound, "MAX_MAP_CELLS"));
        }
        self.grid = Some(Arc::new(grid));
        Ok(())
    }
}

/// `[energy]`: Zhang et al.'s planner constants (Table 2 by default).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct EnergySettings {
    /// R_AUV, the smallest turning radius, metres (Table 2: 8 m).
    pub min_turn_radius_m: f64,
    /// Free control points of the B-spline between start and goal (the particle's genes are
    /// their x, y, z).
    pub control_points: usize,
    /// n_p, points the path is sampled into (Table 2: 500).
    pub path_points: usize,
    /// K_pinit, K_einit, K_rinit, K_ainit (Table 2: 0.25 each).
    pub weights_init: [f64; 4],
    /// K_urp, K_ure, K_urr, K_ura (Table 2: 0.01 each).
    pub weights_range: [f64; 4],
    /// μ of eq. (8), (12), (13) (not in the paper).
    pub mu: f64,
    /// Height kept above the seabed, metres (not in the paper).
    pub terrain_clearance_m: f64,
    /// Constant speed over ground |V_h|, m/s; default: the vehicle's top speed.
    pub ground_speed_mps: Option<f64>,
}

impl Default for EnergySettings {
    fn default() -> Self {
        let w = Weights::default();
        EnergySettings {
            min_turn_radius_m: 8.0,
            control_points: 10,
            path_points: 500,
            weights_init: w.init,
            weights_range: w.range,
            mu: w.mu,
            terrain_clearance_m: 2.0,
            ground_speed_mps: None,
        }
    }
}

impl EnergySettings {
    /// The weight constants.
    pub fn weights(&self) -> Weights {
        Weights {
            init: self.weights_init,
            range: self.weights_range,
            mu: self.mu,
        }
    }

    /// Checks every value; `bad` builds the error naming the field.
    pub fn validate(&self, currents: Option<&Currents>, bad: Bad) -> Result<(), ScenarioError> {
        let positive = [
            ("energy.min_turn_radius_m", self.min_turn_radius_m),
            ("energy.mu", self.mu),
        ];
        for (field, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(
                    field.into(),
                    v.to_string(),
                    "must be a positive number",
                ));
            }
        }
        if !(self.terrain_clearance_m.is_finite() && self.terrain_clearance_m >= 0.0) {
            return Err(bad(
                "energy.terrain_clearance_m".into(),
                self.terrain_clearance_m.to_string(),
                "must be a non-negative number of metres",
            ));
        }
        if let Some(v) = self.ground_speed_mps {
            let unit = "m/s (limits::SPEED_MPS)";
            in_range(bad, "energy.ground_speed_mps", v, limits::SPEED_MPS, unit)?;
        }
        if !(1..=64).contains(&self.control_points) {
            return Err(bad(
                "energy.control_points".into(),
                self.control_points.to_string(),
                "must be between 1 and 64",
            ));
        }
        if !(3..=limits::MAX_PATH_SAMPLES).contains(&self.path_points) {
            return Err(bad(
                "energy.path_points".into(),
                self.path_points.to_string(),
                &format!(
                    "must be between 3 and {} (limits::MAX_PATH_SAMPLES)",
                    limits::MAX_PATH_SAMPLES
                ),
            ));
        }
        for (name, values) in [
            ("energy.weights_init", self.weights_init),
            ("energy.weights_range", self.weights_range),
        ] {
            if !values.iter().all(|v| v.is_finite() && *v >= 0.0) {
                return Err(bad(
                    name.into(),
                    format!("{values:?}"),
                    "must be four non-negative numbers",
                ));
            }
        }
        if let Some(c) = currents {
            c.validate(bad)?;
        }
        Ok(())
    }
}
