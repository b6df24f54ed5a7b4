//! Swarm optimizers on one shape (after argmin): a [`Problem`] gives bounds and a cost, a
//! [`Solver`] has `init` and `step` over an explicit state, and the [`Executor`] alone owns the
//! loop, the budgets (iterations, target cost, wall time, a stop flag) and the observer.
//!
//! # Layout
//! - [`core`]: the problem, solver and state traits, the executor, and the particle machinery
//!   several solvers share ([`population`], [`parallel`]). It names no solver.
//! - [`solvers`]: one file per optimizer, each citing its paper, each with a convergence test
//!   on a known optimum. They build on `core` only (and on each other where a variant extends
//!   another).
//! - [`catalog`]: the one place that maps an algorithm name of a scenario
//!   ([`crate::scenario::Algorithm`]) or of a tour leg ([`catalog::LegAlgorithm`]) to a
//!   configured solver. Planners, tours, the distributed follower and leader and the
//!   benchmarks ask it instead of matching on names.
//!
//! The items of `core` and the solver modules are re-exported here, so `swarm::Executor` and
//! `swarm::pso::Pso` are the short paths. Adding an optimizer is one file in `solvers/` and
//! one catalog entry (docs/guide/new-optimizer.md).

/// Implements [`VelocityCapped`] for solvers with a `max_velocity_fraction` field. Defined
/// before `solvers` so every solver file can use it on itself.
macro_rules! velocity_capped {
    ($($solver:ty),+) => {$(
        impl $crate::swarm::core::VelocityCapped for $solver {
            fn velocity_cap_mut(&mut self) -> &mut f64 {
                &mut self.max_velocity_fraction
            }
        }
    )+};
}

pub mod catalog;
pub mod core;
pub mod solvers;
#[cfg(test)]
mod testfns;
#[cfg(test)]
mod tests;

pub use self::core::{
    is_valid_velocity_cap, parallel, population, Executor, IterationReport, Outcome, Problem,
    Progress, Solver, SolverState, Termination, VelocityCapped,
};
// Every solver module, so `swarm::pso::Pso` keeps working and a new solver needs no line here.
pub use self::solvers::*;
