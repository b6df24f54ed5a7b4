//! `shoal-coordinator bench-scale`: how the cost of planning grows with the fleet. For every
//! fleet size it plans a generated scenario ([`crate::planning::generated`], same layout seed)
//! at the same budget, in process and, with `--distributed`, with one embedded agent process
//! per vehicle, and prints wall time, fitness evaluations per second, CPU time per evaluation,
//! fitness and feasibility (distributed: what a round cost the coordinator), then the exponent
//! `b` of a least-squares fit `cost ∝ N^b` (1 is linear in vehicles) of the CPU time per
//! evaluation in process and of the coordinator's CPU time per round distributed.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Instant;

use shoal_common::plan::Plan;
use shoal_common::scenario::Scenario;
use shoal_common::separation::all_pairs;
use shoal_common::trajectory::Trajectory;

use crate::cpu::cpu_time;
use crate::mission::NetworkOptions;
use crate::planning::generated::{scenario_text, Layout};
use crate::planning::planner::plan_in_process;
use crate::report::out::say;

/// Largest fleet the benchmark plans (the generator's own limit).
const MAX_VEHICLES: u32 = 256;

/// `shoal-coordinator bench-scale`.
#[derive(Debug, Clone, clap::Args)]
pub struct BenchScaleArgs {
    /// Fleet sizes, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = vec![4, 8, 16, 32, 64])]
    pub vehicles: Vec<u32>,
    /// Fleet layout (see `generate --layout`).
    #[arg(long, value_enum, default_value_t = Layout::Crossing)]
    pub layout: Layout,
    /// Layout and optimizer seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Iterations per plan (default: the scenario's, 200).
    #[arg(long)]
    pub iterations: Option<usize>,
    /// Plan the swarm alone, without the refinement after it.
    #[arg(long)]
    pub no_refine: bool,
    /// Also plan each fleet distributed, one embedded agent process per vehicle.
    #[arg(long)]
    pub distributed: bool,
    /// Where the generated scenarios, plans and agent logs go.
    #[arg(long, default_value = "bench-scale")]
    pub out: std::path::PathBuf,
}

/// One plan's figures.
#[derive(Debug, Clone)]
pub struct ScaleRow {
    /// Vehicles.
    pub vehicles: usize,
    /// `in-process` or `distributed`.
    pub mode: &'static str,
    /// Wall time of the plan, seconds.
    pub wall_s: f64,
    /// CPU time of this process over the plan, seconds (agents' processes not included).
    pub cpu_s: f64,
    /// The plan.
    pub plan: Plan,
}

impl ScaleRow {
    /// [`close_pairs_per_vehicle`] of the plan.
    pub fn close_pairs_per_vehicle(&self) -> f64 {
        let tracks: Vec<Trajectory> = (self.plan.vehicles.iter())
            .map(|v| Trajectory::from_samples(&v.trajectory))
            .collect();
        close_pairs_per_vehicle(&tracks, self.plan.d_min_m)
    }

    /// CPU microseconds per fitness evaluation of this process.
    pub fn cpu_per_evaluation_us(&self) -> f64 {
        1e6 * self.cpu_s / self.plan.evaluations.max(1) as f64
    }

    /// What the row's growth is fitted on: CPU µs per evaluation in process; the coordinator's
    /// CPU seconds per round distributed (the agents' evaluations are not its own).
    pub fn cost(&self) -> f64 {
        match self.plan.distributed.as_ref().and_then(|d| d.rounds) {
            Some(r) => r.coordinator_cpu_s,
            None => self.cpu_per_evaluation_us(),
        }
    }
}

