//! Shoal's records as Foxglove messages: a vehicle report as its pose in the scenario frame and
//! its WGS-84 fix, and the mission's geometry (the bounds box, the obstacles, the planned paths)
//! as one scene.

use shoal_common::execution::VehicleState;
use shoal_common::geo::GeoOrigin;
use shoal_common::scenario::{Bounds, Obstacle, ObstacleKind};
use shoal_common::wire::open::PlanNotice;

use super::channels::FRAME;
use super::schemas::{
    Color, Duration, KeyValuePair, LinePrimitive, LineType, LocationFix, Pose, PoseInFrame,
    Quaternion, SceneEntity, SceneUpdate, SpherePrimitive, Time, Vector3,
};

/// Points a planned path is drawn with at most: a longer one is thinned evenly (its ends kept),
/// so a scene message stays small whatever the plan's sampling.
pub const MAX_PATH_POINTS: usize = 1000;

/// Hard obstacles of the scenario.
const HARD: Color = rgba(0.85, 0.15, 0.15, 0.6);
/// Soft obstacles of the scenario.
const SOFT: Color = rgba(1.0, 0.65, 0.0, 0.4);
/// Obstacles published during the execution, hard or soft.
const PUBLISHED: Color = rgba(0.75, 0.2, 0.9, 0.6);
/// The bounds box.
const BOUNDS: Color = rgba(0.6, 0.6, 0.6, 1.0);
/// One colour per vehicle's path, in the scenario's order (then again from the first).
const PATHS: [Color; 6] = [
    rgba(0.1, 0.5, 0.95, 1.0),
    rgba(0.1, 0.75, 0.3, 1.0),
    rgba(0.95, 0.45, 0.1, 1.0),
    rgba(0.55, 0.3, 0.85, 1.0),
    rgba(0.0, 0.7, 0.7, 1.0),
    rgba(0.85, 0.25, 0.55, 1.0),
];

const fn rgba(r: f64, g: f64, b: f64, a: f64) -> Color {
    Color { r, g, b, a }
}

/// A vehicle's pose: its position fix, turned to its heading (counter-clockwise from east, so
/// a yaw about the scenario's up axis).
pub fn pose(state: &VehicleState, stamp: Time) -> PoseInFrame {
    PoseInFrame {
        timestamp: stamp,
        frame_id: FRAME.into(),
        pose: Pose {
            position: Vector3::from(state.position),
            orientation: Quaternion::yaw(state.heading_deg.to_radians()),
        },
    }
}

/// A vehicle's position fix on WGS-84, through the scenario's origin.
pub fn location(
    vehicle: &str,
    state: &VehicleState,
    origin: &GeoOrigin,
    stamp: Time,
) -> LocationFix {
    let [latitude, longitude, altitude] = origin.to_geodetic(state.position);
    LocationFix {
        timestamp: stamp,
        frame_id: vehicle.into(),
        latitude,
        longitude,
        altitude,
        position_covariance: [0.0; 9],
        position_covariance_type: 0,
    }
}

/// An obstacle as a scene entity (`obstacle/<id>`): its sphere, and its inflated sphere (what
/// the planner keeps out of) faint around it. Published obstacles are coloured apart from the
/// scenario's, and hard ones apart from soft ones.
pub fn obstacle(o: &Obstacle, published: bool, stamp: Time) -> SceneEntity {
    let color = match (published, o.kind) {
        (true, _) => PUBLISHED,
        (false, ObstacleKind::Hard) => HARD,
        (false, ObstacleKind::Soft) => SOFT,
    };
    let sphere = |radius: f64, color: Color| SpherePrimitive {
        pose: Pose {
            position: Vector3::from(o.centre),
            orientation: Quaternion::IDENTITY,
        },
        size: Vector3::from([2.0 * radius; 3]),
        color,
    };
    let kind = match o.kind {
        ObstacleKind::Hard => "hard",
        ObstacleKind::Soft => "soft",
    };
    let note = |key: &str, value: String| KeyValuePair {
        key: key.into(),
        value,
    };
    let mut e = entity(format!("obstacle/{}", o.id), stamp);
    e.metadata = vec![
        note("kind", kind.into()),
        note("published", published.to_string()),
        note("radius_m", o.radius_m.to_string()),
        note("inflation_m", o.inflation_m.to_string()),
    ];
    e.spheres = vec![
        sphere(o.radius_m, color),
        sphere(o.inflated_radius(), Color { a: 0.12, ..color }),
    ];
    e
}

