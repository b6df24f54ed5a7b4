//! A plan as QGroundControl `.plan` files, one per vehicle, in QGC's documented plan file format
//! (QGC developer guide, "Plan File Format": file version 1, mission version 2, geofence
//! version 2 with circle and polygon items of version 1, rally points version 2).
//!
//! **Mission.** The vehicle starts at its plan's first sample (`plannedHomePosition`); each leg
//! is a MAV_CMD_NAV_WAYPOINT (16) to its end, preceded by MAV_CMD_DO_CHANGE_SPEED (178) when its
//! speed differs from the last one commanded, so that the vehicle keeps the plan's timing; a
//! leg that does not move is a wait (the waypoint's hold time). Waypoints are in MAV_FRAME_GLOBAL
//! (0): altitude above mean sea level, negative under the sea. This is the layout of the
//! MAVLink link's mission upload, with speed commands only where the speed changes and an
//! acceptance radius ([`acceptance_radius_m`]).
//!
//! **Geofence.** The scenario box is an inclusion polygon; hard obstacles are exclusion circles
//! of their inflated radius. A geofence is two-dimensional and an obstacle is a sphere: a plan
//! may pass over or under one, and a fence the plan itself breaks would stop the vehicle, so
//! each vehicle's file fences only the obstacles its path stays out of horizontally.

use serde_json::{json, Value};

use super::{distance, footprint, leg_speeds, point, round, ExportInput, MAX_ACCEPTANCE_RADIUS_M};
use shoal_common::geometry::{horizontal_distance_to_path, Vec3};
use shoal_common::plan::VehiclePlan;
use shoal_common::scenario::{Obstacle, VehicleKind};

/// MAV_CMD_NAV_WAYPOINT.
pub const NAV_WAYPOINT: u16 = 16;
/// MAV_CMD_DO_CHANGE_SPEED.
pub const DO_CHANGE_SPEED: u16 = 178;
/// MAV_FRAME_GLOBAL: latitude, longitude, altitude above mean sea level.
pub const FRAME_GLOBAL: u8 = 0;
/// MAV_FRAME_MISSION: a command that is not a position.
pub const FRAME_MISSION: u8 = 2;
/// MAV_TYPE_SUBMARINE.
pub const MAV_TYPE_SUBMARINE: u8 = 12;
/// MAV_TYPE_GROUND_ROVER: a seabed crawler drives like one.
pub const MAV_TYPE_GROUND_ROVER: u8 = 10;
/// MAV_AUTOPILOT_PX4: the mission layout above is PX4's (ArduPilot takes item 0 as home; QGC
/// rewrites the layout for the autopilot it uploads to).
pub const MAV_AUTOPILOT_PX4: u8 = 12;

/// One vehicle's `.plan`.
#[derive(Debug, Clone, PartialEq)]
pub struct VehicleFile {
    /// Vehicle id: the file is `<vehicle>.plan`.
    pub vehicle: String,
    /// The file's JSON.
    pub json: Value,
    /// Hard obstacles left out of the geofence because the path passes over or under them.
    pub unfenced: Vec<String>,
}

/// One `.plan` per vehicle of the plan, in plan order (a vehicle without a trajectory has no
/// mission: [`super::check`] refuses such a plan).
pub fn vehicle_files(input: &ExportInput) -> Vec<VehicleFile> {
    input
        .plan
        .vehicles
        .iter()
        .filter(|v| !v.trajectory.is_empty())
        .map(|v| vehicle_file(input, v))
        .collect()
}

/// How close a vehicle must come to a waypoint to count it reached, metres: a quarter of the
/// fleet's minimum separation (two vehicles each that far off their plans are still half of it
/// apart), at most [`MAX_ACCEPTANCE_RADIUS_M`] (10 m is 7 s at 3 knots, more than the plan's
/// timing can spare); 0 (the autopilot's default) without a separation.
pub fn acceptance_radius_m(d_min_m: f64) -> f64 {
    (d_min_m / 4.0).clamp(0.0, MAX_ACCEPTANCE_RADIUS_M)
}

