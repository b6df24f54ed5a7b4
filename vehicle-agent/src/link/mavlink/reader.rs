//! The reader thread: keeps the vehicle's latest telemetry, forwards the replies of the
//! protocol exchanges to the commander, and sends the 1 Hz GCS heartbeat by which autopilots
//! tell that their ground station is still there. It never waits on anything but the socket,
//! so the agent sees the vehicle whatever a command is doing.

use std::io::ErrorKind::{TimedOut, WouldBlock};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::Sender;
use std::sync::{Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};

use mavlink::dialects::common::{self as mav, MavAutopilot, MavMessage as M};
use mavlink::dialects::common::{MavState, MavType};
use mavlink::error::MessageReadError;
use mavlink::{MavConnection, MavHeader};

use shoal_common::geo::GeoOrigin;

/// How often the reader wakes up to send the heartbeat and check for shutdown.
pub const READ_TICK: Duration = Duration::from_millis(50);

/// The connection both threads use.
pub type Conn = mavlink::Connection<M>;

/// What the reader keeps of the vehicle's telemetry.
#[derive(Default, Clone)]
pub struct Latest {
    /// Latest GLOBAL_POSITION_INT.
    pub global: Option<mav::GLOBAL_POSITION_INT_DATA>,
    /// Latest LOCAL_POSITION_NED (used without a global position).
    pub local: Option<mav::LOCAL_POSITION_NED_DATA>,
    /// Latest MISSION_ITEM_REACHED: its item and when it came.
    pub reached: Option<(u16, Instant)>,
    /// Latest MISSION_CURRENT: its item, whether it says the mission is complete, and when.
    pub current: Option<(u16, bool, Instant)>,
    /// Battery left, fraction (SYS_STATUS).
    pub battery: Option<f64>,
    /// The autopilot reports itself critical or in emergency (HEARTBEAT).
    pub critical: bool,
    /// When the vehicle was last heard.
    pub heard: Option<Instant>,
    /// Autopilot family and vehicle type from the autopilot's HEARTBEAT.
    pub autopilot: Option<(MavAutopilot, MavType)>,
}

impl Latest {
    /// Position, velocity (scenario frame) and heading (° ccw from east, if known).
    pub fn fix(&self, origin: &GeoOrigin) -> Option<([f64; 3], [f64; 3], Option<f64>)> {
        if let Some(g) = &self.global {
            let (deg, cm) = (|v: i32| f64::from(v) / 1e7, |v: i16| f64::from(v) / 100.0);
            let p = origin.to_local(deg(g.lat), deg(g.lon), f64::from(g.alt) / 1e3);
            let heading = (g.hdg != u16::MAX).then(|| 90.0 - f64::from(g.hdg) / 100.0);
            return Some((p, [cm(g.vy), cm(g.vx), -cm(g.vz)], heading));
        }
        // NED about the vehicle's local origin, taken to be the scenario origin.
        let l = self.local.as_ref()?;
        let (f, p) = (f64::from, [f64::from(l.y), f64::from(l.x), -f64::from(l.z)]);
        Some((p, [f(l.vy), f(l.vx), -f(l.vz)], None))
    }

    /// Where the vehicle is as lat °, lon °, AMSL altitude m: its own global fix, or its local
    /// one placed by `origin`.
    pub fn geodetic(&self, origin: &GeoOrigin) -> Option<[f64; 3]> {
        if let Some(g) = &self.global {
            let deg = |v: i32| f64::from(v) / 1e7;
            return Some([deg(g.lat), deg(g.lon), f64::from(g.alt) / 1e3]);
        }
        let (p, _, _) = self.fix(origin)?;
        Some(origin.to_geodetic(p))
    }
}

/// State the link, the reader and the commander share.
#[derive(Default)]
pub struct Shared {
    /// Set when the link is dropped: both threads end.
    pub stop: AtomicBool,
    /// Messages skipped (see [`super::MavlinkLink::skipped`]).
    pub skipped: AtomicU64,
    /// Bumped by every new command: an exchange in progress for an older one gives way.
    pub generation: AtomicU64,
    /// The latest telemetry.
    pub latest: Mutex<Latest>,
}

