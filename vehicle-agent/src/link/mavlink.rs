//! The `mavlink` link: a vehicle speaking MAVLink (common dialect) over UDP, driven through the
//! mission microservice and the command protocol, located by its position telemetry.
//!
//! **Frames.** The scenario frame (x east, y north, z up, metres) is tied to WGS-84 by its
//! geodetic origin ([`GeoOrigin`], scenario point (0, 0, 0)) through a local flat-earth
//! (equirectangular) approximation on a sphere of the mean Earth radius, 6 371 km, the constant
//! PX4 uses for its own local frame. Against the WGS-84 ellipsoid this scales distances by up to
//! ~0.6 % (its radii of curvature run from 6 335 to 6 400 km), and keeping cos(lat₀) fixed adds
//! ~tan(lat₀)·Δlat of relative east error: metres over a few km, the same for every vehicle
//! sharing the origin; further out a proper projection is needed. Altitude is `origin alt + z`
//! (AMSL, metres): an AUV's z is below the surface, so with the origin at sea level it is a
//! negative "altitude", which is still what MAVLink's global frames carry.
//!
//! **Mission.** Each leg of the timed plan becomes MAV_CMD_DO_CHANGE_SPEED (the leg's speed, so
//! the vehicle keeps the plan's timing) then MAV_CMD_NAV_WAYPOINT to the leg's end in
//! MAV_FRAME_GLOBAL_INT; a leg that does not move is a wait (the waypoint's hold time). ArduPilot
//! treats uploaded item 0 as its home: this layout suits PX4-like vehicles. The mavlink crate is
//! built without MAVLink 2 extension fields, so `mission_type` is not sent and the receiver reads
//! 0, MAV_MISSION_TYPE_MISSION, which is what is meant.
//!
//! **Threads.** A reader thread keeps the latest telemetry and forwards protocol replies on a
//! channel, so [`VehicleLink::state`] never blocks; it also sends a 1 Hz GCS heartbeat, by which
//! autopilots tell that their ground station is still there.

use std::io::ErrorKind::{TimedOut, WouldBlock};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use mavlink::dialects::common::{self as mav, MavAutopilot, MavCmd, MavFrame, MavMessage as M};
use mavlink::dialects::common::{MavState, MavType};
use mavlink::error::MessageReadError;
use mavlink::{Connectable, ConnectionAddress, MavConnection, MavHeader, MavlinkVersion};
use shoal_common::execution::{VehicleState, VehicleStatus};
use shoal_common::trajectory::Trajectory;

use super::{GeoOrigin, LinkError, MavlinkSettings, VehicleLink};

/// Radius of the flat-earth approximation: the mean Earth radius, metres (PX4's value).
pub const EARTH_RADIUS_M: f64 = 6_371_000.0;
/// A vehicle heard before and silent this long is reported as [`VehicleStatus::Fault`].
pub const SILENCE_FAULT: Duration = Duration::from_secs(5);
/// How often the reader thread wakes up to send the heartbeat and check for shutdown.
const READ_TICK: Duration = Duration::from_millis(50);

/// An angle in degrees wrapped into (−180, 180].
fn wrap_deg(a: f64) -> f64 {
    let h = a.rem_euclid(360.0);
    h - if h > 180.0 { 360.0 } else { 0.0 }
}

impl GeoOrigin {
    /// Scenario point `p` (x east, y north, z up) as [lat °, lon °, alt m].
    pub fn to_geodetic(&self, p: [f64; 3]) -> [f64; 3] {
        let east = EARTH_RADIUS_M * self.lat_deg.to_radians().cos();
        let lat = self.lat_deg + (p[1] / EARTH_RADIUS_M).to_degrees();
        let lon = wrap_deg(self.lon_deg + (p[0] / east).to_degrees());
        [lat, lon, self.alt_m + p[2]]
    }

    /// WGS-84 lat °, lon °, alt m as a scenario point (x east, y north, z up).
    pub fn to_local(&self, lat_deg: f64, lon_deg: f64, alt_m: f64) -> [f64; 3] {
        let east = EARTH_RADIUS_M * self.lat_deg.to_radians().cos();
        let x = wrap_deg(lon_deg - self.lon_deg).to_radians() * east;
        [
            x,
            (lat_deg - self.lat_deg).to_radians() * EARTH_RADIUS_M,
            alt_m - self.alt_m,
        ]
    }
}

