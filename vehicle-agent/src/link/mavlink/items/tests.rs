use super::*;
use mavlink::dialects::common::MavMissionType;
use shoal_common::geometry::Vec3;

use MavCmd::{MAV_CMD_DO_CHANGE_SPEED as SPEED, MAV_CMD_NAV_WAYPOINT as WP};

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

const ORIGIN: GeoOrigin = GeoOrigin::new(43.0, 5.0, 0.0);

/// 150 m east in 100 s; 200 m north and 20 m down in 200 s; 30 m straight down in 60 s.
fn plan() -> Trajectory {
    let points = [
        [0.0, 0.0, -10.0],
        [150.0, 0.0, -10.0],
        [150.0, 200.0, -30.0],
        [150.0, 200.0, -60.0],
    ];
    Trajectory {
        times: vec![0.0, 100.0, 300.0, 360.0],
        points: points.map(Vec3::from).to_vec(),
    }
}

#[test]
fn each_leg_is_its_horizontal_speed_then_its_waypoint() {
    let m = mission_items(&plan(), &ORIGIN, None, (7, 1), (Profile::Generic, 0.0));
    let commands: Vec<_> = m.items.iter().map(|i| i.command).collect();
    assert_eq!(commands, [SPEED, WP, SPEED, WP, SPEED, WP]);
    assert_eq!((m.first, m.last()), (0, 5));
    // 150 m in 100 s, ground speed.
    assert_eq!(m.items[0].param1, 1.0);
    assert!(close(f64::from(m.items[0].param2), 1.5, 1e-6));
    // 200 m across in 200 s: 1.0 m/s ground speed, not the 3-D 1.00499 m/s.
    assert_eq!(m.items[2].param1, 1.0);
    assert!(close(f64::from(m.items[2].param2), 1.0, 1e-6));
    // Straight down 30 m in 60 s: descent (type 3) at 0.5 m/s.
    assert_eq!(m.items[4].param1, 3.0);
    assert!(close(f64::from(m.items[4].param2), 0.5, 1e-6));
    let e7 = |v: i32| f64::from(v) / 1e7;
    for (i, p) in [(1, [150.0, 0.0, -10.0]), (3, [150.0, 200.0, -30.0])] {
        let it = &m.items[i];
        let q = ORIGIN.to_local(e7(it.x), e7(it.y), f64::from(it.z));
        assert!((0..3).all(|j| close(p[j], q[j], 0.02)), "item {i}: {q:?}");
    }
    for (s, i) in m.items.iter().enumerate() {
        let ids = (i.target_system, i.target_component);
        assert_eq!(
            (usize::from(i.seq), i.current, i.autocontinue, ids),
            (s, u8::from(s == 0), 1, (7, 1))
        );
    }
}

#[test]
fn a_replan_keeps_only_the_legs_still_ahead() {
    let all = mission_items(&plan(), &ORIGIN, None, (7, 1), (Profile::Generic, 0.0));
    let later = mission_items(
        &plan(),
        &ORIGIN,
        Some(150.0),
        (7, 1),
        (Profile::Generic, 0.0),
    );
    assert_eq!(later.items.len(), 4);
    let (a, b) = (&later.items[0], &later.items[1]);
    assert_eq!((a.seq, a.current, a.command), (0, 1, SPEED));
    assert_eq!(
        (b.x, b.y, b.z),
        (all.items[3].x, all.items[3].y, all.items[3].z)
    );
}

#[test]
fn ardupilot_gets_a_home_placeholder_and_the_first_speed_at_item_one() {
    let ardusub = Profile::ArduPilot(MavType::MAV_TYPE_SUBMARINE);
    let m = mission_items(&plan(), &ORIGIN, None, (1, 1), (ardusub, 0.0));
    let generic = mission_items(&plan(), &ORIGIN, None, (1, 1), (Profile::Generic, 0.0));
    assert_eq!(m.items.len(), generic.items.len() + 1);
    assert_eq!(
        (m.first, m.items[0].command, m.items[0].current),
        (1, WP, 0)
    );
    // Item 1 is the first leg's speed, marked current: overwriting item 0 loses nothing.
    assert_eq!((m.items[1].command, m.items[1].current), (SPEED, 1));
    assert!(close(f64::from(m.items[1].param2), 1.5, 1e-6));
    // Relative to home (ArduSub refuses AMSL waypoints), at the AMSL altitudes less home's.
    #[allow(deprecated)]
    let (relative, amsl) = (
        MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
        MavFrame::MAV_FRAME_GLOBAL_INT,
    );
    let high_home = mission_items(&plan(), &ORIGIN, None, (1, 1), (ardusub, 5.0));
    assert_eq!(
        (high_home.items[2].frame, high_home.items[2].z),
        (relative, -15.0)
    );
    assert_eq!((generic.items[1].frame, generic.items[1].z), (amsl, -10.0));
    assert!(m
        .items
        .iter()
        .enumerate()
        .all(|(s, i)| usize::from(i.seq) == s));
}

