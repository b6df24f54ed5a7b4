//! Every "best" a run reports is the cost of a position evaluated as a whole.
//!
//! The multi-population optimizers keep their memories block by block (one block per vehicle),
//! and a best assembled from blocks remembered next to different partners was never scored as
//! a whole: for a coupled cost (two vehicles' separation) it can look better than any fleet the
//! run has seen. These tests run every optimizer that keeps block memories on random coupled
//! problems, record every cost the problem returns, and check that each point of the
//! convergence curve is one of them and that the returned best costs what the curve ends at.

use std::collections::HashSet;
use std::ops::Range;
use std::path::Path;
use std::sync::Mutex;

use proptest::prelude::*;
use shoal_common::cost::FleetModel;
use shoal_common::distributed::lockstep;
use shoal_common::scenario::{Algorithm, Scenario};
use shoal_common::swarm::multi::MultiPso;
use shoal_common::swarm::pso::Pso;
use shoal_common::swarm::{Executor, Problem, Solver, SolverState};

/// `blocks` blocks of two dimensions on [−5, 5]. Each block pays its distance to its own target
/// and, for every other block, a clash (`clash` when their first coordinates are within 1 of
/// each other) and a tether (`tether` times that distance): a partner can make a block
/// cheaper or dearer, as a vehicle's arrival time and separation do. Every cost it returns
/// is recorded.
struct Coupled {
    targets: Vec<[f64; 2]>,
    clash: f64,
    tether: f64,
    lower: Vec<f64>,
    upper: Vec<f64>,
    seen: Mutex<HashSet<u64>>,
}

impl Coupled {
    fn new(targets: Vec<[f64; 2]>, clash: f64, tether: f64) -> Coupled {
        let dim = 2 * targets.len();
        Coupled {
            targets,
            clash,
            tether,
            lower: vec![-5.0; dim],
            upper: vec![5.0; dim],
            seen: Mutex::new(HashSet::new()),
        }
    }

    fn part(&self, x: &[f64], b: usize) -> f64 {
        let t = self.targets[b];
        let own = (x[2 * b] - t[0]).powi(2) + (x[2 * b + 1] - t[1]).powi(2);
        let coupling: f64 = (0..self.targets.len())
            .filter(|&o| o != b)
            .map(|o| {
                let d = (x[2 * b] - x[2 * o]).abs();
                self.tether * d + if d < 1.0 { self.clash } else { 0.0 }
            })
            .sum();
        own + coupling
    }

    fn was_seen(&self, cost: f64) -> bool {
        self.seen
            .lock()
            .map(|s| s.contains(&cost.to_bits()))
            .unwrap_or(false)
    }
}

impl Problem for Coupled {
    fn lower(&self) -> &[f64] {
        &self.lower
    }
    fn upper(&self) -> &[f64] {
        &self.upper
    }
    fn cost(&self, x: &[f64]) -> f64 {
        let mut parts = vec![0.0; self.targets.len()];
        self.cost_parts(x, &mut parts)
    }
    fn blocks(&self) -> usize {
        self.targets.len()
    }
    fn block_range(&self, b: usize) -> Range<usize> {
        2 * b..2 * b + 2
    }
    fn cost_parts(&self, x: &[f64], parts: &mut [f64]) -> f64 {
        for (b, p) in parts.iter_mut().enumerate() {
            *p = self.part(x, b);
        }
        let total = parts.iter().sum::<f64>();
        if let Ok(mut s) = self.seen.lock() {
            s.insert(total.to_bits());
        }
        total
    }
}

/// Runs `solver` for `iterations` on `problem` and checks the curve and the result.
fn check_true_best<S: Solver<Coupled>>(
    name: &str,
    problem: &Coupled,
    mut solver: S,
    iterations: usize,
) -> Result<(), TestCaseError> {
    let out = Executor::new(iterations).run(problem, &mut solver, |_| {});
    for (k, c) in out.convergence.iter().enumerate() {
        prop_assert!(
            problem.was_seen(*c),
            "{name}: the curve's {c} at iteration {} is no cost the problem returned",
            k + 1
        );
    }
    let best = out.state.best_cost();
    let truth = problem.cost(out.state.best_position());
    prop_assert_eq!(
        best.to_bits(),
        truth.to_bits(),
        "{}: best {} is {}",
        name,
        best,
        truth
    );
    prop_assert_eq!(out.convergence.last().copied(), Some(best), "{}", name);
    Ok(())
}

fn small(mut m: MultiPso) -> MultiPso {
    m.populations = 4;
    m.particles = 8;
    m.leader_particles = 4;
    m.threads = 1;
    m
}

fn targets() -> impl Strategy<Value = Vec<[f64; 2]>> {
    prop::collection::vec((-4.0..4.0f64, -4.0..4.0f64).prop_map(|(a, b)| [a, b]), 2..5)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn every_optimizer_with_block_memories_reports_only_true_evaluations(
        targets in targets(),
        clash in 0.0..20.0f64,
        tether in 0.0..2.0f64,
        seed in 0u64..1000,
    ) {
        let fresh = || Coupled::new(targets.clone(), clash, tether);
        check_true_best("amp-pso", &fresh(), small(MultiPso::amp(seed)), 40)?;
        check_true_best("mp-pso", &fresh(), small(MultiPso::mp(seed)), 40)?;
        check_true_best("a-pso", &fresh(), Pso::adaptive(12, seed), 40)?;
        check_true_best("pso", &fresh(), Pso::classic(12, seed), 40)?;
    }
}

/// The distributed leader (run in one process, round by round as over the network): its best
/// and the end of its curve are the true fleet fitness of the plan it returns.
#[test]
fn the_distributed_leader_reports_only_true_evaluations() -> Result<(), Box<dyn std::error::Error>>
{
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/amp-pso-1.toml");
    for (seed, algorithm) in [
        (1, Algorithm::AmpPso),
        (2, Algorithm::MpPso),
        (3, Algorithm::AmpPso),
    ] {
        let mut scenario = Scenario::load(&path)?;
        let o = &mut scenario.optimizer;
        o.algorithm = algorithm;
        o.seed = seed;
        o.iterations = 30;
        o.particles = 10;
        o.leader_particles = 5;
        o.distributed.agent_populations = 3;
        let out = lockstep::run(&scenario, None, &mut |_| {});
        let truth = FleetModel::new(&scenario).cost(&out.best_x);
        assert_eq!(
            out.best_cost.to_bits(),
            truth.to_bits(),
            "seed {seed}: best {} is {truth}",
            out.best_cost
        );
        assert_eq!(
            out.convergence.last().copied(),
            Some(out.best_cost),
            "seed {seed}"
        );
        assert!(
            out.convergence.windows(2).all(|w| w[1] <= w[0]),
            "seed {seed}: the best-so-far went up"
        );
    }
    Ok(())
}
