//! Distributed planning (`plan` without `--in-process`): the coordinator embeds a Zenoh router,
//! the vehicle agents run their vehicles' follower populations, and the coordinator holds the
//! leader population (Zhi & Zuo 2024, §3.2, split over processes as
//! [`shoal_common::distributed`] describes).
//!
//! - [`network`]: the router, the mission's keys, decoding and counting bad messages;
//! - [`agents`]: the coordinator's own agent processes (`--agents embedded`);
//! - [`mission`]: joining, exchange rounds, degraded mode.

pub mod agents;
pub mod mission;
pub mod network;

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

use shoal_common::cost::FleetModel;
use shoal_common::plan::Plan;
use shoal_common::scenario::Scenario;
use shoal_common::wire::topics;

use crate::planning::planner::to_plan;

/// Who starts the agents.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum AgentsMode {
    /// The coordinator starts one `shoal-agent` process per vehicle on this machine.
    #[default]
    Embedded,
    /// Agents are started elsewhere (docker compose, vehicles) and connect to `--listen`.
    External,
}

/// Everything a distributed run needs besides the scenario.
#[derive(Debug, Clone)]
pub struct DistributedOptions {
    /// Mission id (keys `shoal/<mission>/…`).
    pub mission: String,
    /// Who starts the agents.
    pub agents: AgentsMode,
    /// Endpoints the embedded router listens on.
    pub listen: Vec<String>,
    /// Other routers to link to (a second coordinator joining a first one's network).
    pub routers: Vec<String>,
    /// How members authenticate to the router (TLS, users, access control).
    pub security: shoal_common::wire::security::Security,
    /// How long agents have to join.
    pub join_timeout: Duration,
    /// How long a round waits for an agent before planning its vehicle here.
    pub round_timeout: Duration,
    /// The `shoal-agent` binary for embedded agents (found next to this one by default).
    pub agent_bin: Option<PathBuf>,
    /// Where embedded agents write their logs.
    pub log_dir: PathBuf,
    /// Rewritten every 2 s while the router is open (container healthchecks).
    pub health_file: Option<PathBuf>,
    /// Extra command-line arguments of embedded agents (e.g. `--position-noise 2`).
    pub agent_args: Vec<String>,
}

/// A mission id for `scenario` unique enough for one network: its name, this process and the
/// time (not an algorithm's randomness, so `--seed` runs stay reproducible).
pub fn default_mission_id(scenario: &Scenario) -> String {
    let name: String = scenario
        .name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '-'
            }
        })
        .take(40)
        .collect();
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    format!("{name}-{:x}{:05x}", std::process::id(), nanos & 0xfffff)
}