/// The mission items of `plan` for vehicle `target` (system, component): the legs ending after
/// mission time `after_t` (all without it), so that a replan does not send the vehicle back to
/// the plan's start; a plan of one sample (or whose legs are all over) is one waypoint.
pub fn mission_items(
    plan: &Trajectory,
    origin: &GeoOrigin,
    after_t: Option<f64>,
    target: (u8, u8),
) -> Vec<mav::MISSION_ITEM_INT_DATA> {
    // MAV_FRAME_GLOBAL_INT is deprecated (2024) for its synonym MAV_FRAME_GLOBAL, but it is the
    // one every autopilot in the field reads as "int lat/lon, AMSL altitude".
    #[allow(deprecated)]
    let waypoint = |p: [f64; 3], hold_s: f64| {
        let [lat, lon, alt] = origin.to_geodetic(p);
        let mut wp = mav::MISSION_ITEM_INT_DATA::default();
        (wp.command, wp.frame) = (MavCmd::MAV_CMD_NAV_WAYPOINT, MavFrame::MAV_FRAME_GLOBAL_INT);
        (wp.param1, wp.param4) = (hold_s as f32, f32::NAN); // yaw NaN: the vehicle's choice
        let e7 = |deg: f64| (deg * 1e7).round() as i32;
        (wp.x, wp.y, wp.z) = (e7(lat), e7(lon), alt as f32);
        wp
    };
    let mut items = Vec::new();
    for (k, speed) in plan.leg_speeds().into_iter().enumerate() {
        let (t0, t1) = (plan.times[k], plan.times[k + 1]);
        if after_t.is_some_and(|t| t1 <= t) {
            continue;
        }
        let moves = (plan.points[k + 1] - plan.points[k]).norm() >= 1e-3;
        if moves && speed.is_finite() && speed > 0.0 {
            let mut change = mav::MISSION_ITEM_INT_DATA::default();
            (change.command, change.frame) =
                (MavCmd::MAV_CMD_DO_CHANGE_SPEED, MavFrame::MAV_FRAME_MISSION);
            // Ground speed (type 1), m/s; throttle −1: unchanged.
            (change.param1, change.param2, change.param3) = (1.0, speed as f32, -1.0);
            items.push(change);
        }
        let hold_s = if moves { 0.0 } else { t1 - t0 };
        items.push(waypoint(plan.points[k + 1].into(), hold_s));
    }
    if let (true, Some(p)) = (items.is_empty(), plan.points.last()) {
        items.push(waypoint((*p).into(), 0.0));
    }
    for (seq, item) in items.iter_mut().enumerate() {
        (item.seq, item.current, item.autocontinue) = (seq as u16, u8::from(seq == 0), 1);
        (item.target_system, item.target_component) = target;
    }
    items
}

/// What the reader thread keeps of the vehicle's telemetry.
#[derive(Default, Clone)]
struct Latest {
    global: Option<mav::GLOBAL_POSITION_INT_DATA>,
    local: Option<mav::LOCAL_POSITION_NED_DATA>,
    reached: Option<(u16, Instant)>,
    battery: Option<f64>,
    critical: bool,
    heard: Option<Instant>,
}

impl Latest {
    /// Position, velocity (scenario frame) and heading (° ccw from east, if known).
    fn fix(&self, origin: &GeoOrigin) -> Option<([f64; 3], [f64; 3], Option<f64>)> {
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
}

/// State shared with the reader thread.
#[derive(Default)]
struct Shared {
    stop: AtomicBool,
    skipped: AtomicU64,
    latest: Mutex<Latest>,
}

impl Shared {
    fn latest(&self) -> MutexGuard<'_, Latest> {
        self.latest.lock().unwrap_or_else(PoisonError::into_inner)
    }
    fn skip(&self) {
        self.skipped.fetch_add(1, Ordering::Relaxed);
    }
}

type Conn = mavlink::Connection<M>;

/// A vehicle on a MAVLink connection.
pub struct MavlinkLink {
    settings: MavlinkSettings,
    /// Our ids, on everything we send.
    header: MavHeader,
    conn: Arc<Conn>,
    replies: Receiver<M>,
    shared: Arc<Shared>,
    reader: Option<JoinHandle<()>>,
    /// What we last commanded (Idle, Underway, Holding, Stopped).
    commanded: VehicleStatus,
    last_item: u16,
    uploaded_at: Instant,
    surface_z: Option<f64>,
    last_now: Option<f64>,
    arrived_s: Option<f64>,
    heading_deg: f64,
}

