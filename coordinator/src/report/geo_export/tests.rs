//! The exports of a two-vehicle toy plan at the equator, against values computed by hand.
//!
//! Origin 0°N 0°E at sea level, z = 0 the surface. East of it along the equator the ellipsoid's
//! section is a circle of radius a = 6 378 137 m, so the scenario point (x, 0, z) — the tangent
//! plane's point (x, 0, 0) on the Earth, at altitude z — is at longitude atan2(x, a) and
//! altitude z exactly. Northwards the meridian's radius of
//! curvature at the equator is a(1 − e²) = 6 335 439.327 m: y metres north is latitude
//! y / 6 335 439.327 rad, to a micrometre over these distances.

use std::path::Path;

use serde_json::Value;
use shoal_common::geo::GeoOrigin;
use shoal_common::geometry::Vec3;
use shoal_common::plan::{assess, Plan};
use shoal_common::scenario::Scenario;
use shoal_common::trajectory::Trajectory;

use super::*;

const A: f64 = 6_378_137.0;
const MERIDIAN_RADIUS: f64 = 6_335_439.327;

/// Longitude (°) and altitude (m) of the scenario point (x, 0, z).
fn east(x: f64, z: f64) -> (f64, f64) {
    (x.atan2(A).to_degrees(), z)
}

/// Latitude (°) of y metres north.
fn north(y: f64) -> f64 {
    (y / MERIDIAN_RADIUS).to_degrees()
}

const SCENARIO: &str = r#"
name = "toy"
[bounds]
min = [0.0, 0.0, -100.0]
max = [1000.0, 1000.0, 0.0]
[origin]
lat_deg = 0.0
lon_deg = 0.0
alt_m = 0.0
[[obstacles]]
id = "H"
kind = "hard"
centre = [500.0, 500.0, -50.0]
radius_m = 20.0
inflation_m = 10.0
[[obstacles]]
id = "S"
kind = "soft"
centre = [200.0, 800.0, -50.0]
radius_m = 40.0
inflation_m = 10.0
[[vehicles]]
id = "a"
kind = "auv"
start = [0.0, 0.0, -10.0]
goal = [300.0, 0.0, -10.0]
speed_min_mps = 0.5
speed_max_mps = 2.0
max_turn_deg = 35.0
max_pitch_deg = 20.0
[[vehicles]]
id = "b"
kind = "auv"
start = [0.0, 500.0, -90.0]
goal = [1000.0, 500.0, -90.0]
speed_min_mps = 0.5
speed_max_mps = 2.0
max_turn_deg = 35.0
max_pitch_deg = 20.0
[fleet]
d_min_m = 20.0
mission_time_s = 500.0
"#;

/// `a` runs east along the equator at 1 m/s, waits 100 s, then goes on at 2 m/s; `b` runs
/// east 500 m north of it at 2 m/s, under the hard obstacle `H`.
fn toy() -> Result<(Scenario, Plan), Box<dyn std::error::Error>> {
    let s = Scenario::parse(SCENARIO, Path::new("toy.toml"))?;
    let t = |samples: &[[f64; 4]]| Trajectory {
        times: samples.iter().map(|p| p[0]).collect(),
        points: samples
            .iter()
            .map(|p| Vec3::new(p[1], p[2], p[3]))
            .collect(),
    };
    let a = [
        [0.0, 0.0, 0.0, -10.0],
        [100.0, 100.0, 0.0, -10.0],
        [200.0, 100.0, 0.0, -10.0],
        [300.0, 300.0, 0.0, -10.0],
    ];
    let b = [[0.0, 0.0, 500.0, -90.0], [500.0, 1000.0, 500.0, -90.0]];
    let assessed = assess(&s, &[t(&a), t(&b)]);
    let plan = Plan {
        scenario: s.name.clone(),
        algorithm: "amp-pso".into(),
        mode: "in-process".into(),
        seed: 1,
        runtime_s: 0.0,
        fitness: 0.0,
        objective: 0.0,
        penalty: 0.0,
        feasible: assessed.violations.is_empty(),
        violations: assessed.violations,
        notices: vec![],
        mission_time_s: 500.0,
        common_arrival_s: 500.0,
        d_min_m: 20.0,
        iterations: 0,
        evaluations: 0,
        termination: "MaxIterations".into(),
        vehicles: assessed.vehicles,
        fleet: assessed.fleet,
        convergence: vec![],
        distributed: None,
        origin: s.origin,
    };
    Ok((s, plan))
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or(f64::NAN)
}

