//! `shoal-coordinator serve`: a router that takes missions from anyone on the network. A client
//! (the Python `eclipse-zenoh` package, a ground station) sends a query on `shoal/submit` whose
//! payload is a JSON [`Submission`]; the reply is a JSON [`Receipt`] with the mission id (or
//! why it was refused). Accepted missions run one after another exactly as `run` runs them —
//! plan, then execute with one embedded agent per vehicle — on a router linked to this one, so
//! their plan, telemetry, status and events appear on the open JSON keys
//! (`shoal/<mission>/…`, see [`shoal_common::wire::open`]).
//!
//! Anyone who reaches the router can submit, so a submission is checked before it is queued
//! (`submission`: sizes, rates, wall time, files under `--data-dir`, the mission id), the
//! queue is bounded and takes each id once (`queue`), and missions still queued at exit are
//! named in the log.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

use anyhow::Context as _;
use shoal_common::scenario::DataDir;
use shoal_common::wire::flags::{ZenohListen, ZenohSecurityArgs};
use shoal_common::wire::{codec, session, topics};
use zenoh::Wait;

use crate::distributed::AgentsMode;
use crate::execute::live::LiveFeed;
use crate::foxglove::{self, FoxgloveArgs};
use crate::mission::{run_mission, MissionOptions, NetworkOptions, RunOptions};

mod environment;
mod queue;
mod refusal;
mod submission;

use queue::Queue;
use refusal::Refusal;
use submission::{accept, check_size, Rules};
pub use submission::{Receipt, Submission};

/// `shoal-coordinator serve`.
#[derive(Debug, Clone, clap::Args)]
pub struct ServeArgs {
    /// Where the serving router listens.
    #[command(flatten)]
    pub listen: ZenohListen,
    /// How clients and agents authenticate (listening beyond loopback needs it, or --insecure).
    #[command(flatten)]
    pub zenoh: ZenohSecurityArgs,
    /// Where each mission's files go (`<out>/<mission>/`).
    #[arg(long, env = "SHOAL_OUT", default_value = "missions")]
    pub out: PathBuf,
    /// Serve this many missions, then exit (default: until Ctrl-C).
    #[arg(long)]
    pub missions: Option<usize>,
    /// The only directory whose files (seabed grids, current fields, heightmaps) a submitted
    /// scenario may name. Without it, a submitted scenario naming any file is refused.
    #[arg(long, env = "SHOAL_DATA_DIR")]
    pub data_dir: Option<PathBuf>,
    /// Longest wall time one mission may take (mission time / time scale), hours: a slower
    /// submission is refused rather than holding the queue.
    #[arg(long, env = "SHOAL_MAX_MISSION_HOURS", default_value_t = 6.0)]
    pub max_mission_hours: f64,
    /// Serve the live web view of the mission running now here (e.g. 127.0.0.1:8080; beyond
    /// loopback, HTTPS with the fleet's keys, or plain with --insecure).
    #[arg(long, env = "SHOAL_VIEW", value_name = "ADDR")]
    pub view: Option<std::net::SocketAddr>,
    /// Show each mission live in Foxglove (one server for all missions; beyond loopback, WSS
    /// with the fleet's keys, or plain with --insecure).
    #[command(flatten)]
    pub foxglove: FoxgloveArgs,
}

/// The operator's rules from the flags.
fn rules(args: &ServeArgs) -> anyhow::Result<Rules> {
    let h = args.max_mission_hours;
    if !(h.is_finite() && h > 0.0) {
        anyhow::bail!("--max-mission-hours (SHOAL_MAX_MISSION_HOURS) = {h}: must be a positive number of hours");
    }
    let data_dir = match &args.data_dir {
        Some(d) => Some(DataDir::open(d).with_context(|| {
            format!(
                "--data-dir (SHOAL_DATA_DIR) {}: not a usable directory",
                d.display()
            )
        })?),
        None => None,
    };
    Ok(Rules {
        data_dir,
        max_wall_s: h * 3600.0,
    })
}