impl MavlinkLink {
    /// Opens the connection and starts the reader thread (no vehicle needs to answer yet).
    pub fn connect(settings: &MavlinkSettings) -> Result<MavlinkLink, LinkError> {
        let io = |e: std::io::Error| LinkError::Io(format!("{}: {e}", settings.address));
        let udp = match ConnectionAddress::parse_address(&settings.address) {
            Ok(ConnectionAddress::Udp(udp)) => udp,
            _ => {
                return Err(LinkError::Io(format!(
                    "{}: not a UDP address",
                    settings.address
                )))
            }
        };
        let mut conn = udp.read_timeout(READ_TICK).connect::<M>().map_err(io)?;
        conn.set_protocol_version(MavlinkVersion::V2);
        conn.set_allow_recv_any_version(true);
        let (conn, shared) = (Arc::new(conn), Arc::new(Shared::default()));
        let (tx, replies) = mpsc::channel();
        let mut header = MavHeader::default();
        (header.system_id, header.component_id) =
            (settings.system_id.into(), settings.component_id);
        let (c, sh, target) = (conn.clone(), shared.clone(), settings.target_system);
        let reader = std::thread::Builder::new()
            .name("mavlink-reader".into())
            .spawn(move || read_loop(&c, &sh, &tx, header, target))
            .map_err(io)?;
        Ok(MavlinkLink {
            settings: settings.clone(),
            header,
            conn,
            replies,
            shared,
            reader: Some(reader),
            commanded: VehicleStatus::Idle,
            last_item: 0,
            uploaded_at: Instant::now(),
            surface_z: None,
            last_now: None,
            arrived_s: None,
            heading_deg: 0.0,
        })
    }

    /// Reports `depth_m = surface_z − z` (an AUV below the scenario's surface, `bounds.max[2]`).
    pub fn with_surface(mut self, surface_z: Option<f64>) -> MavlinkLink {
        self.surface_z = surface_z;
        self
    }

    /// Messages skipped: malformed frames, messages from other systems, and replies that fit
    /// no exchange in progress (stale or out of order). Telemetry we do not use is not counted.
    pub fn skipped(&self) -> u64 {
        self.shared.skipped.load(Ordering::Relaxed)
    }

    /// Sends `msg`; to an `udpin:` address that has not heard the vehicle yet it goes nowhere
    /// (0 bytes), and the exchange's retries send it again.
    fn send(&self, msg: &M) -> Result<(), LinkError> {
        let io = |e| LinkError::Io(format!("{}: {e}", self.settings.address));
        self.conn.send(&self.header, msg).map(drop).map_err(io)
    }

    /// The next reply before `deadline` (`None` then).
    fn reply(&self, deadline: Instant) -> Result<Option<M>, LinkError> {
        let wait = deadline.saturating_duration_since(Instant::now());
        match self.replies.recv_timeout(wait) {
            Ok(msg) => Ok(Some(msg)),
            Err(RecvTimeoutError::Timeout) => Ok(None),
            Err(RecvTimeoutError::Disconnected) => Err(LinkError::Io("reader ended".into())),
        }
    }

    /// Drops replies left over from earlier exchanges.
    fn drain(&self) {
        while self.replies.try_recv().is_ok() {
            self.shared.skip();
        }
    }

    /// The vehicle's system and component ids.
    fn target(&self) -> (u8, u8) {
        (self.settings.target_system, self.settings.target_component)
    }

    /// Whether a reply's target fields name us (0 = broadcast).
    fn for_us(&self, system: u8, component: u8) -> bool {
        (system == 0 || system == self.settings.system_id)
            && (component == 0 || component == self.settings.component_id)
    }

