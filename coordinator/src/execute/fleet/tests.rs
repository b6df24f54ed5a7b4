//! Unit tests of `execute::fleet`.

use super::*;
use shoal_common::execution::VehicleState;
use shoal_common::scenario::ObstacleKind;

pub(super) fn straight(y: f64) -> Trajectory {
    Trajectory {
        times: vec![0.0, 100.0],
        points: vec![Vec3::new(0.0, y, 0.0), Vec3::new(100.0, y, 0.0)],
    }
}

/// A point at sea level.
pub(super) fn p(x: f64, y: f64) -> Vec3 {
    Vec3::new(x, y, 0.0)
}

/// East 100 m then north 100 m, at 1 m/s.
pub(super) fn corner() -> Trajectory {
    Trajectory {
        times: vec![0.0, 100.0, 200.0],
        points: vec![p(0.0, 0.0), p(100.0, 0.0), p(100.0, 100.0)],
    }
}

pub(super) fn report(
    vehicle: &str,
    seq: u64,
    t: f64,
    p: [f64; 3],
    status: VehicleStatus,
) -> Telemetry {
    Telemetry {
        version: OPEN_VERSION,
        mission: "m".into(),
        vehicle: vehicle.into(),
        seq,
        revision: 0,
        sent_unix_us: 1_000_000,
        state: VehicleState {
            t_s: t,
            position: p,
            velocity: [1.0, 0.0, 0.0],
            heading_deg: 0.0,
            depth_m: None,
            altitude_m: None,
            battery: 1.0,
            status,
            arrived_s: (status == VehicleStatus::Arrived).then_some(100.0),
        },
        command: None,
    }
}

#[test]
fn between_two_fixes_the_track_follows_the_plan_round_its_corners() {
    // East 100 m then north 100 m at 1 m/s; an obstacle of 10 m inside the corner.
    let plan = corner();
    let ids = vec!["a".to_string()];
    let mut f = Fleet::new(&ids, std::slice::from_ref(&plan), 50.0, 60.0);
    // Fixes 2 m left of the plan at t = 50 and 2 m short of it at t = 150.
    f.report(
        report("a", 0, 50.0, [50.0, 2.0, 0.0], VehicleStatus::Underway),
        1,
    );
    f.report(
        report("a", 1, 150.0, [98.0, 50.0, 0.0], VehicleStatus::Underway),
        2,
    );
    // The corner (100, 0) at plan time 100, halfway: offset (0, 2) + ½ ((−2, 0) − (0, 2)).
    let track = &f.vehicles[0].track;
    assert_eq!(track.times, vec![50.0, 100.0, 150.0]);
    assert!((track.points[1] - p(99.0, 1.0)).norm() < 1e-9, "{track:?}");
    assert_eq!(f.vehicles[0].fixes, 2);
    let cage = Obstacle {
        id: "o".into(),
        kind: ObstacleKind::Hard,
        centre: [75.0, 25.0, 0.0],
        radius_m: 10.0,
        inflation_m: 1.0,
    };
    // Both legs pass the centre at |49·23 + 25| / √2402 = 23.5053 m: 13.5053 m clear. The
    // chord (50, 2)–(98, 50) would pass 1.414 m from the centre, 8.6 m inside.
    let fig = f.figures(200.0, 10.0, std::slice::from_ref(&cage));
    let clearance = fig.vehicles[0].min_obstacle_clearance_m.unwrap_or(f64::NAN);
    assert!((clearance - 13.505_309_691).abs() < 1e-6, "{clearance}");
    assert_eq!(fig.vehicles[0].reports, 2);
    // A fix 10 s later that matches the plan 110 s further on (past the corner) is joined
    // directly: plan time ran more than twice as fast as mission time.
    let mut f = Fleet::new(&ids, std::slice::from_ref(&plan), 50.0, 60.0);
    f.report(
        report("a", 0, 50.0, [50.0, 2.0, 0.0], VehicleStatus::Underway),
        1,
    );
    f.report(
        report("a", 1, 60.0, [100.0, 60.0, 0.0], VehicleStatus::Underway),
        2,
    );
    assert_eq!(f.vehicles[0].track.times, vec![50.0, 60.0]);
    // One on a new revision of the plan follows the new plan's corners, the earlier fix placed
    // on it (a replan keeps the plan up to it: here the same plan).
    let mut f = Fleet::new(&ids, std::slice::from_ref(&plan), 50.0, 60.0);
    f.report(
        report("a", 0, 50.0, [50.0, 2.0, 0.0], VehicleStatus::Underway),
        1,
    );
    f.vehicles[0].revision = 1;
    f.report(
        report("a", 1, 150.0, [98.0, 50.0, 0.0], VehicleStatus::Underway),
        2,
    );
    assert_eq!(f.vehicles[0].track.times, vec![50.0, 100.0, 150.0]);
}

