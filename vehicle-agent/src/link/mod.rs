//! The vehicle-link seam: everything the agent asks of a vehicle goes through [`VehicleLink`],
//! so a real vehicle's link plugs in here without touching the swarm or the transport.
//!
//! - [`sim`]: a kinematic simulator per vehicle kind (AUV in an optional current, crawler on
//!   the seabed with slip), with position noise, on the mission clock (real time or faster).
//! - [`mavlink`]: a vehicle speaking MAVLink over UDP (mission upload, position telemetry,
//!   hold), its scenario frame tied to WGS-84 by a geodetic origin.
//!
//! Commands (upload, hold, stop) return at once: a real vehicle answers when it answers, and
//! the agent must go on reporting meanwhile. What became of each comes back from
//! [`VehicleLink::outcomes`]. Times are mission seconds (0 = the plan's start); positions are
//! in the scenario frame.

pub mod mavlink;
pub mod sim;

use std::time::Duration;

use shoal_common::execution::{CommandState, VehicleCommand, VehicleState};
use shoal_common::scenario::Scenario;
use shoal_common::trajectory::Trajectory;

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
    /// Which command.
    pub command: VehicleCommand,
    /// Confirmed, failed (a fallback follows) or given up.
    pub state: CommandState,
    /// In plain words: what the vehicle answered, which fallback.
    pub detail: String,
}

