//! `shoal-coordinator generate`: a random fleet scenario of any size, for scaling runs
//! ([`crate::planning::generated`]). The same seed gives the same file.

use std::path::PathBuf;

use shoal_common::scenario::Scenario;

use super::exit::EXIT_FEASIBLE;
use crate::planning::generated::{scenario_text, Layout};
use crate::report::out::say;

/// `shoal-coordinator generate`.
#[derive(Debug, Clone, clap::Args)]
pub struct GenerateArgs {
    /// Vehicles (ids auv1 … auvN).
    #[arg(long, env = "SHOAL_VEHICLES", value_parser = clap::value_parser!(u32).range(1..=256))]
    pub vehicles: u32,
    /// Hard and soft spheres, each (default: one of each per two vehicles, at least 2).
    #[arg(long, env = "SHOAL_SPHERES")]
    pub spheres: Option<u32>,
    /// Layout: `crossing` (goals shuffled along the whole east side, paths cross everywhere) or
    /// `lanes` (a 4 km strip, goals shuffled within groups of four neighbouring lanes).
    #[arg(long, env = "SHOAL_LAYOUT", value_enum, default_value_t = Layout::Crossing)]
    pub layout: Layout,
    /// Random seed of the layout.
    #[arg(long, env = "SHOAL_SEED", default_value_t = 1)]
    pub seed: u64,
    /// Output file (TOML).
    #[arg(long, env = "SHOAL_OUT")]
    pub out: PathBuf,
}

/// Writes the scenario, after checking it loads.
pub fn command(args: &GenerateArgs) -> anyhow::Result<i32> {
    let spheres = args.spheres.unwrap_or((args.vehicles / 2).max(2));
    let text = scenario_text(args.vehicles, spheres, args.seed, args.layout);
    Scenario::parse(&text, &args.out)?;
    std::fs::write(&args.out, text)
        .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", args.out.display()))?;
    say(&format!("Wrote {}\n", args.out.display()));
    Ok(EXIT_FEASIBLE)
}
