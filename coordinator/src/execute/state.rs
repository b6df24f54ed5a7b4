//! What the execution loop shares with the steps it runs (reports, obstacles, replans, standing
//! crawlers): its settings, its state, and how it logs and publishes.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use shoal_common::coverage::reroute::CrawlerGround;
use shoal_common::execution::MissionClock;
use shoal_common::scenario::{Obstacle, Scenario};
use shoal_common::wire::codec;
use shoal_common::wire::coordinator_to_agent::CoordinatorToAgent;
use shoal_common::wire::open::{FleetStatus, MissionEvent, PlanNotice, OPEN_VERSION};
use shoal_common::wire::topics::{self, OpenKey};
use shoal_common::wire::WireTrajectory;
use zenoh::Wait;

use super::fleet::Fleet;
use super::live::LiveFeed;
use super::log::{LogWriter, Record};
use super::plausible::Guard;
use super::queue::ReplanQueue;
use crate::distributed::Session;

/// Settings of an execution.
#[derive(Debug, Clone)]
pub struct ExecOptions {
    /// Mission seconds per wall second.
    pub time_scale: f64,
    /// Telemetry reports per wall second and vehicle.
    pub telemetry_hz: f64,
    /// How far ahead separation is predicted for the live status, mission seconds; conflicts
    /// are looked for this far past the update lead (`react::conflict_horizon_s`).
    pub horizon_s: f64,
    /// Cross-track error beyond which a vehicle is replanned, metres.
    pub deviation_m: f64,
    /// Metres over d_min a replan keeps from the other vehicles' predicted trajectories, for
    /// the tracking error and fix noise of both (a conflict is still predicted at d_min).
    pub separation_buffer_m: f64,
    /// Wall time without a report after which a vehicle is lost.
    pub lost_after: Duration,
    /// Wall-time budget of one replan.
    pub replan_budget: Duration,
    /// Half-width of the arrival window around the common arrival, mission seconds.
    pub arrival_window_s: f64,
    /// The mission log (NDJSON; the MCAP log goes beside it, see [`super::log::mcap_path`]).
    pub log: PathBuf,
    /// Obstacles to publish at given mission times (tests and figures: an obstacle appearing
    /// on a vehicle's path mid-mission), as any client would.
    pub inject: Vec<(f64, Obstacle)>,
    /// No progress line on stderr.
    pub quiet: bool,
    /// RNG seed (simulated noise, replanning).
    pub seed: u64,
    /// Live watchers' feed (the web view, the Foxglove server): every log record and each
    /// published status; `None` when nobody watches.
    pub live: Option<Arc<LiveFeed>>,
}

/// Everything the execution loop shares.
pub(crate) struct Exec<'a> {
    pub(super) scenario: Scenario,
    pub(super) mission: String,
    pub(super) options: &'a ExecOptions,
    pub(super) fleet: Fleet,
    pub(super) session: Session,
    pub(super) log: LogWriter,
    pub(super) mission_clock: MissionClock,
    pub(super) common_arrival_s: f64,
    pub(super) revision: u32,
    pub(super) replans: u64,
    pub(super) holds: u64,
    /// Per vehicle: when it was last replanned or held (wall), for a cool-down.
    pub(super) last_reaction: Vec<Option<Instant>>,
    /// Per vehicle: failed replans since it was told to hold (each retry doubles the budget).
    pub(super) hold_retries: Vec<u32>,
    /// Per vehicle: the wall time its last replan took (see [`super::lead::hold_retry_after`]).
    pub(super) last_attempt: Vec<Duration>,
    /// The replans waiting and the one under way (see [`super::replan_queue`]).
    pub(super) queue: ReplanQueue,
    /// (crawler, standing vehicle): repaired for this stand of it (see [`super::standing`]).
    pub(super) rounded: Vec<(usize, usize)>,
    /// Per vehicle: the revision sent and when, to time its delivery.
    pub(super) pending: Vec<Option<(u32, Instant)>>,
    /// Delivery times of updates (decision → first report on the new revision), ms.
    pub(crate) deliveries_ms: Vec<f64>,
    /// Decision times of obstacle replans (obstacle received → update sent), ms.
    pub(crate) decisions_ms: Vec<f64>,
    pub(super) dropped: u64,
    /// Implausible reports and obstacles refused, the obstacles' rate limit.
    pub(super) guard: Guard,
    /// Longest wall time between two passes of the loop (see [`super::ExecutionReport`]).
    pub(super) longest_pause: Duration,
    /// A coverage fleet's seabed map, for a crawler's way round a new obstacle; `None` for
    /// other missions, or when the map cannot be built (a crawler then holds instead).
    pub(super) ground: Option<Arc<CrawlerGround>>,
}

impl Exec<'_> {
    pub(super) fn clock(&self) -> f64 {
        self.mission_clock.now()
    }

    pub(super) fn put_json<T: serde::Serialize>(&self, key: &str, payload: &T) {
        match codec::encode_json(payload) {
            Ok(bytes) => {
                if let Err(e) = self.session.net.session().put(key, bytes).wait() {
                    tracing::warn!("cannot publish on {key}: {e}");
                }
            }
            Err(e) => tracing::warn!("cannot encode for {key}: {e}"),
        }
    }

    /// Logs and publishes an event.
    pub(super) fn event(&mut self, kind: &str, vehicles: Vec<String>, detail: String) {
        let e = MissionEvent {
            version: OPEN_VERSION,
            mission: self.mission.clone(),
            t_s: self.clock(),
            kind: kind.to_string(),
            vehicles,
            detail,
        };
        tracing::info!(kind, "{}", e.detail);
        if let Ok(key) = topics::open_key(&self.mission, OpenKey::Events) {
            self.put_json(&key, &e);
        }
        self.log.write(&Record::Event(e));
    }

    /// Publishes and logs the current plan; `changed` names the vehicles this revision moved.
    pub(super) fn publish_plan(&mut self, changed: Vec<String>) {
        let notice = PlanNotice {
            version: OPEN_VERSION,
            mission: self.mission.clone(),
            revision: self.revision,
            changed,
            trajectories: self
                .fleet
                .vehicles
                .iter()
                .map(|v| (v.id.clone(), WireTrajectory::new(&v.id, &v.plan).samples))
                .collect(),
        };
        if let Ok(key) = topics::open_key(&self.mission, OpenKey::Plan) {
            self.put_json(&key, &notice);
        }
        self.log.write(&Record::Plan(notice));
    }

    pub(super) fn status(&self) -> FleetStatus {
        self.fleet.status(&self.mission, self.clock())
    }

    /// Vehicle `i`'s plan as the coordinator has it, as an update: its revision and trajectory.
    pub(super) fn update_of(&self, i: usize) -> CoordinatorToAgent {
        let v = &self.fleet.vehicles[i];
        CoordinatorToAgent::Update {
            mission: self.mission.clone(),
            vehicle: v.id.clone(),
            revision: v.revision,
            trajectory: WireTrajectory::new(&v.id, &v.plan),
        }
    }

    /// A hold for vehicle `i`, for `reason`.
    pub(super) fn hold_of(&self, i: usize, reason: &str) -> CoordinatorToAgent {
        CoordinatorToAgent::Hold {
            mission: self.mission.clone(),
            vehicle: self.fleet.vehicles[i].id.clone(),
            reason: reason.to_string(),
        }
    }

    pub(super) fn send(&self, vehicle: &str, m: CoordinatorToAgent) {
        if let Err(e) = self.session.net.send(vehicle, m) {
            tracing::warn!("cannot send to {vehicle}: {e:#}");
        }
    }
}
