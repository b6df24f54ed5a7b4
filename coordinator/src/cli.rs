//! Command-line interface. Every flag also reads a `SHOAL_*` environment variable, so containers
//! need only environment settings.

use std::path::PathBuf;

use clap::{Parser, Subcommand};
use shoal_common::scenario::Algorithm;

use crate::distributed::AgentsMode;

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
    /// Write a plan for maps (GeoJSON) or QGroundControl (.plan per vehicle), on WGS-84 through
    /// the scenario's [origin].
    Export(crate::export::ExportArgs),
    /// Compare the optimizers over several seeds (markdown table on stdout).
    Compare(crate::compare::CompareArgs),
    /// Write a random fleet scenario of any size (for scaling runs).
    Generate(crate::generate::GenerateArgs),
    /// Run only a Zenoh router (what `zenohd` does) until Ctrl-C: a hub that outlives missions,
    /// so several coordinators (`plan --router`) and one set of agents can share it.
    Router(RouterArgs),
    /// Make a secured fleet's certificates and Zenoh configurations: a local CA, one
    /// certificate per member (coordinator, vehicles, operators) and the access-control rules.
    Keys(crate::keys::KeysArgs),
    /// Container healthcheck: exit 0 if the health file was rewritten in the last 10 s.
    Health(HealthArgs),
    /// Run the benchmark-function suite (seed 000 Table 3–6).
    BenchFunctions(crate::bench_functions::BenchFunctionsArgs),
    /// Compare PSO (length only), M-PSO and EPA-PSO on one AUV in a current (seed 001 Table 3).
    BenchEnergy(crate::bench_energy::BenchEnergyArgs),
    /// Compare LDIW-PSO, LCPSO and DE-PSO on cage-inspection tours (seed 003 Table 6).
    BenchCages(crate::bench_cages::BenchCagesArgs),
    /// Plan a scenario, then execute it: every agent drives its vehicle along its trajectory
    /// (simulated vehicles by default), the coordinator watches the fleet and replans.
    Run(crate::run_cmd::RunArgs),
    /// Re-read a mission log (`run`'s mission.ndjson): events, figures and an SVG of the tracks.
    Replay(crate::replay::ReplayArgs),
    /// Measure the coordinator's CPU use and telemetry latency with N simulated vehicles.
    BenchTelemetry(crate::bench_telemetry::BenchTelemetryArgs),
    /// Take missions submitted over Zenoh (`shoal/submit`, JSON) and run each (plan, execute).
    Serve(crate::serve::ServeArgs),
    /// Print the live fleet picture of the running missions (a Zenoh query).
    Status(crate::status_cmd::StatusArgs),
    /// Compare seed 002's arc-smoothed Boustrophedon with the Hybrid A* baseline on seeded maps
    /// (coverage, planning time, clearance, cross-track error; Table 2 and Figure 7).
    BenchCoverage(crate::coverage_cmd::BenchCoverageArgs),
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
    /// Optimizer: amp-pso, a-pso, mp-pso, pso (seed 004); ipso, spso, cbpso, nspso, aco-pso
    /// (seed 000); epa-pso, pso-length, m-pso (seed 001, one AUV, with --in-process); de-pso,
    /// ldiw-pso, lcpso (seed 003 inspection tours, in process or by the agents);
    /// overrides the scenario's.
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
    /// Fleet plans: keep the swarm's own best even when it breaks a limit, instead of
    /// re-planning each vehicle in a violation against the others' paths afterwards (the
    /// scenario's `optimizer.touch_up`).
    #[arg(long, env = "SHOAL_NO_TOUCH_UP")]
    pub no_touch_up: bool,
    /// Distributed mode: start one agent per vehicle here (embedded) or wait for agents started
    /// elsewhere to connect (external).
    #[arg(long, env = "SHOAL_AGENTS", value_enum, default_value_t = AgentsMode::Embedded)]
    pub agents: AgentsMode,
    /// Distributed mode: endpoint(s) the embedded Zenoh router listens on (comma-separated).
    /// Default: tcp/127.0.0.1:0 (a free port) with embedded agents, tcp/127.0.0.1:7447 with
    /// external ones; listening beyond loopback needs authentication (or --insecure).
    #[arg(long, env = "SHOAL_LISTEN", value_delimiter = ',')]
    pub listen: Vec<String>,
    /// Distributed mode: other Zenoh routers to link to, e.g. another coordinator's endpoint, so
    /// two missions share one network and its agents (comma-separated).
    #[arg(long, env = "SHOAL_ROUTERS", value_delimiter = ',')]
    pub router: Vec<String>,
    /// Distributed mode: how members authenticate to the embedded router (listening beyond
    /// loopback needs it, or --insecure).
    #[command(flatten)]
    pub zenoh: shoal_common::wire::flags::ZenohSecurityArgs,
    /// Set by `serve` (never a flag): the identity its mission routers link to the serving
    /// router with, instead of `zenoh`.
    #[arg(skip)]
    pub link_security: Option<shoal_common::wire::security::Security>,
    /// Distributed mode: seconds the agents have to join.
    #[arg(long, env = "SHOAL_JOIN_TIMEOUT", default_value_t = 30.0)]
    pub join_timeout: f64,
    /// Distributed mode: seconds a round waits for an agent's elites before the coordinator
    /// plans that vehicle itself (degraded mode).
    #[arg(long, env = "SHOAL_ROUND_TIMEOUT", default_value_t = 10.0)]
    pub round_timeout: f64,
    /// Distributed mode: mission id (default: scenario name, process id and time).
    #[arg(long, env = "SHOAL_MISSION")]
    pub mission: Option<String>,
    /// Distributed mode: the shoal-agent binary for embedded agents (default: next to this one).
    #[arg(long, env = "SHOAL_AGENT_BIN")]
    pub agent_bin: Option<PathBuf>,
    /// Distributed mode: rewrite this file every 2 s while the router is open (for container
    /// healthchecks: `shoal-coordinator health`).
    #[arg(long, env = "SHOAL_HEALTH_FILE")]
    pub health_file: Option<PathBuf>,
}

/// `shoal-coordinator router`.
#[derive(Debug, Clone, clap::Args)]
pub struct RouterArgs {
    /// Endpoint(s) to listen on (comma-separated); beyond loopback needs authentication.
    #[arg(
        long,
        env = "SHOAL_LISTEN",
        value_delimiter = ',',
        default_value = "tcp/127.0.0.1:7447"
    )]
    pub listen: Vec<String>,
    /// How members authenticate (a router beyond loopback needs it, or --insecure).
    #[command(flatten)]
    pub zenoh: shoal_common::wire::flags::ZenohSecurityArgs,
}

/// `shoal-coordinator health`.
#[derive(Debug, Clone, clap::Args)]
pub struct HealthArgs {
    /// The health file `plan --health-file` rewrites.
    #[arg(long, env = "SHOAL_HEALTH_FILE")]
    pub file: PathBuf,
}
