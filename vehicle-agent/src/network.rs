//! The agent's side of the network: a Zenoh client of the coordinator's router, its inbox
//! (`shoal/*/vehicle/<id>/in`) and the fleets' context keys (`shoal/*/fleet`), its liveliness
//! token, and one planning thread per mission it serves.
//!
//! Every message is decoded here. One that does not decode, has another protocol version,
//! names a mission or vehicle this agent does not serve, or (on its inbox) carries an order
//! number not after the last one taken (the `order_seq` module) is dropped, counted and logged once per
//! kind — never a panic, never a stall.

use std::collections::{HashMap, HashSet};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError, Sender};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

use anyhow::Context as _;
use shoal_common::wire::agent_to_coordinator::AgentToCoordinator;
use shoal_common::wire::codec::{self, DecodeError};
use shoal_common::wire::coordinator_to_agent::CoordinatorToAgent;
use shoal_common::wire::{session, topics, Envelope};
use zenoh::qos::CongestionControl;
use zenoh::{Session, Wait};

use crate::assignment::{Assignment, MissionReport};
use crate::config::AgentConfig;
use crate::execute::{self, Order};
use crate::link;
use crate::mission;
use shoal_common::wire::open::Telemetry;

mod coordinator_watch;
mod drops;
mod order_seq;
pub use coordinator_watch::coordinator_present;
use coordinator_watch::Departures;
pub use drops::Drops;
use order_seq::OrderSeqs;

/// A mission being planned on its own thread.
struct Worker {
    tx: Sender<CoordinatorToAgent>,
    /// It drives the vehicle (an execution), rather than plans: one at a time.
    drives: bool,
    stop: Arc<AtomicBool>,
    handle: JoinHandle<MissionReport>,
}

/// Opens a client session on a thread of its own (zenoh's open blocks while it waits for the
/// router), giving up when `shutdown` is raised.
fn open(agent: &AgentConfig, shutdown: &AtomicBool) -> anyhow::Result<Option<Session>> {
    let config = session::client_config(&agent.connect, true, &agent.security)?;
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(zenoh::open(config).wait());
    });
    let mut waited = Duration::ZERO;
    loop {
        match rx.recv_timeout(Duration::from_millis(100)) {
            Ok(session) => {
                return session
                    .map(Some)
                    .map_err(|e| anyhow::anyhow!("cannot open a Zenoh session: {e}"))
            }
            Err(RecvTimeoutError::Timeout) => {
                if shutdown.load(Ordering::Relaxed) {
                    return Ok(None);
                }
                waited += Duration::from_millis(100);
                if waited.as_millis().is_multiple_of(10_000) {
                    tracing::info!(
                        "waiting for the coordinator at {} ({} s so far)",
                        agent.connect.join(", "),
                        waited.as_secs()
                    );
                }
            }
            Err(RecvTimeoutError::Disconnected) => anyhow::bail!("the Zenoh open thread died"),
        }
    }
}

/// Sends `message` to the coordinator of its mission (blocking on congestion: elites must
/// arrive).
fn send(session: &Session, vehicle: &str, message: AgentToCoordinator) {
    let key = match topics::to_coordinator(message.mission(), vehicle) {
        Ok(k) => k,
        Err(e) => {
            tracing::warn!("cannot send: {e}");
            return;
        }
    };
    match codec::encode(&Envelope::new(message)) {
        Ok(bytes) => {
            let put = session
                .put(key.as_str(), bytes)
                .congestion_control(CongestionControl::Block)
                .wait();
            if let Err(e) = put {
                tracing::warn!("cannot send on {key}: {e}");
            }
        }
        Err(e) => tracing::warn!("cannot encode a message for {key}: {e}"),
    }
}

