//! The vehicle-link seam: everything the agent asks of a vehicle goes through [`VehicleLink`],
//! so a real vehicle's link plugs in here without touching the swarm or the transport.
//!
//! - [`sim`]: a kinematic simulator per vehicle kind (AUV in an optional current, crawler on
//!   the seabed with slip), with position noise, on the mission clock (real time or faster).
//! - [`mavlink`]: a vehicle speaking MAVLink over UDP (mission upload, position telemetry,
//!   pause), its scenario frame tied to WGS-84 by a geodetic origin.
//!
//! Times are mission seconds (0 = the plan's start); positions are in the scenario frame.

pub mod mavlink;
pub mod sim;

use std::time::Duration;

use shoal_common::execution::VehicleState;
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

/// A vehicle as the agent drives it.
pub trait VehicleLink: Send {
    /// Short name for logs (`sim`, `mavlink udp:…`).
    fn name(&self) -> String;
    /// Loads a timed trajectory (mission-timed samples); the vehicle follows it from now on,
    /// replacing what it followed before (and leaving a hold).
    fn upload(&mut self, plan: &Trajectory) -> Result<(), LinkError>;
    /// The vehicle's state at mission time `now` (a simulator advances to it; a real vehicle
    /// reports its latest fix, stamped `now`).
    fn state(&mut self, now: f64) -> Result<VehicleState, LinkError>;
    /// Hold where it is at mission time `now` until the next upload (a simulator first drives
    /// on to `now`: it is advanced only when asked for its state, up to a report interval ago,
    /// which is 250 mission seconds at 2 Hz and 500×).
    fn hold(&mut self, now: f64) -> Result<(), LinkError>;
    /// Stop: the mission is over for this vehicle.
    fn stop(&mut self) -> Result<(), LinkError>;
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
    /// `mavlink` link: where the vehicle is and where the scenario frame is (`None` when the
    /// command line did not give both an address and an origin).
    pub mavlink: Option<MavlinkSettings>,
}

/// `mavlink` link: how to reach the vehicle and where its scenario frame is.
#[derive(Debug, Clone, PartialEq)]
pub struct MavlinkSettings {
    /// Connection address in the mavlink crate's syntax (see [`check_mavlink_address`]).
    pub address: String,
    /// Geodetic origin of the scenario frame.
    pub origin: GeoOrigin,
    /// The vehicle's system id (default 1).
    pub target_system: u8,
    /// The vehicle's component id (default 1, the autopilot).
    pub target_component: u8,
    /// Our system id (default 255, a ground station).
    pub system_id: u8,
    /// Our component id (default 190, MAV_COMP_ID_MISSIONPLANNER).
    pub component_id: u8,
    /// How long to wait for each reply before resending (default 1 s).
    pub timeout: Duration,
    /// Resends before giving up (default 5).
    pub retries: u32,
}

impl MavlinkSettings {
    /// The defaults around an address and an origin.
    pub fn new(address: impl Into<String>, origin: GeoOrigin) -> MavlinkSettings {
        MavlinkSettings {
            address: address.into(),
            origin,
            target_system: 1,
            target_component: 1,
            system_id: 255,
            component_id: 190,
            timeout: Duration::from_secs(1),
            retries: 5,
        }
    }
}

/// Geodetic position of scenario point (0, 0, 0); [`mavlink`] converts between the two frames.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeoOrigin {
    /// Latitude, degrees north.
    pub lat_deg: f64,
    /// Longitude, degrees east.
    pub lon_deg: f64,
    /// Altitude above mean sea level, metres.
    pub alt_m: f64,
}

impl GeoOrigin {
    /// The origin at `lat_deg`, `lon_deg` (degrees), `alt_m` (metres above mean sea level).
    pub const fn new(lat_deg: f64, lon_deg: f64, alt_m: f64) -> GeoOrigin {
        GeoOrigin {
            lat_deg,
            lon_deg,
            alt_m,
        }
    }
}

impl std::str::FromStr for GeoOrigin {
    type Err = String;
    /// `LAT,LON,ALT`: a latitude within 89° of the equator (the flat-earth approximation
    /// divides by cos(lat)), a longitude in [−180, 180], a finite altitude.
    fn from_str(s: &str) -> Result<GeoOrigin, String> {
        let v: Vec<f64> = s.split(',').filter_map(|p| p.trim().parse().ok()).collect();
        match v[..] {
            [lat, lon, alt] if lat.abs() <= 89.0 && lon.abs() <= 180.0 && alt.is_finite() => {
                Ok(GeoOrigin::new(lat, lon, alt))
            }
            _ => Err(format!(
                "{s:?} is not LAT,LON,ALT (latitude in [-89, 89] and longitude in \
                 [-180, 180] degrees, altitude in metres)"
            )),
        }
    }
}

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
            let settings = settings.mavlink.as_ref().ok_or_else(|| {
                LinkError::Io(
                    "the mavlink link needs --mavlink-address and --mavlink-origin".into(),
                )
            })?;
            // An AUV's depth is measured from the scenario's surface, as the simulator does.
            let surface = scenario
                .vehicles
                .get(index)
                .filter(|v| v.kind == shoal_common::scenario::VehicleKind::Auv)
                .map(|_| scenario.bounds.max[2]);
            Ok(Box::new(
                mavlink::MavlinkLink::connect(settings)?.with_surface(surface),
            ))
        }
    }
}
