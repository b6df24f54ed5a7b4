//! Scenario files: the mission a planner is asked to solve, in TOML with SI units (metres, seconds,
//! metres per second, degrees).
//!
//! Loading never panics on user input: a syntax error, an unknown key or a bad value comes back as
//! a [`ScenarioError`] naming the file, the field and the value.

mod coverage;
mod error;
mod files;
mod inspection;
mod model;
mod ocean;
mod optimizer;
mod seabed;
mod sizes;
mod validate;
pub use coverage::CoverageSettings;
pub use error::ScenarioError;
pub use files::{DataDir, FileRefusal, FILE_FIELDS, OUTSIDE_DATA_DIR};
pub use inspection::{FirstPointMode, InspectionSettings};
pub use model::{Bounds, Fleet, Obstacle, ObstacleKind, Scenario, Vehicle, VehicleKind};
pub use ocean::{CurrentModel, Currents, EnergySettings};
pub use optimizer::{Algorithm, DistributedSettings, OptimizerSettings};
pub use seabed::{CrawlerSettings, Seabed, SeabedGrid};
pub use validate::MIN_START_GOAL_DISTANCE_M;

/// One knot in metres per second (1852 m / 3600 s), for scenario comments and tests.
pub const KNOT_MPS: f64 = 1852.0 / 3600.0;

#[cfg(test)]
mod tests;
