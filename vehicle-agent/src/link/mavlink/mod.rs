//! The `mavlink` link: a vehicle speaking MAVLink (common dialect) over UDP, driven through the
//! mission microservice and the command protocol, located by its position telemetry.
//!
//! **Frames.** The scenario frame (x east, y north, z up, metres) is tied to WGS-84 by its
//! geodetic origin ([`GeoOrigin`], scenario point (0, 0, 0)). Altitude is `origin alt + z`
//! (AMSL, metres): an AUV's z is below the surface, so with the origin at sea level it is a
//! negative "altitude", which is still what MAVLink's global frames carry.
//!
//! **Never blind, never lie.** Three threads: the reader ([`reader`]) keeps the latest
//! telemetry, so [`VehicleLink::state`] never waits; the commander ([`commander`]) runs every
//! exchange (uploads, holds, retries, fallbacks), so a vehicle that does not answer delays
//! nothing but its own command; and the agent's loop. The status reported is what the vehicle
//! confirmed: Underway once it accepted a mission, Holding once it acknowledged a hold (or took
//! the fallback mission that ends where it is), never what was merely asked. Arrival is
//! whichever comes first of MISSION_ITEM_REACHED of the last item, MISSION_CURRENT saying the
//! mission is complete (or past its last item), and the vehicle standing at the goal — one
//! lost UDP datagram cannot lose it.
//!
//! Autopilot differences (item 0, hold commands, speed types, geofence) are in [`items`].

pub mod commander;
pub mod items;
pub mod reader;

use std::sync::atomic::Ordering;
use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use mavlink::dialects::common::MavMessage as M;
use mavlink::{Connectable, ConnectionAddress, MavConnection, MavHeader, MavlinkVersion};
use shoal_common::execution::{VehicleCommand, VehicleState, VehicleStatus};
use shoal_common::trajectory::Trajectory;

use super::types::{CommandSerial, LinkError, LinkOutcome, MavlinkSettings, VehicleLink};
pub use commander::FenceSource;
use commander::{Commander, Done, Effect, Job};
use reader::{Shared, READ_TICK};
use shoal_common::geo::GeoOrigin;

pub use items::{fence_items, mission_items, AutopilotChoice, Profile};

/// A vehicle heard before and silent this long is reported as [`VehicleStatus::Fault`].
pub const SILENCE_FAULT: Duration = Duration::from_secs(5);
/// Below this speed (m/s) a vehicle at its goal is taken to stand there.
const STANDING_MPS: f64 = 0.3;

/// An angle in degrees wrapped into (−180, 180].
fn wrap_deg(a: f64) -> f64 {
    let h = a.rem_euclid(360.0);
    h - if h > 180.0 { 360.0 } else { 0.0 }
}

/// Where a mission is on Earth, and what the vehicle should know of it.
#[derive(Debug, Clone)]
pub struct Placement {
    /// The geodetic origin of the scenario frame.
    pub origin: GeoOrigin,
    /// The geofence uploaded with each mission as an onboard safety net, if any.
    pub fence: Option<FenceSource>,
    /// An AUV's surface (`bounds.max[2]`): depth is reported below it, and an ArduPilot
    /// vehicle's home is taken there until its own position says where home is.
    pub surface_z: Option<f64>,
}

impl Placement {
    /// At `origin`, with no geofence and no surface.
    pub fn at(origin: GeoOrigin) -> Placement {
        Placement {
            origin,
            fence: None,
            surface_z: None,
        }
    }
}

/// The mission the vehicle confirmed, as arrival detection needs it.
#[derive(Debug, Clone, Copy)]
struct Confirmed {
    last_item: u16,
    goal: [f64; 3],
    at: Instant,
}