/// Serves missions until `shutdown` (or, with `--once`, the first mission's end).
pub fn serve(args: &AgentConfig, shutdown: &AtomicBool) -> anyhow::Result<()> {
    let vehicle = args.vehicle.clone();
    tracing::info!(
        "agent for {vehicle}: connecting to {}",
        args.connect.join(", ")
    );
    // Healthy = serving: waiting for a coordinator is part of the job (between missions no
    // coordinator runs), so the file beats from the start.
    let _health = args
        .health_file
        .as_deref()
        .map(shoal_common::health::Heartbeat::start);
    let Some(session) = open(args, shutdown)? else {
        return Ok(());
    };
    let (tx, rx) = mpsc::channel::<(String, Vec<u8>)>();
    let forward = |tx: Sender<(String, Vec<u8>)>| {
        move |sample: zenoh::sample::Sample| {
            let _ = tx.send((
                sample.key_expr().as_str().to_string(),
                sample.payload().to_bytes().into_owned(),
            ));
        }
    };
    let inbox_key = topics::agent_inbox(&vehicle)?;
    let _inbox = session
        .declare_subscriber(inbox_key.as_str())
        .callback(forward(tx.clone()))
        .wait()
        .map_err(|e| anyhow::anyhow!("cannot subscribe to {inbox_key}: {e}"))?;
    let _fleets = session
        .declare_subscriber(topics::ALL_FLEETS)
        .callback(forward(tx))
        .wait()
        .map_err(|e| anyhow::anyhow!("cannot subscribe to {}: {e}", topics::ALL_FLEETS))?;
    // A coordinator that leaves (exit, crash, cut link) ends its missions here within a few
    // seconds (the `coordinator_watch` module), instead of after --idle-timeout.
    let (token_tx, token_rx) = mpsc::channel::<(String, bool)>();
    let _coordinators = session
        .liveliness()
        .declare_subscriber(topics::ALL_COORDINATORS)
        .callback(move |sample| {
            if let Some(m) = topics::mission_of_coordinator(sample.key_expr().as_str()) {
                let declared = sample.kind() == zenoh::sample::SampleKind::Put;
                let _ = token_tx.send((m.to_string(), declared));
            }
        })
        .wait()
        .map_err(|e| anyhow::anyhow!("cannot watch the coordinators' liveliness: {e}"))?;
    // Declared last: a coordinator that sees the token can reach the subscriptions.
    let token_key = topics::liveliness(&vehicle)?;
    let token = session
        .liveliness()
        .declare_token(token_key.as_str())
        .wait()
        .map_err(|e| anyhow::anyhow!("cannot declare the liveliness token {token_key}: {e}"))?;
    tracing::info!("agent for {vehicle}: connected, waiting for missions");
    let mut drops = Drops::default();
    let mut seqs = OrderSeqs::default();
    let mut workers: HashMap<String, Worker> = HashMap::new();
    let mut finished: HashSet<String> = HashSet::new();
    let mut served = 0usize;
    let mut departures = Departures::new(token_rx);
    while !shutdown.load(Ordering::Relaxed) {
        match rx.recv_timeout(Duration::from_millis(100)) {
            Ok((key, bytes)) => {
                let m = Inbound {
                    args,
                    session: &session,
                    workers: &mut workers,
                    finished: &finished,
                    drops: &mut drops,
                    seqs: &mut seqs,
                };
                m.handle(&key, &bytes);
            }
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => break,
        }
        for m in departures.poll(&session, |m| workers.contains_key(m)) {
            if let Some(w) = workers.get(&m) {
                let _ = w.tx.send(CoordinatorToAgent::Stop {
                    mission: m,
                    reason: "its coordinator left the network (liveliness token gone)".into(),
                });
            }
        }
        let done: Vec<String> = workers
            .iter()
            .filter(|(_, w)| w.handle.is_finished())
            .map(|(m, _)| m.clone())
            .collect();
        for m in done {
            if let Some(w) = workers.remove(&m) {
                match w.handle.join() {
                    Ok(r) => tracing::info!(
                        "mission {m}: {} after {} iterations, {} elite messages",
                        r.outcome,
                        r.iterations,
                        r.elites_sent
                    ),
                    Err(_) => tracing::error!("mission {m}: the planning thread panicked"),
                }
                departures.forget(&m);
                finished.insert(m);
                served += 1;
            }
        }
        if args.once && served > 0 && workers.is_empty() {
            break;
        }
    }
    for (m, w) in workers {
        w.stop.store(true, Ordering::Relaxed);
        drop(w.tx);
        if w.handle.join().is_err() {
            tracing::error!("mission {m}: the planning thread panicked");
        }
    }
    drop(token);
    if let Err(e) = session.close().wait() {
        tracing::warn!("closing the Zenoh session: {e}");
    }
    Ok(())
}

