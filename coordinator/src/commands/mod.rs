//! The coordinator's commands: one file per command, its clap arguments beside its handler.
//! Every flag also reads a `SHOAL_*` environment variable, so containers need only environment
//! settings. A command turns its flags into typed options in one place and calls the layers
//! below (`mission`, `planning`, `report`, `distributed`, `execute`), never another command.

pub mod bench;
pub mod compare;
pub mod exit;
pub mod export;
pub mod generate;
pub mod health;
pub mod keys;
pub mod plan;
pub mod plan_args;
pub mod replay;
pub mod router;
pub mod run;
pub mod serve;
pub mod status;

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use clap::{Parser, Subcommand};

pub use exit::{EXIT_ERROR, EXIT_FEASIBLE, EXIT_VIOLATIONS};

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
    // -- Planning --
    /// Plan a scenario and write plan.json and plan.svg.
    Plan(plan_args::PlanArgs),
    /// Write a plan for maps (GeoJSON) or QGroundControl (.plan per vehicle), on WGS-84 through
    /// the scenario's `[origin]`; or a mission log as MCAP (`--format mcap`).
    Export(export::ExportArgs),
    /// Compare the optimizers over several seeds (markdown table on stdout).
    Compare(compare::CompareArgs),
    /// Write a random fleet scenario of any size (for scaling runs).
    Generate(generate::GenerateArgs),

    // -- Missions --
    /// Plan a scenario, then execute it: every agent drives its vehicle along its trajectory
    /// (simulated vehicles by default), the coordinator watches the fleet and replans.
    Run(run::RunArgs),
    /// Take missions submitted over Zenoh (`shoal/submit`, JSON) and run each (plan, execute).
    Serve(serve::ServeArgs),
    /// Print the live fleet picture of the running missions (a Zenoh query).
    Status(status::StatusArgs),
    /// Re-read a mission log (`run`'s mission.ndjson or mission.mcap): events, figures and an
    /// SVG of the tracks.
    Replay(replay::ReplayArgs),

    // -- Network and deployment --
    /// Run only a Zenoh router (what `zenohd` does) until Ctrl-C: a hub that outlives missions,
    /// so several coordinators (`plan --router`) and one set of agents can share it.
    Router(router::RouterArgs),
    /// Make a secured fleet's certificates and Zenoh configurations: a local CA, one
    /// certificate per member (coordinator, vehicles, operators) and the access-control rules.
    Keys(keys::KeysArgs),
    /// Container healthcheck: exit 0 if the health file was rewritten in the last 10 s.
    Health(health::HealthArgs),

    // -- Benchmarks --
    /// Run the benchmark-function suite (Lu et al. 2023, Table 3–6).
    BenchFunctions(bench::functions::BenchFunctionsArgs),
    /// Compare PSO (length only), M-PSO and EPA-PSO on one AUV in a current (Zhang et al. 2022, Table 3).
    BenchEnergy(bench::energy::BenchEnergyArgs),
    /// Compare LDIW-PSO, LCPSO and DE-PSO on cage-inspection tours (Hu et al. 2023, Table 6).
    BenchCages(bench::cages::BenchCagesArgs),
    /// Measure the coordinator's CPU use and telemetry latency with N simulated vehicles.
    BenchTelemetry(bench::telemetry::BenchTelemetryArgs),
    /// Plan generated fleets of growing size at one budget: wall time, evaluations per second,
    /// CPU per evaluation and the exponent of its growth with the fleet.
    BenchScale(bench::scale::BenchScaleArgs),
    /// Compare CPP-DSMV's arc-smoothed Boustrophedon with the Hybrid A* baseline on seeded maps
    /// (coverage, planning time, clearance, cross-track error; Table 2 and Figure 7).
    BenchCoverage(bench::coverage::BenchCoverageArgs),
}

/// The log filter a command uses when `RUST_LOG` is not set.
pub fn default_log_filter(command: &Command) -> &'static str {
    match command {
        Command::Status(_) => status::DEFAULT_LOG_FILTER,
        _ => "warn",
    }
}

/// Runs one command to completion. `shutdown` ends long work early (the best result so far is
/// still written). Returns the process exit status.
pub fn run(command: Command, shutdown: Arc<AtomicBool>) -> anyhow::Result<i32> {
    match command {
        Command::Plan(args) => plan::command(&args, shutdown),
        Command::Export(args) => export::command(&args),
        Command::Compare(args) => compare::command(&args, &shutdown),
        Command::Generate(args) => generate::command(&args),
        Command::Run(args) => run::command(&args, shutdown),
        Command::Serve(args) => serve::command(&args, shutdown),
        Command::Status(args) => status::command(&args),
        Command::Replay(args) => replay::command(&args, &shutdown),
        Command::Router(args) => router::command(&args, &shutdown),
        Command::Keys(args) => keys::command(&args),
        Command::Health(args) => health::command(&args),
        Command::BenchFunctions(args) => bench::functions::command(&args, &shutdown),
        Command::BenchEnergy(args) => bench::energy::command(&args, &shutdown),
        Command::BenchCages(args) => bench::cages::command(&args, &shutdown),
        Command::BenchTelemetry(args) => bench::telemetry::command(&args, &shutdown),
        Command::BenchScale(args) => bench::scale::command(&args, &shutdown),
        Command::BenchCoverage(args) => bench::coverage::bench_coverage(&args, &shutdown),
    }
}
