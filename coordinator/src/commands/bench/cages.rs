//! `bench-cages`: Hu et al.'s comparison (§V-B, Table 6) — LDIW-PSO, LCPSO and DE-PSO planning the
//! cage-inspection tour of groups A and B, several seeds each — as a markdown table with the
//! paper's numbers beside ours.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use anyhow::Context;
use shoal_common::scenario::{Algorithm, Scenario};

use crate::commands::bench::pool::run_jobs;
use crate::planning::tour;

/// `shoal-coordinator bench-cages`.
#[derive(Debug, Clone, clap::Args)]
pub struct BenchCagesArgs {
    /// Tour scenario files (their algorithm and seed are overridden).
    #[arg(default_values_t = vec!["scenarios/cages-a.toml".to_string(), "scenarios/cages-b.toml".to_string()])]
    pub scenarios: Vec<String>,
    /// Seeds per cell (1..=runs).
    #[arg(long, default_value_t = 10)]
    pub runs: u64,
    /// Worker threads (the numbers do not depend on it).
    #[arg(long, default_value_t = 2)]
    pub threads: usize,
    /// Also write the table to this file.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Hu et al.'s three leg swarms, in Table 6's order.
pub const METHODS: [Algorithm; 3] = [Algorithm::LdiwPso, Algorithm::Lcpso, Algorithm::DePso];

/// Hu et al. 2023, Table 6: (group, method, mean growth m, variance m², std m, mean growth rate %);
/// `None` where the paper's LCPSO found no complete route.
const PAPER: [(&str, &str, Option<[f64; 4]>); 6] = [
    ("A", "ldiw-pso", Some([500.654, 3259.42, 57.0913, 23.72])),
    ("A", "lcpso", None),
    ("A", "de-pso", Some([488.928, 1364.39, 36.9377, 22.75])),
    ("B", "ldiw-pso", Some([456.093, 7519.38, 86.7143, 17.81])),
    ("B", "lcpso", None),
    ("B", "de-pso", Some([461.729, 3911.56, 62.5425, 17.59])),
];

/// One tour's figures.
#[derive(Debug, Clone)]
pub struct Run {
    /// Scenario name.
    pub scenario: String,
    /// Leg swarm.
    pub algorithm: Algorithm,
    /// Seed.
    pub seed: u64,
    /// Flown tour length (all vehicles), metres.
    pub length_m: f64,
    /// Growth over the straight tour, metres.
    pub growth_m: f64,
    /// Growth over the straight tour's length.
    pub growth_rate: f64,
    /// Segment–cage intersections.
    pub intersections: usize,
    /// Whether every point was visited in a plan with no violation.
    pub feasible: bool,
    /// Wall time, seconds.
    pub runtime_s: f64,
}

/// Mean, population variance and standard deviation.
pub fn moments(v: &[f64]) -> (f64, f64, f64) {
    if v.is_empty() {
        return (f64::NAN, f64::NAN, f64::NAN);
    }
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
    (mean, var, var.sqrt())
}

/// The markdown table of `runs`, with the paper's rows for comparison.
pub fn markdown(runs: &[Run]) -> String {
    let mut s = String::from(
        "| scenario | method | runs | mean growth (m) | growth variance (m²) | growth std (m) | mean growth rate | mean tour (m) | runs with 0 cage intersections | feasible runs | s per run | paper: mean / var / std / rate |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n",
    );
    let mut names: Vec<&str> = runs.iter().map(|r| r.scenario.as_str()).collect();
    names.dedup();
    for name in names {
        for m in METHODS {
            let cell: Vec<&Run> = runs
                .iter()
                .filter(|r| r.scenario == name && r.algorithm == m)
                .collect();
            if cell.is_empty() {
                continue;
            }
            let growth: Vec<f64> = cell.iter().map(|r| r.growth_m).collect();
            let (mean, var, std) = moments(&growth);
            let rate = moments(&cell.iter().map(|r| r.growth_rate).collect::<Vec<_>>()).0;
            let tour = moments(&cell.iter().map(|r| r.length_m).collect::<Vec<_>>()).0;
            let clean = cell.iter().filter(|r| r.intersections == 0).count();
            let feasible = cell.iter().filter(|r| r.feasible).count();
            let secs = moments(&cell.iter().map(|r| r.runtime_s).collect::<Vec<_>>()).0;
            let group = name.rsplit('-').next().unwrap_or("").to_uppercase();
            let paper = PAPER
                .iter()
                .find(|(g, a, _)| *g == group && *a == m.as_str())
                .map(|(_, _, v)| match v {
                    Some([a, b, c, d]) => format!("{a} / {b} / {c} / {d} %"),
                    None => "no complete route".to_string(),
                })
                .unwrap_or_else(|| "–".to_string());
            s.push_str(&format!(
                "| {name} | {} | {} | {mean:.1} | {var:.1} | {std:.2} | {:.2} % | {tour:.1} | {clean} | {feasible} | {secs:.2} | {paper} |\n",
                m.as_str(),
                cell.len(),
                100.0 * rate,
            ));
        }
    }
    s
}

/// The command.
pub fn command(args: &BenchCagesArgs, stop: &AtomicBool) -> anyhow::Result<i32> {
    if args.runs == 0 {
        anyhow::bail!("--runs must be at least 1");
    }
    let scenarios = args
        .scenarios
        .iter()
        .map(|p| Scenario::load(std::path::Path::new(p)).map_err(anyhow::Error::from))
        .collect::<anyhow::Result<Vec<_>>>()?;
    if let Some(s) = scenarios.iter().find(|s| s.inspection.is_none()) {
        anyhow::bail!("{}: has no [inspection] table to plan tours on", s.name);
    }
    let mut jobs = Vec::new();
    for (i, _) in scenarios.iter().enumerate() {
        for m in METHODS {
            for seed in 1..=args.runs {
                jobs.push((i, m, seed));
            }
        }
    }
    let work = |&(i, algorithm, seed): &(usize, Algorithm, u64)| {
        let mut sc = scenarios[i].clone();
        sc.optimizer.algorithm = algorithm;
        sc.optimizer.seed = seed;
        let plan = tour::plan(&sc, None, &mut |_| {});
        let tours = plan.vehicles.iter().filter_map(|v| v.tour.as_ref());
        let (length_m, straight, intersections) = tours.fold((0.0, 0.0, 0), |(l, s, n), t| {
            (
                l + t.tour_length_m,
                s + t.straight_tour_length_m,
                n + t.cage_intersections,
            )
        });
        Run {
            scenario: sc.name.clone(),
            algorithm,
            seed,
            length_m,
            growth_m: length_m - straight,
            growth_rate: if straight > 0.0 {
                (length_m - straight) / straight
            } else {
                0.0
            },
            intersections,
            feasible: plan.feasible,
            runtime_s: plan.runtime_s,
        }
    };
    let runs = run_jobs(&jobs, args.threads, stop, &work, &|r: &Run, n, total| {
        eprintln!(
            "[{n}/{total}] {} {} seed {}: tour {:.1} m, growth {:.1} m ({:.2} %), {} cage intersections, {:.2} s",
            r.scenario,
            r.algorithm.as_str(),
            r.seed,
            r.length_m,
            r.growth_m,
            100.0 * r.growth_rate,
            r.intersections,
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moments_by_hand() {
        // 2, 4, 4, 4, 5, 5, 7, 9: mean 5, population variance 4, std 2.
        let (m, v, s) = moments(&[2., 4., 4., 4., 5., 5., 7., 9.]);
        assert!((m - 5.0).abs() < 1e-12 && (v - 4.0).abs() < 1e-12 && (s - 2.0).abs() < 1e-12);
        assert!(moments(&[]).0.is_nan());
    }
}