/// One inbound message and what it may touch.
struct Inbound<'a> {
    args: &'a AgentConfig,
    session: &'a Session,
    workers: &'a mut HashMap<String, Worker>,
    finished: &'a HashSet<String>,
    drops: &'a mut Drops,
    /// Order numbers taken on the inbox, per mission.
    seqs: &'a mut OrderSeqs,
}

impl Inbound<'_> {
    fn handle(self, key: &str, bytes: &[u8]) {
        let (seq, message) = match codec::decode::<CoordinatorToAgent>(bytes) {
            Ok(m) => (m.seq, m.body),
            Err(e @ DecodeError::Version { .. }) => {
                return self
                    .drops
                    .drop_message("wrong protocol version", &format!("{key}: {e}"))
            }
            Err(e) => return self.drops.drop_message("malformed", &format!("{key}: {e}")),
        };
        let key_mission = topics::mission_of_fleet(key)
            .or_else(|| topics::mission_and_vehicle(key).map(|(m, _)| m));
        if key_mission != Some(message.mission()) {
            return self.drops.drop_message(
                "mission differs from its key",
                &format!("{key} carries mission {:?}", message.mission()),
            );
        }
        let mission = message.mission().to_string();
        // Orders on the inbox are numbered (see `order_seq`); the fleet key is not.
        let numbered = topics::mission_and_vehicle(key).is_some();
        if numbered && !self.seqs.admits(self.drops, &mission, seq) {
            return;
        }
        let vehicle = &self.args.vehicle;
        let take = |seqs: &mut OrderSeqs| {
            if numbered {
                seqs.take(&mission, seq);
            }
        };
        match message {
            CoordinatorToAgent::Assign {
                vehicle: v,
                scenario_toml,
                context,
                ..
            } => {
                if v != *vehicle {
                    return self.drops.drop_message(
                        "unknown vehicle",
                        &format!("mission {mission} assigned {v:?} to the agent of {vehicle}"),
                    );
                }
                if self.workers.contains_key(&mission) || self.finished.contains(&mission) {
                    // A repeat (with a number of its own): our Joined was lost or is on its way.
                    take(self.seqs);
                    send(self.session, vehicle, joined(&mission, vehicle));
                    return;
                }
                match Assignment::new(&mission, vehicle, &scenario_toml, &context) {
                    Ok(a) => {
                        take(self.seqs);
                        self.start(a)
                    }
                    Err(why) => self
                        .drops
                        .drop_message("unusable assignment", &why.to_string()),
                }
            }
            CoordinatorToAgent::Execute {
                vehicle: v,
                scenario_toml,
                trajectory,
                epoch_unix_ms,
                time_scale,
                telemetry_hz,
                seed,
                ..
            } => {
                if v != *vehicle {
                    return self.drops.drop_message(
                        "unknown vehicle",
                        &format!("mission {mission} gave {v:?} to the agent of {vehicle}"),
                    );
                }
                if self.workers.contains_key(&mission) || self.finished.contains(&mission) {
                    take(self.seqs);
                    return; // a repeat: our telemetry is on its way
                }
                // One vehicle drives one mission: an order to drive another while it does is
                // refused (a genuine next mission repeats its order until this one ends).
                if let Some((other, _)) = self.workers.iter().find(|(_, w)| w.drives) {
                    return self.drops.drop_message(
                        "busy driving",
                        &format!("mission {mission} asked {vehicle} to drive while it drives mission {other}"),
                    );
                }
                match Order::new(
                    &mission,
                    vehicle,
                    &scenario_toml,
                    &trajectory,
                    epoch_unix_ms,
                    time_scale,
                    telemetry_hz,
                    seed,
                ) {
                    Ok(order) => {
                        take(self.seqs);
                        self.start_execution(order)
                    }
                    Err(why) => self
                        .drops
                        .drop_message("unusable execution order", &why.to_string()),
                }
            }
            CoordinatorToAgent::Migrants { vehicle: ref v, .. }
            | CoordinatorToAgent::Update { vehicle: ref v, .. }
            | CoordinatorToAgent::Hold { vehicle: ref v, .. }
                if v != vehicle =>
            {
                self.drops.drop_message(
                    "unknown vehicle",
                    &format!("migrants for {v:?} reached the agent of {vehicle}"),
                )
            }
            other => match self.workers.get(&mission) {
                Some(w) => {
                    take(self.seqs);
                    let _ = w.tx.send(other);
                }
                None if self.finished.contains(&mission) => {}
                None => self.drops.drop_message(
                    "unknown mission",
                    &format!("{key}: this agent does not plan mission {mission}"),
                ),
            },
        }
    }

    fn start(self, a: Assignment) {
        let vehicle = self.args.vehicle.clone();
        let mission = a.mission.clone();
        let what = format!(
            "scenario {} ({} vehicles)",
            a.scenario.name,
            a.scenario.vehicles.len()
        );
        let (tx, rx) = mpsc::channel();
        let stop = Arc::new(AtomicBool::new(false));
        let session = self.session.clone();
        let dropped = Arc::clone(&self.drops.count);
        let (threads, idle, flag) = (self.args.threads, self.args.idle_timeout, Arc::clone(&stop));
        let spawned = std::thread::Builder::new()
            .name(format!("mission-{mission}"))
            .spawn(move || {
                let out = |m: AgentToCoordinator| send(&session, &vehicle, m);
                mission::run(a, threads, &rx, &out, &dropped, &flag, idle)
            })
            .context("cannot start a planning thread");
        match spawned {
            Ok(handle) => {
                send(
                    self.session,
                    &self.args.vehicle,
                    joined(&mission, &self.args.vehicle),
                );
                // Logged once the thread runs and the coordinator has been told, so the log
                // never says "planning" for a mission this agent could not start.
                tracing::info!(
                    "mission {mission}: joined; planning {} in {what}",
                    self.args.vehicle
                );
                self.workers.insert(
                    mission,
                    Worker {
                        tx,
                        drives: false,
                        stop,
                        handle,
                    },
                );
            }
            Err(e) => tracing::error!("mission {mission}: {e:#}"),
        }
    }
}

