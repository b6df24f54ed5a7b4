//! The one solver loop every in-process planner runs: an optimizer under an [`Executor`], and
//! what it leaves behind.

use shoal_common::scenario::OptimizerSettings;
use shoal_common::swarm::catalog::{with_solver, MultiSizes, SolverSettings, SolverVisitor};
use shoal_common::swarm::{Executor, IterationReport, Problem, Solver, SolverState, Termination};

/// What an optimizer run leaves behind, whatever the algorithm and the mode.
#[derive(Debug, Clone)]
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
    /// The best position after each sweep the executor was asked to keep
    /// ([`Executor::checkpoint_every`]), oldest first.
    pub checkpoints: Vec<Vec<f64>>,
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
        checkpoints: out.checkpoints,
    }
}

/// Runs the solver the catalog builds for `o.algorithm` on `problem` under `executor`.
pub fn run_algorithm<P: Problem>(
    problem: &P,
    o: &OptimizerSettings,
    executor: &Executor,
    observe: &mut dyn FnMut(&IterationReport),
) -> RunResult {
    let run = RunOn {
        problem,
        executor,
        observe,
    };
    with_solver(o.algorithm, &solver_settings(o), run)
}

/// The catalog's settings a scenario's optimizer settings give.
pub fn solver_settings(o: &OptimizerSettings) -> SolverSettings {
    SolverSettings {
        particles: o.particles,
        multi: MultiSizes {
            populations: o.populations,
            particles: o.particles,
            leader_particles: o.leader_particles,
            exchange_every: o.exchange_every,
        },
        threads: o.threads,
        seed: o.seed,
        velocity_cap: o.max_velocity_fraction,
    }
}

/// [`run_solver`] as a catalog visitor.
struct RunOn<'a, P> {
    /// The problem.
    problem: &'a P,
    /// Budgets and stop flag.
    executor: &'a Executor,
    /// Sees every iteration.
    observe: &'a mut dyn FnMut(&IterationReport),
}

impl<P: Problem> SolverVisitor<P> for RunOn<'_, P> {
    type Output = RunResult;
    fn visit<S: Solver<P>>(self, solver: S) -> RunResult {
        run_solver(self.problem, solver, self.executor, self.observe)
    }
}