/// Twice the signed area of a ring of `[x, y, …]` positions (positive: counter-clockwise).
fn signed_area(ring: &[Value]) -> f64 {
    ring.windows(2)
        .map(|w| num(&w[0][0]) * num(&w[1][1]) - num(&w[1][0]) * num(&w[0][1]))
        .sum()
}

#[test]
fn origins_come_from_anywhere_but_must_agree() {
    let (p, q) = (GeoOrigin::new(1.0, 2.0, 3.0), GeoOrigin::new(1.0, 2.0, 4.0));
    assert_eq!(resolve_origin(Some(p), None, None), Ok(p));
    assert_eq!(resolve_origin(None, None, Some(q)), Ok(q));
    assert_eq!(resolve_origin(Some(p), Some(p), Some(p)), Ok(p));
    let e = resolve_origin(None, None, None)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        e.starts_with("no origin:") && e.contains("--origin LAT,LON,ALT"),
        "{e}"
    );
    let e = resolve_origin(None, Some(p), Some(q))
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        e.starts_with("the scenario's [origin] 1,2,3 and --origin 1,2,4 differ"),
        "{e}"
    );
    let e = resolve_origin(Some(q), Some(p), None)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        e.starts_with("plan.json's origin 1,2,4 and the scenario's [origin] 1,2,3"),
        "{e}"
    );
}

#[test]
fn a_plan_goes_out_with_its_own_scenario_and_file_safe_ids(
) -> Result<(), Box<dyn std::error::Error>> {
    let (s, mut plan) = toy()?;
    assert_eq!(check(&plan, Some(&s)), Ok(()));
    let mut other = s.clone();
    other.name = "other".into();
    let e = check(&plan, Some(&other))
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert_eq!(e, "the plan was made for scenario \"toy\", not \"other\"");
    other = s.clone();
    other.vehicles.truncate(1);
    let e = check(&plan, Some(&other))
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert_eq!(e, "vehicle b is not in scenario \"toy\"");
    plan.vehicles[1].id = "../b".into();
    let e = check(&plan, None)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        e.contains("../b") && e.contains("a vehicle id must be"),
        "{e}"
    );
    Ok(())
}

