//! Command-line interface. Every flag also reads a `SHOAL_*` environment variable, so containers
//! need only environment settings.

use std::path::PathBuf;

use clap::{Parser, Subcommand};
use shoal_common::scenario::Algorithm;

/// Shoal fleet coordinator: plans collision-free, time-coordinated paths for a fleet of
/// underwater vehicles.
#[derive(Debug, Parser)]
#[command(name = "shoal-coordinator", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The coordinator's commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Plan a scenario and write plan.json and plan.svg.
    Plan(PlanArgs),
    /// Compare the optimizers over several seeds (markdown table on stdout).
    Compare(crate::compare::CompareArgs),
}

/// `shoal-coordinator plan`.
#[derive(Debug, Clone, clap::Args)]
pub struct PlanArgs {
    /// Scenario file (TOML).
    #[arg(env = "SHOAL_SCENARIO")]
    pub scenario: PathBuf,
    /// Directory for plan.json and plan.svg (created if missing).
    #[arg(long, env = "SHOAL_OUT", default_value = "out")]
    pub out: PathBuf,
    /// Plan inside this process (no agents, no network).
    #[arg(long, env = "SHOAL_IN_PROCESS")]
    pub in_process: bool,
    /// RNG seed (overrides the scenario's).
    #[arg(long, env = "SHOAL_SEED")]
    pub seed: Option<u64>,
    /// Optimizer: amp-pso, pso, mp-pso or a-pso (overrides the scenario's).
    #[arg(long, env = "SHOAL_ALGORITHM")]
    pub algorithm: Option<Algorithm>,
    /// Iterations (overrides the scenario's).
    #[arg(long, env = "SHOAL_ITERATIONS")]
    pub iterations: Option<usize>,
    /// Follower populations (overrides the scenario's).
    #[arg(long, env = "SHOAL_POPULATIONS")]
    pub populations: Option<usize>,
    /// Particles per population (overrides the scenario's).
    #[arg(long, env = "SHOAL_PARTICLES")]
    pub particles: Option<usize>,
    /// Worker threads (overrides the scenario's; the plan does not depend on it).
    #[arg(long, env = "SHOAL_THREADS")]
    pub threads: Option<usize>,
    /// No progress output on stderr.
    #[arg(long, short, env = "SHOAL_QUIET")]
    pub quiet: bool,
}
