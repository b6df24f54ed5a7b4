//! What the agent and every link share: the seam's trait, its outcomes and errors, and the
//! settings a link is opened with, apart from `mod.rs` so that the links depend on them and not
//! on the module that picks a link.

use std::time::Duration;

use shoal_common::execution::{CommandState, VehicleCommand, VehicleState};
use shoal_common::geo::GeoOrigin;
use shoal_common::trajectory::Trajectory;

use super::mavlink::items::AutopilotChoice;

/// Why a link could not do what was asked.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LinkError {
    /// The vehicle did not answer in time (after the link's retries).
    #[error("the vehicle did not answer: {0}")]
    Timeout(String),
    /// The vehicle refused (e.g. a mission item out of its limits).
    #[error("the vehicle refused: {0}")]
    Refused(String),
    /// The link itself failed (socket, I/O).
    #[error("link failure: {0}")]
    Io(String),
}

/// What became of a command the link was given.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkOutcome {
    /// Which giving of it: the serial the link returned when it was given. Two uploads in quick
    /// succession are told apart by it, so the agent reports the plan the vehicle confirmed,
    /// not the last one it was sent.
    pub serial: CommandSerial,
    /// Which command.
    pub command: VehicleCommand,
    /// Confirmed, failed (a fallback follows) or given up.
    pub state: CommandState,
    /// In plain words: what the vehicle answered, which fallback.
    pub detail: String,
}

impl LinkOutcome {
    /// A command the vehicle confirmed.
    pub fn confirmed(
        serial: CommandSerial,
        command: VehicleCommand,
        detail: impl Into<String>,
    ) -> LinkOutcome {
        let detail = detail.into();
        let state = CommandState::Confirmed;
        LinkOutcome {
            serial,
            command,
            state,
            detail,
        }
    }

    /// Whether it ends its command (confirmed, or given up).
    pub fn is_final(&self) -> bool {
        matches!(self.state, CommandState::Confirmed | CommandState::GaveUp)
    }
}

/// The number a link gives each command it is given, growing from 1: what its outcomes carry.
pub type CommandSerial = u64;

/// A vehicle as the agent drives it.
pub trait VehicleLink: Send {
    /// Short name for logs (`sim`, `mavlink udp:…`).
    fn name(&self) -> String;
    /// Starts loading a timed trajectory (mission-timed samples) that the vehicle follows from
    /// then on, replacing what it followed before (and leaving a hold). Returns at once, with
    /// the command's serial; an error means the command could not even be given (a bad plan, a
    /// closed link).
    fn upload(&mut self, plan: &Trajectory) -> Result<CommandSerial, LinkError>;
    /// The vehicle's state at mission time `now` (a simulator advances to it; a real vehicle
    /// reports its latest fix, stamped `now`), with the status the vehicle confirmed. Never
    /// waits on a command.
    fn state(&mut self, now: f64) -> Result<VehicleState, LinkError>;
    /// Starts a hold where it is at mission time `now`, until the next upload (a simulator
    /// first drives on to `now`: it is advanced only when asked for its state, up to a report
    /// interval ago, which is 250 mission seconds at 2 Hz and 500×). Returns at once, with the
    /// command's serial.
    fn hold(&mut self, now: f64) -> Result<CommandSerial, LinkError>;
    /// Starts a stop: the mission is over for this vehicle. Returns at once, with the
    /// command's serial.
    fn stop(&mut self) -> Result<CommandSerial, LinkError>;
    /// What became of the commands given, since the last call, in order.
    fn outcomes(&mut self) -> Vec<LinkOutcome>;
}

/// Which link an agent drives its vehicle through.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum LinkKind {
    /// The kinematic simulator.
    #[default]
    Sim,
    /// A MAVLink vehicle (`--mavlink-address`, `--mavlink-origin`).
    Mavlink,
}

/// Settings of the links, from the agent's command line.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkSettings {
    /// Which link.
    pub kind: LinkKind,
    /// Simulated position noise (standard deviation per axis), metres.
    pub position_noise_m: f64,
    /// `mavlink` link: where the vehicle is (`None` when the command line gave no address).
    pub mavlink: Option<MavlinkSettings>,
}

/// `mavlink` link: how to reach the vehicle and where its scenario frame is.
#[derive(Debug, Clone, PartialEq)]
pub struct MavlinkSettings {
    /// Connection address in the mavlink crate's syntax (see
    /// [`check_mavlink_address`](super::check_mavlink_address)).
    pub address: String,
    /// Geodetic origin of the scenario frame given to this agent (`--mavlink-origin`); the
    /// scenario's own `[origin]` is used without it, and must agree with it when both exist.
    pub origin: Option<GeoOrigin>,
    /// Which autopilot profile (default: read from the vehicle's HEARTBEAT).
    pub autopilot: AutopilotChoice,
    /// The vehicle's system id (default 1).
    pub target_system: u8,
    /// The vehicle's component id (default 1, the autopilot).
    pub target_component: u8,
    /// Our system id (default 255, a ground station).
    pub system_id: u8,
    /// Our component id (default 190, MAV_COMP_ID_MISSIONPLANNER).
    pub component_id: u8,
    /// How long to wait for each reply of an upload before resending (default 1 s).
    pub timeout: Duration,
    /// Resends of an upload before giving up (default 5).
    pub retries: u32,
    /// A vehicle standing this close to its last waypoint has arrived, metres (default 2 m:
    /// a typical waypoint acceptance radius).
    pub arrival_radius_m: f64,
    /// Upload the scenario's bounds and hard obstacles as a geofence (default true).
    pub fence: bool,
}

impl MavlinkSettings {
    /// The defaults around an address and an origin.
    pub fn new(address: impl Into<String>, origin: Option<GeoOrigin>) -> MavlinkSettings {
        MavlinkSettings {
            address: address.into(),
            origin,
            autopilot: AutopilotChoice::Auto,
            target_system: 1,
            target_component: 1,
            system_id: 255,
            component_id: 190,
            timeout: Duration::from_secs(1),
            retries: 5,
            arrival_radius_m: 2.0,
            fence: true,
        }
    }
}