/// The bounds box's twelve edges (`bounds`).
pub fn bounds(b: &Bounds, stamp: Time) -> SceneEntity {
    let corner = |i: usize| {
        let pick = |axis: usize| {
            if (i >> axis) & 1 == 1 {
                b.max[axis]
            } else {
                b.min[axis]
            }
        };
        Vector3::from([pick(0), pick(1), pick(2)])
    };
    // Corners i and j share an edge when they differ in one axis.
    let mut points = Vec::with_capacity(24);
    for i in 0..8usize {
        for axis in 0..3 {
            let j = i | (1 << axis);
            if j != i {
                points.extend([corner(i), corner(j)]);
            }
        }
    }
    let mut e = entity("bounds".into(), stamp);
    e.lines = vec![line(LineType::List, points, BOUNDS)];
    e
}

/// Each vehicle's planned path as a line strip (`path/<vehicle>`), at most
/// [`MAX_PATH_POINTS`] points.
pub fn paths(plan: &PlanNotice, stamp: Time) -> Vec<SceneEntity> {
    plan.trajectories
        .iter()
        .enumerate()
        .map(|(k, (vehicle, samples))| {
            let points = thinned(samples, MAX_PATH_POINTS)
                .map(|s| Vector3::from([s[1], s[2], s[3]]))
                .collect();
            let mut e = entity(format!("path/{vehicle}"), stamp);
            e.metadata = vec![KeyValuePair {
                key: "revision".into(),
                value: plan.revision.to_string(),
            }];
            e.lines = vec![line(LineType::Strip, points, PATHS[k % PATHS.len()])];
            e
        })
        .collect()
}

/// The whole scene: bounds, obstacles (the scenario's, then those published), paths.
pub fn scene(
    b: Option<&Bounds>,
    obstacles: &[(Obstacle, bool)],
    plan: Option<&PlanNotice>,
    stamp: Time,
) -> SceneUpdate {
    let mut entities: Vec<SceneEntity> = b.map(|b| bounds(b, stamp)).into_iter().collect();
    entities.extend(obstacles.iter().map(|(o, p)| obstacle(o, *p, stamp)));
    entities.extend(plan.map(|p| paths(p, stamp)).unwrap_or_default());
    SceneUpdate {
        deletions: Vec::new(),
        entities,
    }
}

/// At most `max` of `samples`, evenly spread, the first and the last always among them.
fn thinned<T>(samples: &[T], max: usize) -> impl Iterator<Item = &T> {
    let n = samples.len();
    let keep = n.min(max.max(2));
    (0..keep).filter_map(move |k| {
        let i = if keep <= 1 {
            0
        } else {
            k * (n - 1) / (keep - 1)
        };
        samples.get(i)
    })
}

fn line(line_type: LineType, points: Vec<Vector3>, color: Color) -> LinePrimitive {
    LinePrimitive {
        line_type,
        pose: Pose {
            position: Vector3::from([0.0; 3]),
            orientation: Quaternion::IDENTITY,
        },
        thickness: 2.0,
        scale_invariant: true,
        points,
        color,
        colors: Vec::new(),
        indices: Vec::new(),
    }
}