    /// Sends COMMAND_LONG `command` (`param1`, `param2`, the others 0) and waits for its
    /// COMMAND_ACK, resending up to `retries` times with `confirmation` counting the resends.
    fn command(&self, command: MavCmd, params: [f32; 2], retries: u32) -> Result<(), LinkError> {
        self.drain();
        let mut msg = mav::COMMAND_LONG_DATA::default();
        (msg.command, [msg.param1, msg.param2]) = (command, params);
        (msg.target_system, msg.target_component) = self.target();
        for attempt in 0..=retries {
            msg.confirmation = attempt.min(255) as u8;
            self.send(&M::COMMAND_LONG(msg.clone()))?;
            let deadline = Instant::now() + self.settings.timeout;
            while let Some(reply) = self.reply(deadline)? {
                match reply {
                    M::COMMAND_ACK(a) if a.command == command => match a.result {
                        mav::MavResult::MAV_RESULT_ACCEPTED => return Ok(()),
                        mav::MavResult::MAV_RESULT_IN_PROGRESS => {}
                        r => return Err(LinkError::Refused(format!("{command:?}: {r:?}"))),
                    },
                    _ => self.shared.skip(),
                }
            }
        }
        let tries = retries + 1;
        Err(LinkError::Timeout(format!(
            "no COMMAND_ACK to {command:?} ({tries} tries)"
        )))
    }

    /// The upload exchange: MISSION_COUNT, a MISSION_ITEM_INT per request, then MISSION_ACK.
    /// Without a reply in time the last message goes again, up to `retries` times.
    fn send_mission(&self, items: &[mav::MISSION_ITEM_INT_DATA]) -> Result<(), LinkError> {
        let n = items.len();
        let count = u16::try_from(n).map_err(|_| LinkError::Refused(format!("{n} items")))?;
        self.drain();
        let mut first = mav::MISSION_COUNT_DATA::default();
        (first.count, (first.target_system, first.target_component)) = (count, self.target());
        let mut last = M::MISSION_COUNT(first);
        let (mut waiting, mut sent_all, mut tries) = ("MISSION_REQUEST 0".to_string(), false, 0);
        self.send(&last)?;
        let mut deadline = Instant::now() + self.settings.timeout;
        loop {
            let Some(reply) = self.reply(deadline)? else {
                if tries >= self.settings.retries {
                    let (t, tries) = (self.settings.timeout, tries + 1);
                    let why = format!("mission upload: no {waiting} ({tries} tries of {t:?})");
                    return Err(LinkError::Timeout(why));
                }
                tries += 1;
                self.send(&last)?;
                deadline = Instant::now() + self.settings.timeout;
                continue;
            };
            #[allow(deprecated)] // MISSION_REQUEST: older vehicles still send it
            let request = match &reply {
                M::MISSION_REQUEST_INT(r) => Some((r.seq, r.target_system, r.target_component)),
                M::MISSION_REQUEST(r) => Some((r.seq, r.target_system, r.target_component)),
                _ => None,
            };
            match (request, reply) {
                (Some((seq, s, c)), _) if self.for_us(s, c) && seq < count => {
                    last = M::MISSION_ITEM_INT(items[usize::from(seq)].clone());
                    self.send(&last)?;
                    sent_all |= seq + 1 == count;
                    waiting = match seq + 1 == count {
                        true => "MISSION_ACK".to_string(),
                        false => format!("MISSION_REQUEST {}", seq + 1),
                    };
                    (tries, deadline) = (0, Instant::now() + self.settings.timeout);
                }
                (_, M::MISSION_ACK(a)) if self.for_us(a.target_system, a.target_component) => {
                    match a.mavtype {
                        mav::MavMissionResult::MAV_MISSION_ACCEPTED if sent_all => return Ok(()),
                        mav::MavMissionResult::MAV_MISSION_ACCEPTED => self.shared.skip(), // stale
                        r => return Err(LinkError::Refused(format!("mission upload: {r:?}"))),
                    }
                }
                _ => self.shared.skip(),
            }
        }
    }

    /// MAV_CMD_DO_PAUSE_CONTINUE with param1 = 0 (pause), then reports `status`.
    fn pause(&mut self, status: VehicleStatus) -> Result<(), LinkError> {
        self.command(
            MavCmd::MAV_CMD_DO_PAUSE_CONTINUE,
            [0.0; 2],
            self.settings.retries,
        )?;
        self.commanded = status;
        Ok(())
    }
}

impl Drop for MavlinkLink {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::Relaxed);
        if let Some(h) = self.reader.take() {
            let _ = h.join(); // returns within READ_TICK: the socket has a read timeout
        }
    }
}

