//! `shoal-coordinator compare`: every algorithm on every scenario over several seeds, as a
//! markdown table like seed 004's Figures 7, 9 and 11 (run time, collisions, fitness).

use std::fmt::Write;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use shoal_common::plan::Plan;
use shoal_common::scenario::{Algorithm, Scenario};
use shoal_common::stats;

use std::time::Instant;

use crate::distributed::{default_mission_id, plan_distributed, DistributedOptions};
use crate::planning::planner::plan_in_process;

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
                for seed in seeds.clone() {
                    if stop.load(Ordering::Relaxed) {
                        return Ok(cells);
                    }
                    let mut s = s.clone();
                    s.optimizer.algorithm = a;
                    s.optimizer.seed = seed;
                    // The algorithms as their papers give them: no touch-up afterwards.
                    s.optimizer.touch_up = false;
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
mod tests {
    use super::*;
    use std::path::Path;

    /// Two AUVs crossing a 1 km box, on a tiny budget.
    fn two_auvs() -> Scenario {
        let auv = |id: &str, start: [f64; 3], goal: [f64; 3]| {
            format!(
                "[[vehicles]]\nid = \"{id}\"\nkind = \"auv\"\nstart = {start:?}\ngoal = {goal:?}\n\
                 speed_min_mps = 0.5\nspeed_max_mps = 1.5\nmax_turn_deg = 35.0\nmax_pitch_deg = 20.0\n"
            )
        };
        let text = format!(
            "name = \"pair\"\n[bounds]\nmin = [0.0, 0.0, 0.0]\nmax = [1000.0, 1000.0, 500.0]\n{}{}\
             [fleet]\nd_min_m = 50.0\nmission_time_s = 1000.0\n\
             [optimizer]\nwaypoints = 4\nparticles = 10\niterations = 5\n",
            auv("a", [100.0, 100.0, 100.0], [900.0, 900.0, 100.0]),
            auv("b", [100.0, 900.0, 100.0], [900.0, 100.0, 100.0]),
        );
        match Scenario::parse(&text, Path::new("pair.toml")) {
            Ok(s) => s,
            Err(e) => panic!("fixture does not parse: {e}"),
        }
    }

    #[test]
    fn cells_hold_every_seeds_fitness_in_seed_order_and_their_median_and_range() {
        let scenario = two_auvs();
        let mut seen: Vec<(String, u64, f64)> = Vec::new();
        let cells = compare(
            std::slice::from_ref(&scenario),
            &[Algorithm::Pso, Algorithm::APso],
            1..4,
            None,
            &Arc::new(AtomicBool::new(false)),
            &mut |p| seen.push((p.algorithm.clone(), p.seed, p.fitness)),
        )
        .unwrap_or_else(|e| panic!("compare failed: {e}"));
        assert_eq!(cells.len(), 2);
        assert_eq!(seen.len(), 6);
        for (c, name) in cells.iter().zip(["pso", "a-pso"]) {
            let own: Vec<&(String, u64, f64)> = seen.iter().filter(|s| s.0 == name).collect();
            assert_eq!(own.iter().map(|s| s.1).collect::<Vec<_>>(), [1, 2, 3]);
            let fitness: Vec<f64> = own.iter().map(|s| s.2).collect();
            assert_eq!(c.fitness, fitness);
            assert_eq!((c.runs, c.mode.as_str()), (3, "in-process"));
            let mut sorted = fitness.clone();
            sorted.sort_by(f64::total_cmp);
            assert_eq!(c.median_fitness(), sorted[1]);
            assert_eq!(c.fitness_range(), (sorted[0], sorted[2]));
        }
        // The first algorithm named is the reference of the significance rows.
        let rows = crate::report::significance::significance(&cells);
        assert_eq!(rows.len(), 1);
        assert_eq!(
            (rows[0].reference, rows[0].other),
            (Algorithm::Pso, Algorithm::APso)
        );
    }

    /// `compare` measures the algorithms themselves: a plan the swarm leaves over a limit is
    /// not touched up there, whatever the scenario says.
    #[test]
    fn compare_measures_the_swarms_own_plans_without_the_touch_up() {
        // Scenario 3 on a budget of 3 iterations of 10 particles: plans that break limits.
        let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/amp-pso-3.toml");
        let mut scenario =
            Scenario::load(Path::new(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        scenario.optimizer.iterations = 3;
        scenario.optimizer.particles = 10;
        assert!(scenario.optimizer.touch_up, "the file's default");
        let cells = compare(
            std::slice::from_ref(&scenario),
            &[Algorithm::Pso],
            1..4,
            None,
            &Arc::new(AtomicBool::new(false)),
            &mut |_| {},
        )
        .unwrap_or_else(|e| panic!("compare failed: {e}"));
        let mut touched_differs = 0;
        for seed in 1..4u64 {
            let mut s = scenario.clone();
            s.optimizer.algorithm = Algorithm::Pso;
            s.optimizer.seed = seed;
            let touched = crate::planning::planner::plan_in_process(&s, None, &mut |_| {});
            s.optimizer.touch_up = false;
            let own = crate::planning::planner::plan_in_process(&s, None, &mut |_| {});
            assert_eq!(
                cells[0].fitness[seed as usize - 1],
                own.fitness,
                "seed {seed}"
            );
            if touched.fitness < own.fitness {
                touched_differs += 1;
            }
        }
        // The swarm's plans break limits and `plan` would touch them up, so the equality above
        // is not trivial.
        assert!(touched_differs > 0);
    }

    #[test]
    fn a_raised_stop_returns_the_cells_completed_so_far() {
        let scenario = two_auvs();
        let cells = compare(
            &[scenario],
            &[Algorithm::Pso],
            1..3,
            None,
            &Arc::new(AtomicBool::new(true)),
            &mut |_| {},
        )
        .unwrap_or_else(|e| panic!("compare failed: {e}"));
        assert!(cells.is_empty());
    }
}
