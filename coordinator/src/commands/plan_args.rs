//! The planning flags `plan` and `run` share (each flattens [`PlanArgs`]), and what they become:
//! the scenario with the overrides applied, the distributed-mode options, a coverage mission
//! planned as `plan` plans it. Flags only: no command's handler lives here.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use anyhow::{bail, Context};
use shoal_common::scenario::{Algorithm, Scenario};

use crate::distributed::{self, AgentsMode};
use crate::planning::{coverage, coverage_fleet};

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
    /// ldiw-pso, lcpso (seed 003 inspection tours, in process or by the agents); cf-pso
    /// (Clerc and Kennedy 2002, with --in-process); overrides the scenario's.
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

/// Loads a scenario and applies the command-line overrides.
pub fn load_scenario(args: &PlanArgs) -> anyhow::Result<Scenario> {
    let mut s = Scenario::load(&args.scenario)?;
    let o = &mut s.optimizer;
    // The flags given, as typed, for an error that would otherwise blame the file.
    let mut given = Vec::new();
    if let Some(v) = args.seed {
        o.seed = v;
        given.push(format!("--seed {v}"));
    }
    if let Some(v) = args.algorithm {
        o.algorithm = v;
        given.push(format!("--algorithm {}", v.as_str()));
    }
    if let Some(v) = args.iterations {
        o.iterations = v;
        given.push(format!("--iterations {v}"));
    }
    if let Some(v) = args.populations {
        o.populations = v;
        given.push(format!("--populations {v}"));
    }
    if let Some(v) = args.particles {
        o.particles = v;
        given.push(format!("--particles {v}"));
    }
    if let Some(v) = args.threads {
        o.threads = v;
        given.push(format!("--threads {v}"));
    }
    if args.no_touch_up {
        o.touch_up = false;
    }
    // Overrides are user input too: check them with the same rules, naming the field, and
    // saying that the command line set it.
    match s.validate(&args.scenario) {
        Ok(()) => Ok(s),
        Err(e) if given.is_empty() => Err(e.into()),
        Err(e) => Err(anyhow::Error::new(e).context(format!(
            "with the command line's {} over the scenario file",
            given.join(" ")
        ))),
    }
}

/// A duration from a number of seconds given by the user, or an error naming the flag.
fn seconds(flag: &str, value: f64) -> anyhow::Result<std::time::Duration> {
    match std::time::Duration::try_from_secs_f64(value) {
        Ok(d) if value > 0.0 => Ok(d),
        _ => bail!("{flag} = {value}: must be a positive number of seconds"),
    }
}

/// The distributed-mode settings the command line gives.
pub fn distributed_options(
    args: &PlanArgs,
    scenario: &Scenario,
) -> anyhow::Result<distributed::DistributedOptions> {
    let listen = if args.listen.is_empty() {
        vec![match args.agents {
            distributed::AgentsMode::Embedded => "tcp/127.0.0.1:0".to_string(),
            distributed::AgentsMode::External => "tcp/127.0.0.1:7447".to_string(),
        }]
    } else {
        args.listen.clone()
    };
    Ok(distributed::DistributedOptions {
        mission: args
            .mission
            .clone()
            .unwrap_or_else(|| distributed::default_mission_id(scenario)),
        agents: args.agents,
        listen,
        routers: args.router.clone(),
        security: match &args.link_security {
            Some(s) => s.clone(),
            None => args.zenoh.security()?,
        },
        join_timeout: seconds("--join-timeout (SHOAL_JOIN_TIMEOUT)", args.join_timeout)?,
        round_timeout: seconds("--round-timeout (SHOAL_ROUND_TIMEOUT)", args.round_timeout)?,
        agent_bin: args.agent_bin.clone(),
        log_dir: args.out.join("logs"),
        health_file: args.health_file.clone(),
        agent_args: Vec::new(),
    })
}

/// Plans a `[coverage]` mission as `plan` does (`run` too): one crawler in this process, a
/// fleet over its agents (with the options `distributed` gives) unless `--in-process`; writes
/// `plan.json` and `plan.svg` into `--out`.
pub fn plan_coverage_mission(
    args: &PlanArgs,
    scenario: &Scenario,
    shutdown: &Arc<AtomicBool>,
    distributed: impl FnOnce() -> anyhow::Result<distributed::DistributedOptions>,
) -> anyhow::Result<coverage::PlannedCoverage> {
    let Some(settings) = &scenario.coverage else {
        bail!("{}: no [coverage] table", args.scenario.display());
    };
    let fleet = scenario.vehicles.len() > 1;
    if !fleet && !args.in_process {
        bail!(
            "{}: a [coverage] mission with one crawler plans inside this process: add --in-process (several crawlers split the area among their agents)",
            args.scenario.display()
        );
    }
    if let Some(a) = args.algorithm {
        eprintln!(
            "note: --algorithm {} is not used: a [coverage] mission plans with seed 002's Boustrophedon",
            a.as_str()
        );
    }
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create output directory {}", args.out.display()))?;
    if fleet {
        let options = if args.in_process {
            None
        } else {
            Some(distributed()?)
        };
        coverage_fleet::plan_fleet_coverage(
            &args.scenario,
            scenario,
            &args.out,
            args.quiet,
            options.as_ref(),
            shutdown,
        )
    } else {
        coverage::plan_coverage_command(
            &args.scenario,
            scenario,
            settings,
            &args.out,
            args.quiet,
            shutdown,
        )
    }
}
