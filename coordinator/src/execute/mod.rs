//! Executing a plan (`shoal-coordinator run`): every agent drives its vehicle along its
//! trajectory through its vehicle link and reports telemetry; the coordinator keeps the live
//! fleet picture ([`fleet`]), publishes it on the open JSON keys, logs everything ([`log`]) and
//! reacts (`react`): a predicted loss of separation, a deviation beyond the tolerance, a
//! vehicle that stops reporting or a new obstacle makes it replan the affected vehicles
//! ([`replan`]; an inspection tour or an energy plan is repaired instead, `repair`) or, when
//! no safe replan comes in time, command a hold.

mod confirmations;
mod detour;
pub mod fleet;
mod ground;
mod keep_out;
mod lead;
pub mod live;
pub mod log;
pub mod plausible;
mod queue;
mod react;
mod repair;
pub mod replan;
mod replan_queue;
pub mod replayed;
mod resend;
mod standing;
mod state;
mod track;
mod tracked;
pub mod verdict;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::sync::Arc;
use std::time::{Duration, Instant};

use shoal_common::coverage::reroute::CrawlerGround;
use shoal_common::execution::{unix_us, MissionClock};
use shoal_common::scenario::{Obstacle, Scenario};
use shoal_common::trajectory::Trajectory;
use shoal_common::wire::codec;
use shoal_common::wire::coordinator_to_agent::CoordinatorToAgent;
use shoal_common::wire::open::FleetStatus;
use shoal_common::wire::topics::{self, OpenKey};
use shoal_common::wire::WireTrajectory;
use zenoh::Wait;

use crate::distributed::network::Event;
use crate::distributed::{DistributedOptions, Session};
use fleet::{ExecutionFigures, Fleet};
use log::{LogWriter, Record, Start};
pub(crate) use state::Exec;
pub use state::ExecOptions;

/// Raw input from the open-interface subscriptions (callbacks do no work themselves).
enum Open {
    /// Key, payload, receipt time (unix µs).
    Telemetry(String, Vec<u8>, u64),
    /// An obstacle and when it came (the rate limit counts arrivals, not the loop's pace).
    Obstacle(Vec<u8>, Instant),
}

/// What an execution leaves.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ExecutionReport {
    /// The figures.
    pub figures: ExecutionFigures,
    /// Replans sent.
    pub replans: u64,
    /// Holds commanded.
    pub holds: u64,
    /// Obstacle replans: obstacle received → update sent, milliseconds.
    pub obstacle_decision_ms: Vec<f64>,
    /// Update sent → first report on the new revision, milliseconds.
    pub update_delivery_ms: Vec<f64>,
    /// Malformed or unusable open-interface messages dropped.
    pub dropped: u64,
    /// Well-formed reports and obstacles refused as implausible (or over a limit), per reason
    /// (see [`plausible`]).
    pub implausible: plausible::Refusals,
    /// Longest wall time between two passes of the execution loop, milliseconds: for that long
    /// no report was read, no conflict looked for and no status published.
    pub loop_longest_pause_ms: f64,
    /// Why it ended.
    pub ended: String,
}

/// The seabed of a coverage fleet, for its crawlers' ways round new obstacles; `None` for
/// other missions, or (with a warning) when the map cannot be built here.
fn crawler_ground(scenario: &Scenario) -> Option<CrawlerGround> {
    scenario.coverage.as_ref()?;
    match CrawlerGround::of(scenario, std::path::Path::new(".")) {
        Ok(g) => Some(g),
        Err(e) => {
            tracing::warn!("a blocked crawler will hold, with no way round: {e}");
            None
        }
    }
}

