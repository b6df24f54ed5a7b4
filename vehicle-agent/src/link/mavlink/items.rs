//! What the link sends, per autopilot family: the mission items of a timed plan, the geofence
//! that backs it up on board, and the commands that make a vehicle hold.
//!
//! **Autopilots differ** where the MAVLink spec leaves room (MAVLink mission protocol,
//! <https://mavlink.io/en/services/mission.html>):
//! - ArduPilot (ArduSub, ArduCopter, Rover) keeps its home position in mission item 0 and
//!   overwrites whatever is uploaded there, so a mission starts at item 1 behind a placeholder;
//!   it pauses an AUTO mission on MAV_CMD_DO_PAUSE_CONTINUE in recent firmware, and otherwise
//!   holds in a station-keeping mode (ArduSub POSHOLD, Copter LOITER, Rover HOLD).
//! - PX4 does not implement DO_PAUSE_CONTINUE: a mission is paused by switching to its Hold
//!   mode (main mode AUTO, sub-mode LOITER) with MAV_CMD_DO_SET_MODE.
//! - Anything else is read as the spec has it: item 0 is the first item, DO_PAUSE_CONTINUE
//!   pauses.
//!
//! **Speeds.** MAV_CMD_DO_CHANGE_SPEED's "ground speed" (type 1) is the horizontal speed to
//! ArduPilot (WPNAV_SPEED) and PX4 alike; the vertical rate follows from reaching the
//! waypoint's altitude. So each leg sends its horizontal speed, and a purely vertical leg its
//! climb (type 2) or descent (type 3) rate: the leg then takes the planned time. Sending the
//! 3-D speed as ground speed would run a 20° dive leg 1/cos 20° = 6.4 % fast.

use mavlink::dialects::common::{self as mav, MavAutopilot, MavCmd, MavFrame, MavType};
use shoal_common::geometry::horizontal_distance_to_path;
use shoal_common::scenario::{Bounds, Obstacle, ObstacleKind};
use shoal_common::trajectory::Trajectory;

use shoal_common::geo::GeoOrigin;

/// How long a fallback hold keeps the vehicle at its waypoint, seconds (an hour: until the
/// next upload, in practice).
pub const FALLBACK_HOLD_S: f32 = 3600.0;

/// An autopilot family, as the link treats it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Profile {
    /// The MAVLink spec as written.
    Generic,
    /// ArduPilot, with the vehicle type its HEARTBEAT gives (it picks the hold mode).
    ArduPilot(MavType),
    /// PX4.
    Px4,
}

/// Which profile to use: the vehicle's own HEARTBEAT, or a fixed one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum AutopilotChoice {
    /// Read HEARTBEAT.autopilot (generic if none is heard within a few seconds).
    #[default]
    Auto,
    /// The MAVLink spec as written.
    Generic,
    /// ArduPilot (ArduSub by default when the type is unknown).
    Ardupilot,
    /// PX4.
    Px4,
}

impl Profile {
    /// The profile of a vehicle whose HEARTBEAT says `autopilot` and `vehicle`.
    pub fn from_heartbeat(autopilot: MavAutopilot, vehicle: MavType) -> Profile {
        match autopilot {
            MavAutopilot::MAV_AUTOPILOT_ARDUPILOTMEGA => Profile::ArduPilot(vehicle),
            MavAutopilot::MAV_AUTOPILOT_PX4 => Profile::Px4,
            _ => Profile::Generic,
        }
    }

    /// The profile `choice` fixes, if it fixes one.
    pub fn chosen(choice: AutopilotChoice) -> Option<Profile> {
        match choice {
            AutopilotChoice::Auto => None,
            AutopilotChoice::Generic => Some(Profile::Generic),
            AutopilotChoice::Ardupilot => Some(Profile::ArduPilot(MavType::MAV_TYPE_SUBMARINE)),
            AutopilotChoice::Px4 => Some(Profile::Px4),
        }
    }

    /// The frame of a waypoint at AMSL altitude `amsl`, and its altitude in it. ArduSub runs
    /// waypoints only relative to home (its home is at the surface, so depths are negative:
    /// "BAD NAV AltFrame" otherwise, `Sub::start_command`), hence
    /// MAV_FRAME_GLOBAL_RELATIVE_ALT_INT above `home_amsl` for ArduPilot; the others take
    /// MAV_FRAME_GLOBAL_INT, AMSL — deprecated (2024) for its synonym MAV_FRAME_GLOBAL, but the
    /// one every autopilot in the field reads as "int lat/lon, AMSL altitude".
    pub fn altitude(self, amsl: f64, home_amsl: f64) -> (MavFrame, f64) {
        #[allow(deprecated)]
        match self {
            Profile::ArduPilot(_) => (
                MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
                amsl - home_amsl,
            ),
            _ => (MavFrame::MAV_FRAME_GLOBAL_INT, amsl),
        }
    }

    /// Sequence number of the first item that is ours (ArduPilot keeps home at 0).
    pub fn first_item(self) -> u16 {
        u16::from(matches!(self, Profile::ArduPilot(_)))
    }