/// Runs the benchmark and prints its table.
pub fn command(args: &BenchScaleArgs, stop: &Arc<AtomicBool>) -> anyhow::Result<i32> {
    if let Some(&bad) = args
        .vehicles
        .iter()
        .find(|&&n| !(2..=MAX_VEHICLES).contains(&n))
    {
        anyhow::bail!("--vehicles: {bad} is outside 2..={MAX_VEHICLES}");
    }
    if args.iterations.is_some_and(|i| i == 0) {
        anyhow::bail!("--iterations must be at least 1");
    }
    std::fs::create_dir_all(&args.out)?;
    let mut rows = Vec::new();
    say("vehicles | mode | wall (s) | evaluations | evaluations/s | CPU µs/evaluation | fitness | feasible | close pairs per vehicle\n");
    for &n in &args.vehicles {
        let scenario = scenario_of(n, args)?;
        for distributed in [false, true] {
            if stop.load(std::sync::atomic::Ordering::Relaxed) {
                break;
            }
            if distributed && !args.distributed {
                continue;
            }
            let row = plan_one(&scenario, distributed, args, stop)?;
            say(&format!("{}\n", line(&row)));
            rows.push(row);
        }
    }
    for mode in ["in-process", "distributed"] {
        let points: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.mode == mode)
            .map(|r| (r.vehicles as f64, r.cost()))
            .collect();
        let what = if mode == "in-process" {
            "CPU per evaluation"
        } else {
            "the coordinator's CPU per round"
        };
        if let Some(b) = fitted_exponent(&points) {
            say(&format!(
                "{mode}: {what} grows as N^{b:.2} over {} fleet sizes\n",
                points.len()
            ));
        }
    }
    Ok(super::super::exit::EXIT_FEASIBLE)
}

/// The generated scenario of `n` vehicles with the benchmark's settings.
fn scenario_of(n: u32, args: &BenchScaleArgs) -> anyhow::Result<Scenario> {
    let spheres = (n / 2).max(2);
    let text = scenario_text(n, spheres, args.seed, args.layout);
    let path = args.out.join(format!("{}-{n}.toml", args.layout.stem()));
    std::fs::write(&path, &text)?;
    let mut s = Scenario::parse(&text, &path)?;
    s.optimizer.seed = args.seed;
    if let Some(i) = args.iterations {
        s.optimizer.iterations = i;
    }
    if args.no_refine {
        s.optimizer.refine = false;
    }
    Ok(s)
}

/// Plans `scenario` once and measures it.
fn plan_one(
    scenario: &Scenario,
    distributed: bool,
    args: &BenchScaleArgs,
    stop: &Arc<AtomicBool>,
) -> anyhow::Result<ScaleRow> {
    let n = scenario.vehicles.len();
    let cpu0 = cpu_time().unwrap_or_default();
    let started = Instant::now();
    let plan = if distributed {
        let options = NetworkOptions {
            join_timeout: std::time::Duration::from_secs(120),
            ..NetworkOptions::default()
        }
        .for_mission(
            format!("bench-scale-{n}-{}", std::process::id()),
            args.out.join(format!("logs-{n}")),
        );
        crate::distributed::plan_distributed(scenario, &options, stop, &mut |_| {})?
    } else {
        plan_in_process(scenario, Some(stop.clone()), &mut |_| {})
    };
    let wall_s = started.elapsed().as_secs_f64();
    let cpu_s = (cpu_time().unwrap_or_default().saturating_sub(cpu0)).as_secs_f64();
    Ok(ScaleRow {
        vehicles: n,
        mode: if distributed {
            "distributed"
        } else {
            "in-process"
        },
        wall_s,
        cpu_s,
        plan,
    })
}

/// One table line; a distributed one ends with what a round cost the coordinator.
fn line(r: &ScaleRow) -> String {
    let rounds = match r.plan.distributed.as_ref().and_then(|d| d.rounds) {
        Some(x) => format!(
            " | per round: elites {:.3} s, leader {:.3} s, coordinator CPU {:.3} s",
            x.collect_s, x.leader_s, x.coordinator_cpu_s
        ),
        None => String::new(),
    };
    format!(
        "{} | {} | {:.2} | {} | {:.0} | {:.1} | {:.4} | {} | {:.2}{rounds}",
        r.vehicles,
        r.mode,
        r.wall_s,
        r.plan.evaluations,
        r.plan.evaluations as f64 / r.wall_s.max(1e-9),
        r.cpu_per_evaluation_us(),
        r.plan.fitness,
        if r.plan.feasible { "yes" } else { "no" },
        r.close_pairs_per_vehicle(),
    )
}