impl LinkOutcome {
    /// A command the vehicle confirmed.
    pub fn confirmed(command: VehicleCommand, detail: impl Into<String>) -> LinkOutcome {
        let detail = detail.into();
        let state = CommandState::Confirmed;
        LinkOutcome {
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

/// A vehicle as the agent drives it.
pub trait VehicleLink: Send {
    /// Short name for logs (`sim`, `mavlink udp:…`).
    fn name(&self) -> String;
    /// Starts loading a timed trajectory (mission-timed samples) that the vehicle follows from
    /// then on, replacing what it followed before (and leaving a hold). Returns at once; an
    /// error means the command could not even be given (a bad plan, a closed link).
    fn upload(&mut self, plan: &Trajectory) -> Result<(), LinkError>;
    /// The vehicle's state at mission time `now` (a simulator advances to it; a real vehicle
    /// reports its latest fix, stamped `now`), with the status the vehicle confirmed. Never
    /// waits on a command.
    fn state(&mut self, now: f64) -> Result<VehicleState, LinkError>;
    /// Starts a hold where it is at mission time `now`, until the next upload (a simulator
    /// first drives on to `now`: it is advanced only when asked for its state, up to a report
    /// interval ago, which is 250 mission seconds at 2 Hz and 500×). Returns at once.
    fn hold(&mut self, now: f64) -> Result<(), LinkError>;
    /// Starts a stop: the mission is over for this vehicle. Returns at once.
    fn stop(&mut self) -> Result<(), LinkError>;
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
    /// Connection address in the mavlink crate's syntax (see [`check_mavlink_address`]).
    pub address: String,
    /// Geodetic origin of the scenario frame given to this agent (`--mavlink-origin`); the
    /// scenario's own `[origin]` is used without it, and must agree with it when both exist.
    pub origin: Option<GeoOrigin>,
    /// Which autopilot profile (default: read from the vehicle's HEARTBEAT).
    pub autopilot: mavlink::AutopilotChoice,
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
            autopilot: mavlink::AutopilotChoice::Auto,
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

/// The origin a mission is flown on: the agent's and the scenario's, which must agree (to
/// 1e-7° ≈ 1 cm and 1 cm in altitude) when both are given; one of them is needed.
pub fn mission_origin(
    agent: Option<GeoOrigin>,
    scenario: Option<GeoOrigin>,
) -> Result<GeoOrigin, LinkError> {
    match (agent, scenario) {
        (Some(a), Some(s)) if !a.agrees_with(&s, 1e-7, 0.01) => Err(LinkError::Refused(format!(
            "the mission's origin ({}, {}, {} m) is not this agent's --mavlink-origin \
             ({}, {}, {} m): refused rather than fly the plan somewhere else",
            s.lat_deg, s.lon_deg, s.alt_m, a.lat_deg, a.lon_deg, a.alt_m
        ))),
        (Some(o), _) | (None, Some(o)) => Ok(o),
        (None, None) => Err(LinkError::Refused(
            "no geodetic origin: the scenario has no [origin] and the agent no \
             --mavlink-origin"
                .into(),
        )),
    }
}

pub use shoal_common::geo::GeoOrigin;

/// Reads `SYS,COMP`: the vehicle's MAVLink system id (not 0) and component id.
pub fn parse_mavlink_target(s: &str) -> Result<(u8, u8), String> {
    let id = |x: &str| x.trim().parse::<u8>().ok();
    match s.split_once(',').map(|(a, b)| (id(a), id(b))) {
        Some((Some(system), Some(component))) if system != 0 => Ok((system, component)),
        _ => Err(format!(
            "{s:?} is not SYS,COMP (system id 1..=255, component id 0..=255)"
        )),
    }
}

/// Checks a MAVLink connection address: only UDP (`udpout:HOST:PORT`, `udpin:ADDR:PORT`,
/// `udpbcast:…`) is built in, and a `file:` source could not take commands.
pub fn check_mavlink_address(address: &str) -> Result<String, String> {
    match ::mavlink::ConnectionAddress::parse_address(address) {
        Ok(::mavlink::ConnectionAddress::Udp(_)) => Ok(address.to_string()),
        _ => Err(format!(
            "{address:?} is not udpin:, udpout: or udpbcast:ADDR:PORT"
        )),
    }
}

/// Opens the link of vehicle `index` of `scenario`.
pub fn open(
    settings: &LinkSettings,
    scenario: &Scenario,
    index: usize,
    seed: u64,
) -> Result<Box<dyn VehicleLink>, LinkError> {
    match settings.kind {
        LinkKind::Sim => Ok(Box::new(sim::SimLink::new(
            scenario,
            index,
            settings.position_noise_m,
            seed,
        )?)),
        LinkKind::Mavlink => {
            let settings = settings
                .mavlink
                .as_ref()
                .ok_or_else(|| LinkError::Io("the mavlink link needs --mavlink-address".into()))?;
            let origin = mission_origin(settings.origin, scenario.origin)?;
            // An AUV's depth is measured from the scenario's surface, as the simulator does.
            let surface = scenario
                .vehicles
                .get(index)
                .filter(|v| v.kind == shoal_common::scenario::VehicleKind::Auv)
                .map(|_| scenario.bounds.max[2]);
            let fence = settings.fence.then(|| mavlink::commander::FenceSource {
                bounds: scenario.bounds.clone(),
                obstacles: scenario.obstacles.clone(),
            });
            let place = mavlink::Placement {
                origin,
                fence,
                surface_z: surface,
            };
            Ok(Box::new(mavlink::MavlinkLink::connect(settings, place)?))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mission_flies_on_one_origin_and_refuses_two() {
        let (a, b) = (
            GeoOrigin::new(43.1, 5.9, 0.0),
            GeoOrigin::new(43.1, 5.9001, 0.0),
        );
        assert_eq!(mission_origin(Some(a), None), Ok(a));
        assert_eq!(mission_origin(None, Some(b)), Ok(b));
        assert_eq!(mission_origin(Some(a), Some(a)), Ok(a));
        let refused = |r: Result<GeoOrigin, LinkError>| match r {
            Err(LinkError::Refused(why)) => why,
            other => format!("not refused: {other:?}"),
        };
        let two = refused(mission_origin(Some(a), Some(b)));
        assert!(
            two.contains("5.9001") && two.contains("--mavlink-origin"),
            "{two}"
        );
        assert!(refused(mission_origin(None, None)).contains("no geodetic origin"));
        // A centimetre apart is the same origin.
        let near = GeoOrigin::new(43.1 + 5e-8, 5.9, 0.005);
        assert_eq!(mission_origin(Some(a), Some(near)), Ok(a));
    }

    #[test]
    fn an_agent_refuses_to_open_a_link_for_a_mission_placed_elsewhere() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/amp-pso-3.toml");
        let scenario = match Scenario::load(std::path::Path::new(path)) {
            Ok(s) => s,
            Err(e) => panic!("{e}"),
        };
        assert!(scenario.origin.is_some(), "amp-pso-3 has an [origin]");
        let elsewhere = GeoOrigin::new(43.1, 5.9, 0.0);
        let settings = LinkSettings {
            kind: LinkKind::Mavlink,
            position_noise_m: 0.0,
            mavlink: Some(MavlinkSettings::new("udpout:127.0.0.1:9", Some(elsewhere))),
        };
        match open(&settings, &scenario, 0, 1) {
            Err(LinkError::Refused(why)) => assert!(why.contains("--mavlink-origin"), "{why}"),
            Err(e) => panic!("not refused: {e}"),
            Ok(link) => panic!("opened {}", link.name()),
        }
    }
}
