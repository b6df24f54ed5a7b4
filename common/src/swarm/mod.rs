//! Swarm optimizers on one shape (argmin-like): a [`Problem`] gives bounds and a cost, a
//! [`Solver`] has `init` and `step` over an explicit state, and the [`Executor`] alone owns the
//! loop, the budgets (iterations, target cost, wall time, a stop flag) and the observer.
//!
//! A new variant (IPSO, EPA-PSO, DE-PSO…) is one file implementing [`Solver`].

pub mod acopso;
pub mod cbpso;
pub mod depso;
pub mod epapso;
pub mod ipso;
pub mod lcpso;
pub mod ldiwpso;
pub mod multi;
pub mod nspso;
pub mod parallel;
pub mod population;
pub mod pso;
#[cfg(test)]
mod testfns;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use rand::rngs::StdRng;
use rand::Rng;

/// A box-bounded minimisation problem.
pub trait Problem: Sync {
    /// Lower bound of every dimension.
    fn lower(&self) -> &[f64];
    /// Upper bound of every dimension.
    fn upper(&self) -> &[f64];
    /// Cost of a position; lower is better. Must be finite for any in-bounds position.
    fn cost(&self, x: &[f64]) -> f64;
    /// Number of dimensions.
    fn dim(&self) -> usize {
        self.lower().len()
    }
    /// How many blocks the cost is a sum of (1: not decomposable). The fleet fitness, eq. (12),
    /// is a sum over vehicles, one block per chromosome; solvers keep their memories (o_pbest,
    /// o_gbest) block by block so a good chromosome is not forgotten because another vehicle of
    /// the same particle was bad.
    fn blocks(&self) -> usize {
        1
    }
    /// Dimensions of block `b`.
    fn block_range(&self, b: usize) -> std::ops::Range<usize> {
        let _ = b;
        0..self.dim()
    }
    /// Ranges of dimensions a solver moves as a whole: one random factor per range and one
    /// velocity scaling per range. The default, one range per dimension, is textbook PSO; a
    /// problem whose ranges are geometric objects (a vehicle's path) keeps them smooth this way.
    fn move_groups(&self) -> Vec<std::ops::Range<usize>> {
        (0..self.dim()).map(|d| d..d + 1).collect()
    }
    /// Cost split by block: writes block `b`'s share into `parts[b]` and returns the total, which
    /// equals the sum of the parts and [`Problem::cost`].
    fn cost_parts(&self, x: &[f64], parts: &mut [f64]) -> f64 {
        let c = self.cost(x);
        if let Some(p) = parts.first_mut() {
            *p = c;
        }
        c
    }
    /// True when `x` meets every hard constraint of the problem. Solvers that keep a set of
    /// feasible solutions (EPA-PSO, seed 001 §3.2.2) ask it; the default calls everything
    /// feasible, which is right for unconstrained problems.
    fn feasible(&self, x: &[f64]) -> bool {
        let _ = x;
        true
    }
    /// An initial position. Default: uniform in the box (seed 004 §3.1, `g ~ U`).
    fn sample(&self, rng: &mut StdRng) -> Vec<f64> {
        self.lower()
            .iter()
            .zip(self.upper())
            .map(|(lo, hi)| rng.random_range(*lo..=*hi))
            .collect()
    }
}

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

/// An optimizer: builds its state, then advances it one iteration at a time.
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

/// Implements [`VelocityCapped`] for solvers with a `max_velocity_fraction` field.
macro_rules! velocity_capped {
    ($($solver:ty),+) => {$(
        impl VelocityCapped for $solver {
            fn velocity_cap_mut(&mut self) -> &mut f64 {
                &mut self.max_velocity_fraction
            }
        }
    )+};
}

velocity_capped!(
    ipso::Ipso,
    pso::Pso,
    cbpso::Cbpso,
    nspso::Nspso,
    acopso::AcoPso,
    multi::MultiPso,
    epapso::EpaPso,
    ldiwpso::LdiwPso,
    lcpso::Lcpso,
    depso::DePso
);

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
        }
    }
}

#[cfg(test)]
mod tests {
    use super::multi::MultiPso;
    use super::pso::Pso;
    use super::testfns::{Rastrigin, ShiftedSphere};
    use super::*;

