//! Tests across solvers: the executor's budgets, and the Zhi & Zuo 2024 solvers against each other.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use super::core::{is_valid_velocity_cap, Executor, Solver, SolverState, Termination};
use super::solvers::multi::MultiPso;
use super::solvers::pso::Pso;
use super::testfns::{Rastrigin, ShiftedSphere};

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
    // Lu et al.'s SPSO (ω = 0.5, c1 = c2 = 2) on the same bowl.
    assert_converged("spso", 3, solve(Pso::spso(30, 7), 3, 300));
    // ...but it loses its momentum before reaching the optimum in 10-D, the premature
    // convergence Zhi & Zuo 2024, §4.2 reports for classic PSO; A-PSO on the same budget does not.
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

#[test]
fn a_longer_amp_pso_run_repeats_the_default_run_and_ends_no_worse() {
    // Rastrigin's many local minima stall the greedy end of a sweep; more sweeps may leave one.
    use super::core::population::ADAPTIVE_SPAN;
    let problem = Rastrigin::new(6);
    for seed in 1..=3 {
        let solver = || {
            let mut m = MultiPso::amp(seed);
            (m.populations, m.particles, m.leader_particles, m.threads) = (3, 8, 3, 1);
            m
        };
        let short = Executor::new(ADAPTIVE_SPAN).run(&problem, &mut solver(), |_| {});
        let long = Executor::new(3 * ADAPTIVE_SPAN + 17).run(&problem, &mut solver(), |_| {});
        assert_eq!(
            long.convergence[..ADAPTIVE_SPAN],
            short.convergence[..],
            "seed {seed}: the first sweep differs"
        );
        assert!(
            long.state.best_cost() <= short.state.best_cost(),
            "seed {seed}"
        );
    }
}

#[test]
fn checkpoints_hold_the_best_after_each_sweep_before_the_last_iteration() {
    let problem = Rastrigin::new(4);
    let solver = || Pso::classic(10, 3);
    let every = |max: usize| Executor {
        checkpoint_every: Some(20),
        ..Executor::new(max)
    };
    let out = every(65).run(&problem, &mut solver(), |_| {});
    // After iterations 20, 40 and 60; 65 is the run's own end.
    assert_eq!(out.checkpoints.len(), 3);
    for (k, x) in out.checkpoints.iter().enumerate() {
        let shorter = Executor::new(20 * (k + 1)).run(&problem, &mut solver(), |_| {});
        assert_eq!(
            x.as_slice(),
            shorter.state.best_position(),
            "checkpoint {k}"
        );
    }
    // A run that ends on a sweep keeps no checkpoint there; none without the setting.
    assert_eq!(
        every(40)
            .run(&problem, &mut solver(), |_| {})
            .checkpoints
            .len(),
        1
    );
    let plain = Executor::new(65).run(&problem, &mut solver(), |_| {});
    assert!(plain.checkpoints.is_empty());
}
