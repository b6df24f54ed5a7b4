//! Independent checker of `plan.json`.
//!
//! This crate deliberately does not depend on `shoal-common` or `shoal-coordinator`: it reads the
//! scenario TOML and the plan JSON with its own minimal serde structs and recomputes every figure
//! from the timed trajectories with its own geometry. A bug shared by the planner and its own
//! assessment therefore shows up here as a mismatch.
//!
//! Semantics (the `plan.json` contract):
//! * a vehicle moves in a straight line at constant speed between consecutive samples
//!   `[t_s, x, y, z]`, holds at its first sample before it and at its last sample after it;
//! * turn = heading change in the horizontal (x–y) plane, degrees in `[0, 180]`, between each leg
//!   with horizontal extent (`√(dx² + dy²) > 1e-9` m) and the next such leg; legs without
//!   horizontal extent (vertical or zero-length) have no heading and are skipped over, so they
//!   neither give nor hide a turn; the largest turn is 0 with fewer than two such legs;
//! * pitch = `atan2(dz, horizontal length)` of a leg, degrees (absolute value);
//! * a hard collision is a (leg, hard obstacle) pair whose segment comes strictly closer than
//!   `radius_m + inflation_m` to the obstacle centre;
//! * clearance = segment distance to a hard obstacle's centre minus its `radius_m`;
//! * separation = distance between two vehicles at the same instant, over `[0, last arrival]`.
//!
//! Modules: `model` reads the files, [`geometry`] is the checker's own geometry, `figures`
//! recomputes the figures, `check` compares them with the plan and applies the contract rules,
//! `feasibility` judges the plan's `feasible` verdict, `report` holds the result, and
//! `tolerance` says how close is equal.

mod check;
pub mod crawler;
mod feasibility;
mod figures;
#[cfg(test)]
mod fixtures;
pub mod geometry;
pub mod mobility;
mod model;
mod report;
pub mod seabed_grid;
pub mod sections;
mod tolerance;

pub use check::{check, check_file, check_parsed};
pub use figures::{fleet_figures, vehicle_figures, FleetFigures, VehicleFigures};
pub use model::{
    parse_plan, parse_scenario, parse_scenario_file, Bounds, Fleet, Obstacle, ObstacleKind, Plan,
    PlanFleet, PlanVehicle, Scenario, Vehicle,
};
pub use report::Report;
pub use tolerance::{close, MAX_ARRIVAL_SPREAD_S, SEPARATION_TOL, TOL};