/// The reader thread: routes what system `target` sends until the link is dropped.
fn read_loop(conn: &Conn, shared: &Shared, replies: &Sender<M>, header: MavHeader, target: u8) {
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
        if h.system_id != u32::from(target) {
            shared.skip();
            continue;
        }
        let mut latest = shared.latest();
        latest.heard = Some(Instant::now());
        match msg {
            M::GLOBAL_POSITION_INT(m) => latest.global = Some(m),
            M::LOCAL_POSITION_NED(m) => latest.local = Some(m),
            M::MISSION_ITEM_REACHED(m) => latest.reached = Some((m.seq, Instant::now())),
            M::SYS_STATUS(m) => {
                let left = m.battery_remaining; // %, −1 when unknown
                latest.battery = (left >= 0).then(|| f64::from(left.min(100)) / 100.0);
            }
            M::HEARTBEAT(m) => {
                let bad = [MavState::MAV_STATE_CRITICAL, MavState::MAV_STATE_EMERGENCY];
                latest.critical = bad.contains(&m.system_status);
            }
            #[allow(deprecated)]
            m @ (M::MISSION_REQUEST_INT(_) | M::MISSION_REQUEST(_))
            | m @ (M::MISSION_ACK(_) | M::COMMAND_ACK(_)) => {
                let _ = replies.send(m); // fails only once the link is gone
            }
            _ => {}
        }
    }
}

impl VehicleLink for MavlinkLink {
    fn name(&self) -> String {
        format!("mavlink {}", self.settings.address)
    }

    fn upload(&mut self, plan: &Trajectory) -> Result<(), LinkError> {
        let ok = !plan.times.is_empty()
            && plan.times.len() == plan.points.len()
            && plan.times.iter().all(|t| t.is_finite())
            && plan.points.iter().all(|p| p.iter().all(|v| v.is_finite()))
            && plan.times.windows(2).all(|w| w[1] >= w[0]);
        if !ok {
            let (t, p) = (plan.times.len(), plan.points.len());
            let why = format!("{t} times and {p} points, not finite or out of order");
            return Err(LinkError::Refused(why));
        }
        let items = mission_items(plan, &self.settings.origin, self.last_now, self.target());
        self.send_mission(&items)?;
        (self.commanded, self.last_item) = (VehicleStatus::Underway, (items.len() - 1) as u16);
        (self.uploaded_at, self.arrived_s) = (Instant::now(), None);
        // Items 0 to the last. A vehicle may refuse to start (e.g. not armed) yet start later by
        // itself: log only.
        let run = [0.0, f32::from(self.last_item)];
        if let Err(e) = self.command(MavCmd::MAV_CMD_MISSION_START, run, 0) {
            tracing::warn!("mavlink: mission uploaded, MISSION_START not acknowledged: {e}");
        }
        Ok(())
    }

    fn state(&mut self, now: f64) -> Result<VehicleState, LinkError> {
        self.last_now = Some(now);
        let latest = self.shared.latest().clone();
        let no_fix = LinkError::Timeout("no position from the vehicle yet".into());
        let (position, velocity, heading) = latest.fix(&self.settings.origin).ok_or(no_fix)?;
        let [ve, vn, _] = velocity;
        self.heading_deg = match heading {
            Some(h) => wrap_deg(h),
            None if ve.hypot(vn) > 0.05 => vn.atan2(ve).to_degrees(),
            None => self.heading_deg, // still, heading unknown: keep the last one
        };
        let (last, since) = (self.last_item, self.uploaded_at);
        let reached = latest
            .reached
            .filter(|&(seq, at)| seq == last && at >= since);
        if let (VehicleStatus::Underway, None, Some((_, at))) =
            (self.commanded, self.arrived_s, reached)
        {
            // A real vehicle's mission clock runs in real time.
            self.arrived_s = Some((now - at.elapsed().as_secs_f64()).max(0.0));
        }
        let silent = latest.heard.is_some_and(|t| t.elapsed() > SILENCE_FAULT);
        let status = match self.commanded {
            _ if silent || latest.critical => VehicleStatus::Fault,
            VehicleStatus::Underway if self.arrived_s.is_some() => VehicleStatus::Arrived,
            s => s,
        };
        Ok(VehicleState {
            t_s: now,
            position,
            velocity,
            heading_deg: self.heading_deg,
            depth_m: self.surface_z.map(|s| s - position[2]),
            altitude_m: None,
            battery: latest.battery.unwrap_or(1.0),
            status,
            arrived_s: self.arrived_s,
        })
    }