/// Executes the given trajectories of `scenario` (scenario order, mission-timed; their common
/// arrival `common_arrival_s`): opens a router (and the agents `distributed` asks for), has
/// every agent drive its vehicle, and watches until every vehicle has arrived or is lost.
pub fn execute_trajectories(
    scenario: &Scenario,
    plans: &[Trajectory],
    common_arrival_s: f64,
    distributed: &DistributedOptions,
    options: &ExecOptions,
    stop: &AtomicBool,
) -> anyhow::Result<ExecutionReport> {
    topics::check_id("mission", &distributed.mission)?;
    let ids: Vec<String> = scenario.vehicles.iter().map(|v| v.id.clone()).collect();
    if plans.len() != ids.len() {
        anyhow::bail!("{} trajectories for {} vehicles", plans.len(), ids.len());
    }
    // Every agent reads the scenario back with the same parser and drops an order it cannot
    // read (the coordinator would only see its vehicle go silent and be lost): checked here,
    // before anything starts, with the name the agents give it.
    let scenario_toml = toml::to_string(scenario)?;
    let origin = format!("<scenario of mission {}>", distributed.mission);
    Scenario::parse(&scenario_toml, std::path::Path::new(&origin))
        .map_err(|e| anyhow::anyhow!("the scenario sent to the agents does not read back: {e}"))?;
    let session = Session::open(scenario, distributed)?;
    let (tx, rx) = mpsc::channel::<Open>();
    let net_session = session.net.session().clone();
    let tel_key = topics::all_telemetry(&distributed.mission)?;
    let tx_t = tx.clone();
    let _telemetry = net_session
        .declare_subscriber(tel_key.as_str())
        .callback(move |s| {
            let _ = tx_t.send(Open::Telemetry(
                s.key_expr().as_str().to_string(),
                s.payload().to_bytes().into_owned(),
                unix_us(),
            ));
        })
        .wait()
        .map_err(|e| anyhow::anyhow!("cannot subscribe to {tel_key}: {e}"))?;
    let obs_key = topics::open_key(&distributed.mission, OpenKey::Obstacles)?;
    let _obstacles = net_session
        .declare_subscriber(obs_key.as_str())
        .callback(move |s| {
            let _ = tx.send(Open::Obstacle(
                s.payload().to_bytes().into_owned(),
                Instant::now(),
            ));
        })
        .wait()
        .map_err(|e| anyhow::anyhow!("cannot subscribe to {obs_key}: {e}"))?;
    // `status` answers from the latest picture (the loop refreshes it).
    let latest = std::sync::Arc::new(std::sync::Mutex::new(Vec::<u8>::new()));
    let status_key = topics::open_key(&distributed.mission, OpenKey::Status)?;
    let answer = std::sync::Arc::clone(&latest);
    let key_for_reply = status_key.clone();
    let _queryable = net_session
        .declare_queryable(status_key.as_str())
        .callback(move |q| {
            let bytes = answer.lock().map(|b| b.clone()).unwrap_or_default();
            if !bytes.is_empty() {
                let _ = q.reply(key_for_reply.as_str(), bytes).wait();
            }
        })
        .wait()
        .map_err(|e| anyhow::anyhow!("cannot declare the queryable {status_key}: {e}"))?;
    // Built before the mission clock starts: a large map takes a moment.
    let ground = crawler_ground(scenario).map(Arc::new);
    let watcher = options
        .live
        .clone()
        .map(|feed| feed as Arc<dyn log::RecordWatcher>);
    let log = LogWriter::create(&options.log)?.with_watcher(watcher);
    let epoch_unix_ms = unix_us() / 1000 + 1500;
    let mut x = Exec {
        scenario: scenario.clone(),
        mission: distributed.mission.clone(),
        options,
        fleet: Fleet::new(&ids, plans, scenario.fleet.d_min_m, options.horizon_s),
        session,
        log,
        mission_clock: MissionClock {
            epoch_unix_ms,
            scale: options.time_scale,
        },
        common_arrival_s,
        revision: 0,
        replans: 0,
        holds: 0,
        last_reaction: vec![None; ids.len()],
        hold_retries: vec![0; ids.len()],
        last_attempt: vec![Duration::ZERO; ids.len()],
        queue: queue::ReplanQueue::default(),
        rounded: Vec::new(),
        pending: vec![None; ids.len()],
        deliveries_ms: Vec::new(),
        decisions_ms: Vec::new(),
        dropped: 0,
        guard: plausible::Guard::default(),
        longest_pause: Duration::ZERO,
        ground,
    };
    x.log.write(&Record::Start(Start {
        mission: x.mission.clone(),
        scenario_toml: scenario_toml.clone(),
        common_arrival_s,
        arrival_window_s: options.arrival_window_s,
        horizon_s: options.horizon_s,
        time_scale: options.time_scale,
        epoch_unix_ms,
    }));
    x.publish_plan(ids.clone());
    let ended = run_loop(&mut x, &rx, plans, &scenario_toml, &latest, stop);
    // The picture as the mission ended (a vehicle lost in its last second included): the last
    // status the status key, the web view and Foxglove show.
    publish_status(&mut x, &latest);
    for id in &ids {
        x.send(
            id,
            CoordinatorToAgent::Stop {
                mission: x.mission.clone(),
                reason: ended.clone(),
            },
        );
    }
    x.event("mission_end", Vec::new(), ended.clone());
    let figures = x
        .fleet
        .figures_for(&x.scenario, common_arrival_s, options.arrival_window_s);
    x.log.write(&Record::End(figures.clone()));
    x.log.finish();
    let report = ExecutionReport {
        figures,
        replans: x.replans,
        holds: x.holds,
        obstacle_decision_ms: x.decisions_ms.clone(),
        update_delivery_ms: x.deliveries_ms.clone(),
        dropped: x.dropped,
        implausible: x.guard.refusals.clone(),
        loop_longest_pause_ms: x.longest_pause.as_secs_f64() * 1000.0,
        ended,
    };
    std::thread::sleep(Duration::from_millis(200)); // let the stops go out
    x.session.close();
    Ok(report)
}