#[test]
fn geojson_has_paths_timed_waypoints_circles_and_bounds_where_computed_by_hand(
) -> Result<(), Box<dyn std::error::Error>> {
    let (s, plan) = toy()?;
    let origin = GeoOrigin::new(0.0, 0.0, 0.0);
    let fc = geojson::feature_collection(&ExportInput {
        plan: &plan,
        origin,
        scenario: Some(&s),
    });
    assert_eq!(fc["type"], "FeatureCollection");
    let Some(features) = fc["features"].as_array() else {
        panic!("no features: {fc}");
    };
    let kinds: Vec<&str> = features
        .iter()
        .filter_map(|f| f["properties"]["feature"].as_str())
        .collect();
    let mut expected = vec!["origin", "bounds", "obstacle", "obstacle", "path"];
    expected.extend(["waypoint"; 4]);
    expected.extend(["path", "waypoint", "waypoint"]);
    assert_eq!(kinds, expected);
    assert_eq!(
        features[0]["geometry"]["coordinates"],
        serde_json::json!([0.0, 0.0, 0.0])
    );

    let bounds = &features[1];
    let ring = bounds["geometry"]["coordinates"][0]
        .as_array()
        .cloned()
        .unwrap_or_default();
    assert_eq!(
        (
            ring.len(),
            ring.first(),
            bounds["properties"]["bottom_depth_m"].as_f64()
        ),
        (5, ring.last(), Some(100.0))
    );
    let (lon_1000, _) = east(1000.0, 0.0);
    assert!(
        (num(&ring[2][0]) - lon_1000).abs() < 1e-7
            && (num(&ring[2][1]) - north(1000.0)).abs() < 1e-7,
        "{ring:?}"
    );
    assert!(signed_area(&ring) > 0.0, "bounds ring is clockwise");

    let h = &features[2];
    let p = &h["properties"];
    assert_eq!(
        (
            p["id"].as_str(),
            p["kind"].as_str(),
            num(&p["inflated_radius_m"])
        ),
        (Some("H"), Some("hard"), 30.0)
    );
    assert_eq!(
        (
            num(&p["centre_depth_m"]),
            num(&p["top_depth_m"]),
            num(&p["bottom_depth_m"])
        ),
        (50.0, 20.0, 80.0)
    );
    let ring = h["geometry"]["coordinates"][0]
        .as_array()
        .cloned()
        .unwrap_or_default();
    assert_eq!(
        (ring.len(), ring.first()),
        (CIRCLE_VERTICES + 1, ring.last())
    );
    assert!(signed_area(&ring) > 0.0, "obstacle ring is clockwise");
    // The first vertex is due east of the centre, 30 / cos(π/64) m out.
    let out = 30.0 / (std::f64::consts::PI / 64.0).cos();
    let lon = num(&ring[0][0]).to_radians() * A;
    assert!(
        (lon - (500.0 + out)).abs() < 0.01 && (num(&ring[0][1]) - north(500.0)).abs() < 1e-7,
        "{:?}",
        ring[0]
    );

    let path = &features[4];
    assert_eq!(path["geometry"]["type"], "LineString");
    assert_eq!(
        (
            path["properties"]["vehicle"].as_str(),
            path["properties"]["kind"].as_str()
        ),
        (Some("a"), Some("auv"))
    );
    assert_eq!(num(&path["properties"]["length_m"]), 300.0);
    let last = &path["geometry"]["coordinates"][3];
    let (lon, alt) = east(300.0, -10.0);
    assert!(
        (num(&last[0]) - lon).abs() < 1e-9
            && num(&last[1]).abs() < 1e-9
            && (num(&last[2]) - alt).abs() < 1e-3,
        "{last}"
    );
    let speeds: Vec<Option<f64>> = features[5..9]
        .iter()
        .map(|f| f["properties"]["speed_mps"].as_f64())
        .collect();
    assert_eq!(speeds, [Some(1.0), Some(0.0), Some(2.0), None]);
    let w = &features[7]["properties"];
    assert_eq!(
        (num(&w["index"]), num(&w["t_s"]), num(&w["depth_m"])),
        (2.0, 200.0, 10.0)
    );
    let b_start = &features[10]["geometry"]["coordinates"];
    assert!(
        (num(&b_start[1]) - north(500.0)).abs() < 1e-7 && num(&b_start[0]).abs() < 1e-12,
        "{b_start}"
    );
    Ok(())
}

#[test]
fn without_a_scenario_geojson_has_the_paths_only() -> Result<(), Box<dyn std::error::Error>> {
    let (_, plan) = toy()?;
    let origin = GeoOrigin::new(0.0, 0.0, 0.0);
    let fc = geojson::feature_collection(&ExportInput {
        plan: &plan,
        origin,
        scenario: None,
    });
    let features = fc["features"].as_array().cloned().unwrap_or_default();
    assert_eq!(features.len(), 1 + 5 + 3);
    assert_eq!(features[1]["properties"]["kind"], Value::Null);
    Ok(())
}