#[test]
fn reports_give_progress_separation_and_figures() {
    let ids = vec!["a".to_string(), "b".to_string()];
    let mut f = Fleet::new(&ids, &[straight(0.0), straight(60.0)], 50.0, 60.0);
    // a is 3 m off its line at x = 50 when the plan has it at x = 50: cross-track 3.
    assert!(f.report(
        report("a", 0, 50.0, [50.0, 3.0, 0.0], VehicleStatus::Underway),
        1_002_000
    ));
    assert!(f.report(
        report("b", 0, 50.0, [50.0, 60.0, 0.0], VehicleStatus::Underway),
        1_001_000
    ));
    // An older report is ignored.
    assert!(!f.report(
        report("a", 0, 40.0, [40.0, 0.0, 0.0], VehicleStatus::Underway),
        1_001_000
    ));
    let p = f.vehicles[0]
        .progress
        .unwrap_or_else(|| panic!("no progress"));
    assert!((p.cross_track_m - 3.0).abs() < 1e-9 && (p.fraction - 0.5).abs() < 1e-9);
    // 57 m apart now (60 − 3).
    assert!((f.live_min_separation - 57.0).abs() < 1e-9);
    let s = f.status("m", 50.0);
    assert!((s.current_min_separation_m.unwrap_or(0.0) - 57.0).abs() < 1e-9);
    assert_eq!(s.current_pair, Some(["a".to_string(), "b".to_string()]));
    f.report(
        report("a", 1, 100.0, [100.0, 0.0, 0.0], VehicleStatus::Arrived),
        1_004_000,
    );
    f.report(
        report("b", 1, 100.0, [100.0, 60.0, 0.0], VehicleStatus::Arrived),
        1_003_000,
    );
    let wall = Obstacle {
        id: "o".into(),
        kind: ObstacleKind::Hard,
        centre: [50.0, 30.0, 0.0],
        radius_m: 10.0,
        inflation_m: 5.0,
    };
    let fig = f.figures(100.0, 10.0, &[wall]);
    // Tracks: a from (50,3) to (100,0), b along y = 60: closest 57 m at t = 50.
    assert!(
        (fig.min_separation_m.unwrap_or(0.0) - 57.0).abs() < 1e-9,
        "{fig:?}"
    );
    assert!(fig.all_arrived_in_window);
    assert_eq!(fig.vehicles[0].arrived_s, Some(100.0));
    // a's track passes (50, 3): 27 m from the centre, 17 m from the surface.
    assert!((fig.vehicles[0].min_obstacle_clearance_m.unwrap_or(0.0) - 17.0).abs() < 1e-9);
    assert!((fig.vehicles[1].min_obstacle_clearance_m.unwrap_or(0.0) - 20.0).abs() < 1e-9);
    // Latencies 2, 1, 4, 3 ms: median 2.5.
    let median = fig.latency_median_ms.unwrap_or(f64::NAN);
    assert!((median - 2.5).abs() < 1e-9, "{fig:?}");
    assert_eq!(fig.reports, 4);
}

