//! The solver side of the argmin-like shape: a [`Solver`] builds a [`SolverState`] and steps it,
//! told where the run is by [`Progress`]; [`VelocityCapped`] lets a scenario set any solver's
//! velocity cap.

use super::problem::Problem;

/// Where the run is: `a` and `b` of eq. (7), the iteration and the iteration budget.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// Current iteration, 0-based (a).
    pub iteration: usize,
    /// Iteration budget (b).
    pub max_iterations: usize,
}

impl Progress {
    /// `a / b`, the share of the budget already spent, in [0, 1].
    pub fn fraction(&self) -> f64 {
        if self.max_iterations == 0 {
            1.0
        } else {
            (self.iteration as f64 / self.max_iterations as f64).min(1.0)
        }
    }
}

/// What every solver state reports to the executor.
pub trait SolverState {
    /// Best cost found so far.
    fn best_cost(&self) -> f64;
    /// Position of the best cost.
    fn best_position(&self) -> &[f64];
    /// Cost evaluations so far.
    fn evaluations(&self) -> u64;
}

/// An optimizer: builds its state, then advances it one iteration at a time. The loop, the
/// budgets and the stop flag belong to the [`Executor`](super::Executor), never to a solver, so
/// every solver is driven the same way (the split of argmin's `Solver` and `Executor`).
///
/// # Example
///
/// A 2-D bowl with its minimum at (1, −2), solved by Lu et al.'s standard PSO:
///
/// ```
/// use shoal_common::swarm::pso::Pso;
/// use shoal_common::swarm::{Executor, Problem, SolverState};
///
/// struct Bowl;
///
/// impl Problem for Bowl {
///     fn lower(&self) -> &[f64] {
///         &[-5.0, -5.0]
///     }
///     fn upper(&self) -> &[f64] {
///         &[5.0, 5.0]
///     }
///     fn cost(&self, x: &[f64]) -> f64 {
///         (x[0] - 1.0).powi(2) + (x[1] + 2.0).powi(2)
///     }
/// }
///
/// let mut solver = Pso::spso(30, 7);
/// let out = Executor::new(300).run(&Bowl, &mut solver, |_| {});
/// let best = out.state.best_position();
/// assert!(out.state.best_cost() < 1e-8);
/// assert!((best[0] - 1.0).abs() < 1e-3 && (best[1] + 2.0).abs() < 1e-3);
/// ```
pub trait Solver<P: Problem> {
    /// Everything the solver needs between iterations.
    type State: SolverState;
    /// Display name.
    fn name(&self) -> &'static str;
    /// Initial state (positions sampled and evaluated).
    fn init(&mut self, problem: &P) -> Self::State;
    /// One iteration.
    fn step(&mut self, problem: &P, state: Self::State, progress: Progress) -> Self::State;
}

/// Whether `cap` is a usable velocity cap: a fraction of each dimension's range in (0, 1]
/// (NaN is not).
pub fn is_valid_velocity_cap(cap: f64) -> bool {
    cap > 0.0 && cap <= 1.0
}

/// A solver whose moves are capped at a fraction of each dimension's range. None of the seeds
/// gives the cap, so each solver carries its own default and a scenario (or a command) may set
/// one for all.
pub trait VelocityCapped: Sized {
    /// The cap, as a fraction of each dimension's range.
    fn velocity_cap_mut(&mut self) -> &mut f64;

    /// This solver with its cap set to `cap`, or left as it is for `None`.
    fn capped(mut self, cap: Option<f64>) -> Self {
        if let Some(c) = cap {
            *self.velocity_cap_mut() = c;
        }
        self
    }
}
