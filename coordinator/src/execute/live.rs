//! What an execution shows to live watchers (the operator's web view, a Foxglove client): every
//! record of the mission log as it is written, and the fleet status each time it is published.
//!
//! The execution loop must never wait for a watcher: [`LiveFeed::publish`] hands each message to
//! every subscriber's bounded queue without blocking, and a subscriber whose queue is full is
//! cut off (it sees its channel close and subscribes again, with a fresh catch-up). A watcher
//! that connects mid-mission first gets the [`CatchUp`]: the start, the current plan, every
//! obstacle published so far, the latest events, each vehicle's track so far (thinned to a
//! bounded length) and the latest status.

use std::collections::{BTreeMap, VecDeque};
use std::sync::mpsc::{self, Receiver, SyncSender, TrySendError};
use std::sync::{Arc, Mutex};

use shoal_common::wire::open::{FleetStatus, Telemetry};

use super::log::{Record, RecordWatcher};

/// One message to a watcher.
#[derive(Debug, Clone, PartialEq)]
pub enum LiveMessage {
    /// A record of the mission log, as it was written.
    Record(Record),
    /// The fleet status (the same as the open `status` key's).
    Status(FleetStatus),
}

/// Messages a subscriber's queue holds before it is cut off as too slow.
pub const SUBSCRIBER_QUEUE: usize = 4096;
/// Events a catch-up keeps (the latest ones).
pub const CATCH_UP_EVENTS: usize = 500;
/// Track points a catch-up keeps per vehicle: past this, every other point is dropped.
pub const CATCH_UP_TRACK_POINTS: usize = 2000;

/// What a watcher connecting now needs to draw the mission as it stands.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CatchUp {
    /// The log's start record (`None` before the execution starts).
    pub start: Option<Record>,
    /// The latest plan record.
    pub plan: Option<Record>,
    /// Obstacle records published during the execution, in order.
    pub obstacles: Vec<Record>,
    /// The latest event records, oldest first (at most [`CATCH_UP_EVENTS`]).
    pub events: VecDeque<Record>,
    /// Per vehicle: its reports so far, thinned to at most [`CATCH_UP_TRACK_POINTS`] (the
    /// latest report always kept).
    pub tracks: BTreeMap<String, Vec<Telemetry>>,
    /// The latest status.
    pub status: Option<FleetStatus>,
    /// The end record, once the execution has ended.
    pub end: Option<Record>,
}

impl CatchUp {
    /// The catch-up as messages, in an order a watcher can apply one by one: start, plan,
    /// obstacles, events, tracks (each vehicle's reports in time order), status, end.
    pub fn messages(&self) -> Vec<LiveMessage> {
        let mut out = Vec::new();
        let records = self
            .start
            .iter()
            .chain(self.plan.iter())
            .chain(self.obstacles.iter())
            .chain(self.events.iter())
            .cloned()
            .map(LiveMessage::Record);
        out.extend(records);
        for track in self.tracks.values() {
            out.extend(track.iter().map(|t| {
                LiveMessage::Record(Record::Telemetry {
                    received_unix_us: t.sent_unix_us,
                    telemetry: t.clone(),
                })
            }));
        }
        out.extend(self.status.clone().map(LiveMessage::Status));
        out.extend(self.end.clone().map(LiveMessage::Record));
        out
    }

    fn apply(&mut self, m: &LiveMessage) {
        match m {
            LiveMessage::Status(s) => self.status = Some(s.clone()),
            LiveMessage::Record(r) => match r {
                Record::Start(_) => {
                    *self = CatchUp {
                        start: Some(r.clone()),
                        ..CatchUp::default()
                    }
                }
                Record::Plan(_) => self.plan = Some(r.clone()),
                Record::Obstacle(_) => self.obstacles.push(r.clone()),
                Record::Event(_) => {
                    if self.events.len() >= CATCH_UP_EVENTS {
                        self.events.pop_front();
                    }
                    self.events.push_back(r.clone());
                }
                Record::Telemetry { telemetry, .. } => {
                    let track = self.tracks.entry(telemetry.vehicle.clone()).or_default();
                    track.push(telemetry.clone());
                    if track.len() > CATCH_UP_TRACK_POINTS {
                        thin(track);
                    }
                }
                Record::End(_) => self.end = Some(r.clone()),
            },
        }
    }
}