impl Shared {
    /// The latest telemetry (a poisoned lock still holds valid data: plain values).
    pub fn latest(&self) -> MutexGuard<'_, Latest> {
        self.latest.lock().unwrap_or_else(PoisonError::into_inner)
    }
    /// Counts a skipped message.
    pub fn skip(&self) {
        self.skipped.fetch_add(1, Ordering::Relaxed);
    }
    /// Whether a command newer than `generation` has come.
    pub fn superseded(&self, generation: u64) -> bool {
        self.generation.load(Ordering::Relaxed) != generation
    }
}

/// Runs until the link is dropped: routes what system `target.0` sends.
pub fn read_loop(
    conn: &Conn,
    shared: &Shared,
    replies: &Sender<M>,
    header: MavHeader,
    target: (u8, u8),
) {
    let mut beat = mav::HEARTBEAT_DATA::default();
    (beat.mavtype, beat.autopilot) = (MavType::MAV_TYPE_GCS, MavAutopilot::MAV_AUTOPILOT_INVALID);
    (beat.system_status, beat.mavlink_version) = (MavState::MAV_STATE_ACTIVE, 3);
    let (beat, mut last_beat) = (M::HEARTBEAT(beat), None::<Instant>);
    while !shared.stop.load(Ordering::Relaxed) {
        if last_beat.is_none_or(|t| t.elapsed() >= Duration::from_secs(1)) {
            let _ = conn.send(&header, &beat); // best effort: a lost heartbeat is the norm
            last_beat = Some(Instant::now());
        }
        let (h, msg) = match conn.recv() {
            Ok(m) => m,
            Err(MessageReadError::Io(e)) if matches!(e.kind(), WouldBlock | TimedOut) => continue,
            Err(e) => {
                tracing::debug!("mavlink: skipped: {e}");
                shared.skip();
                if matches!(e, MessageReadError::Io(_)) {
                    std::thread::sleep(READ_TICK); // do not spin on a failing socket
                }
                continue;
            }
        };
        if h.system_id != u32::from(target.0) {
            shared.skip();
            continue;
        }
        keep(shared, replies, h.component_id == target.1, msg);
    }
}

/// Keeps or forwards one message of the vehicle (`autopilot`: from its autopilot component).
fn keep(shared: &Shared, replies: &Sender<M>, autopilot: bool, msg: M) {
    let mut latest = shared.latest();
    latest.heard = Some(Instant::now());
    match msg {
        M::GLOBAL_POSITION_INT(m) => latest.global = Some(m),
        M::LOCAL_POSITION_NED(m) => latest.local = Some(m),
        M::MISSION_ITEM_REACHED(m) => latest.reached = Some((m.seq, Instant::now())),
        M::MISSION_CURRENT(m) => {
            let complete = m.mission_state == mav::MissionState::MISSION_STATE_COMPLETE;
            latest.current = Some((m.seq, complete, Instant::now()));
        }
        M::SYS_STATUS(m) => {
            let left = m.battery_remaining; // %, −1 when unknown
            latest.battery = (left >= 0).then(|| f64::from(left.min(100)) / 100.0);
        }
        M::HEARTBEAT(m) => {
            let bad = [MavState::MAV_STATE_CRITICAL, MavState::MAV_STATE_EMERGENCY];
            latest.critical = bad.contains(&m.system_status);
            if autopilot && m.autopilot != MavAutopilot::MAV_AUTOPILOT_INVALID {
                latest.autopilot = Some((m.autopilot, m.mavtype));
            }
        }
        #[allow(deprecated)]
        m @ (M::MISSION_REQUEST_INT(_) | M::MISSION_REQUEST(_))
        | m @ (M::MISSION_ACK(_) | M::COMMAND_ACK(_)) => {
            drop(latest);
            let _ = replies.send(m); // fails only once the link is gone
        }
        _ => {}
    }
}