    /// The commands that make the vehicle hold, in the order to try them, each with a label
    /// for reports. After them all comes the fallback mission ([`fallback_items`]).
    pub fn hold_steps(self) -> Vec<HoldStep> {
        let pause = HoldStep {
            label: "MAV_CMD_DO_PAUSE_CONTINUE".into(),
            command: MavCmd::MAV_CMD_DO_PAUSE_CONTINUE,
            params: [0.0; 7],
        };
        let custom = 1.0; // MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
        match self {
            Profile::Generic => vec![pause],
            Profile::Px4 => vec![HoldStep {
                label: "PX4 Hold mode (DO_SET_MODE AUTO.LOITER)".into(),
                command: MavCmd::MAV_CMD_DO_SET_MODE,
                params: [custom, 4.0, 3.0, 0.0, 0.0, 0.0, 0.0], // main AUTO, sub LOITER
            }],
            Profile::ArduPilot(vehicle) => {
                let (name, mode) = ardupilot_hold_mode(vehicle);
                let set = HoldStep {
                    label: format!("ArduPilot {name} mode (DO_SET_MODE {mode})"),
                    command: MavCmd::MAV_CMD_DO_SET_MODE,
                    params: [custom, f32::from(mode), 0.0, 0.0, 0.0, 0.0, 0.0],
                };
                vec![pause, set]
            }
        }
    }
}

/// ArduPilot's station-keeping mode for a vehicle type: its name and custom-mode number.
fn ardupilot_hold_mode(vehicle: MavType) -> (&'static str, u8) {
    use MavType::*;
    match vehicle {
        MAV_TYPE_GROUND_ROVER | MAV_TYPE_SURFACE_BOAT => ("HOLD", 4),
        MAV_TYPE_FIXED_WING => ("LOITER", 12),
        MAV_TYPE_QUADROTOR | MAV_TYPE_HEXAROTOR | MAV_TYPE_OCTOROTOR | MAV_TYPE_TRICOPTER
        | MAV_TYPE_COAXIAL | MAV_TYPE_HELICOPTER => ("LOITER", 5),
        _ => ("POSHOLD", 16), // ArduSub, the underwater vehicle's firmware
    }
}

/// One way of asking a vehicle to hold.
#[derive(Debug, Clone, PartialEq)]
pub struct HoldStep {
    /// What it is, for reports.
    pub label: String,
    /// The COMMAND_LONG command.
    pub command: MavCmd,
    /// Its seven parameters.
    pub params: [f32; 7],
}

/// A NAV_WAYPOINT at lat, lon (degrees) and an altitude in `frame` (metres), held `hold_s`.
fn waypoint(
    lat: f64,
    lon: f64,
    (frame, alt): (MavFrame, f64),
    hold_s: f32,
) -> mav::MISSION_ITEM_INT_DATA {
    let mut wp = mav::MISSION_ITEM_INT_DATA::default();
    (wp.command, wp.frame) = (MavCmd::MAV_CMD_NAV_WAYPOINT, frame);
    (wp.param1, wp.param4) = (hold_s, f32::NAN); // yaw NaN: the vehicle's choice
    (wp.x, wp.y, wp.z) = (e7(lat), e7(lon), alt as f32);
    wp
}

/// Degrees as MAVLink's degE7 integers.
fn e7(deg: f64) -> i32 {
    (deg * 1e7).round() as i32
}

/// The DO_CHANGE_SPEED that times a leg of `dt` seconds from `a` to `b` (see the module doc),
/// `None` for a leg that does not move.
fn speed_item(a: [f64; 3], b: [f64; 3], dt: f64) -> Option<mav::MISSION_ITEM_INT_DATA> {
    let (horizontal, dz) = ((b[0] - a[0]).hypot(b[1] - a[1]), b[2] - a[2]);
    if dt.is_nan() || dt <= 0.0 || horizontal.hypot(dz) < 1e-3 {
        return None;
    }
    let (kind, speed) = match horizontal >= 1e-3 {
        true => (1.0, horizontal / dt),      // ground speed
        false if dz > 0.0 => (2.0, dz / dt), // climb
        false => (3.0, -dz / dt),            // descent
    };
    let mut change = mav::MISSION_ITEM_INT_DATA::default();
    (change.command, change.frame) = (MavCmd::MAV_CMD_DO_CHANGE_SPEED, MavFrame::MAV_FRAME_MISSION);
    // Throttle −1: unchanged.
    (change.param1, change.param2, change.param3) = (kind, speed as f32, -1.0);
    Some(change)
}

/// Numbers `items` from 0, marks the first of ours current, and addresses them to `target`.
fn finish(mut items: Vec<mav::MISSION_ITEM_INT_DATA>, first: u16, target: (u8, u8)) -> Items {
    for (seq, item) in items.iter_mut().enumerate() {
        let seq = seq as u16;
        (item.seq, item.current, item.autocontinue) = (seq, u8::from(seq == first), 1);
        (item.target_system, item.target_component) = target;
    }
    Items { items, first }
}

/// A mission as uploaded: its items, and the first that is ours.
#[derive(Debug, Clone, PartialEq)]
pub struct Items {
    /// Every item, numbered from 0.
    pub items: Vec<mav::MISSION_ITEM_INT_DATA>,
    /// The first item that is ours (1 behind ArduPilot's home).
    pub first: u16,
}

