//! What a mission is asked to do, typed and checked: the settings `plan` and `run` take from
//! their flags and `serve` from a submission, apart from how they were given (ripgrep's
//! low-level arguments becoming its `HiArgs`; dora's `RunDataflowOptions`). New settings belong
//! here, with a default, so every way of starting a mission gets them.

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::bail;
use shoal_common::scenario::{Algorithm, Scenario};
use shoal_common::wire::flags::DEFAULT_ENDPOINT;
use shoal_common::wire::security::Security;

use crate::distributed::{self, AgentsMode, DistributedOptions};

/// Settings that replace the scenario file's `[optimizer]` ones for this mission.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Overrides {
    /// RNG seed.
    pub seed: Option<u64>,
    /// Optimizer.
    pub algorithm: Option<Algorithm>,
    /// Iterations.
    pub iterations: Option<usize>,
    /// Follower populations.
    pub populations: Option<usize>,
    /// Particles per population.
    pub particles: Option<usize>,
    /// Worker threads (the plan does not depend on them).
    pub threads: Option<usize>,
    /// Keep the swarm's own best instead of re-planning each vehicle in a violation (the
    /// scenario's `optimizer.touch_up` off).
    pub no_touch_up: bool,
    /// Keep the swarm's (touched-up) plan without the local refinement (the scenario's
    /// `optimizer.refine` off).
    pub no_refine: bool,
}

/// Loads a scenario and applies `overrides`, checking the result with the file's own rules; an
/// error an override caused names it as the command line's, not the file's.
pub fn load_scenario(path: &Path, overrides: &Overrides) -> anyhow::Result<Scenario> {
    let mut s = Scenario::load(path)?;
    let o = &mut s.optimizer;
    // The overrides given, as typed, for an error that would otherwise blame the file.
    let mut given = Vec::new();
    if let Some(v) = overrides.seed {
        o.seed = v;
        given.push(format!("--seed {v}"));
    }
    if let Some(v) = overrides.algorithm {
        o.algorithm = v;
        given.push(format!("--algorithm {}", v.as_str()));
    }
    if let Some(v) = overrides.iterations {
        o.iterations = v;
        given.push(format!("--iterations {v}"));
    }
    if let Some(v) = overrides.populations {
        o.populations = v;
        given.push(format!("--populations {v}"));
    }
    if let Some(v) = overrides.particles {
        o.particles = v;
        given.push(format!("--particles {v}"));
    }
    if let Some(v) = overrides.threads {
        o.threads = v;
        given.push(format!("--threads {v}"));
    }
    if overrides.no_touch_up {
        o.touch_up = false;
    }
    if overrides.no_refine {
        o.refine = false;
    }
    match s.validate(path) {
        Ok(()) => Ok(s),
        Err(e) if given.is_empty() => Err(e.into()),
        Err(e) => Err(anyhow::Error::new(e).context(format!(
            "with the command line's {} over the scenario file",
            given.join(" ")
        ))),
    }
}

/// Seconds the agents have to join by default.
pub const DEFAULT_JOIN_TIMEOUT_S: f64 = 30.0;
/// Seconds a round waits for an agent's elites by default, before the coordinator plans that
/// vehicle itself (degraded mode).
pub const DEFAULT_ROUND_TIMEOUT_S: f64 = 10.0;

/// Where the embedded router listens when nothing says: embedded agents find any free
/// loopback port; external ones must be told one, so it is Zenoh's own.
pub fn default_listen(agents: AgentsMode) -> &'static str {
    match agents {
        AgentsMode::Embedded => "tcp/127.0.0.1:0",
        AgentsMode::External => DEFAULT_ENDPOINT,
    }
}

/// A duration from a number of seconds the user gave, or an error naming where it came from.
pub fn seconds(flag: &str, value: f64) -> anyhow::Result<Duration> {
    match Duration::try_from_secs_f64(value) {
        Ok(d) if value > 0.0 => Ok(d),
        _ => bail!("{flag} = {value}: must be a positive number of seconds"),
    }
}

/// The fleet's network as a mission uses it: the embedded router, who starts the agents and
/// how long they are waited for. Distributed planning and `run`'s execution both go over it.
#[derive(Debug, Clone)]
pub struct NetworkOptions {
    /// Mission id (keys `shoal/<mission>/…`); `None`: from the scenario's name, this process
    /// and the time ([`distributed::default_mission_id`]).
    pub mission: Option<String>,
    /// Who starts the agents.
    pub agents: AgentsMode,
    /// Endpoints the embedded router listens on (never empty: see [`default_listen`]).
    pub listen: Vec<String>,
    /// Other routers to link to, so two missions share one network and its agents.
    pub routers: Vec<String>,
    /// How members authenticate to the embedded router.
    pub security: Security,
    /// How long the agents have to join.
    pub join_timeout: Duration,
    /// How long a round waits for an agent before planning its vehicle here.
    pub round_timeout: Duration,
    /// The `shoal-agent` binary for embedded agents (default: next to this one).
    pub agent_bin: Option<PathBuf>,
    /// Rewritten every 2 s while the router is open (container healthchecks).
    pub health_file: Option<PathBuf>,
}

impl Default for NetworkOptions {
    /// Embedded agents on a free loopback port, no authentication (loopback only), the
    /// default timeouts.
    fn default() -> Self {
        NetworkOptions {
            mission: None,
            agents: AgentsMode::Embedded,
            listen: vec![default_listen(AgentsMode::Embedded).to_string()],
            routers: Vec::new(),
            security: Security::default(),
            join_timeout: Duration::from_secs_f64(DEFAULT_JOIN_TIMEOUT_S),
            round_timeout: Duration::from_secs_f64(DEFAULT_ROUND_TIMEOUT_S),
            agent_bin: None,
            health_file: None,
        }
    }
}

