//! The server's picture of the mission, fed from the live feed one message at a time: which
//! channels are advertised (the fleet's three, and two per vehicle once the start record names
//! the fleet) and, per channel, the latest message, which a client that subscribes late gets
//! first (the latest status, scene and pose of each vehicle, and the latest events).
//!
//! Times: a message is stamped with the mission time it is about (a report's fix time, an
//! event's, the status's; the scene takes the latest such time), mapped onto Unix time as the
//! start record's `epoch_unix_ms` plus the mission seconds. The stamp is both the message's
//! `timestamp` field and the time in the protocol's message header.

use std::collections::{BTreeMap, VecDeque};
use std::path::Path;
use std::sync::Arc;

use serde::Serialize;
use shoal_common::scenario::{Obstacle, Scenario};
use shoal_common::wire::open::PlanNotice;

use super::channels::{Channel, Content};
use super::schemas::Time;
use super::shaping;
use crate::execute::live::LiveMessage;
use crate::execute::log::channels::mission_ns;
use crate::execute::log::{Record, Start};

/// Events a late subscriber gets first (the latest ones).
pub const LATCHED_EVENTS: usize = 100;

/// One message on a channel.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Data {
    /// The channel.
    pub channel: u32,
    /// Unix time, nanoseconds (see the module's header).
    pub stamp_ns: u64,
    /// The JSON message.
    pub payload: Vec<u8>,
}

/// What a message from the feed changes for the clients.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Update {
    /// New channels (a new fleet).
    Advertise(Vec<Channel>),
    /// Channels gone (the previous fleet's).
    Unadvertise(Vec<u32>),
    /// A message on a channel.
    Data(Arc<Data>),
}

/// The mission as the server serves it.
pub struct Hub {
    /// Channels advertised now.
    channels: Vec<Channel>,
    /// The next channel id (ids are never reused within a server's life).
    next_id: u32,
    /// The start record of the mission being served.
    start: Option<Start>,
    /// Its scenario (bounds, origin, obstacles); `None` before the start or when it does not
    /// parse (the scene then has only what the execution publishes).
    scenario: Option<Scenario>,
    /// Obstacles to draw, each with whether it was published during the execution.
    obstacles: Vec<(Obstacle, bool)>,
    /// The latest plan.
    plan: Option<PlanNotice>,
    /// Latest mission time seen, nanoseconds.
    latest_ns: u64,
    /// The latest message of each channel but the events'.
    latched: BTreeMap<u32, Arc<Data>>,
    /// The latest events.
    events: VecDeque<Arc<Data>>,
}

impl Default for Hub {
    fn default() -> Hub {
        Hub::new()
    }
}

impl Hub {
    /// Channel id of the status.
    pub const STATUS: u32 = 1;
    /// Channel id of the events.
    pub const EVENTS: u32 = 2;
    /// Channel id of the scene.
    pub const SCENE: u32 = 3;

    /// A hub with the fleet's channels and no mission yet.
    pub fn new() -> Hub {
        Hub {
            channels: vec![
                Channel::fleet(Hub::STATUS, Content::Status),
                Channel::fleet(Hub::EVENTS, Content::Events),
                Channel::fleet(Hub::SCENE, Content::Scene),
            ],
            next_id: Hub::SCENE + 1,
            start: None,
            scenario: None,
            obstacles: Vec::new(),
            plan: None,
            latest_ns: 0,
            latched: BTreeMap::new(),
            events: VecDeque::new(),
        }
    }

    /// The channels advertised now.
    pub fn channels(&self) -> &[Channel] {
        &self.channels
    }

    /// Whether channel `id` is advertised now.
    pub fn has_channel(&self, id: u32) -> bool {
        self.channels.iter().any(|c| c.id == id)
    }

    /// What a client subscribing to channel `id` now gets first.
    pub fn latched(&self, id: u32) -> Vec<Arc<Data>> {
        if id == Hub::EVENTS {
            return self.events.iter().cloned().collect();
        }
        self.latched.get(&id).cloned().into_iter().collect()
    }

    /// Takes in one message of the feed; what it changes for the clients.
    pub fn apply(&mut self, m: &LiveMessage) -> Vec<Update> {
        match m {
            LiveMessage::Status(s) => self.data(Hub::STATUS, s.t_s, s).into_iter().collect(),
            LiveMessage::Record(r) => match r {
                Record::Start(s) => self.begin(s),
                Record::Plan(p) => {
                    self.plan = Some(p.clone());
                    self.scene()
                }
                Record::Obstacle(o) => {
                    self.obstacles.push((o.clone(), true));
                    self.scene()
                }
                Record::Telemetry { telemetry, .. } => {
                    self.report(&telemetry.vehicle, &telemetry.state)
                }
                Record::Event(e) => self.data(Hub::EVENTS, e.t_s, e).into_iter().collect(),
                Record::End(_) => Vec::new(),
            },
        }
    }

