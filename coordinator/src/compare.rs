//! `shoal-coordinator compare`: every algorithm on every scenario over several seeds, as a
//! markdown table like seed 004's Figures 7, 9 and 11 (run time, collisions, fitness).

use std::fmt::Write;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

use shoal_common::plan::Plan;
use shoal_common::scenario::{Algorithm, Scenario};

use std::time::Instant;

use crate::distributed::{default_mission_id, plan_distributed, DistributedOptions};
use crate::planner::plan_in_process;

/// Aggregates of one (scenario, algorithm) cell over all seeds.
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    /// Scenario name.
    pub scenario: String,
    /// Algorithm.
    pub algorithm: Algorithm,
    /// `in-process` or `distributed`.
    pub mode: String,
    /// Seeds run.
    pub runs: usize,
    /// Plans with no violation at all.
    pub feasible: usize,
    /// Plans with zero hard-obstacle collisions.
    pub collision_free: usize,
    /// Plans whose minimum separation is at least d_min.
    pub separated: usize,
    /// Median fitness.
    pub median_fitness: f64,
    /// Best and worst fitness.
    pub fitness_range: (f64, f64),
    /// Median planning time (plan.json's runtime_s), seconds.
    pub median_runtime_s: f64,
    /// Median wall time of the whole call (for distributed runs: router, agent processes,
    /// joining, planning and teardown), seconds.
    pub median_wall_s: f64,
    /// Mean hard collisions per plan.
    pub mean_collisions: f64,
    /// Smallest separation over all seeds, metres.
    pub worst_separation_m: f64,
    /// Evaluations per second over all runs.
    pub evals_per_s: f64,
    /// Crawler figures, when the scenario has crawlers.
    pub crawler: Option<crate::crawler_table::CrawlerStats>,
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Summarises the plans of one cell; `walls` are the wall times of the calls that made them.
pub fn cell(
    scenario: &str,
    algorithm: Algorithm,
    plans: &[Plan],
    walls: &[f64],
    d_min: f64,
) -> Cell {
    let mut fitness: Vec<f64> = plans.iter().map(|p| p.fitness).collect();
    let mut walls = walls.to_vec();
    let mut runtime: Vec<f64> = plans.iter().map(|p| p.runtime_s).collect();
    let evals: u64 = plans.iter().map(|p| p.evaluations).sum();
    let time: f64 = runtime.iter().sum();
    let sep = |p: &Plan| p.fleet.min_separation_m.unwrap_or(f64::INFINITY);
    Cell {
        scenario: scenario.to_string(),
        algorithm,
        mode: plans
            .first()
            .map_or_else(|| "in-process".to_string(), |p| p.mode.clone()),
        runs: plans.len(),
        feasible: plans.iter().filter(|p| p.feasible).count(),
        collision_free: plans
            .iter()
            .filter(|p| p.fleet.hard_collisions == 0)
            .count(),
        separated: plans.iter().filter(|p| sep(p) >= d_min).count(),
        fitness_range: (
            fitness.iter().copied().fold(f64::INFINITY, f64::min),
            fitness.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        ),
        median_fitness: median(&mut fitness),
        median_runtime_s: median(&mut runtime),
        median_wall_s: median(&mut walls),
        mean_collisions: plans
            .iter()
            .map(|p| p.fleet.hard_collisions as f64)
            .sum::<f64>()
            / plans.len().max(1) as f64,
        worst_separation_m: plans.iter().map(sep).fold(f64::INFINITY, f64::min),
        evals_per_s: if time > 0.0 { evals as f64 / time } else { 0.0 },
        crawler: crate::crawler_table::CrawlerStats::of(plans),
    }
}

/// Runs `algorithms` × `seeds` on every scenario, in-process and, for the multi-population
/// algorithms when `distributed` is given, also distributed (one agent process per vehicle);
/// `progress` sees each finished plan. When `stop` is raised it finishes the plan in hand and
/// returns the cells completed so far.
pub fn compare(
    scenarios: &[Scenario],
    algorithms: &[Algorithm],
    seeds: std::ops::Range<u64>,
    distributed: Option<&DistributedOptions>,
    stop: &AtomicBool,
    progress: &mut dyn FnMut(&Plan),
) -> anyhow::Result<Vec<Cell>> {
    let mut cells = Vec::new();
    for s in scenarios {
        for &a in algorithms {
            let multi = a.is_multi_population();
            for remote in [false, true] {
                if remote && !(multi && distributed.is_some()) {
                    continue;
                }
                let mut plans = Vec::new();
                let mut walls = Vec::new();
                for seed in seeds.clone() {
                    if stop.load(Ordering::Relaxed) {
                        return Ok(cells);
                    }
                    let mut s = s.clone();
                    s.optimizer.algorithm = a;
                    s.optimizer.seed = seed;
                    let started = Instant::now();
                    let p = match distributed {
                        Some(o) if remote => {
                            let mut o = o.clone();
                            o.mission = default_mission_id(&s);
                            plan_distributed(&s, &o, stop, &mut |_| {})?
                        }
                        _ => plan_in_process(&s, None, &mut |_| {}),
                    };
                    walls.push(started.elapsed().as_secs_f64());
                    progress(&p);
                    plans.push(p);
                }
                cells.push(cell(&s.name, a, &plans, &walls, s.fleet.d_min_m));
            }
        }
    }
    Ok(cells)
}

/// The cells as a markdown table.
pub fn markdown(cells: &[Cell]) -> String {
    let mut s = String::from(
        "| scenario | algorithm | mode | runs | feasible | no hard collision | separation ≥ d_min | mean collisions | worst separation (m) | median fitness | fitness best–worst | median run time (s) | median wall time (s) | evaluations/s |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for c in cells {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {:.1} | {:.1} | {:.4} | {:.4}–{:.4} | {:.2} | {:.2} | {:.0} |",
            c.scenario,
            c.algorithm.as_str(),
            c.mode,
            c.runs,
            c.feasible,
            c.collision_free,
            c.separated,
            c.mean_collisions,
            c.worst_separation_m,
            c.median_fitness,
            c.fitness_range.0,
            c.fitness_range.1,
            c.median_runtime_s,
            c.median_wall_s,
            c.evals_per_s
        );
    }
    s
}

/// `shoal-coordinator compare`.
#[derive(Debug, Clone, clap::Args)]
pub struct CompareArgs {
    /// Scenario files.
    #[arg(required = true, env = "SHOAL_SCENARIOS", value_delimiter = ',')]
    pub scenarios: Vec<PathBuf>,
    /// Seeds 1..=N.
    #[arg(long, default_value_t = 10, env = "SHOAL_SEEDS", value_parser = clap::value_parser!(u64).range(1..))]
    pub seeds: u64,
    /// Algorithms to compare.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "amp-pso,a-pso,mp-pso,pso",
        env = "SHOAL_ALGORITHMS"
    )]
    pub algorithms: Vec<Algorithm>,
    /// Iterations (overrides the scenarios').
    #[arg(long, env = "SHOAL_ITERATIONS")]
    pub iterations: Option<usize>,
    /// Also plan every multi-population cell distributed: one local agent process per vehicle
    /// over the embedded Zenoh router, side by side with the in-process run.
    #[arg(long, env = "SHOAL_DISTRIBUTED")]
    pub distributed: bool,
    /// Write the markdown table here too.
    #[arg(long, env = "SHOAL_OUT")]
    pub out: Option<PathBuf>,
    /// Crawler scenarios: grid spacing of the reference shortest admissible path, metres.
    #[arg(long, default_value_t = 0.5, env = "SHOAL_REFERENCE_CELL")]
    pub reference_cell: f64,
}