/// Drops every other point of `track`, keeping its first and last.
fn thin(track: &mut Vec<Telemetry>) {
    let last = track.len().saturating_sub(1);
    let mut i = 0;
    track.retain(|_| {
        let keep = i % 2 == 0 || i == last;
        i += 1;
        keep
    });
}

/// A subscription: the catch-up, then every message from then on. The receiver closes when
/// the subscriber fell [`SUBSCRIBER_QUEUE`] messages behind (subscribe again) or the feed is
/// dropped.
pub struct Subscription {
    /// The mission as it stood when subscribing.
    pub catch_up: CatchUp,
    /// What came after.
    pub messages: Receiver<Arc<LiveMessage>>,
}

#[derive(Default)]
struct Inner {
    catch_up: CatchUp,
    subscribers: Vec<SyncSender<Arc<LiveMessage>>>,
    /// Subscribers cut off for falling behind, in all.
    cut_off: u64,
}

/// The feed an execution writes to and watchers subscribe to. Cheap to share (`Arc`).
#[derive(Default)]
pub struct LiveFeed {
    inner: Mutex<Inner>,
}

impl RecordWatcher for LiveFeed {
    fn record(&self, r: &Record) {
        self.publish(LiveMessage::Record(r.clone()));
    }
}

/// A feed equals only itself: two options structs are equal when they hand the execution to the
/// same watchers.
impl PartialEq for LiveFeed {
    fn eq(&self, other: &LiveFeed) -> bool {
        std::ptr::eq(self, other)
    }
}

impl std::fmt::Debug for LiveFeed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LiveFeed")
            .field("subscribers", &self.subscribers())
            .field("cut_off", &self.cut_off())
            .finish()
    }
}

impl LiveFeed {
    /// An empty feed.
    pub fn new() -> Arc<LiveFeed> {
        Arc::new(LiveFeed::default())
    }

    /// Hands `m` to every subscriber without waiting, and keeps it for the catch-up.
    pub fn publish(&self, m: LiveMessage) {
        let Ok(mut inner) = self.inner.lock() else {
            return;
        };
        inner.catch_up.apply(&m);
        if inner.subscribers.is_empty() {
            return;
        }
        let m = Arc::new(m);
        let mut cut = 0;
        inner
            .subscribers
            .retain(|s| match s.try_send(Arc::clone(&m)) {
                Ok(()) => true,
                Err(TrySendError::Full(_)) => {
                    cut += 1;
                    false
                }
                Err(TrySendError::Disconnected(_)) => false,
            });
        inner.cut_off += cut;
    }

    /// Subscribes: the mission so far and a queue of what comes next, taken together so no
    /// message is missed or seen twice.
    pub fn subscribe(&self) -> Subscription {
        let (tx, rx) = mpsc::sync_channel(SUBSCRIBER_QUEUE);
        let catch_up = match self.inner.lock() {
            Ok(mut inner) => {
                inner.subscribers.push(tx);
                inner.catch_up.clone()
            }
            Err(_) => CatchUp::default(),
        };
        Subscription {
            catch_up,
            messages: rx,
        }
    }

    /// Subscribers connected now.
    pub fn subscribers(&self) -> usize {
        self.inner.lock().map_or(0, |i| i.subscribers.len())
    }

    /// Subscribers cut off so far for falling behind.
    pub fn cut_off(&self) -> u64 {
        self.inner.lock().map_or(0, |i| i.cut_off)
    }
}

/// A vehicle's report as a feed message, for tests: `seq` numbers and stamps it (microseconds),
/// at mission time `t_s` and `position`, underway at 1 m/s east.
#[cfg(test)]
pub(crate) fn test_report(vehicle: &str, seq: u64, t_s: f64, position: [f64; 3]) -> LiveMessage {
    LiveMessage::Record(Record::Telemetry {
        received_unix_us: seq,
        telemetry: test_telemetry(vehicle, seq, t_s, position),
    })
}

