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
mod types;

use shoal_common::scenario::Scenario;
pub use types::{
    CommandSerial, LinkError, LinkKind, LinkOutcome, LinkSettings, MavlinkSettings, VehicleLink,
};

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