#[test]
fn qgc_missions_change_speed_wait_and_fence_what_the_path_keeps_out_of(
) -> Result<(), Box<dyn std::error::Error>> {
    let (s, plan) = toy()?;
    let origin = GeoOrigin::new(0.0, 0.0, 0.0);
    let files = qgc::vehicle_files(&ExportInput {
        plan: &plan,
        origin,
        scenario: Some(&s),
    });
    assert_eq!(
        files.iter().map(|f| f.vehicle.as_str()).collect::<Vec<_>>(),
        ["a", "b"]
    );
    let a = &files[0].json;
    assert_eq!(
        (
            a["fileType"].as_str(),
            a["version"].as_u64(),
            a["groundStation"].as_str()
        ),
        (Some("Plan"), Some(1), Some("QGroundControl"))
    );
    let m = &a["mission"];
    assert_eq!(
        (
            m["version"].as_u64(),
            m["vehicleType"].as_u64(),
            m["firmwareType"].as_u64()
        ),
        (Some(2), Some(12), Some(12))
    );
    assert_eq!((num(&m["cruiseSpeed"]), num(&m["hoverSpeed"])), (1.0, 1.0)); // 300 m in 300 s
    let (_, alt) = east(0.0, -10.0);
    assert_eq!(
        m["plannedHomePosition"],
        serde_json::json!([0.0, 0.0, (alt * 1000.0).round() / 1000.0])
    );
    let items = m["items"].as_array().cloned().unwrap_or_default();
    let shape: Vec<(u64, u64, u64)> = items
        .iter()
        .map(|i| {
            (
                i["command"].as_u64().unwrap_or(0),
                i["frame"].as_u64().unwrap_or(9),
                i["doJumpId"].as_u64().unwrap_or(0),
            )
        })
        .collect();
    assert_eq!(
        shape,
        [(178, 2, 1), (16, 0, 2), (16, 0, 3), (178, 2, 4), (16, 0, 5)]
    );
    assert_eq!(
        items[0]["params"],
        serde_json::json!([1, 1.0, -1, 0, 0, 0, 0])
    );
    assert_eq!(num(&items[3]["params"][1]), 2.0);
    // Hold 0 s then 100 s at the same place; acceptance radius d_min / 4 = 5 m; yaw null.
    let wait = &items[2]["params"];
    assert_eq!(
        (
            num(&items[1]["params"][0]),
            num(&wait[0]),
            num(&wait[1]),
            &wait[3]
        ),
        (0.0, 100.0, 5.0, &Value::Null)
    );
    let (lon, alt) = east(300.0, -10.0);
    let end = &items[4]["params"];
    assert!(
        num(&end[4]).abs() < 1e-9
            && (num(&end[5]) - lon).abs() < 1e-9
            && (num(&end[6]) - alt).abs() < 1e-3,
        "{end}"
    );
    assert!(items
        .iter()
        .all(|i| i["type"] == "SimpleItem" && i["autoContinue"] == true));

    // a keeps clear of H and is fenced from it; b passes under it and is not.
    let fence = &a["geoFence"];
    assert_eq!(fence["version"].as_u64(), Some(2));
    let circle = &fence["circles"][0];
    assert_eq!(
        (
            circle["inclusion"].as_bool(),
            num(&circle["circle"]["radius"]),
            circle["version"].as_u64()
        ),
        (Some(false), 30.0, Some(1))
    );
    let centre = &circle["circle"]["center"];
    assert!(
        (num(&centre[0]) - north(500.0)).abs() < 1e-7
            && (num(&centre[1]) - east(500.0, -50.0).0).abs() < 1e-7,
        "{centre}"
    );
    assert!(files[0].unfenced.is_empty());
    assert_eq!(
        (
            files[1].unfenced.clone(),
            files[1].json["geoFence"]["circles"]
                .as_array()
                .map(Vec::len)
        ),
        (vec!["H".to_string()], Some(0))
    );
    // The box as an inclusion polygon of [lat, lon], clockwise (QGC's winding), not closed.
    let polygon = fence["polygons"][0]["polygon"]
        .as_array()
        .cloned()
        .unwrap_or_default();
    assert_eq!(
        (fence["polygons"][0]["inclusion"].as_bool(), polygon.len()),
        (Some(true), 4)
    );
    let lon_lat: Vec<Value> = polygon
        .iter()
        .map(|p| serde_json::json!([p[1], p[0]]))
        .chain(polygon.first().map(|p| serde_json::json!([p[1], p[0]])))
        .collect();
    assert!(signed_area(&lon_lat) < 0.0, "{polygon:?}");
    assert_eq!(polygon[0], serde_json::json!([0.0, 0.0]));
    assert_eq!(
        a["rallyPoints"],
        serde_json::json!({"version": 2, "points": []})
    );
    Ok(())
}

#[test]
fn without_a_scenario_a_qgc_plan_has_no_fence() -> Result<(), Box<dyn std::error::Error>> {
    let (_, plan) = toy()?;
    let origin = GeoOrigin::new(0.0, 0.0, 0.0);
    let files = qgc::vehicle_files(&ExportInput {
        plan: &plan,
        origin,
        scenario: None,
    });
    let fence = &files[1].json["geoFence"];
    assert_eq!(
        (
            fence["circles"].as_array().map(Vec::len),
            fence["polygons"].as_array().map(Vec::len)
        ),
        (Some(0), Some(0))
    );
    assert_eq!(
        files[1].json["mission"]["items"].as_array().map(Vec::len),
        Some(2)
    );
    Ok(())
}