/// The report of [`test_report`].
#[cfg(test)]
pub(crate) fn test_telemetry(vehicle: &str, seq: u64, t_s: f64, position: [f64; 3]) -> Telemetry {
    use shoal_common::execution::{VehicleState, VehicleStatus};
    Telemetry {
        version: shoal_common::wire::open::OPEN_VERSION,
        mission: "m".into(),
        vehicle: vehicle.into(),
        seq,
        revision: 0,
        sent_unix_us: seq,
        state: VehicleState {
            t_s,
            position,
            velocity: [1.0, 0.0, 0.0],
            heading_deg: 0.0,
            depth_m: None,
            altitude_m: None,
            battery: 1.0,
            status: VehicleStatus::Underway,
            arrived_s: None,
        },
        command: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shoal_common::wire::open::{MissionEvent, OPEN_VERSION};

    fn report(vehicle: &str, seq: u64) -> LiveMessage {
        test_report(vehicle, seq, seq as f64, [seq as f64, 0.0, 0.0])
    }

    fn event(n: usize) -> LiveMessage {
        LiveMessage::Record(Record::Event(MissionEvent {
            version: OPEN_VERSION,
            mission: "m".into(),
            t_s: n as f64,
            kind: "hold".into(),
            vehicles: vec![],
            detail: format!("{n}"),
        }))
    }

    #[test]
    fn a_late_subscriber_catches_up_then_follows() {
        let feed = LiveFeed::new();
        for s in 0..3 {
            feed.publish(report("auv1", s));
        }
        let sub = feed.subscribe();
        assert_eq!(sub.catch_up.tracks["auv1"].len(), 3);
        assert_eq!(sub.catch_up.messages().len(), 3);
        feed.publish(report("auv1", 3));
        let next = sub.messages.try_recv().ok();
        assert_eq!(next.as_deref(), Some(&report("auv1", 3)));
        assert!(sub.messages.try_recv().is_err(), "nothing twice");
    }

    #[test]
    fn tracks_and_events_stay_bounded_and_keep_the_latest() {
        let feed = LiveFeed::new();
        let n = 3 * CATCH_UP_TRACK_POINTS as u64 + 7;
        for s in 0..n {
            feed.publish(report("auv1", s));
        }
        for k in 0..CATCH_UP_EVENTS + 10 {
            feed.publish(event(k));
        }
        let c = feed.subscribe().catch_up;
        let track = &c.tracks["auv1"];
        assert!(track.len() <= CATCH_UP_TRACK_POINTS, "{}", track.len());
        assert_eq!(track.first().map(|t| t.seq), Some(0));
        assert_eq!(track.last().map(|t| t.seq), Some(n - 1));
        assert!(track.windows(2).all(|w| w[0].seq < w[1].seq));
        assert_eq!(c.events.len(), CATCH_UP_EVENTS);
        assert_eq!(
            c.events.back(),
            Some(&match event(CATCH_UP_EVENTS + 9) {
                LiveMessage::Record(r) => r,
                LiveMessage::Status(_) => unreachable!(),
            })
        );
    }

    #[test]
    fn a_subscriber_that_falls_behind_is_cut_off_and_the_feed_goes_on() {
        let feed = LiveFeed::new();
        let slow = feed.subscribe();
        let fast = feed.subscribe();
        for s in 0..SUBSCRIBER_QUEUE as u64 {
            feed.publish(report("auv1", s));
            assert!(fast.messages.try_recv().is_ok());
        }
        assert_eq!(feed.cut_off(), 0);
        feed.publish(report("auv1", 99_999));
        assert_eq!(feed.cut_off(), 1);
        assert_eq!(feed.subscribers(), 1);
        assert!(fast.messages.try_recv().is_ok());
        // The slow one drains what it had, then sees its channel closed.
        let drained = slow.messages.try_iter().count();
        assert_eq!(drained, SUBSCRIBER_QUEUE);
        assert!(matches!(
            slow.messages.try_recv(),
            Err(mpsc::TryRecvError::Disconnected)
        ));
        drop(fast);
        feed.publish(report("auv1", 100_000));
        assert_eq!(feed.subscribers(), 0, "a dropped subscriber is forgotten");
    }

    #[test]
    fn a_new_start_resets_the_catch_up() {
        let feed = LiveFeed::new();
        feed.publish(report("auv1", 0));
        feed.publish(LiveMessage::Record(Record::Start(
            super::super::log::Start {
                mission: "m2".into(),
                scenario_toml: String::new(),
                common_arrival_s: 1.0,
                arrival_window_s: 1.0,
                horizon_s: 1.0,
                time_scale: 1.0,
                epoch_unix_ms: 0,
            },
        )));
        let c = feed.subscribe().catch_up;
        assert!(c.tracks.is_empty());
        assert!(c.start.is_some());
    }
}