/// Checks one submission and queues it: the mission id, or why it was refused. Never
/// panics: a bug in a check is a refusal, not a dead server.
fn answer(
    payload: Option<&zenoh::bytes::ZBytes>,
    rules: &Rules,
    queue: &Queue,
) -> Result<String, Refusal> {
    // The size before copying or decoding anything.
    check_size(payload.map_or(0, |p| p.len()))?;
    let bytes = payload
        .map(|p| p.to_bytes().into_owned())
        .unwrap_or_default();
    let checked = catch_unwind(AssertUnwindSafe(|| accept(&bytes, rules)));
    let a = checked.map_err(|_| Refusal::Unchecked)??;
    queue.offer(a.mission.clone(), a.submission)?;
    Ok(a.mission)
}

/// Serves until `shutdown` (or `--missions` missions).
pub fn command(args: &ServeArgs, shutdown: Arc<AtomicBool>) -> anyhow::Result<i32> {
    let rules = rules(args)?;
    // One feed for every mission: each starts with its start record, which the page, the
    // Foxglove clients (and the feed's catch-up) take as a new mission.
    let feed = LiveFeed::new();
    let security = args.zenoh.security()?;
    let view = crate::view::start_live(args.view, &security, &feed)?;
    let foxglove = foxglove::start(&args.foxglove, &security, &feed)?;
    let live = (view.is_some() || foxglove.is_some()).then_some(&feed);
    let listen: Vec<String> = args
        .listen
        .listen
        .iter()
        .map(|e| crate::distributed::network::resolve_port_zero(e))
        .collect::<anyhow::Result<_>>()?;
    let config = session::router_config(&listen, &[], &security)?;
    // Each mission's router links to this one with this router's own identity.
    let link_security = shoal_common::wire::security::link_identity(&config);
    let router = zenoh::open(config)
        .wait()
        .map_err(|e| anyhow::anyhow!("cannot open a Zenoh router on {}: {e}", listen.join(", ")))?;
    let queue = Arc::new(Queue::new(args.out.clone()));
    let refused = Arc::new(AtomicU64::new(0));
    let (count, waiting) = (Arc::clone(&refused), Arc::clone(&queue));
    let submit = router
        .declare_queryable(topics::SUBMIT)
        .callback(move |q| {
            let receipt = match answer(q.payload(), &rules, &waiting) {
                Ok(mission) => {
                    tracing::info!("accepted mission {mission}");
                    submission::accepted(&mission)
                }
                Err(why) => {
                    count.fetch_add(1, Ordering::Relaxed);
                    tracing::warn!("refused a submission: {why}");
                    submission::refused(why.to_string())
                }
            };
            if let Ok(b) = codec::encode_json(&receipt) {
                let _ = q.reply(topics::SUBMIT, b).wait();
            }
        })
        .wait()
        .map_err(|e| anyhow::anyhow!("cannot declare the queryable {}: {e}", topics::SUBMIT))?;
    let link = Link {
        endpoint: listen
            .first()
            .map(|e| e.replace("/0.0.0.0:", "/127.0.0.1:"))
            .unwrap_or_default(),
        security: link_security,
    };
    eprintln!(
        "serving missions on {} (submit on {}); Ctrl-C to stop",
        listen.join(", "),
        topics::SUBMIT
    );
    let mut served = 0usize;
    while !shutdown.load(Ordering::Relaxed) && args.missions.is_none_or(|n| served < n) {
        let Some((mission, s)) = queue.take(Duration::from_millis(200)) else {
            continue;
        };
        served += 1;
        let ran = catch_unwind(AssertUnwindSafe(|| {
            run_one(args, &link, &mission, &s, &shutdown, live)
        }));
        match ran {
            Ok(Ok(code)) => eprintln!("mission {mission}: ended with status {code}"),
            Ok(Err(e)) => eprintln!("mission {mission}: failed: {e:#}"),
            Err(_) => eprintln!("mission {mission}: failed: the run panicked"),
        }
        queue.finished();
    }
    // No more submissions, then say which were left.
    drop(submit);
    if let Err(e) = router.close().wait() {
        tracing::warn!("closing the router: {e}");
    }
    let left = queue.drain();
    if !left.is_empty() {
        eprintln!(
            "{} mission(s) still queued, not run: {}",
            left.len(),
            left.join(", ")
        );
    }
    eprintln!(
        "served {served} mission(s); refused {} submission(s)",
        refused.load(Ordering::Relaxed)
    );
    Ok(crate::commands::exit::EXIT_FEASIBLE)
}

