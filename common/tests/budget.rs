//! More budget never makes the swarm's best worse: the adaptive schedule of eq. (7)–(8)
//! (Zhi & Zuo 2024) sweeps once over a budget of up to Table 5's 200 iterations and again every
//! 200 iterations beyond, so a longer run repeats the shorter one's first 200 iterations exactly
//! and keeps the best it has seen. The in-process case is in the swarm's unit tests
//! (`a_longer_amp_pso_run_repeats_the_default_run_and_ends_no_worse`).

use std::path::Path;

use shoal_common::distributed::lockstep;
use shoal_common::scenario::Scenario;
use shoal_common::swarm::population::ADAPTIVE_SPAN;

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