/// Pairs that come within two d_min of each other at the same instant, per vehicle (each pair
/// counted for both): the interactions the fitness must measure exactly. A fleet in which it
/// grows does more work per vehicle whatever the planner.
pub fn close_pairs_per_vehicle(tracks: &[Trajectory], d_min: f64) -> f64 {
    let reach = 2.0 * d_min;
    let close = all_pairs(tracks, reach)
        .iter()
        .filter(|(_, s)| s.min_distance < reach)
        .count();
    2.0 * close as f64 / tracks.len().max(1) as f64
}

/// The slope `b` of the least-squares line through `(ln x, ln y)`: `y ∝ x^b`. `None` with
/// fewer than two distinct sizes or a non-positive value.
pub fn fitted_exponent(points: &[(f64, f64)]) -> Option<f64> {
    if points.iter().any(|(x, y)| !(*x > 0.0 && *y > 0.0)) {
        return None;
    }
    let logs: Vec<(f64, f64)> = points.iter().map(|(x, y)| (x.ln(), y.ln())).collect();
    let n = logs.len() as f64;
    let (mx, my) = (
        logs.iter().map(|p| p.0).sum::<f64>() / n,
        logs.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxx: f64 = logs.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = logs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn close_pairs_are_counted_for_both_vehicles_by_hand() {
        // Two AUVs side by side 80 m apart (under 2 × 50 m), a third 500 m away, all heading
        // east at 1 m/s for 1000 s: one close pair, 2 / 3 per vehicle.
        let east =
            |y: f64| Trajectory::from_samples(&[[0.0, 0.0, y, 100.0], [1000.0, 1000.0, y, 100.0]]);
        let fleet = [east(0.0), east(80.0), east(580.0)];
        assert_abs_diff_eq!(
            close_pairs_per_vehicle(&fleet, 50.0),
            2.0 / 3.0,
            epsilon = 1e-12
        );
        // 120 m apart is not close.
        assert_abs_diff_eq!(
            close_pairs_per_vehicle(&fleet[1..], 50.0),
            0.0,
            epsilon = 1e-12
        );
        // Crossing paths meet only if they are there at the same time: the second starts
        // 1000 s after the first has passed the crossing.
        let north = Trajectory::from_samples(&[
            [1500.0, 500.0, -500.0, 100.0],
            [2500.0, 500.0, 500.0, 100.0],
        ]);
        assert_abs_diff_eq!(
            close_pairs_per_vehicle(&[east(0.0), north], 50.0),
            0.0,
            epsilon = 1e-12
        );
    }

    #[test]
    fn the_fitted_exponent_of_a_power_law_is_its_power() {
        let square: Vec<(f64, f64)> = [4.0, 8.0, 16.0, 32.0]
            .iter()
            .map(|&n: &f64| (n, 3.0 * n * n))
            .collect();
        assert_abs_diff_eq!(
            fitted_exponent(&square).unwrap_or(0.0),
            2.0,
            epsilon = 1e-12
        );
        // 10, 20, 40 by hand: ln y = ln 10 + 1·(ln x − ln 4) … slope 1.
        let linear = [(4.0, 10.0), (8.0, 20.0), (16.0, 40.0)];
        assert_abs_diff_eq!(
            fitted_exponent(&linear).unwrap_or(0.0),
            1.0,
            epsilon = 1e-12
        );
        assert_eq!(fitted_exponent(&[(4.0, 1.0)]), None);
        assert_eq!(fitted_exponent(&[(4.0, 1.0), (8.0, 0.0)]), None);
    }
}