#[test]
fn the_hold_ladder_follows_the_autopilot() {
    use MavCmd::{MAV_CMD_DO_PAUSE_CONTINUE as PAUSE, MAV_CMD_DO_SET_MODE as MODE};
    let steps = |p: Profile| -> Vec<(MavCmd, [f32; 3])> {
        let s = p.hold_steps();
        s.iter()
            .map(|s| (s.command, [s.params[0], s.params[1], s.params[2]]))
            .collect()
    };
    assert_eq!(steps(Profile::Generic), [(PAUSE, [0.0; 3])]);
    assert_eq!(steps(Profile::Px4), [(MODE, [1.0, 4.0, 3.0])]);
    let sub = Profile::ArduPilot(MavType::MAV_TYPE_SUBMARINE);
    assert_eq!(steps(sub), [(PAUSE, [0.0; 3]), (MODE, [1.0, 16.0, 0.0])]);
    let boat = Profile::ArduPilot(MavType::MAV_TYPE_SURFACE_BOAT);
    assert_eq!(steps(boat)[1], (MODE, [1.0, 4.0, 0.0]));
    let ardu = MavAutopilot::MAV_AUTOPILOT_ARDUPILOTMEGA;
    assert_eq!(
        Profile::from_heartbeat(ardu, MavType::MAV_TYPE_SUBMARINE),
        sub
    );
    let px4 = MavAutopilot::MAV_AUTOPILOT_PX4;
    assert_eq!(
        Profile::from_heartbeat(px4, MavType::MAV_TYPE_SUBMARINE),
        Profile::Px4
    );
    let generic = MavAutopilot::MAV_AUTOPILOT_GENERIC;
    assert_eq!(
        Profile::from_heartbeat(generic, MavType::MAV_TYPE_SUBMARINE),
        Profile::Generic
    );
}

#[test]
fn the_fallback_is_one_long_hold_where_the_vehicle_is() {
    let m = fallback_items([43.01, 5.02, -25.0], (1, 1), (Profile::Generic, 0.0));
    assert_eq!((m.items.len(), m.first), (1, 0));
    let wp = &m.items[0];
    assert_eq!(
        (wp.command, wp.x, wp.y, wp.z),
        (WP, 430_100_000, 50_200_000, -25.0)
    );
    assert_eq!(wp.param1, FALLBACK_HOLD_S);
    // ArduSub: behind home's placeholder, relative to a home 2 m above sea level.
    let ardusub = Profile::ArduPilot(MavType::MAV_TYPE_SUBMARINE);
    let sub = fallback_items([43.01, 5.02, -25.0], (1, 1), (ardusub, 2.0));
    assert_eq!(
        (sub.items.len(), sub.first, sub.items[1].param1),
        (2, 1, FALLBACK_HOLD_S)
    );
    #[allow(deprecated)]
    let relative = MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT_INT;
    assert_eq!((sub.items[1].frame, sub.items[1].z), (relative, -27.0));
}

fn obstacle(id: &str, kind: ObstacleKind, centre: [f64; 3], radius_m: f64) -> Obstacle {
    Obstacle {
        id: id.into(),
        kind,
        centre,
        radius_m,
        inflation_m: 10.0,
    }
}

#[test]
fn the_fence_is_the_bounds_and_the_hard_obstacles_the_plan_keeps_clear_of_sideways() {
    let bounds = Bounds {
        min: [-100.0, -100.0, -200.0],
        max: [400.0, 400.0, 0.0],
    };
    let obstacles = [
        // Beside the first leg (y = 0): 60 m off it, radius 40: fenced.
        obstacle("beside", ObstacleKind::Hard, [75.0, 60.0, -10.0], 40.0),
        // Below the second leg's path in plan view: the plan passes over it, not fenced.
        obstacle("under", ObstacleKind::Hard, [150.0, 100.0, -150.0], 20.0),
        // Soft: never fenced.
        obstacle("soft", ObstacleKind::Soft, [300.0, 300.0, -10.0], 20.0),
    ];
    let items = fence_items(&bounds, &obstacles, &plan(), &ORIGIN, (1, 1));
    use MavCmd::{
        MAV_CMD_NAV_FENCE_CIRCLE_EXCLUSION as CIRCLE,
        MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION as VERTEX,
    };
    let commands: Vec<_> = items.iter().map(|i| i.command).collect();
    assert_eq!(commands, [VERTEX, VERTEX, VERTEX, VERTEX, CIRCLE]);
    assert!(items[..4].iter().all(|i| i.param1 == 4.0));
    assert_eq!(items[4].param1, 40.0); // the physical radius
    let e7 = |v: i32| f64::from(v) / 1e7;
    let corner = ORIGIN.to_local(e7(items[2].x), e7(items[2].y), 0.0);
    assert!(
        close(corner[0], 400.0, 0.02) && close(corner[1], 400.0, 0.02),
        "{corner:?}"
    );
    let centre = ORIGIN.to_local(e7(items[4].x), e7(items[4].y), 0.0);
    assert!(
        close(centre[0], 75.0, 0.02) && close(centre[1], 60.0, 0.02),
        "{centre:?}"
    );
    assert!(items
        .iter()
        .enumerate()
        .all(|(s, i)| usize::from(i.seq) == s
            && i.mission_type == MavMissionType::MAV_MISSION_TYPE_FENCE));
}
