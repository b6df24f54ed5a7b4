//! What every optimizer shares (argmin's `core`): the [`Problem`] a swarm minimises, the
//! [`Solver`] and [`SolverState`] traits, the [`Executor`] that alone owns the loop and its
//! budgets, and the particle machinery several solvers reuse ([`population`], [`parallel`]).
//!
//! Nothing here names a solver: `solvers/` builds on this module, never the other way round.

mod executor;
pub mod parallel;
pub mod population;
mod problem;
mod solver;

pub use executor::{Executor, IterationReport, Outcome, Termination};
pub use problem::Problem;
pub use solver::{is_valid_velocity_cap, Progress, Solver, SolverState, VelocityCapped};
