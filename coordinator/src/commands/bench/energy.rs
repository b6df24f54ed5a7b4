//! `bench-energy`: Zhang et al.'s comparison (§4, Tables 3–4) — PSO on length only, M-PSO and
//! EPA-PSO at several iteration budgets over several seeds — as a markdown table with the
//! paper's numbers beside ours.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use anyhow::Context;
use shoal_common::energy::EnergyTerms;
use shoal_common::scenario::{Algorithm, Scenario};

use crate::commands::bench::pool::run_jobs;
use crate::planning::energy;

/// `shoal-coordinator bench-energy`.
#[derive(Debug, Clone, clap::Args)]
pub struct BenchEnergyArgs {
    /// Scenario file (one AUV; its algorithm, iterations and seed are overridden).
    #[arg(default_value = "scenarios/epa-pso.toml")]
    pub scenario: PathBuf,
    /// Seeds per cell (1..=runs).
    #[arg(long, default_value_t = 10)]
    pub runs: u64,
    /// Iteration budgets, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = vec![100, 200, 500])]
    pub iterations: Vec<usize>,
    /// Worker threads (the numbers do not depend on it).
    #[arg(long, default_value_t = 2)]
    pub threads: usize,
    /// Also write the table to this file.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// The three methods of Zhang et al. 2022, §4, in the paper's order.
pub const METHODS: [Algorithm; 3] = [Algorithm::PsoLength, Algorithm::MPso, Algorithm::EpaPso];

/// Zhang et al. 2022, Table 3 (fitness, q_e, q_r, q_a, q_path) and Table 4 (f_f), by budget then method.
const PAPER: [(usize, [[f64; 6]; 3]); 3] = [
    (
        100,
        [
            [93.81, 280.36, 77.81, 283.50, 93.81, 183.87],
            [92.87, 104.68, 32.05, 48.87, 185.87, 92.87],
            [80.76, 81.83, 24.29, 41.73, 206.58, 88.60],
        ],
    ),
    (
        200,
        [
            [96.23, 335.12, 71.39, 194.20, 96.23, 174.24],
            [92.07, 123.28, 15.67, 43.52, 187.80, 92.07],
            [67.44, 83.19, 12.39, 42.77, 195.14, 83.37],
        ],
    ),
    (
        500,
        [
            [93.41, 334.00, 43.02, 268.97, 93.41, 248.42],
            [96.61, 87.00, 27.24, 52.05, 220.12, 109.71],
            [65.71, 60.16, 8.75, 25.01, 218.81, 79.43],
        ],
    ),
];

/// One run's figures.
#[derive(Debug, Clone, Copy)]
pub struct Run {
    /// Iteration budget.
    pub iterations: usize,
    /// Method.
    pub algorithm: Algorithm,
    /// Seed.
    pub seed: u64,
    /// The method's own final fitness.
    pub fitness: f64,
    /// Zhang et al. 2022 figures of the final path.
    pub terms: EnergyTerms,
    /// No violation at all.
    pub feasible: bool,
    /// Wall time, seconds.
    pub runtime_s: f64,
}

/// Runs every (budget, method, seed) cell, `threads` at a time; `stop` ends early.
pub fn bench(
    scenario: &Scenario,
    args: &BenchEnergyArgs,
    stop: &AtomicBool,
    progress: &(dyn Fn(&Run, usize, usize) + Sync),
) -> Vec<Run> {
    let mut jobs = Vec::new();
    for &iterations in &args.iterations {
        for algorithm in METHODS {
            for seed in 1..=args.runs {
                jobs.push((iterations, algorithm, seed));
            }
        }
    }
    let work = |&(iterations, algorithm, seed): &(usize, Algorithm, u64)| {
        let mut sc = scenario.clone();
        sc.optimizer.algorithm = algorithm;
        sc.optimizer.iterations = iterations;
        sc.optimizer.seed = seed;
        let plan = energy::plan(&sc, None, &mut |_| {});
        Run {
            iterations,
            algorithm,
            seed,
            fitness: plan.fitness,
            terms: plan
                .vehicles
                .first()
                .and_then(|v| v.energy)
                .unwrap_or_default(),
            feasible: plan.feasible,
            runtime_s: plan.runtime_s,
        }
    };
    let mut runs = run_jobs(&jobs, args.threads, stop, &work, progress);
    runs.sort_by_key(|r| {
        (
            r.iterations,
            METHODS.iter().position(|m| *m == r.algorithm),
            r.seed,
        )
    });
    runs
}

fn mean(v: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    if n == 0 {
        f64::NAN
    } else {
        s / n as f64
    }
}

/// The markdown tables: means per (budget, method), the q_e ratio to the length-only PSO, and
/// the paper's numbers.
pub fn markdown(runs: &[Run]) -> String {
    let mut s = String::new();
    s.push_str("| iterations | method | runs | fitness | q_e (J) | q_r (m²) | q_a (deg²) | q_path (m) | f_f | min turn radius (m) | max \\|pitch\\| (°) | runs with q_r = q_a = 0 | feasible runs | q_e / PSO's | s per run |\n");
    s.push_str("|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    let mut budgets: Vec<usize> = runs.iter().map(|r| r.iterations).collect();
    budgets.dedup();
    for &b in &budgets {
        let pso_qe = mean(
            runs.iter()
                .filter(|r| r.iterations == b && r.algorithm == Algorithm::PsoLength)
                .map(|r| r.terms.q_e),
        );
        for m in METHODS {
            let cell: Vec<&Run> = runs
                .iter()
                .filter(|r| r.iterations == b && r.algorithm == m)
                .collect();
            if cell.is_empty() {
                continue;
            }
            let avg = |f: &dyn Fn(&Run) -> f64| mean(cell.iter().map(|r| f(r)));
            let qe = avg(&|r| r.terms.q_e);
            let min_radius = cell
                .iter()
                .map(|r| r.terms.min_turn_radius_m)
                .fold(f64::INFINITY, f64::min);
            let max_pitch = cell
                .iter()
                .map(|r| r.terms.max_pitch_deg.max(-r.terms.min_pitch_deg))
                .fold(0.0, f64::max);
            let clean = cell
                .iter()
                .filter(|r| r.terms.q_r == 0.0 && r.terms.q_a == 0.0)
                .count();
            let feasible = cell.iter().filter(|r| r.feasible).count();
            s.push_str(&format!(
                "| {b} | {} | {} | {:.4} | {:.0} | {:.3} | {:.3} | {:.1} | {:.1} | {:.2} | {:.2} | {clean} | {feasible} | {:.1} % | {:.2} |\n",
                m.as_str(),
                cell.len(),
                avg(&|r| r.fitness),
                qe,
                avg(&|r| r.terms.q_r),
                avg(&|r| r.terms.q_a),
                avg(&|r| r.terms.q_path),
                avg(&|r| r.terms.f_f),
                min_radius,
                max_pitch,
                100.0 * qe / pso_qe,
                avg(&|r| r.runtime_s),
            ));
        }
    }
    s.push_str("\nZhang et al.'s own numbers (Table 3, Table 4; its energy unit is not stated, its fitness is normalised differently):\n\n");
    s.push_str(
        "| iterations | method | fitness | q_e | q_r | q_a | q_path | f_f | q_e / PSO's |\n",
    );
    s.push_str("|---:|---|---:|---:|---:|---:|---:|---:|---:|\n");
    for (b, rows) in PAPER {
        for (m, r) in METHODS.iter().zip(rows) {
            s.push_str(&format!(
                "| {b} | {} | {} | {} | {} | {} | {} | {} | {:.1} % |\n",
                m.as_str(),
                r[0],
                r[1],
                r[2],
                r[3],
                r[4],
                r[5],
                100.0 * r[1] / rows[0][1]
            ));
        }
    }
    s
}

/// The command.
pub fn command(args: &BenchEnergyArgs, stop: &AtomicBool) -> anyhow::Result<i32> {
    let scenario = Scenario::load(&args.scenario)?;
    if args.runs == 0 || args.iterations.is_empty() || args.iterations.contains(&0) {
        anyhow::bail!("--runs and every --iterations budget must be at least 1");
    }
    let runs = bench(&scenario, args, stop, &|r, n, total| {
        eprintln!(
            "[{n}/{total}] {} iterations, {} seed {}: fitness {:.4}, q_e {:.0} J, q_r {:.3}, q_a {:.3}, {:.2} s",
            r.iterations,
            r.algorithm.as_str(),
            r.seed,
            r.fitness,
            r.terms.q_e,
            r.terms.q_r,
            r.terms.q_a,
            r.runtime_s
        )
    });
    let table = markdown(&runs);
    print!("{table}");
    if let Some(out) = &args.out {
        std::fs::write(out, &table).with_context(|| format!("cannot write {}", out.display()))?;
    }
    Ok(0)
}