#[test]
fn a_vehicle_predicted_into_a_lost_one_is_a_conflict() {
    let ids = vec!["a".to_string(), "b".to_string()];
    let b_plan = Trajectory {
        times: vec![0.0, 100.0],
        points: vec![Vec3::new(100.0, 0.0, 0.0), Vec3::new(100.0, 100.0, 0.0)],
    };
    let mut f = Fleet::new(&ids, &[straight(0.0), b_plan], 50.0, 120.0);
    f.report(
        report("a", 0, 10.0, [10.0, 0.0, 0.0], VehicleStatus::Underway),
        1_000_000,
    );
    f.report(
        report("b", 0, 10.0, [100.0, 10.0, 0.0], VehicleStatus::Underway),
        1_000_000,
    );
    // Both on plan: a reaches (100, 0) at t = 100, b is at (100, 100) by then.
    assert!(f.conflicts(10.0).is_empty());
    // b is lost where it was last seen: a drives into it.
    f.vehicles[1].lost = true;
    let c = f.conflicts(10.0);
    assert_eq!(c.len(), 1);
    assert!((c[0].min_distance_m - 10.0).abs() < 1e-6, "{c:?}");
}

#[test]
fn a_conflict_beyond_the_horizon_is_found_over_a_longer_one() {
    // Head-on along y = 0 at 1 m/s each, 600 m apart at t = 0: they meet at t = 300 s.
    let ids = vec!["a".to_string(), "b".to_string()];
    let west = Trajectory {
        times: vec![0.0, 600.0],
        points: vec![p(600.0, 0.0), p(0.0, 0.0)],
    };
    let east = Trajectory {
        times: vec![0.0, 600.0],
        points: vec![p(0.0, 0.0), p(600.0, 0.0)],
    };
    let f = Fleet::new(&ids, &[east, west], 50.0, 180.0);
    // Within 180 s they close to 600 − 2·180 = 240 m: nothing.
    assert!(f.conflicts(0.0).is_empty());
    assert!(f.conflicts_over(0.0, 180.0).is_empty());
    // Within 455 s they meet, at t = 300.
    let c = f.conflicts_over(0.0, 455.0);
    assert_eq!(c.len(), 1, "{c:?}");
    assert!(c[0].min_distance_m.abs() < 1e-6, "{c:?}");
    assert!((c[0].at_s - 300.0).abs() < 1e-6, "{c:?}");
}

#[test]
fn a_prediction_starts_from_the_fix_carried_forward_to_now() {
    let ids = vec!["a".to_string()];
    let mut f = Fleet::new(&ids, &[straight(0.0)], 50.0, 60.0);
    // On its plan at x = 40 at t = 40; at t = 65 it is predicted at x = 65, not left at 40.
    f.report(
        report("a", 0, 40.0, [40.0, 0.0, 0.0], VehicleStatus::Underway),
        1_000_000,
    );
    let p = &f.predictions_over(65.0, 20.0)[0];
    assert_eq!(p.times.first(), Some(&65.0));
    assert!(
        (p.position_at(65.0) - Vec3::new(65.0, 0.0, 0.0)).norm() < 1e-9,
        "{p:?}"
    );
    assert!(
        (p.position_at(85.0) - Vec3::new(85.0, 0.0, 0.0)).norm() < 1e-9,
        "{p:?}"
    );
}

/// A vehicle whose link reports a fault is predicted to stay where it is, keeps the time its
/// fault began over later fault reports, and is clear of it once a report says otherwise.
#[test]
fn a_faulted_vehicle_stays_put_in_the_picture_until_its_link_recovers() {
    let ids = vec!["a".to_string()];
    let mut f = Fleet::new(&ids, &[straight(0.0)], 50.0, 60.0);
    f.report(
        report("a", 0, 10.0, [10.0, 0.0, 0.0], VehicleStatus::Underway),
        1,
    );
    assert_eq!(f.vehicles[0].fault_s, None);
    f.report(
        report("a", 1, 20.0, [20.0, 0.0, 0.0], VehicleStatus::Fault),
        2,
    );
    f.report(
        report("a", 2, 30.0, [20.0, 0.0, 0.0], VehicleStatus::Fault),
        3,
    );
    assert_eq!(f.vehicles[0].fault_s, Some(20.0));
    let p = &f.predictions(30.0)[0];
    assert!(
        (p.position_at(80.0) - Vec3::new(20.0, 0.0, 0.0)).norm() < 1e-9,
        "{p:?}"
    );
    let figures = f.figures(100.0, 30.0, &[]);
    assert_eq!(figures.vehicles[0].fault_s, Some(20.0));
    f.report(
        report("a", 3, 40.0, [21.0, 0.0, 0.0], VehicleStatus::Underway),
        4,
    );
    assert_eq!(f.vehicles[0].fault_s, None);
}