fn entity(id: String, stamp: Time) -> SceneEntity {
    SceneEntity {
        timestamp: stamp,
        frame_id: FRAME.into(),
        id,
        lifetime: Duration::default(),
        frame_locked: false,
        metadata: Vec::new(),
        arrows: Vec::new(),
        cubes: Vec::new(),
        spheres: Vec::new(),
        cylinders: Vec::new(),
        lines: Vec::new(),
        triangles: Vec::new(),
        texts: Vec::new(),
        models: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shoal_common::execution::VehicleStatus;

    fn state(position: [f64; 3], heading_deg: f64) -> VehicleState {
        VehicleState {
            t_s: 12.5,
            position,
            velocity: [0.0, 1.5, 0.0],
            heading_deg,
            depth_m: None,
            altitude_m: None,
            battery: 0.9,
            status: VehicleStatus::Underway,
            arrived_s: None,
        }
    }

    const STAMP: Time = Time { sec: 10, nsec: 5 };

    #[test]
    fn a_report_becomes_its_pose_in_the_scenario_frame() -> serde_json::Result<()> {
        // Heading north: a quarter turn counter-clockwise from east.
        let p = pose(&state([100.0, 200.0, -30.0], 90.0), STAMP);
        let json = serde_json::to_value(&p)?;
        assert_eq!(json["frame_id"], "shoal");
        assert_eq!(json["timestamp"], serde_json::json!({"sec": 10, "nsec": 5}));
        assert_eq!(
            json["pose"]["position"],
            serde_json::json!({"x": 100.0, "y": 200.0, "z": -30.0})
        );
        let q = json["pose"]["orientation"].clone();
        let half = std::f64::consts::FRAC_1_SQRT_2;
        assert!((q["z"].as_f64().unwrap_or(0.0) - half).abs() < 1e-12, "{q}");
        assert!((q["w"].as_f64().unwrap_or(0.0) - half).abs() < 1e-12, "{q}");
        Ok(())
    }

    #[test]
    fn a_report_at_the_origin_is_the_origin_on_the_map() {
        let origin = GeoOrigin::new(31.5, -22.0, -2000.0);
        let fix = location("auv1", &state([0.0, 0.0, 2000.0], 0.0), &origin, STAMP);
        assert!((fix.latitude - 31.5).abs() < 1e-12, "{fix:?}");
        assert!((fix.longitude + 22.0).abs() < 1e-12, "{fix:?}");
        assert!(
            fix.altitude.abs() < 1e-9,
            "the surface is at 0 m AMSL: {fix:?}"
        );
        assert_eq!(fix.frame_id, "auv1");
        // 1 km north is about 0.009° of latitude.
        let north = location("auv1", &state([0.0, 1000.0, 0.0], 0.0), &origin, STAMP);
        assert!((north.latitude - 31.5 - 0.00902).abs() < 1e-4, "{north:?}");
    }

    #[test]
    fn an_obstacle_becomes_a_sphere_entity_coloured_by_kind_and_origin() {
        let o = Obstacle {
            id: "HObs#1".into(),
            kind: ObstacleKind::Hard,
            centre: [500.0, 600.0, 700.0],
            radius_m: 100.0,
            inflation_m: 50.0,
        };
        let e = obstacle(&o, false, STAMP);
        assert_eq!(e.id, "obstacle/HObs#1");
        assert_eq!(e.frame_id, "shoal");
        assert_eq!(e.spheres.len(), 2);
        assert_eq!(
            e.spheres[0].pose.position,
            Vector3::from([500.0, 600.0, 700.0])
        );
        assert_eq!(e.spheres[0].size, Vector3::from([200.0; 3]), "a diameter");
        assert_eq!(e.spheres[1].size, Vector3::from([300.0; 3]), "inflated");
        assert_eq!(e.spheres[0].color, HARD);
        let soft = Obstacle {
            kind: ObstacleKind::Soft,
            ..o.clone()
        };
        assert_eq!(obstacle(&soft, false, STAMP).spheres[0].color, SOFT);
        assert_eq!(obstacle(&o, true, STAMP).spheres[0].color, PUBLISHED);
    }

    #[test]
    fn the_bounds_are_twelve_edges_and_paths_stay_short() {
        let b = Bounds {
            min: [0.0; 3],
            max: [10.0, 20.0, 30.0],
        };
        let e = bounds(&b, STAMP);
        let points = &e.lines[0].points;
        assert_eq!(points.len(), 24);
        for pair in points.chunks(2) {
            let d = [
                pair[1].x - pair[0].x,
                pair[1].y - pair[0].y,
                pair[1].z - pair[0].z,
            ];
            assert_eq!(d.iter().filter(|c| **c != 0.0).count(), 1, "{pair:?}");
        }
        let samples: Vec<[f64; 4]> = (0..5000).map(|i| [i as f64, i as f64, 0.0, 0.0]).collect();
        let plan = PlanNotice {
            version: 1,
            mission: "m".into(),
            revision: 2,
            changed: vec![],
            trajectories: vec![("auv1".into(), samples)],
        };
        let path = &paths(&plan, STAMP)[0];
        assert_eq!(path.id, "path/auv1");
        let points = &path.lines[0].points;
        assert_eq!(points.len(), MAX_PATH_POINTS);
        assert_eq!((points[0].x, points[MAX_PATH_POINTS - 1].x), (0.0, 4999.0));
    }
}
