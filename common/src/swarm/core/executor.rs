//! The [`Executor`]: the one optimisation loop, its budgets and its observer.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use super::problem::Problem;
use super::solver::{Progress, Solver, SolverState};

/// Why a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Termination {
    /// The iteration budget was spent.
    MaxIterations,
    /// The best cost reached the target.
    TargetReached,
    /// The wall-time budget was spent.
    TimeLimit,
    /// The stop flag was raised (Ctrl-C, shutdown).
    Interrupted,
}

/// One line of progress for observers.
#[derive(Debug, Clone, Copy)]
pub struct IterationReport {
    /// Iterations done.
    pub iteration: usize,
    /// Iteration budget.
    pub max_iterations: usize,
    /// Best cost so far.
    pub best_cost: f64,
    /// Evaluations so far.
    pub evaluations: u64,
}

/// Result of a run.
#[derive(Debug)]
pub struct Outcome<S> {
    /// Final solver state.
    pub state: S,
    /// Why it stopped.
    pub termination: Termination,
    /// Best cost after each iteration (the convergence curve).
    pub convergence: Vec<f64>,
    /// Wall time, including init.
    pub elapsed: Duration,
    /// The best position after every [`Executor::checkpoint_every`] iterations, oldest first,
    /// when the run went on past it.
    pub checkpoints: Vec<Vec<f64>>,
}

/// Owns the optimisation loop and its budgets.
#[derive(Debug, Clone, Default)]
pub struct Executor {
    /// Iteration budget.
    pub max_iterations: usize,
    /// Stop once the best cost is at or below this.
    pub target_cost: Option<f64>,
    /// Stop after this much wall time.
    pub time_limit: Option<Duration>,
    /// Stop when this flag is raised.
    pub stop: Option<Arc<AtomicBool>>,
    /// Keep the best position after every this many iterations (before the last), so a caller
    /// can finish each as it would have finished a run of that budget.
    pub checkpoint_every: Option<usize>,
}

impl Executor {
    /// An executor with an iteration budget only.
    pub fn new(max_iterations: usize) -> Executor {
        Executor {
            max_iterations,
            ..Executor::default()
        }
    }

    /// Runs `solver` on `problem`, calling `observe` after every iteration.
    pub fn run<P, S>(
        &self,
        problem: &P,
        solver: &mut S,
        mut observe: impl FnMut(&IterationReport),
    ) -> Outcome<S::State>
    where
        P: Problem,
        S: Solver<P>,
    {
        let started = Instant::now();
        let mut state = solver.init(problem);
        let mut convergence = Vec::with_capacity(self.max_iterations);
        let mut termination = Termination::MaxIterations;
        let mut checkpoints = Vec::new();
        for iteration in 0..self.max_iterations {
            if let Some(t) = self.target_cost {
                if state.best_cost() <= t {
                    termination = Termination::TargetReached;
                    break;
                }
            }
            if self.time_limit.is_some_and(|l| started.elapsed() >= l) {
                termination = Termination::TimeLimit;
                break;
            }
            if self
                .stop
                .as_ref()
                .is_some_and(|s| s.load(Ordering::Relaxed))
            {
                termination = Termination::Interrupted;
                break;
            }
            let progress = Progress {
                iteration,
                max_iterations: self.max_iterations,
            };
            state = solver.step(problem, state, progress);
            convergence.push(state.best_cost());
            let done = iteration + 1;
            if self
                .checkpoint_every
                .is_some_and(|k| k > 0 && done % k == 0 && done < self.max_iterations)
            {
                checkpoints.push(state.best_position().to_vec());
            }
            observe(&IterationReport {
                iteration: iteration + 1,
                max_iterations: self.max_iterations,
                best_cost: state.best_cost(),
                evaluations: state.evaluations(),
            });
        }
        Outcome {
            state,
            termination,
            convergence,
            elapsed: started.elapsed(),
            checkpoints,
        }
    }
}
