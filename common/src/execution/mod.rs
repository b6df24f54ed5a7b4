//! Executing a plan: what a vehicle reports while it drives its timed trajectory, a
//! kinematic simulator of the vehicle kinds ([`sim`]), and the coordinator's live fleet picture
//! computed from the latest reports and the plans ([`picture`]).
//!
//! Times are *mission* seconds: 0 is the plan's start, the same clock the timed trajectories
//! use. Positions are in the scenario frame (x east, y north, z up, metres).

pub mod picture;
pub mod sim;

use serde::{Deserialize, Serialize};

/// Unix time now, microseconds: the clock telemetry is stamped with (agent send, coordinator
/// receipt) and the mission clock's epoch is on.
pub fn unix_us() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_micros() as u64)
}

/// The fleet's one mission clock: mission time = `(unix_now − epoch) × scale`, never negative.
/// The coordinator and every agent read the same epoch, so they share it (agents on other
/// machines need synchronised clocks, e.g. NTP).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MissionClock {
    /// Unix time of mission time 0, milliseconds.
    pub epoch_unix_ms: u64,
    /// Mission seconds per wall second.
    pub scale: f64,
}

impl MissionClock {
    /// Mission time now, seconds.
    pub fn now(&self) -> f64 {
        (self.since_epoch().as_secs_f64() * self.scale).max(0.0)
    }

    /// Wall time since mission time 0 (zero before it).
    pub fn since_epoch(&self) -> std::time::Duration {
        std::time::Duration::from_micros(unix_us().saturating_sub(self.epoch_unix_ms * 1000))
    }
}

/// What a vehicle is doing, as its link reports it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum VehicleStatus {
    /// Powered, no trajectory loaded yet.
    Idle,
    /// Following its trajectory.
    Underway,
    /// Commanded to hold where it is (AUV: station-keeping; crawler: stopped on the seabed).
    Holding,
    /// Reached the end of its trajectory and holds there.
    Arrived,
    /// Commanded to stop: the mission is over for it.
    Stopped,
    /// The link reports a fault (lost fix, motor fault, …).
    Fault,
}

/// A command an agent passes to its vehicle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum VehicleCommand {
    /// Load a (re)planned trajectory and start it.
    Upload,
    /// Hold where it is until the next upload.
    Hold,
    /// Stop: the mission is over for it.
    Stop,
}

impl VehicleCommand {
    /// Lower-case name, as in event kinds (`hold_failed`).
    pub fn name(self) -> &'static str {
        match self {
            VehicleCommand::Upload => "upload",
            VehicleCommand::Hold => "hold",
            VehicleCommand::Stop => "stop",
        }
    }
}

/// Where a command stands, as far as the vehicle has confirmed it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum CommandState {
    /// Sent; the vehicle has not answered yet.
    Pending,
    /// The vehicle confirmed it (directly or through a fallback: `detail` says how).
    Confirmed,
    /// The vehicle refused it or did not answer; a fallback is under way (`detail` says which).
    Failed,
    /// Refused or unanswered, and so was every fallback: the vehicle goes on as before.
    GaveUp,
}

/// The latest command of an agent and what its vehicle made of it: carried in every
/// telemetry report, so that a lost report does not lose a refused hold.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct CommandReport {
    /// Which command.
    pub command: VehicleCommand,
    /// Where it stands.
    pub state: CommandState,
    /// In plain words: what was sent, what the vehicle answered, which fallback.
    pub detail: String,
    /// Mission time the command was given, seconds (tells two holds apart).
    pub given_s: f64,
}

/// One state report of a vehicle (the telemetry it sends), in the scenario frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct VehicleState {
    /// Mission time of the fix, seconds.
    pub t_s: f64,
    /// Position fix, metres (with the link's position noise).
    pub position: [f64; 3],
    /// Velocity over ground, m/s.
    pub velocity: [f64; 3],
    /// Heading of the horizontal velocity (or of the hull when still), degrees counter-clockwise
    /// from east (+x), in (−180, 180].
    pub heading_deg: f64,
    /// AUVs: depth below the surface (`bounds.max[2] − z`), metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_m: Option<f64>,
    /// Crawlers: height above the seabed, metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub altitude_m: Option<f64>,
    /// Battery left, fraction of a full charge in [0, 1].
    pub battery: f64,
    /// What it is doing.
    pub status: VehicleStatus,
    /// Mission time it reached the end of its trajectory, as the vehicle tells it (reports
    /// come only every few mission seconds at high time scales).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arrived_s: Option<f64>,
}