fn vehicle_file(input: &ExportInput, v: &VehiclePlan) -> VehicleFile {
    let (circles, unfenced) = fence_circles(input, v);
    let polygons: Vec<Value> = input
        .scenario
        .map(|s| {
            // QGC's polygons wind clockwise: south-west, north-west, north-east, south-east.
            let mut corners = footprint(s, s.bounds.max[2]);
            corners.reverse();
            corners.rotate_right(1);
            let polygon: Vec<[f64; 2]> = corners.iter().map(|p| lat_lon(input, *p)).collect();
            json!({"inclusion": true, "polygon": polygon, "version": 1})
        })
        .into_iter()
        .collect();
    let home = geodetic(input, point(&v.trajectory[0]));
    let vehicle_type = match input.kind(&v.id) {
        Some(VehicleKind::Crawler) => MAV_TYPE_GROUND_ROVER,
        _ => MAV_TYPE_SUBMARINE,
    };
    let duration = v.arrival_s - v.trajectory[0][0];
    let mean_speed = if duration > 0.0 && v.length_m > 0.0 {
        v.length_m / duration
    } else {
        v.max_speed_mps
    };
    let json = json!({
        "fileType": "Plan",
        "version": 1,
        "groundStation": "QGroundControl",
        "mission": {
            "version": 2,
            "firmwareType": MAV_AUTOPILOT_PX4,
            "vehicleType": vehicle_type,
            "cruiseSpeed": round(mean_speed, 6),
            "hoverSpeed": round(mean_speed, 6),
            "plannedHomePosition": home,
            "items": items(input, v),
        },
        "geoFence": {"version": 2, "circles": circles, "polygons": polygons},
        "rallyPoints": {"version": 2, "points": []},
    });
    VehicleFile {
        vehicle: v.id.clone(),
        json,
        unfenced,
    }
}

/// The mission items: speed changes and waypoints, `doJumpId` numbered from 1.
fn items(input: &ExportInput, v: &VehiclePlan) -> Vec<Value> {
    let accept = acceptance_radius_m(input.plan.d_min_m);
    let waypoint = |p: [f64; 3], hold_s: f64| {
        let [lat, lon, alt] = geodetic(input, p);
        // Yaw null: the vehicle's choice (QGC writes NaN as null).
        (
            NAV_WAYPOINT,
            FRAME_GLOBAL,
            json!([round(hold_s, 3), accept, 0, null, lat, lon, alt]),
        )
    };
    let mut out = Vec::new();
    let mut commanded: Option<f64> = None;
    for (k, speed) in leg_speeds(v).into_iter().enumerate() {
        let (a, b) = (&v.trajectory[k], &v.trajectory[k + 1]);
        let moves = distance(&point(a), &point(b)) >= 1e-3;
        if let (true, Some(speed)) = (moves, speed.filter(|s| *s > 0.0)) {
            if commanded.is_none_or(|c| (c - speed).abs() > super::SPEED_CHANGE_MPS) {
                // Ground speed (type 1), m/s; throttle −1: unchanged.
                let params = json!([1, round(speed, 6), -1, 0, 0, 0, 0]);
                out.push((DO_CHANGE_SPEED, FRAME_MISSION, params));
                commanded = Some(speed);
            }
        }
        let hold_s = if moves { 0.0 } else { (b[0] - a[0]).max(0.0) };
        out.push(waypoint(point(b), hold_s));
    }
    if out.is_empty() {
        out.push(waypoint(point(&v.trajectory[0]), 0.0));
    }
    out.into_iter()
        .enumerate()
        .map(|(k, (command, frame, params))| {
            json!({
                "type": "SimpleItem",
                "autoContinue": true,
                "command": command,
                "doJumpId": k + 1,
                "frame": frame,
                "params": params,
            })
        })
        .collect()
}

/// Exclusion circles of the hard obstacles the vehicle's path stays out of horizontally, and
/// the ids of those it passes over or under.
fn fence_circles(input: &ExportInput, v: &VehiclePlan) -> (Vec<Value>, Vec<String>) {
    let (mut circles, mut unfenced) = (Vec::new(), Vec::new());
    let Some(s) = input.scenario else {
        return (circles, unfenced);
    };
    for ob in s.hard_obstacles() {
        if crosses(v, ob) {
            unfenced.push(ob.id.clone());
        } else {
            let [lat, lon] = lat_lon(input, ob.centre);
            circles.push(json!({
                "circle": {"center": [lat, lon], "radius": ob.inflated_radius()},
                "inclusion": false,
                "version": 1,
            }));
        }
    }
    (circles, unfenced)
}

/// Whether the path, seen from above, enters the obstacle's inflated circle.
fn crosses(v: &VehiclePlan, ob: &Obstacle) -> bool {
    let points: Vec<Vec3> = v.trajectory.iter().map(|s| Vec3::from(point(s))).collect();
    let centre = [ob.centre[0], ob.centre[1]];
    horizontal_distance_to_path(&points, centre) < ob.inflated_radius()
}

/// `[lat, lon, alt]`, rounded (0.1 mm, 1 mm).
fn geodetic(input: &ExportInput, p: [f64; 3]) -> [f64; 3] {
    let [lat, lon, alt] = input.origin.to_geodetic(p);
    [round(lat, 9), round(lon, 9), round(alt, 3)]
}

/// `[lat, lon]`, rounded.
fn lat_lon(input: &ExportInput, p: [f64; 3]) -> [f64; 2] {
    let [lat, lon, _] = geodetic(input, p);
    [lat, lon]
}