/// How a mission's router reaches the serving one.
struct Link {
    /// The serving router's first endpoint, on loopback.
    endpoint: String,
    /// The serving router's own identity (see `security::link_identity`).
    security: shoal_common::wire::security::Security,
}

/// Runs one accepted mission as `run` would, in `<out>/<mission>/` (which must not exist yet:
/// it is never overwritten).
fn run_one(
    args: &ServeArgs,
    link: &Link,
    mission: &str,
    s: &Submission,
    shutdown: &Arc<AtomicBool>,
    live: Option<&Arc<LiveFeed>>,
) -> anyhow::Result<i32> {
    let dir = args.out.join(mission);
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    std::fs::create_dir(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let file = dir.join("scenario.toml");
    std::fs::write(&file, &s.scenario_toml)
        .with_context(|| format!("cannot write {}", file.display()))?;
    let mut options = mission_options(link, mission, s, file, dir.clone())?;
    options.execution.live = live.cloned();
    eprintln!(
        "mission {mission}: planning and executing (files in {})",
        dir.display()
    );
    Ok(if run_mission(&options, Arc::clone(shutdown))? {
        crate::commands::exit::EXIT_FEASIBLE
    } else {
        crate::commands::exit::EXIT_VIOLATIONS
    })
}

/// What a submitted mission runs with: its own settings, serve's output directory, embedded
/// agents on a free loopback port linked to the serving router with its identity, no progress
/// output; every other setting is `run`'s default unless the `SHOAL_*` variable `run` reads for
/// it is set in serve's environment ([`environment::overlay`]), as it always was.
fn mission_options(
    link: &Link,
    mission: &str,
    s: &Submission,
    scenario: PathBuf,
    out: PathBuf,
) -> anyhow::Result<RunOptions> {
    let mut options = RunOptions {
        mission: MissionOptions {
            scenario,
            out,
            overrides: Default::default(),
            quiet: true,
            in_process: false,
            network: Some(NetworkOptions {
                mission: Some(mission.to_string()),
                // Explicit, so that serve's own SHOAL_LISTEN / SHOAL_AGENTS never reach the
                // mission.
                agents: AgentsMode::Embedded,
                listen: vec!["tcp/127.0.0.1:0".into()],
                routers: vec![link.endpoint.clone()],
                security: link.security.clone(),
                ..NetworkOptions::default()
            }),
        },
        execution: Default::default(),
    };
    environment::overlay(&mut options)?;
    let (m, e) = (&mut options.mission, &mut options.execution);
    m.in_process |= s.in_process;
    m.overrides.iterations = s.iterations.or(m.overrides.iterations);
    m.overrides.seed = s.seed.or(m.overrides.seed);
    e.time_scale = s.time_scale.unwrap_or(e.time_scale);
    e.telemetry_hz = s.telemetry_hz.unwrap_or(e.telemetry_hz);
    Ok(options)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A submission's own settings and serve's decisions reach the mission as options, with
    /// `run`'s defaults for the rest (no `SHOAL_*` variable set in the test's environment).
    #[test]
    fn a_submission_becomes_run_options_without_an_argv() -> anyhow::Result<()> {
        let link = Link {
            endpoint: "tcp/127.0.0.1:7447".into(),
            security: Default::default(),
        };
        let s = Submission {
            version: 1,
            scenario_toml: String::new(),
            mission: None,
            time_scale: Some(50.0),
            telemetry_hz: None,
            iterations: Some(7),
            seed: None,
            in_process: true,
        };
        let o = mission_options(&link, "m-1", &s, "m/scenario.toml".into(), "m".into())?;
        let (m, e) = (&o.mission, &o.execution);
        assert!(m.in_process && m.quiet);
        assert_eq!((m.overrides.iterations, m.overrides.seed), (Some(7), None));
        assert_eq!((e.time_scale, e.telemetry_hz), (50.0, 2.0));
        let n = m.network()?;
        assert_eq!(n.mission.as_deref(), Some("m-1"));
        assert_eq!(n.agents, AgentsMode::Embedded);
        assert_eq!(n.listen, ["tcp/127.0.0.1:0"]);
        assert_eq!(n.routers, ["tcp/127.0.0.1:7447"]);
        Ok(())
    }
}
