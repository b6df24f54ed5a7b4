//! `shoal-coordinator compare`: every algorithm on every scenario over several seeds, as a
//! markdown table like Zhi & Zuo's Figures 7, 9 and 11 (run time, collisions, fitness).

use std::fmt::Write;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use shoal_common::plan::Plan;
use shoal_common::scenario::{Algorithm, Scenario};
use shoal_common::stats;

use std::time::Instant;

use crate::distributed::{default_mission_id, plan_distributed, DistributedOptions};
use crate::planning::planner::plan_alone_and_refined;

/// Aggregates of one (scenario, algorithm) cell over all seeds.
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    /// Scenario name.
    pub scenario: String,
    /// Algorithm.
    pub algorithm: Algorithm,
    /// `in-process`, `in-process+refine` or `distributed`.
    pub mode: String,
    /// Seeds run.
    pub runs: usize,
    /// Plans with no violation at all.
    pub feasible: usize,
    /// Plans with zero hard-obstacle collisions.
    pub collision_free: usize,
    /// Plans whose minimum separation is at least d_min.
    pub separated: usize,
    /// Fitness of each run, in seed order.
    pub fitness: Vec<f64>,
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
    pub crawler: Option<crate::report::crawler_stats::CrawlerStats>,
}

impl Cell {
    /// Median fitness over the seeds.
    pub fn median_fitness(&self) -> f64 {
        stats::quantile(&self.fitness, 0.5)
    }

    /// Best and worst fitness over the seeds.
    pub fn fitness_range(&self) -> (f64, f64) {
        (stats::min(&self.fitness), stats::max(&self.fitness))
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
    let runtime: Vec<f64> = plans.iter().map(|p| p.runtime_s).collect();
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
        fitness: plans.iter().map(|p| p.fitness).collect(),
        median_runtime_s: stats::quantile(&runtime, 0.5),
        median_wall_s: stats::quantile(walls, 0.5),
        mean_collisions: plans
            .iter()
            .map(|p| p.fleet.hard_collisions as f64)
            .sum::<f64>()
            / plans.len().max(1) as f64,
        worst_separation_m: plans.iter().map(sep).fold(f64::INFINITY, f64::min),
        evals_per_s: if time > 0.0 { evals as f64 / time } else { 0.0 },
        crawler: crate::report::crawler_stats::CrawlerStats::of(plans),
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
    stop: &Arc<AtomicBool>,
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
                let mut refined = Vec::new();
                for seed in seeds.clone() {
                    if stop.load(Ordering::Relaxed) {
                        return Ok(cells);
                    }
                    let mut s = s.clone();
                    s.optimizer.algorithm = a;
                    s.optimizer.seed = seed;
                    // The algorithms as their papers give them: no touch-up or refinement
                    // afterwards; in process also the same run refined, beside it.
                    s.optimizer.touch_up = false;
                    s.optimizer.refine = false;
                    let started = Instant::now();
                    let p = match distributed {
                        Some(o) if remote => {
                            let mut o = o.clone();
                            o.mission = default_mission_id(&s);
                            plan_distributed(&s, &o, stop, &mut |_| {})?
                        }
                        _ => {
                            let (alone, with) = plan_alone_and_refined(&s);
                            refined.extend(with);
                            alone
                        }
                    };
                    walls.push(started.elapsed().as_secs_f64());
                    progress(&p);
                    plans.push(p);
                }
                cells.push(cell(&s.name, a, &plans, &walls, s.fleet.d_min_m));
                if !refined.is_empty() {
                    // Wall times are the pair's: the refined plan's own time is its runtime.
                    let runtimes: Vec<f64> = refined.iter().map(|p| p.runtime_s).collect();
                    cells.push(cell(&s.name, a, &refined, &runtimes, s.fleet.d_min_m));
                }
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
            c.median_fitness(),
            c.fitness_range().0,
            c.fitness_range().1,
            c.median_runtime_s,
            c.median_wall_s,
            c.evals_per_s
        );
    }
    s
}

/// One line naming the seeds a table was made on, e.g. "Seeds 11–30 (20 per cell)."
pub fn seeds_line(seeds: &std::ops::Range<u64>) -> String {
    let n = seeds.end.saturating_sub(seeds.start);
    match n {
        0 => "No seeds.\n\n".to_string(),
        1 => format!("Seed {}.\n\n", seeds.start),
        _ => format!(
            "Seeds {}–{} ({n} per cell).\n\n",
            seeds.start,
            seeds.end - 1
        ),
    }
}

#[cfg(test)]
mod tests;