    #[test]
    fn a_velocity_cap_is_a_fraction_in_zero_to_one() {
        for ok in [1e-9, 0.1, 1.0] {
            assert!(is_valid_velocity_cap(ok), "{ok}");
        }
        for bad in [0.0, -0.1, 1.0 + 1e-12, f64::NAN, f64::INFINITY] {
            assert!(!is_valid_velocity_cap(bad), "{bad}");
        }
    }

    fn small_multi(mut m: MultiPso) -> MultiPso {
        m.populations = 6;
        m.particles = 20;
        m.leader_particles = 6;
        m
    }

    fn solve<S: Solver<ShiftedSphere>>(mut s: S, dim: usize, iters: usize) -> (f64, Vec<f64>) {
        let problem = ShiftedSphere::new(dim);
        let out = Executor::new(iters).run(&problem, &mut s, |_| {});
        (out.state.best_cost(), out.state.best_position().to_vec())
    }

    fn assert_converged(name: &str, dim: usize, (cost, x): (f64, Vec<f64>)) {
        let target = ShiftedSphere::new(dim).shift;
        assert!(cost < 1e-6, "{name}: best cost {cost}");
        for (a, b) in x.iter().zip(&target) {
            assert!((a - b).abs() < 1e-3, "{name}: {a} vs optimum {b}");
        }
    }

    #[test]
    fn adaptive_and_multi_population_optimizers_converge_on_the_shifted_sphere() {
        assert_converged("a-pso", 10, solve(Pso::adaptive(50, 7), 10, 300));
        assert_converged("mp-pso", 10, solve(small_multi(MultiPso::mp(7)), 10, 300));
        assert_converged("amp-pso", 10, solve(small_multi(MultiPso::amp(7)), 10, 300));
    }

    #[test]
    fn classic_pso_converges_in_low_dimension_and_stalls_in_high() {
        // Table 5's ω = 0.15 is a greedy setting: fine on a 3-D bowl...
        assert_converged("pso", 3, solve(Pso::classic(50, 7), 3, 300));
        // Seed 000's SPSO (ω = 0.5, c1 = c2 = 2) on the same bowl.
        assert_converged("spso", 3, solve(Pso::spso(30, 7), 3, 300));
        // ...but it loses its momentum before reaching the optimum in 10-D, the premature
        // convergence seed 004 §4.2 reports for classic PSO; A-PSO on the same budget does not.
        let (pso, _) = solve(Pso::classic(50, 7), 10, 300);
        let (apso, _) = solve(Pso::adaptive(50, 7), 10, 300);
        assert!(pso > 1e3 * apso.max(1e-12), "pso {pso} a-pso {apso}");
    }

    #[test]
    fn same_seed_same_result_whatever_the_threads() {
        let problem = Rastrigin::new(6);
        let ex = Executor::new(30);
        let mut one = small_multi(MultiPso::amp(11));
        one.threads = 1;
        let mut two = small_multi(MultiPso::amp(11));
        two.threads = 3;
        let a = ex.run(&problem, &mut one, |_| {});
        let b = ex.run(&problem, &mut two, |_| {});
        assert_eq!(a.convergence, b.convergence);
        assert_eq!(a.state.best_position(), b.state.best_position());
    }

    #[test]
    fn executor_owns_budgets() {
        let problem = ShiftedSphere::new(4);
        let mut s = Pso::classic(30, 1);
        let mut seen = 0;
        let out = Executor::new(25).run(&problem, &mut s, |r| seen = r.iteration);
        assert_eq!(out.termination, Termination::MaxIterations);
        assert_eq!((out.convergence.len(), seen), (25, 25));
        // Convergence is the best-so-far: never increases.
        assert!(out.convergence.windows(2).all(|w| w[1] <= w[0]));
        assert_eq!(out.state.evaluations(), 30 * 26);

        let ex = Executor {
            target_cost: Some(1e9),
            ..Executor::new(25)
        };
        let out = ex.run(&problem, &mut Pso::classic(30, 1), |_| {});
        assert_eq!(
            (out.termination, out.convergence.len()),
            (Termination::TargetReached, 0)
        );

        let stop = Arc::new(AtomicBool::new(true));
        let ex = Executor {
            stop: Some(stop),
            ..Executor::new(25)
        };
        let out = ex.run(&problem, &mut Pso::classic(30, 1), |_| {});
        assert_eq!(out.termination, Termination::Interrupted);
    }
}
