//! Shoal's shared model and algorithms: scenarios, geometry, timed trajectories, the fleet
//! fitness of Zhi & Zuo 2024 and the swarm optimizers.

pub mod benchfns;
pub mod broad_phase;
pub mod bspline;
pub mod cost;
pub mod coverage;
pub mod crawler;
pub mod current;
pub mod current_grid;
pub mod distributed;
pub mod energy;
pub mod execution;
#[cfg(test)]
mod fixtures;
pub mod fleet;
pub mod fleet_trajectories;
pub mod geo;
pub mod geometry;
pub mod gridsearch;
pub mod health;
pub mod limits;
pub mod plan;
pub mod queue;
pub mod refine;
pub mod scenario;
pub mod separation;
pub mod stats;
#[cfg(test)]
mod strategies;
pub mod swarm;
pub mod terrain;
pub mod touch_up;
pub mod tour;
pub mod trajectory;
pub mod vehicle_problem;
pub mod wire;

/// Version of the shared crate, reported by the binaries.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