    /// A new mission: the previous fleet's channels go, this one's come, the scene is redrawn.
    fn begin(&mut self, s: &Start) -> Vec<Update> {
        let gone: Vec<u32> = self
            .channels
            .iter()
            .filter(|c| c.vehicle.is_some())
            .map(|c| c.id)
            .collect();
        self.channels.retain(|c| c.vehicle.is_none());
        self.latched.clear();
        self.events.clear();
        self.plan = None;
        self.latest_ns = 0;
        self.start = Some(s.clone());
        let origin = format!("the start record of mission {}", s.mission);
        self.scenario = Scenario::parse(&s.scenario_toml, Path::new(&origin))
            .map_err(|e| tracing::warn!("Foxglove: {e}; the scene has no bounds or obstacles"))
            .ok();
        self.obstacles = self
            .scenario
            .iter()
            .flat_map(|sc| sc.obstacles.iter().map(|o| (o.clone(), false)))
            .collect();
        let mut added = Vec::new();
        let vehicles: Vec<String> = self
            .scenario
            .iter()
            .flat_map(|sc| sc.vehicles.iter().map(|v| v.id.clone()))
            .collect();
        let geodetic = self.scenario.as_ref().is_some_and(|sc| sc.origin.is_some());
        for v in &vehicles {
            added.push(Channel::vehicle(self.take_id(), Content::Pose, v));
            if geodetic {
                added.push(Channel::vehicle(self.take_id(), Content::Location, v));
            }
        }
        self.channels.extend(added.iter().cloned());
        let mut updates = Vec::new();
        if !gone.is_empty() {
            updates.push(Update::Unadvertise(gone));
        }
        if !added.is_empty() {
            updates.push(Update::Advertise(added));
        }
        updates.extend(self.scene());
        updates
    }

    /// A vehicle's report: its pose, and its fix on the map when the scenario has an origin.
    fn report(
        &mut self,
        vehicle: &str,
        state: &shoal_common::execution::VehicleState,
    ) -> Vec<Update> {
        let stamp = self.stamp(state.t_s);
        let time = Time::from_ns(stamp);
        let origin = self.scenario.as_ref().and_then(|s| s.origin);
        let mut out = Vec::new();
        let ours =
            |c: &&Channel, content| c.content == content && c.vehicle.as_deref() == Some(vehicle);
        if let Some(id) = self
            .channels
            .iter()
            .find(|c| ours(c, Content::Pose))
            .map(|c| c.id)
        {
            out.extend(self.latch(id, stamp, &shaping::pose(state, time)));
        }
        let location = self
            .channels
            .iter()
            .find(|c| ours(c, Content::Location))
            .map(|c| c.id);
        if let (Some(id), Some(origin)) = (location, origin) {
            out.extend(self.latch(id, stamp, &shaping::location(vehicle, state, &origin, time)));
        }
        out
    }

    /// The whole scene, on the scene channel.
    fn scene(&mut self) -> Vec<Update> {
        let stamp = self.epoch_ns() + self.latest_ns;
        let scene = shaping::scene(
            self.scenario.as_ref().map(|s| &s.bounds),
            &self.obstacles,
            self.plan.as_ref(),
            Time::from_ns(stamp),
        );
        self.latch(Hub::SCENE, stamp, &scene).into_iter().collect()
    }

    /// A message at mission time `t_s` on `channel`, latched (the events: kept among the latest).
    fn data<T: Serialize>(&mut self, channel: u32, t_s: f64, message: &T) -> Option<Update> {
        let stamp = self.stamp(t_s);
        self.latch(channel, stamp, message)
    }

    fn latch<T: Serialize>(&mut self, channel: u32, stamp_ns: u64, message: &T) -> Option<Update> {
        let payload = serde_json::to_vec(message)
            .map_err(|e| tracing::warn!("Foxglove: cannot serialise a message: {e}"))
            .ok()?;
        let d = Arc::new(Data {
            channel,
            stamp_ns,
            payload,
        });
        if channel == Hub::EVENTS {
            if self.events.len() >= LATCHED_EVENTS {
                self.events.pop_front();
            }
            self.events.push_back(Arc::clone(&d));
        } else {
            self.latched.insert(channel, Arc::clone(&d));
        }
        Some(Update::Data(d))
    }

    /// Unix nanoseconds of mission time `t_s` (and the latest mission time moves on).
    fn stamp(&mut self, t_s: f64) -> u64 {
        let ns = mission_ns(t_s);
        self.latest_ns = self.latest_ns.max(ns);
        self.epoch_ns().saturating_add(ns)
    }

    fn epoch_ns(&self) -> u64 {
        self.start
            .as_ref()
            .map_or(0, |s| s.epoch_unix_ms.saturating_mul(1_000_000))
    }

    fn take_id(&mut self) -> u32 {
        let id = self.next_id;
        self.next_id = self.next_id.saturating_add(1);
        id
    }
}

#[cfg(test)]
mod tests;
