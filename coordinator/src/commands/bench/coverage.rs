//! `shoal-coordinator bench-coverage`: CPP-DSMV's Table 2 comparison (arc method vs the Hybrid
//! A* baseline) over seeded maps.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::Context;
use shoal_common::coverage::metrics::Distribution;
use shoal_common::coverage::mission::{build_map, run_coverage};
use shoal_common::coverage::params::DetourMethod;
use shoal_common::scenario::Scenario;

use crate::planning::coverage::*;
use crate::report::summary::opt;

/// `shoal-coordinator bench-coverage`.
#[derive(Debug, Clone, clap::Args)]
pub struct BenchCoverageArgs {
    /// Coverage scenario file.
    #[arg(default_value = "scenarios/cpp-seabed.toml")]
    pub scenario: PathBuf,
    /// Terrain seeds 1..=N.
    #[arg(long, default_value_t = 10)]
    pub seeds: u64,
    /// Skip the tracking simulation (planning figures only).
    #[arg(long)]
    pub no_track: bool,
    /// Also write the table to this file.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Runs both methods on every seed and prints CPP-DSMV, Table 2 style rows. A raised `stop`
/// (Ctrl-C) ends the bench: the run it cut short is left out, the tables hold the finished ones.
pub fn bench_coverage(args: &BenchCoverageArgs, stop: &AtomicBool) -> anyhow::Result<i32> {
    let scenario = Scenario::load(&args.scenario)?;
    let Some(settings) = scenario.coverage.clone() else {
        anyhow::bail!("{}: no [coverage] table", args.scenario.display());
    };
    let dir = args.scenario.parent().unwrap_or(Path::new("."));
    let mut table = String::from(
        "| seed | method | coverage % | passable % | planning s | samples < clearance | min clearance m | max abs cte m | median abs cte m | detours | virtual boundaries | transits | unreached |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut sums: Vec<(DetourMethod, Vec<BenchRow>)> = Vec::new();
    'seeds: for seed in 1..=args.seeds {
        for method in [DetourMethod::Arcs, DetourMethod::HybridAStar] {
            if stop.load(Ordering::Relaxed) {
                break 'seeds;
            }
            let mut s = settings.clone();
            s.planner.detour = method;
            s.track = !args.no_track;
            let map = build_map(&s, seed, dir)?;
            let (r, _) = run_coverage(
                &s,
                &map,
                scenario_area(&scenario),
                Some(seed),
                seed,
                Some(stop),
                &mut |_, _| {},
            )?;
            if r.tracking.as_ref().is_some_and(|t| t.interrupted) {
                break 'seeds;
            }
            let cte = r
                .tracking
                .as_ref()
                .map(|t| (t.max_abs_cte_m, t.median_abs_cte_m));
            let name = match method {
                DetourMethod::Arcs => "arcs",
                DetourMethod::HybridAStar => "hybrid-a-star",
            };
            let row = format!(
                "| {seed} | {name} | {:.2} | {:.2} | {:.3} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
                100.0 * r.coverage.ratio,
                100.0 * r.coverage.ratio_of_passable,
                r.planning_time_s,
                r.samples_below_clearance,
                clearance_cell(&r.clearance),
                opt(cte.map(|c| c.0), 2),
                opt(cte.map(|c| c.1), 3),
                r.event_counts[0],
                r.event_counts[1],
                r.event_counts[3],
                r.event_counts[4]
            );
            eprint!("{row}");
            table.push_str(&row);
            let entry = BenchRow {
                coverage: r.coverage.ratio,
                planning_s: r.planning_time_s,
                below_clearance: r.samples_below_clearance,
                cte,
            };
            match sums.iter_mut().find(|(m, _)| *m == method) {
                Some((_, v)) => v.push(entry),
                None => sums.push((method, vec![entry])),
            }
        }
    }
    table.push_str("\n| method | mean coverage % | min coverage % | max planning s | runs with samples < clearance | worst max abs cte m | mean median abs cte m |\n|---|---|---|---|---|---|---|\n");
    for (method, rows) in &sums {
        table.push_str(&summary_row(method, rows));
    }
    let (finished, runs) = (
        sums.iter().map(|(_, rows)| rows.len()).sum::<usize>(),
        2 * args.seeds as usize,
    );
    if finished < runs {
        table.push_str(&format!(
            "\ninterrupted: {finished} of {runs} runs finished; the tables hold only those\n"
        ));
    }
    print!("{table}");
    if let Some(path) = &args.out {
        std::fs::write(path, &table).with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(0)
}

/// One finished run of `bench-coverage`, as its summary needs it.
struct BenchRow {
    coverage: f64,
    planning_s: f64,
    below_clearance: usize,
    /// Max and median |cross-track error|, metres, when the run was tracked.
    cte: Option<(f64, f64)>,
}

/// The min clearance cell: metres, "unbounded" on a map without impassable ground, "–" when
/// there is no path (see [`clearance_words`]).
fn clearance_cell(d: &Distribution) -> String {
    if d.min.is_finite() {
        format!("{:.2}", d.min)
    } else if d.count > 0 {
        "unbounded".into()
    } else {
        "–".into()
    }
}

/// The summary line of one method over its finished runs; the tracking columns are "–" when
/// no run was tracked (`--no-track`).
fn summary_row(method: &DetourMethod, rows: &[BenchRow]) -> String {
    let n = rows.len().max(1) as f64;
    let tracked: Vec<(f64, f64)> = rows.iter().filter_map(|r| r.cte).collect();
    let worst_cte = tracked.iter().map(|c| c.0).reduce(f64::max);
    let mean_median_cte = (!tracked.is_empty())
        .then(|| tracked.iter().map(|c| c.1).sum::<f64>() / tracked.len() as f64);
    format!(
        "| {:?} | {:.2} | {:.2} | {:.3} | {} | {} | {} |\n",
        method,
        100.0 * rows.iter().map(|r| r.coverage).sum::<f64>() / n,
        100.0
            * rows
                .iter()
                .map(|r| r.coverage)
                .fold(f64::INFINITY, f64::min),
        rows.iter().map(|r| r.planning_s).fold(0.0, f64::max),
        rows.iter().filter(|r| r.below_clearance > 0).count(),
        opt(worst_cte, 2),
        opt(mean_median_cte, 3)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bench_cells_say_what_is_missing_instead_of_nan() {
        let some = Distribution::new(&[12.5, f64::INFINITY, 20.0], 0.0, 40.0, 40);
        assert_eq!(clearance_cell(&some), "12.50");
        let unbounded = Distribution::new(&[f64::INFINITY; 3], 0.0, 40.0, 40);
        assert_eq!(clearance_cell(&unbounded), "unbounded");
        assert_eq!(clearance_cell(&Distribution::new(&[], 0.0, 40.0, 40)), "–");
        let run = |coverage, cte| BenchRow {
            coverage,
            planning_s: coverage,
            below_clearance: 0,
            cte,
        };
        // Untracked runs (`--no-track`): no cross-track figures, not -inf or NaN.
        let rows = [run(0.5, None), run(0.7, None)];
        assert_eq!(
            summary_row(&DetourMethod::Arcs, &rows),
            "| Arcs | 60.00 | 50.00 | 0.700 | 0 | – | – |\n"
        );
        // Tracked: worst of the maxima, mean of the medians.
        let rows = [run(0.5, Some((2.0, 0.25))), run(0.7, Some((3.5, 0.5)))];
        assert_eq!(
            summary_row(&DetourMethod::HybridAStar, &rows),
            "| HybridAStar | 60.00 | 50.00 | 0.700 | 0 | 3.50 | 0.375 |\n"
        );
    }
}
