//! The one solver loop every in-process planner runs: an optimizer under an [`Executor`], and
//! what it leaves behind.

use shoal_common::swarm::{Executor, IterationReport, Problem, Solver, SolverState, Termination};

/// What an optimizer run leaves behind, whatever the algorithm and the mode.
pub struct RunResult {
    /// Best fleet position (a true evaluation).
    pub best_x: Vec<f64>,
    /// Best fitness after each iteration.
    pub convergence: Vec<f64>,
    /// Cost evaluations.
    pub evaluations: u64,
    /// Why it stopped.
    pub termination: Termination,
    /// Wall time, seconds.
    pub runtime_s: f64,
}

/// Runs `solver` on `model` under `executor`.
pub fn run_solver<P: Problem, S: Solver<P>>(
    model: &P,
    mut solver: S,
    executor: &Executor,
    observe: &mut dyn FnMut(&IterationReport),
) -> RunResult {
    let out = executor.run(model, &mut solver, observe);
    RunResult {
        best_x: out.state.best_position().to_vec(),
        evaluations: out.state.evaluations(),
        convergence: out.convergence,
        termination: out.termination,
        runtime_s: out.elapsed.as_secs_f64(),
    }
}