impl Inbound<'_> {
    /// Starts driving the vehicle on a thread of its own, through the link the command line
    /// chose.
    fn start_execution(self, order: Order) {
        let mission = order.mission.clone();
        let mut link = match link::open(&self.args.link, &order.scenario, order.index, order.seed) {
            Ok(l) => l,
            Err(e) => {
                tracing::error!("mission {mission}: cannot open the vehicle link: {e}");
                return;
            }
        };
        let key = match topics::telemetry(&mission, &self.args.vehicle) {
            Ok(k) => k,
            Err(e) => return tracing::error!("mission {mission}: {e}"),
        };
        let (tx, rx) = mpsc::channel();
        let stop = Arc::new(AtomicBool::new(false));
        let session = self.session.clone();
        let (idle, flag) = (self.args.idle_timeout, Arc::clone(&stop));
        let spawned = std::thread::Builder::new()
            .name(format!("execute-{mission}"))
            .spawn(move || {
                // Telemetry is latest-wins: a congested link drops a report rather than block.
                let publish = |t: &Telemetry| match codec::encode_json(t) {
                    Ok(bytes) => {
                        let put = session
                            .put(key.as_str(), bytes)
                            .congestion_control(CongestionControl::Drop)
                            .wait();
                        if let Err(e) = put {
                            tracing::warn!("cannot publish on {key}: {e}");
                        }
                    }
                    Err(e) => tracing::warn!("cannot encode telemetry: {e}"),
                };
                execute::run(order, link.as_mut(), &rx, &publish, &flag, idle)
            })
            .context("cannot start an execution thread");
        match spawned {
            Ok(handle) => {
                self.workers.insert(
                    mission,
                    Worker {
                        tx,
                        drives: true,
                        stop,
                        handle,
                    },
                );
            }
            Err(e) => tracing::error!("mission {mission}: {e:#}"),
        }
    }
}

fn joined(mission: &str, vehicle: &str) -> AgentToCoordinator {
    AgentToCoordinator::Joined {
        mission: mission.to_string(),
        vehicle: vehicle.to_string(),
    }
}
