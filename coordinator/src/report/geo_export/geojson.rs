//! A plan as one GeoJSON FeatureCollection (RFC 7946): positions `[longitude, latitude,
//! altitude]` in degrees on WGS-84 and metres above mean sea level (see [`shoal_common::geo`] on
//! why that altitude stands in for the ellipsoidal height RFC 7946 §4 names).
//!
//! Every feature's `feature` property says what it is:
//! - `origin`: a Point at the scenario point (0, 0, 0);
//! - `bounds`: the scenario box's footprint, a Polygon (with a scenario);
//! - `obstacle`: each obstacle's inflated sphere seen from above, a circle at its centre depth,
//!   as a [`super::CIRCLE_VERTICES`]-gon around it (RFC 7946 has no circles; `radius_m` and
//!   `inflated_radius_m` are there for tools that draw circles);
//! - `path`: each vehicle's trajectory, a LineString;
//! - `waypoint`: each timed sample of it, a Point.
//!
//! Polygons follow the right-hand rule (§3.1.6: exterior rings counter-clockwise) and are closed.
//! Geometries crossing the antimeridian are not cut in two as §3.1.9 asks: their longitudes run
//! on past ±180° so that each stays one valid geometry.

use serde_json::{json, Value};

use super::{circle, footprint, leg_speeds, point, round, ExportInput};
use shoal_common::plan::VehiclePlan;
use shoal_common::scenario::{Obstacle, Scenario};

/// `plan.geojson`: origin, bounds and obstacles (with a scenario), then per vehicle its path and
/// its waypoints.
pub fn feature_collection(input: &ExportInput) -> Value {
    let o = input.origin;
    let mut features = vec![feature(
        json!({"type": "Point", "coordinates": position(input, [0.0; 3])}),
        json!({"feature": "origin", "lat_deg": o.lat_deg, "lon_deg": o.lon_deg, "alt_m": o.alt_m}),
    )];
    if let Some(s) = input.scenario {
        features.push(bounds(input, s));
        features.extend(s.obstacles.iter().map(|ob| obstacle(input, ob)));
    }
    for v in &input.plan.vehicles {
        features.extend(path(input, v));
        features.extend(waypoints(input, v));
    }
    json!({"type": "FeatureCollection", "features": features})
}

/// A Feature.
fn feature(geometry: Value, properties: Value) -> Value {
    json!({"type": "Feature", "geometry": geometry, "properties": properties})
}

/// `[lon, lat, alt]` of scenario point `p`; the longitude continues past ±180° rather than jump
/// when the origin is near the antimeridian.
fn position(input: &ExportInput, p: [f64; 3]) -> [f64; 3] {
    let [lat, lon, alt] = input.origin.to_geodetic(p);
    let lon0 = input.origin.lon_deg;
    let lon = if (lon - lon0).abs() > 180.0 {
        lon - 360.0 * (lon - lon0).signum()
    } else {
        lon
    };
    [round(lon, 9), round(lat, 9), round(alt, 3)]
}

/// `[lon, lat]` of a footprint vertex (polygons are outlines seen from above).
fn position_2d(input: &ExportInput, p: [f64; 3]) -> [f64; 2] {
    let [lon, lat, _] = position(input, p);
    [lon, lat]
}

/// A closed ring of `vertices` (counter-clockwise in the scenario's x-east, y-north plane, so
/// counter-clockwise in longitude and latitude too).
fn ring(input: &ExportInput, vertices: &[[f64; 3]]) -> Vec<[f64; 2]> {
    let mut ring: Vec<[f64; 2]> = vertices.iter().map(|p| position_2d(input, *p)).collect();
    if let Some(&first) = ring.first() {
        ring.push(first);
    }
    ring
}

/// The box's footprint at its top; depths of its top and floor.
fn bounds(input: &ExportInput, s: &Scenario) -> Value {
    let b = &s.bounds;
    feature(
        json!({"type": "Polygon", "coordinates": [ring(input, &footprint(s, b.max[2]))]}),
        json!({
            "feature": "bounds",
            "min_m": b.min,
            "max_m": b.max,
            "top_depth_m": round(input.depth_m(b.max[2]), 3),
            "bottom_depth_m": round(input.depth_m(b.min[2]), 3),
        }),
    )
}

/// The horizontal circle through the centre of the obstacle's inflated sphere; depths of its
/// centre, top and bottom (negative: above the sea surface).
fn obstacle(input: &ExportInput, ob: &Obstacle) -> Value {
    let r = ob.inflated_radius();
    let z = ob.centre[2];
    feature(
        json!({"type": "Polygon", "coordinates": [ring(input, &circle(ob.centre, r))]}),
        json!({
            "feature": "obstacle",
            "id": ob.id,
            "kind": ob.kind,
            "radius_m": ob.radius_m,
            "inflation_m": ob.inflation_m,
            "inflated_radius_m": r,
            "polygon_vertices": super::CIRCLE_VERTICES,
            "centre_depth_m": round(input.depth_m(z), 3),
            "top_depth_m": round(input.depth_m(z + r), 3),
            "bottom_depth_m": round(input.depth_m(z - r), 3),
        }),
    )
}

/// The vehicle's path (none for a single sample: a LineString needs two positions).
fn path(input: &ExportInput, v: &VehiclePlan) -> Option<Value> {
    if v.trajectory.len() < 2 {
        return None;
    }
    let line: Vec<[f64; 3]> = v
        .trajectory
        .iter()
        .map(|s| position(input, point(s)))
        .collect();
    Some(feature(
        json!({"type": "LineString", "coordinates": line}),
        json!({
            "feature": "path",
            "vehicle": v.id,
            "kind": input.kind(&v.id),
            "waypoints": v.trajectory.len(),
            "length_m": v.length_m,
            "arrival_s": v.arrival_s,
            "min_speed_mps": v.min_speed_mps,
            "max_speed_mps": v.max_speed_mps,
            "hard_collisions": v.hard_collisions,
            "min_clearance_m": v.min_clearance_m,
        }),
    ))
}

/// One Point per timed sample, with its time, depth and the speed of the leg it starts.
fn waypoints<'a>(input: &'a ExportInput, v: &'a VehiclePlan) -> impl Iterator<Item = Value> + 'a {
    let speeds = leg_speeds(v);
    v.trajectory.iter().enumerate().map(move |(k, s)| {
        feature(
            json!({"type": "Point", "coordinates": position(input, point(s))}),
            json!({
                "feature": "waypoint",
                "vehicle": v.id,
                "index": k,
                "t_s": s[0],
                "depth_m": round(input.depth_m(s[3]), 3),
                "speed_mps": speeds.get(k).copied().flatten(),
            }),
        )
    })
}