/// Publishes the fleet status: the status key (and the latest kept for its queries) and the
/// live feed; returns it.
fn publish_status(x: &mut Exec, latest: &std::sync::Mutex<Vec<u8>>) -> FleetStatus {
    let status = x.status();
    if let Ok(bytes) = codec::encode_json(&status) {
        if let Ok(mut l) = latest.lock() {
            *l = bytes;
        }
    }
    if let Ok(key) = topics::open_key(&x.mission, OpenKey::Status) {
        x.put_json(&key, &status);
    }
    if let Some(feed) = &x.options.live {
        feed.publish(live::LiveMessage::Status(status.clone()));
    }
    status
}

/// The loop: orders out, reports in, the picture refreshed and acted on.
fn run_loop(
    x: &mut Exec,
    rx: &Receiver<Open>,
    plans: &[Trajectory],
    scenario_toml: &str,
    latest: &std::sync::Mutex<Vec<u8>>,
    stop: &AtomicBool,
) -> String {
    let o = x.options;
    let started = Instant::now();
    let mut resend = Instant::now();
    let mut tick = Instant::now();
    let mut publish = Instant::now();
    let mut injections: Vec<(f64, Obstacle)> = o.inject.clone();
    // Past the window, a mission that still has vehicles under way is given up.
    let give_up_s = x.common_arrival_s + o.arrival_window_s + 600.0;
    let mut last_pass = Instant::now();
    loop {
        x.longest_pause = x.longest_pause.max(last_pass.elapsed());
        last_pass = Instant::now();
        if stop.load(Ordering::Relaxed) {
            return "interrupted".into();
        }
        let now_wall = Instant::now();
        if now_wall >= resend {
            resend = now_wall + Duration::from_secs(1);
            for (i, planned) in plans.iter().enumerate().take(x.fleet.vehicles.len()) {
                for order in resend::repeated(&x.fleet.vehicles[i]) {
                    let m = repeated_order(x, i, order, planned, scenario_toml);
                    x.send(&x.fleet.vehicles[i].id, m);
                }
            }
        }
        match rx.recv_timeout(Duration::from_millis(20)) {
            Ok(Open::Telemetry(key, bytes, received)) => {
                react::telemetry(x, &key, &bytes, received)
            }
            Ok(Open::Obstacle(bytes, arrived)) => react::obstacle_bytes(x, &bytes, arrived),
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => return "the network closed".into(),
        }
        replan_queue::poll(x);
        while let Some(e) = x.session.net.next(Instant::now()) {
            if let Event::Gone(v) = e {
                react::lose(x, &v, "its agent left the network (liveliness token gone)");
            }
        }
        let now = x.clock();
        while let Some(k) = injections.iter().position(|(t, _)| *t <= now) {
            let (_, obstacle) = injections.remove(k);
            // Published like any client would; it comes back through the subscription.
            if let Ok(key) = topics::open_key(&x.mission, OpenKey::Obstacles) {
                x.put_json(&key, &obstacle);
            }
        }
        if tick.elapsed() >= Duration::from_millis(100) {
            tick = Instant::now();
            react::check(x, now);
            standing::check(x, now);
        }
        if publish.elapsed() >= Duration::from_secs(1) {
            publish = Instant::now();
            let status = publish_status(x, latest);
            if !o.quiet {
                eprintln!("{}", react::progress_line(&status, x.fleet.reports));
            }
            x.log.flush();
        }
        let done = x.fleet.vehicles.iter().all(|v| !v.driven());
        if done {
            return "every vehicle arrived, is lost or reports a fault".into();
        }
        if now > give_up_s {
            return format!("mission time {now:.0} s is past the arrival window: given up");
        }
        if started.elapsed() > Duration::from_secs(30) && x.fleet.reports == 0 {
            return "no telemetry from any vehicle within 30 s".into();
        }
    }
}

/// Vehicle `i`'s `order`, repeated until it first reports (see [`resend`]); `planned` is its
/// plan of revision 0.
fn repeated_order(
    x: &Exec,
    i: usize,
    order: resend::Repeated,
    planned: &Trajectory,
    scenario_toml: &str,
) -> CoordinatorToAgent {
    let o = x.options;
    let id = &x.fleet.vehicles[i].id;
    match order {
        resend::Repeated::Execute => CoordinatorToAgent::Execute {
            trajectory: WireTrajectory::new(id, planned),
            mission: x.mission.clone(),
            vehicle: id.clone(),
            scenario_toml: scenario_toml.to_string(),
            epoch_unix_ms: x.mission_clock.epoch_unix_ms,
            time_scale: o.time_scale,
            telemetry_hz: o.telemetry_hz,
            seed: o.seed.wrapping_add(i as u64),
        },
        resend::Repeated::Update => x.update_of(i),
        resend::Repeated::Hold => x.hold_of(i, "told to hold before its first report"),
    }
}
