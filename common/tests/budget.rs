//! More budget never makes the swarm's best worse: the adaptive schedule of eq. (7)–(8)
//! (Zhi & Zuo 2024) sweeps once over a budget of up to Table 5's 200 iterations and again every
//! 200 iterations beyond, so a longer run repeats the shorter one's first 200 iterations exactly
//! and keeps the best it has seen.

use std::path::Path;

use shoal_common::distributed::lockstep;
use shoal_common::scenario::Scenario;
use shoal_common::swarm::multi::MultiPso;
use shoal_common::swarm::population::ADAPTIVE_SPAN;
use shoal_common::swarm::{Executor, SolverState};

/// Rastrigin in 6-D: many local minima, so the greedy end of a sweep stalls in one of them.
fn rastrigin(x: &[f64]) -> f64 {
    x.iter()
        .map(|v| v * v - 10.0 * (2.0 * std::f64::consts::PI * v).cos() + 10.0)
        .sum()
}

struct Rastrigin {
    lower: Vec<f64>,
    upper: Vec<f64>,
}

impl shoal_common::swarm::Problem for Rastrigin {
    fn lower(&self) -> &[f64] {
        &self.lower
    }
    fn upper(&self) -> &[f64] {
        &self.upper
    }
    fn cost(&self, x: &[f64]) -> f64 {
        rastrigin(x)
    }
}

#[test]
fn a_longer_amp_pso_run_repeats_the_default_run_and_ends_no_worse() {
    let problem = Rastrigin {
        lower: vec![-5.12; 6],
        upper: vec![5.12; 6],
    };
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
fn a_longer_distributed_run_repeats_the_default_run_and_ends_no_worse(
) -> Result<(), Box<dyn std::error::Error>> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/amp-pso-1.toml");
    let mut scenario = Scenario::load(&path)?;
    let o = &mut scenario.optimizer;
    (o.particles, o.leader_particles, o.seed) = (8, 4, 2);
    o.distributed.agent_populations = 2;
    o.iterations = ADAPTIVE_SPAN;
    let short = lockstep::run(&scenario, None, &mut |_| {});
    scenario.optimizer.iterations = ADAPTIVE_SPAN + 50;
    let long = lockstep::run(&scenario, None, &mut |_| {});
    assert_eq!(long.convergence[..ADAPTIVE_SPAN], short.convergence[..]);
    assert!(long.best_cost <= short.best_cost);
    Ok(())
}
