//! `shoal-coordinator compare`: every algorithm on every scenario over several seeds, as a
//! markdown table like Zhi & Zuo's Figures 7, 9 and 11 (run time, collisions, fitness), with the
//! significance rows and, for crawlers, the gap to a reference path.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use anyhow::Context;
use shoal_common::scenario::{Algorithm, Scenario};

use crate::mission::NetworkOptions;
use crate::report::compare::{self, seeds_line};
use crate::report::out::say;
use crate::report::{crawler_table, significance};

use super::exit::EXIT_FEASIBLE;

/// `shoal-coordinator compare`.
#[derive(Debug, Clone, clap::Args)]
pub struct CompareArgs {
    /// Scenario files.
    #[arg(required = true, env = "SHOAL_SCENARIOS", value_delimiter = ',')]
    pub scenarios: Vec<PathBuf>,
    /// How many seeds: `--first-seed` … `--first-seed` + N − 1 (1..=N by default).
    #[arg(long, default_value_t = 10, env = "SHOAL_SEEDS", value_parser = clap::value_parser!(u64).range(1..))]
    pub seeds: u64,
    /// First seed, so a comparison can be repeated on seeds no setting was chosen on (e.g.
    /// `--first-seed 11 --seeds 20` runs seeds 11–30).
    #[arg(long, default_value_t = 1, env = "SHOAL_FIRST_SEED")]
    pub first_seed: u64,
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

impl CompareArgs {
    /// The seeds to run, `first_seed .. first_seed + seeds`; an error names both flags when the
    /// last seed would not fit in a u64.
    pub fn seed_range(&self) -> anyhow::Result<std::ops::Range<u64>> {
        match self.first_seed.checked_add(self.seeds) {
            Some(end) => Ok(self.first_seed..end),
            None => anyhow::bail!(
                "--first-seed {} with --seeds {}: the last seed would be past {}",
                self.first_seed,
                self.seeds,
                u64::MAX
            ),
        }
    }
}

/// `shoal-coordinator compare`: the table of every algorithm over the seeds, written where asked;
/// `stop` ends it early with what is done.
pub fn command(args: &CompareArgs, stop: &Arc<AtomicBool>) -> anyhow::Result<i32> {
    let seeds = args.seed_range()?;
    let scenarios = args
        .scenarios
        .iter()
        .map(|p| {
            let mut s = Scenario::load(p)?;
            if let Some(i) = args.iterations {
                s.optimizer.iterations = i;
            }
            s.validate(p)?;
            // Every algorithm must fit every scenario, checked before the first run.
            for &a in &args.algorithms {
                let mut with = s.clone();
                with.optimizer.algorithm = a;
                with.validate(p)?;
            }
            Ok(s)
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let multi = args
        .algorithms
        .iter()
        .filter(|a| a.is_multi_population())
        .count();
    let per_scenario = args.algorithms.len() + if args.distributed { multi } else { 0 };
    let total = scenarios.len() * per_scenario * args.seeds as usize;
    let mut done = 0;
    // Embedded agents on a free loopback port with the default timeouts; each run names its
    // own mission.
    let distributed = args.distributed.then(|| {
        NetworkOptions::default().for_mission(
            String::new(),
            std::env::temp_dir().join("shoal-compare-logs"),
        )
    });
    let cells = compare::compare(
        &scenarios,
        &args.algorithms,
        seeds.clone(),
        distributed.as_ref(),
        stop,
        &mut |p| {
            done += 1;
            eprintln!(
                "[{done}/{total}] {} {} {} seed {}: fitness {:.4}, {} in {:.2} s",
                p.scenario,
                p.algorithm,
                p.mode,
                p.seed,
                p.fitness,
                if p.feasible { "feasible" } else { "infeasible" },
                p.runtime_s
            );
        },
    )?;
    if stop.load(std::sync::atomic::Ordering::Relaxed) {
        eprintln!("interrupted: the table has only the cells completed before Ctrl-C");
    }
    let mut table = seeds_line(&seeds);
    table.push_str(&compare::markdown(&cells));
    table.push_str(&significance::markdown(&significance::significance(&cells)));
    if cells.iter().any(|c| c.crawler.is_some()) {
        eprintln!(
            "computing the reference crawler paths (grid {} m)…",
            args.reference_cell
        );
        let references = crawler_table::references(&scenarios, args.reference_cell);
        table.push_str(&crawler_table::markdown(&cells, &references));
    }
    say(&table);
    if let Some(out) = &args.out {
        std::fs::write(out, &table).with_context(|| format!("cannot write {}", out.display()))?;
    }
    Ok(EXIT_FEASIBLE)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(clap::Parser)]
    struct Cli {
        #[command(flatten)]
        compare: CompareArgs,
    }

    fn parsed(args: &[&str]) -> CompareArgs {
        use clap::Parser;
        match Cli::try_parse_from(std::iter::once("compare").chain(args.iter().copied())) {
            Ok(c) => c.compare,
            Err(e) => panic!("{args:?} did not parse: {e}"),
        }
    }

    #[test]
    fn seeds_start_at_one_unless_a_first_seed_is_given() {
        let range = |args: &[&str]| {
            parsed(args)
                .seed_range()
                .unwrap_or_else(|e| panic!("{args:?}: {e}"))
        };
        assert_eq!(range(&["a.toml"]), 1..11);
        assert_eq!(range(&["a.toml", "--seeds", "3"]), 1..4);
        assert_eq!(
            range(&["a.toml", "--first-seed", "11", "--seeds", "20"]),
            11..31
        );
        let past = parsed(&[
            "a.toml",
            "--first-seed",
            &u64::MAX.to_string(),
            "--seeds",
            "2",
        ]);
        let e = match past.seed_range() {
            Ok(r) => panic!("a range past u64::MAX was accepted: {r:?}"),
            Err(e) => e.to_string(),
        };
        assert!(
            e.contains("--first-seed 18446744073709551615") && e.contains("--seeds 2"),
            "{e}"
        );
        assert_eq!(seeds_line(&(11..31)), "Seeds 11–30 (20 per cell).\n\n");
        assert_eq!(seeds_line(&(4..5)), "Seed 4.\n\n");
    }
}