impl Items {
    /// The last item's sequence number.
    pub fn last(&self) -> u16 {
        self.items.len().saturating_sub(1) as u16
    }
}

/// The mission items of `plan` for vehicle `target` (system, component) under `profile`
/// (`home_amsl`: the home altitude of relative frames): the legs ending after mission time
/// `after_t` (all without it), so that a replan does not send the vehicle back to the plan's
/// start; a plan of one sample (or whose legs are all over) is one waypoint.
pub fn mission_items(
    plan: &Trajectory,
    origin: &GeoOrigin,
    after_t: Option<f64>,
    target: (u8, u8),
    (profile, home_amsl): (Profile, f64),
) -> Items {
    let at = |p: [f64; 3], hold_s: f32| {
        let [lat, lon, alt] = origin.to_geodetic(p);
        waypoint(lat, lon, profile.altitude(alt, home_amsl), hold_s)
    };
    let mut items = Vec::new();
    if let (Profile::ArduPilot(_), Some(p)) = (profile, plan.points.first()) {
        items.push(at((*p).into(), 0.0)); // home's place: the autopilot overwrites it
    }
    let first = items.len();
    for k in 0..plan.times.len().saturating_sub(1) {
        let (t0, t1) = (plan.times[k], plan.times[k + 1]);
        if after_t.is_some_and(|t| t1 <= t) {
            continue;
        }
        let (a, b): ([f64; 3], [f64; 3]) = (plan.points[k].into(), plan.points[k + 1].into());
        let change = speed_item(a, b, t1 - t0);
        let hold_s = if change.is_some() {
            0.0
        } else {
            (t1 - t0) as f32
        };
        items.extend(change);
        items.push(at(b, hold_s));
    }
    if let (true, Some(p)) = (items.len() == first, plan.points.last()) {
        items.push(at((*p).into(), 0.0));
    }
    finish(items, first as u16, target)
}

/// The fallback that every MissionRaw implementation accepts when a hold is refused or
/// unanswered: a mission whose only waypoint is where the vehicle is (lat, lon in degrees,
/// AMSL altitude in metres), held for [`FALLBACK_HOLD_S`].
pub fn fallback_items(
    here: [f64; 3],
    target: (u8, u8),
    (profile, home_amsl): (Profile, f64),
) -> Items {
    let [lat, lon, alt] = here;
    let alt = profile.altitude(alt, home_amsl);
    let mut items = Vec::new();
    if matches!(profile, Profile::ArduPilot(_)) {
        items.push(waypoint(lat, lon, alt, 0.0)); // home's place
    }
    let first = items.len() as u16;
    items.push(waypoint(lat, lon, alt, FALLBACK_HOLD_S));
    finish(items, first, target)
}

/// The geofence (MAV_MISSION_TYPE_FENCE) that backs a plan up on board: the scenario's bounds
/// as an inclusion polygon, and each hard obstacle as an exclusion circle of its physical
/// radius — unless the plan passes over or under it inside that circle (a fence is 2-D, the
/// plan keeps clear in 3-D), when it is left out rather than trip the vehicle's failsafe.
pub fn fence_items(
    bounds: &Bounds,
    obstacles: &[Obstacle],
    plan: &Trajectory,
    origin: &GeoOrigin,
    target: (u8, u8),
) -> Vec<mav::MISSION_ITEM_INT_DATA> {
    let z = bounds.max[2];
    let corners = [
        [bounds.min[0], bounds.min[1], z],
        [bounds.max[0], bounds.min[1], z],
        [bounds.max[0], bounds.max[1], z],
        [bounds.min[0], bounds.max[1], z],
    ];
    let fence_item = |command: MavCmd, p: [f64; 3], param1: f32| {
        let [lat, lon, _] = origin.to_geodetic(p);
        let mut item = mav::MISSION_ITEM_INT_DATA::default();
        (item.command, item.frame, item.param1) = (command, MavFrame::MAV_FRAME_GLOBAL, param1);
        (item.x, item.y) = (e7(lat), e7(lon));
        item.mission_type = mav::MavMissionType::MAV_MISSION_TYPE_FENCE;
        item
    };
    let mut items: Vec<_> = corners
        .iter()
        .map(|c| fence_item(MavCmd::MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION, *c, 4.0))
        .collect();
    let passes_inside = |o: &Obstacle| {
        let centre = [o.centre[0], o.centre[1]];
        horizontal_distance_to_path(&plan.points, centre) <= o.radius_m
    };
    for o in obstacles.iter().filter(|o| o.kind == ObstacleKind::Hard) {
        if !passes_inside(o) {
            let radius = o.radius_m as f32;
            items.push(fence_item(
                MavCmd::MAV_CMD_NAV_FENCE_CIRCLE_EXCLUSION,
                o.centre,
                radius,
            ));
        }
    }
    for (seq, item) in items.iter_mut().enumerate() {
        item.seq = seq as u16;
        (item.target_system, item.target_component) = target;
    }
    items
}

#[cfg(test)]
mod tests;