impl NetworkOptions {
    /// What the distributed layer takes for `scenario`'s mission, embedded agents logging into
    /// `log_dir`.
    pub fn distributed(&self, scenario: &Scenario, log_dir: PathBuf) -> DistributedOptions {
        let mission = self
            .mission
            .clone()
            .unwrap_or_else(|| distributed::default_mission_id(scenario));
        self.for_mission(mission, log_dir)
    }

    /// What the distributed layer takes for mission `mission` (whatever [`Self::mission`]
    /// says), embedded agents logging into `log_dir`.
    pub fn for_mission(&self, mission: String, log_dir: PathBuf) -> DistributedOptions {
        DistributedOptions {
            mission,
            agents: self.agents,
            listen: self.listen.clone(),
            routers: self.routers.clone(),
            security: self.security.clone(),
            join_timeout: self.join_timeout,
            round_timeout: self.round_timeout,
            agent_bin: self.agent_bin.clone(),
            log_dir,
            health_file: self.health_file.clone(),
            agent_args: Vec::new(),
        }
    }
}

/// A mission to plan: `plan`'s settings, and the planning half of `run`'s.
#[derive(Debug, Clone)]
pub struct MissionOptions {
    /// The scenario file (TOML); files it names are found beside it.
    pub scenario: PathBuf,
    /// Directory for `plan.json`, `plan.svg` and the logs (created if missing).
    pub out: PathBuf,
    /// What replaces the scenario's optimizer settings.
    pub overrides: Overrides,
    /// No progress output on stderr.
    pub quiet: bool,
    /// Plan inside this process (no agents, no network) rather than over the agents.
    pub in_process: bool,
    /// The agents' network: needed to plan over the agents and for `run`'s execution; `None`
    /// when nothing uses it (an in-process plan).
    pub network: Option<NetworkOptions>,
}

impl MissionOptions {
    /// The network settings, which distributed planning and execution cannot do without.
    pub fn network(&self) -> anyhow::Result<&NetworkOptions> {
        match &self.network {
            Some(n) => Ok(n),
            None => bail!(
                "{}: planning over the agents needs the network's settings",
                self.scenario.display()
            ),
        }
    }
}

/// Where an injected obstacle goes.
#[derive(Debug, Clone, PartialEq)]
pub enum Place {
    /// At a point, metres.
    At([f64; 3]),
    /// On a vehicle's planned path, [`AHEAD_S`] after the injection time.
    OnPath(String),
}

/// How far ahead on a vehicle's planned path [`Place::OnPath`] puts the obstacle, mission
/// seconds.
pub const AHEAD_S: f64 = 150.0;

/// A hard obstacle published during the execution, as a client would.
#[derive(Debug, Clone, PartialEq)]
pub struct Injection {
    /// Mission time it appears, seconds.
    pub at_s: f64,
    /// Where.
    pub place: Place,
    /// Radius, metres.
    pub radius_m: f64,
}

/// Mission seconds per wall second by default: real time.
pub const DEFAULT_TIME_SCALE: f64 = 1.0;

/// How `run` executes a plan; every field has the default `run`'s flags show.
#[derive(Debug, Clone, PartialEq)]
pub struct ExecutionSettings {
    /// Mission seconds per wall second.
    pub time_scale: f64,
    /// Telemetry reports per wall second and vehicle.
    pub telemetry_hz: f64,
    /// Prediction horizon of the separation check, mission seconds.
    pub horizon_s: f64,
    /// Cross-track error that triggers a replan, metres (`None`: d_min / 2, or 10 m alone).
    pub deviation_m: Option<f64>,
    /// Metres over d_min a replan keeps from the other vehicles (`None`: d_min / 5).
    pub separation_buffer_m: Option<f64>,
    /// Wall seconds without telemetry after which a vehicle is lost.
    pub lost_after_s: f64,
    /// Wall-time budget of one replan, milliseconds.
    pub replan_budget_ms: u64,
    /// Half-width of the arrival window around the common arrival time, mission seconds.
    pub arrival_window_s: f64,
    /// Simulated vehicles: position noise of their fixes, metres.
    pub position_noise_m: f64,
    /// Obstacles published during the execution.
    pub inject: Vec<Injection>,
    /// The mission log (`None`: `<out>/mission.ndjson`; the MCAP log goes beside it).
    pub log: Option<PathBuf>,
    /// Live watchers' feed (see [`crate::execute::live`]); `None` when nobody watches.
    pub live: Option<std::sync::Arc<crate::execute::live::LiveFeed>>,
}

impl ExecutionSettings {
    /// The defaults, also what `run`'s flags show.
    pub const DEFAULT: ExecutionSettings = ExecutionSettings {
        time_scale: DEFAULT_TIME_SCALE,
        telemetry_hz: 2.0,
        horizon_s: 180.0,
        deviation_m: None,
        separation_buffer_m: None,
        lost_after_s: 3.0,
        replan_budget_ms: 300,
        arrival_window_s: 30.0,
        position_noise_m: 1.0,
        inject: Vec::new(),
        log: None,
        live: None,
    };
}

impl Default for ExecutionSettings {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// A mission to plan and execute: `run`'s settings.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// What to plan, where, and how; its network (required) is the execution's too.
    pub mission: MissionOptions,
    /// How the plan is executed.
    pub execution: ExecutionSettings,
}