/// A vehicle on a MAVLink connection.
pub struct MavlinkLink {
    settings: MavlinkSettings,
    origin: GeoOrigin,
    shared: Arc<Shared>,
    threads: Vec<JoinHandle<()>>,
    jobs: Sender<(u64, Job)>,
    done: Receiver<Done>,
    /// What the vehicle confirmed it does (Idle, Underway, Holding, Stopped).
    confirmed: VehicleStatus,
    mission: Option<Confirmed>,
    /// Outcomes not yet collected by [`VehicleLink::outcomes`].
    outcomes: Vec<LinkOutcome>,
    surface_z: Option<f64>,
    last_now: Option<f64>,
    arrived_s: Option<f64>,
    heading_deg: f64,
}

impl MavlinkLink {
    /// Opens the connection and starts the reader and commander threads (no vehicle needs to
    /// answer yet), for a mission placed as `place` says.
    pub fn connect(settings: &MavlinkSettings, place: Placement) -> Result<MavlinkLink, LinkError> {
        let Placement {
            origin,
            fence,
            surface_z,
        } = place;
        let io = |e: std::io::Error| LinkError::Io(format!("{}: {e}", settings.address));
        let udp = match ConnectionAddress::parse_address(&settings.address) {
            Ok(ConnectionAddress::Udp(udp)) => udp,
            _ => {
                let why = format!("{}: not a UDP address", settings.address);
                return Err(LinkError::Io(why));
            }
        };
        let mut conn = udp.read_timeout(READ_TICK).connect::<M>().map_err(io)?;
        conn.set_protocol_version(MavlinkVersion::V2);
        conn.set_allow_recv_any_version(true);
        let (conn, shared) = (Arc::new(conn), Arc::new(Shared::default()));
        let (reply_tx, replies) = mpsc::channel();
        let (jobs, job_rx) = mpsc::channel();
        let (done_tx, done) = mpsc::channel();
        let mut header = MavHeader::default();
        (header.system_id, header.component_id) =
            (settings.system_id.into(), settings.component_id);
        let target = (settings.target_system, settings.target_component);
        let (c, sh) = (conn.clone(), shared.clone());
        let reader = std::thread::Builder::new()
            .name("mavlink-reader".into())
            .spawn(move || reader::read_loop(&c, &sh, &reply_tx, header, target))
            .map_err(io)?;
        let commander = Commander {
            conn,
            header,
            replies,
            shared: shared.clone(),
            settings: settings.clone(),
            origin,
            done: done_tx,
            fence,
            fence_taken: None,
            profile: None,
            surface_amsl: surface_z.map(|z| origin.alt_m + z),
        };
        let commander = std::thread::Builder::new()
            .name("mavlink-commander".into())
            .spawn(move || commander.run(&job_rx));
        let link = MavlinkLink {
            settings: settings.clone(),
            origin,
            shared,
            threads: vec![reader],
            jobs,
            done,
            confirmed: VehicleStatus::Idle,
            mission: None,
            outcomes: Vec::new(),
            surface_z,
            last_now: None,
            arrived_s: None,
            heading_deg: 0.0,
        };
        // On failure the link is dropped here, which ends the reader.
        let commander = commander.map_err(io)?;
        let mut link = link;
        link.threads.push(commander);
        Ok(link)
    }

    /// Messages skipped: malformed frames, messages from other systems, and replies that fit
    /// no exchange in progress (stale or out of order). Telemetry we do not use is not counted.
    pub fn skipped(&self) -> u64 {
        self.shared.skipped.load(Ordering::Relaxed)
    }

    /// Hands `job` to the commander, where anything older in progress gives way; its serial,
    /// the generation that supersedes every job before it.
    fn submit(&mut self, job: Job) -> Result<CommandSerial, LinkError> {
        let generation = self.shared.generation.fetch_add(1, Ordering::Relaxed) + 1;
        self.jobs
            .send((generation, job))
            .map(|()| generation)
            .map_err(|_| LinkError::Io("the commander thread has ended".into()))
    }