/// Plans `scenario` with one agent per vehicle. `observe` sees every round.
pub fn plan_distributed(
    scenario: &Scenario,
    options: &DistributedOptions,
    stop: &Arc<AtomicBool>,
    observe: &mut dyn FnMut(&mission::Status),
) -> anyhow::Result<Plan> {
    topics::check_id("mission", &options.mission)?;
    let algorithm = scenario.optimizer.algorithm;
    if !algorithm.is_multi_population() && !algorithm.is_tour_planner() {
        anyhow::bail!(
            "distributed planning runs the multi-population algorithms (amp-pso, mp-pso) and the inspection tours (de-pso, ldiw-pso, lcpso); {} is a single-population algorithm: plan it with --in-process",
            algorithm.as_str()
        );
    }
    // Tour missions: the job is a function of the scenario (every agent derives the same one);
    // a scenario without one is refused before the network opens.
    let tours = if algorithm.is_tour_planner() {
        Some(shoal_common::tour::FleetTours::new(scenario).map_err(anyhow::Error::msg)?)
    } else {
        None
    };
    let started = std::time::Instant::now();
    if let Some(job) = tours {
        let (shares, figures) = share_mission(
            scenario,
            mission::ShareJob::Tours(Box::new(job.clone())),
            options,
            stop,
            observe,
        )?;
        let tours = shares
            .into_iter()
            .zip(&scenario.vehicles)
            .map(|(share, v)| match share {
                mission::Share::Tour(t) => Ok(t),
                other => Err(anyhow::anyhow!("{}: no tour ({other:?})", v.id)),
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        let mut plan =
            crate::planning::tour::assemble(scenario, &job, &tours, "distributed", started);
        for d in &figures.degraded {
            plan.notices.push(format!(
                "{}'s tour was planned by the coordinator: {}",
                d.vehicle, d.reason
            ));
        }
        plan.distributed = Some(figures);
        return Ok(plan);
    }
    let mut session = Session::open(scenario, options)?;
    let outcome = mission::run(
        scenario,
        &mut session.net,
        &options.mission,
        timing(options),
        session.local.as_mut(),
        stop,
        observe,
    );
    session.close();
    let (run, figures) = outcome?;
    let model = FleetModel::new(scenario);
    let mut plan = to_plan(scenario, &model, run, "distributed", Some(stop));
    for d in &figures.degraded {
        plan.notices.push(format!(
            "{} was planned in degraded mode by the coordinator from exchange round {}: {}",
            d.vehicle, d.from_round, d.reason
        ));
    }
    plan.distributed = Some(figures);
    Ok(plan)
}

/// Plans a fleet coverage mission (CPP-DSMV with several crawlers): each agent plans its own
/// strip of `map`; a strip whose agent fails is planned here. Returns the strips' plans in
/// scenario order and the network figures.
pub fn plan_strips_distributed(
    scenario: &Scenario,
    job: shoal_common::coverage::fleet::FleetCoverage,
    map: shoal_common::coverage::TerrainMap25,
    options: &DistributedOptions,
    stop: &Arc<AtomicBool>,
    observe: &mut dyn FnMut(&mission::Status),
) -> anyhow::Result<(
    Vec<shoal_common::coverage::fleet::StripPlan>,
    shoal_common::plan::DistributedFigures,
)> {
    topics::check_id("mission", &options.mission)?;
    let (shares, figures) = share_mission(
        scenario,
        mission::ShareJob::Strips(Box::new(job), Box::new(map)),
        options,
        stop,
        observe,
    )?;
    let plans = shares
        .into_iter()
        .zip(&scenario.vehicles)
        .map(|(share, v)| match share {
            mission::Share::Strip(p) => Ok(*p),
            mission::Share::Failed(why) => Err(anyhow::anyhow!("{}'s strip: {why}", v.id)),
            other => Err(anyhow::anyhow!("{}: no strip plan ({other:?})", v.id)),
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    Ok((plans, figures))
}

/// Runs a one-shot mission (see [`mission::ShareJob`]) on its own router and agents.
fn share_mission(
    scenario: &Scenario,
    job: mission::ShareJob,
    options: &DistributedOptions,
    stop: &Arc<AtomicBool>,
    observe: &mut dyn FnMut(&mission::Status),
) -> anyhow::Result<(Vec<mission::Share>, shoal_common::plan::DistributedFigures)> {
    let mut session = Session::open(scenario, options)?;
    let outcome = mission::run_share_mission(
        scenario,
        job,
        &mut session.net,
        &options.mission,
        timing(options),
        session.local.as_mut(),
        stop,
        observe,
    );
    session.close();
    outcome
}

/// How patient the mission is, from the options.
fn timing(options: &DistributedOptions) -> mission::Timing {
    mission::Timing {
        join: options.join_timeout,
        round: options.round_timeout,
    }
}

/// The network side of a run: the embedded router, its health file and the local agents.
pub(crate) struct Session {
    pub(crate) net: network::Network,
    health: Option<shoal_common::health::Heartbeat>,
    pub(crate) local: Option<agents::LocalAgents>,
}

impl Session {
    /// Opens the router for `scenario`'s vehicles and starts the agents `options` asks for.
    pub(crate) fn open(
        scenario: &Scenario,
        options: &DistributedOptions,
    ) -> anyhow::Result<Session> {
        let ids: Vec<String> = scenario.vehicles.iter().map(|v| v.id.clone()).collect();
        let net = network::Network::open(
            &options.listen,
            &options.routers,
            &options.security,
            &options.mission,
            &ids,
        )?;
        let health = options
            .health_file
            .as_deref()
            .map(shoal_common::health::Heartbeat::start);
        tracing::info!(
            mission = %options.mission,
            "coordinator listening on {}",
            net.endpoints.join(", ")
        );
        let local = match options.agents {
            AgentsMode::Embedded => {
                let bin = agents::agent_binary(options.agent_bin.as_deref())?;
                let endpoint = net.endpoints.first().cloned().unwrap_or_default();
                Some(agents::LocalAgents::spawn(
                    &bin,
                    &ids,
                    &endpoint,
                    &options.log_dir,
                    &options.agent_args,
                )?)
            }
            AgentsMode::External => {
                eprintln!(
                    "mission {}: waiting up to {:.0} s for one agent per vehicle ({}) on {}",
                    options.mission,
                    options.join_timeout.as_secs_f64(),
                    ids.join(", "),
                    net.endpoints.join(", ")
                );
                None
            }
        };
        Ok(Session { net, health, local })
    }

    /// Stops the local agents, then closes the router, then the health file.
    pub(crate) fn close(self) {
        let Session { net, health, local } = self;
        drop(local);
        net.close();
        drop(health);
    }
}
