//! Distributed AMP-PSO in one process (no network) over several seeds: fitness, feasibility and
//! time per seed. `cargo run --release -p shoal-common --example lockstep -- SCENARIO SEEDS`
use shoal_common::cost::FleetModel;
use shoal_common::distributed::lockstep;
use shoal_common::plan::assess;
use shoal_common::scenario::Scenario;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let path = args
        .get(1)
        .ok_or("usage: lockstep SCENARIO [SEEDS] [EVERY] [THREADS]")?;
    let seeds: u64 = args.get(2).map_or(Ok(10), |s| s.parse())?;
    let mut s = Scenario::load(std::path::Path::new(path))?;
    if let Some(e) = args.get(3) {
        s.optimizer.exchange_every = e.parse()?;
    }
    if let Some(t) = args.get(4) {
        s.optimizer.threads = t.parse()?;
    }
    let mut fits = Vec::new();
    for seed in 1..=seeds {
        s.optimizer.seed = seed;
        let out = lockstep::run(&s, None, &mut |_| {});
        let model = FleetModel::new(&s);
        let e = model.evaluate(&out.best_x);
        let a = assess(&s, &e.trajectories.to_vec());
        println!(
            "seed {seed}: fitness {:.4} feasible {} min sep {:.1} time {:.2} s evals {}",
            out.best_cost,
            a.violations.is_empty(),
            a.fleet.min_separation_m.unwrap_or(f64::INFINITY),
            out.runtime_s,
            out.evaluations
        );
        fits.push(out.best_cost);
    }
    fits.sort_by(f64::total_cmp);
    let n = fits.len();
    let median = if n % 2 == 1 {
        fits[n / 2]
    } else {
        0.5 * (fits[n / 2 - 1] + fits[n / 2])
    };
    println!("median {median:.4}");
    Ok(())
}