    /// Takes the commander's finished commands into the link's picture.
    fn collect(&mut self) {
        while let Ok(Done { outcome, effect }) = self.done.try_recv() {
            match effect {
                Effect::None => {}
                Effect::Underway { last_item, goal } => {
                    self.confirmed = VehicleStatus::Underway;
                    let at = Instant::now();
                    self.mission = Some(Confirmed {
                        last_item,
                        goal,
                        at,
                    });
                    self.arrived_s = None;
                }
                Effect::Still(status) => (self.confirmed, self.mission) = (status, None),
            }
            self.outcomes.push(outcome);
        }
    }

    /// Whether the vehicle has finished `mission`, by any of the three signs (module doc).
    fn finished(
        &self,
        latest: &reader::Latest,
        mission: &Confirmed,
        p: [f64; 3],
        v: [f64; 3],
    ) -> bool {
        let after = |at: Instant| at >= mission.at;
        let reached = latest
            .reached
            .is_some_and(|(seq, at)| seq == mission.last_item && after(at));
        let gap = (0..3)
            .map(|i| (p[i] - mission.goal[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        let at_goal = gap <= self.settings.arrival_radius_m;
        // Past the last item (MAVSDK's MissionRawServer counts on to the item count), or the
        // mission state says complete (MAVLink 2 extension).
        let current = latest
            .current
            .is_some_and(|(seq, complete, at)| after(at) && (complete || seq > mission.last_item));
        let speed = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let standing =
            at_goal && speed < STANDING_MPS && mission.at.elapsed() > Duration::from_secs(1);
        reached || current || standing
    }
}

impl Drop for MavlinkLink {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::Relaxed);
        for h in self.threads.drain(..) {
            let _ = h.join(); // each returns within READ_TICK (socket and channel timeouts)
        }
    }
}

impl VehicleLink for MavlinkLink {
    fn name(&self) -> String {
        format!("mavlink {}", self.settings.address)
    }

    fn upload(&mut self, plan: &Trajectory) -> Result<CommandSerial, LinkError> {
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
        let after_t = self.last_now;
        self.submit(Job::Upload {
            plan: plan.clone(),
            after_t,
        })
    }

    fn state(&mut self, now: f64) -> Result<VehicleState, LinkError> {
        self.collect();
        self.last_now = Some(now);
        let latest = self.shared.latest().clone();
        let no_fix = LinkError::Timeout("no position from the vehicle yet".into());
        let (position, velocity, heading) = latest.fix(&self.origin).ok_or(no_fix)?;
        let [ve, vn, _] = velocity;
        self.heading_deg = match heading {
            Some(h) => wrap_deg(h),
            None if ve.hypot(vn) > 0.05 => vn.atan2(ve).to_degrees(),
            None => self.heading_deg, // still, heading unknown: keep the last one
        };
        if let (VehicleStatus::Underway, None, Some(m)) =
            (self.confirmed, self.arrived_s, self.mission)
        {
            if self.finished(&latest, &m, position, velocity) {
                // A real vehicle's mission clock runs in real time; the sign came at most a
                // report interval ago: stamped now.
                self.arrived_s = Some(now);
            }
        }
        let silent = latest.heard.is_some_and(|t| t.elapsed() > SILENCE_FAULT);
        let status = match self.confirmed {
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

    fn hold(&mut self, _now: f64) -> Result<CommandSerial, LinkError> {
        self.submit(Job::Hold(VehicleCommand::Hold))
    }

    /// MAVLink has no "mission over" command short of landing or disarming, which an AUV must
    /// not do unasked: the vehicle holds where it is, and is reported Stopped once it confirms.
    fn stop(&mut self) -> Result<CommandSerial, LinkError> {
        self.submit(Job::Hold(VehicleCommand::Stop))
    }

    fn outcomes(&mut self) -> Vec<LinkOutcome> {
        self.collect();
        std::mem::take(&mut self.outcomes)
    }
}