    fn hold(&mut self, _now: f64) -> Result<(), LinkError> {
        self.pause(VehicleStatus::Holding)
    }

    /// MAVLink has no "mission over" command short of landing or disarming, which an AUV must
    /// not do unasked: the vehicle is paused where it is, and reported Stopped.
    fn stop(&mut self) -> Result<(), LinkError> {
        self.pause(VehicleStatus::Stopped)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shoal_common::geometry::Vec3;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn flat_earth_matches_hand_computed_offsets_and_round_trips() {
        let equator = GeoOrigin::new(0.0, 0.0, 0.0);
        let [lat, lon, alt] = equator.to_geodetic([0.0, 1000.0, -20.0]);
        assert!(
            close(lat, 0.0089932, 1e-7) && lon == 0.0 && alt == -20.0,
            "north: {lat}"
        );
        let sixty = GeoOrigin::new(60.0, 10.0, 5.0);
        let [lat, lon, _] = sixty.to_geodetic([1000.0, 0.0, 0.0]);
        assert!(
            lat == 60.0 && close(lon - 10.0, 0.017986, 1e-6),
            "east: {lon}"
        );
        let date_line = GeoOrigin::new(-45.0, 179.99, 0.0);
        let points = [[0.0; 3], [2500.0, -1800.0, -75.0], [-4000.0, 3000.0, 12.5]];
        for (o, p) in [equator, sixty, date_line]
            .iter()
            .flat_map(|o| points.map(|p| (o, p)))
        {
            let [lat, lon, alt] = o.to_geodetic(p);
            let q = o.to_local(lat, lon, alt);
            assert!(
                (0..3).all(|i| close(p[i], q[i], 1e-6)),
                "{o:?}: {p:?} -> {q:?}"
            );
        }
    }

    #[test]
    #[allow(deprecated)] // MAV_FRAME_GLOBAL_INT
    fn a_three_sample_plan_is_two_speed_and_waypoint_pairs() {
        let points = [
            [0.0, 0.0, -10.0],
            [150.0, 0.0, -10.0],
            [150.0, 200.0, -30.0],
        ];
        let (times, o) = (vec![0.0, 100.0, 300.0], GeoOrigin::new(43.0, 5.0, 0.0));
        let plan = Trajectory {
            times,
            points: points.map(Vec3::from).to_vec(),
        };
        let items = mission_items(&plan, &o, None, (7, 1));
        use MavCmd::{MAV_CMD_DO_CHANGE_SPEED as SPEED, MAV_CMD_NAV_WAYPOINT as WP};
        let commands: Vec<_> = items.iter().map(|i| i.command).collect();
        assert_eq!(commands, [SPEED, WP, SPEED, WP]);
        assert!(close(f64::from(items[0].param2), 1.5, 1e-6)); // 150 m in 100 s
        let second = 101.0f64.sqrt() / 10.0; // √(200² + 20²) m in 200 s
        assert!(close(f64::from(items[2].param2), second, 1e-6));
        for (i, p) in [(1, points[1]), (3, points[2])] {
            let it = &items[i];
            assert_eq!(it.frame, MavFrame::MAV_FRAME_GLOBAL_INT, "item {i}");
            let e7 = |v: i32| f64::from(v) / 1e7;
            let q = o.to_local(e7(it.x), e7(it.y), f64::from(it.z));
            assert!((0..3).all(|j| close(p[j], q[j], 0.02)), "item {i}: {q:?}");
        }
        for (s, i) in items.iter().enumerate() {
            let ids = (i.target_system, i.target_component);
            assert_eq!(
                (usize::from(i.seq), i.current, i.autocontinue, ids),
                (s, u8::from(s == 0), 1, (7, 1))
            );
        }
        // A replan at t = 150 s keeps only the leg still ahead, numbered from 0.
        let later = mission_items(&plan, &o, Some(150.0), (7, 1));
        let (a, b) = (&later[0], &later[1]);
        assert_eq!((later.len(), a.seq, a.current, a.command), (2, 0, 1, SPEED));
        assert_eq!((b.x, b.y, b.z), (items[3].x, items[3].y, items[3].z));
    }
}