#[test]
fn an_obstacle_published_mid_run_is_measured_on_the_track_from_then_on() {
    let ids = vec!["a".to_string()];
    let mut f = Fleet::new(&ids, &[straight(0.0)], 50.0, 60.0);
    // a drives along y = 0 and reports at x = 20, 50 and 90; the obstacle (radius 5, centre
    // (30, 0)) is published after the fix at x = 50, when a is already past it.
    f.report(
        report("a", 0, 20.0, [20.0, 0.0, 0.0], VehicleStatus::Underway),
        1_001_000,
    );
    f.report(
        report("a", 1, 50.0, [50.0, 0.0, 0.0], VehicleStatus::Underway),
        1_002_000,
    );
    f.obstacle_published();
    f.report(
        report("a", 2, 90.0, [90.0, 0.0, 0.0], VehicleStatus::Underway),
        1_003_000,
    );
    let rock = Obstacle {
        id: "rock".into(),
        kind: ObstacleKind::Hard,
        centre: [30.0, 0.0, 0.0],
        radius_m: 5.0,
        inflation_m: 0.0,
    };
    let fig = f.figures(100.0, 10.0, std::slice::from_ref(&rock));
    // Measured from the fix at x = 50 (the leg it was on when the rock came): 20 m from the
    // centre, 15 m from the surface. The track before went through it (clearance −5).
    let c = fig.vehicles[0].min_obstacle_clearance_m.unwrap_or(f64::NAN);
    assert!((c - 15.0).abs() < 1e-9, "{c}");
    // The same rock as one of the scenario's own (no publication noted) counts all the way.
    let mut g = f.clone();
    g.published.clear();
    let fig = g.figures(100.0, 10.0, std::slice::from_ref(&rock));
    let c = fig.vehicles[0].min_obstacle_clearance_m.unwrap_or(f64::NAN);
    assert!((c + 5.0).abs() < 1e-9, "{c}");
}

#[test]
fn a_fix_on_the_way_back_by_the_same_point_is_placed_on_the_way_back() {
    // East 100 m along y = 0, 3 m north, back west along y = 3, at 1 m/s: the way out and the
    // way back pass every point 3 m apart, both well inside the 300 s search window.
    let plan = Trajectory {
        times: vec![0.0, 100.0, 103.0, 203.0],
        points: vec![p(0.0, 0.0), p(100.0, 0.0), p(100.0, 3.0), p(0.0, 3.0)],
    };
    let ids = vec!["a".to_string()];
    let mut f = Fleet::new(&ids, std::slice::from_ref(&plan), 50.0, 60.0);
    f.report(
        report("a", 0, 60.0, [60.0, 0.5, 0.0], VehicleStatus::Underway),
        1,
    );
    // On its way back, 2 m south of it at x = 53: 1 m from the way out (plan time 53), 2 m
    // from the way back (150), where the first fix carried on for 90 s has it.
    f.report(
        report("a", 1, 150.0, [53.0, 1.0, 0.0], VehicleStatus::Underway),
        1,
    );
    let v = &f.vehicles[0];
    let pr = v.progress.unwrap_or_else(|| panic!("no progress"));
    assert!((pr.plan_time_s - 150.0).abs() < 1e-9, "{pr:?}");
    assert!((pr.cross_track_m - 2.0).abs() < 1e-9, "{pr:?}");
    // So the track goes round the end at x = 100 instead of a chord from x = 60 back to 53.
    let east = v.track.points.iter().map(|q| q.x).fold(f64::MIN, f64::max);
    assert!((east - 100.0).abs() < 1e-9, "{:?}", v.track.points);
    assert_eq!(v.track.points.len(), 4);
    // Its prediction goes on west along the way back.
    let ahead = f.predictions_over(150.0, 10.0)[0].position_at(160.0);
    assert!(ahead.x < 53.0, "{ahead:?}");
    // Replanned since (the new plan keeps the old one up to the replan): the fix is found
    // afresh on the new plan, and still on the way back.
    f.vehicles[0].revision = 1;
    let again = f.vehicles[0]
        .fix_progress()
        .unwrap_or_else(|| panic!("no fix"));
    assert!((again.plan_time_s - 150.0).abs() < 1e-9, "{again:?}");
}
