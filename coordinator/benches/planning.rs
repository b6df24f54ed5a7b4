//! Planning benchmarks: one fitness evaluation per scenario, and a whole default-budget AMP-PSO
//! plan of scenario 3 (Zhi & Zuo 2024, Table 6's hardest case). Run with `cargo bench -p shoal-coordinator`.

// `criterion_group!` defines an undocumented `pub fn`; a benchmark binary has no public API.
#![allow(missing_docs)]

use std::hint::black_box;
use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion};
use rand::rngs::StdRng;
use rand::SeedableRng;
use shoal_common::cost::FleetModel;
use shoal_common::scenario::Scenario;
use shoal_common::swarm::Problem;
use shoal_coordinator::planning::planner::plan_in_process;

fn scenario(n: u32) -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../scenarios/amp-pso-{n}.toml"));
    match Scenario::load(&path) {
        Ok(s) => s,
        Err(e) => panic!("benchmark scenario: {e}"),
    }
}

fn fitness(c: &mut Criterion) {
    for n in 1..=3 {
        let model = FleetModel::new(&scenario(n));
        let mut rng = StdRng::seed_from_u64(1);
        let xs: Vec<Vec<f64>> = (0..64).map(|_| model.sample(&mut rng)).collect();
        let mut k = 0;
        c.bench_function(&format!("fitness/amp-pso-{n}"), |b| {
            b.iter(|| {
                k = (k + 1) % xs.len();
                black_box(model.cost(black_box(&xs[k])))
            })
        });
    }
}

fn plan_scenario3(c: &mut Criterion) {
    let s = scenario(3);
    let mut g = c.benchmark_group("plan");
    g.sample_size(10);
    g.bench_function("amp-pso-3/default-budget", |b| {
        b.iter(|| black_box(plan_in_process(&s, None, &mut |_| {}).fitness))
    });
    g.finish();
}

criterion_group!(benches, fitness, plan_scenario3);
criterion_main!(benches);
