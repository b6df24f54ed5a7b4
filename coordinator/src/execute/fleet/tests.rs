//! Unit tests of `execute::fleet`.

use super::*;
use shoal_common::execution::VehicleState;
use shoal_common::scenario::ObstacleKind;

fn straight(y: f64) -> Trajectory {
    Trajectory {
        times: vec![0.0, 100.0],
        points: vec![Vec3::new(0.0, y, 0.0), Vec3::new(100.0, y, 0.0)],
    }
}

/// A point at sea level.
fn p(x: f64, y: f64) -> Vec3 {
    Vec3::new(x, y, 0.0)
}

/// East 100 m then north 100 m, at 1 m/s.
fn corner() -> Trajectory {
    Trajectory {
        times: vec![0.0, 100.0, 200.0],
        points: vec![p(0.0, 0.0), p(100.0, 0.0), p(100.0, 100.0)],
    }
}

fn report(vehicle: &str, seq: u64, t: f64, p: [f64; 3], status: VehicleStatus) -> Telemetry {
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

/// A vehicle that stopped at x = 30 m (plan time 30 s) is found there on its plan long after
/// its plan went on: the plan time of where it stopped, not of now. Under way, there is none.
#[test]
fn a_holding_vehicle_resumes_from_where_it_stopped_on_its_plan() {
    // A sample every 100 m: searched around now (t = 900 s), the nearest would be x = 600 m.
    let plan = Trajectory {
        times: (0..=10).map(|k| 100.0 * k as f64).collect(),
        points: (0..=10)
            .map(|k| Vec3::new(100.0 * k as f64, 0.0, 0.0))
            .collect(),
    };
    let ids = vec!["a".to_string()];
    let mut f = Fleet::new(&ids, std::slice::from_ref(&plan), 50.0, 60.0);
    f.report(
        report("a", 0, 30.0, [30.0, 1.0, 0.0], VehicleStatus::Underway),
        1,
    );
    assert_eq!(f.vehicles[0].resume_s(), None);
    f.vehicles[0].holding = true;
    f.vehicles[0].held_since_s = Some(32.0);
    f.report(
        report("a", 1, 900.0, [30.5, 1.0, 0.0], VehicleStatus::Holding),
        2,
    );
    let resume = f.vehicles[0].resume_s().unwrap_or(f64::NAN);
    assert!((resume - 30.5).abs() < 1e-9, "{resume}");
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
fn a_holding_vehicles_fixes_are_joined_directly_not_along_its_plan() {
    // Out along y = 0 to (100, 0), up to (100, 20), back to (0, 20) and down to (0, 2).
    let plan = Trajectory {
        times: vec![0.0, 100.0, 120.0, 220.0, 238.0],
        points: vec![
            p(0.0, 0.0),
            p(100.0, 0.0),
            p(100.0, 20.0),
            p(0.0, 20.0),
            p(0.0, 2.0),
        ],
    };
    let ids = vec!["a".to_string()];
    let track_of = |holding: bool| {
        let mut f = Fleet::new(&ids, std::slice::from_ref(&plan), 50.0, 60.0);
        f.report(
            report("a", 0, 2.0, [2.0, 0.0, 0.0], VehicleStatus::Underway),
            1_001_000,
        );
        let status = if holding {
            f.vehicles[0].holding = true;
            VehicleStatus::Holding
        } else {
            VehicleStatus::Underway
        };
        // At t = 236 s it reports (1, 3): 1 m from the plan's last leg (at plan time 237 s),
        // 3 m from its first. Under way, it would have driven the loop in between.
        f.report(report("a", 1, 236.0, [1.0, 3.0, 0.0], status), 1_002_000);
        f.vehicles[0].track.clone()
    };
    // Held, it stopped where it was at its first fix (the plan first comes within 3 m of
    // (1, 3) there): it stands, never out along the loop.
    let held = track_of(true);
    assert!(held.points.iter().all(|q| q.x <= 2.0 + 1e-9), "{held:?}");
    assert!((held.points[held.points.len() - 1] - p(1.0, 3.0)).norm() < 1e-9);
    // Under way, the same fixes are joined along the plan's corners (the loop's far end).
    let driven = track_of(false);
    let far = driven.points.iter().map(|q| q.x).fold(0.0, f64::max);
    assert!(far > 90.0, "{driven:?}");
}

#[test]
fn a_vehicle_told_to_hold_between_fixes_drove_its_plan_to_the_stop() {
    // East 100 m then north 100 m at 1 m/s. Under way at (50, 0) at t = 50; told to hold,
    // it reports (100, 30) holding at t = 180: it drove round the corner, stopped at t = 130.
    let plan = corner();
    let ids = vec!["a".to_string()];
    let mut f = Fleet::new(&ids, std::slice::from_ref(&plan), 50.0, 60.0);
    f.report(
        report("a", 0, 50.0, [50.0, 0.0, 0.0], VehicleStatus::Underway),
        1,
    );
    f.vehicles[0].holding = true;
    f.report(
        report("a", 1, 180.0, [100.0, 30.0, 0.0], VehicleStatus::Holding),
        2,
    );
    // Round the corner (not the chord across it, which passes 30 m from it), at the stop by
    // t = 130, standing after. The stop is matched where the plan first comes within 3 m of
    // it, (100, 27), and that 3 m offset is spread over the way: the corner is drawn 2 m north.
    let track = &f.vehicles[0].track;
    let corner = track
        .points
        .iter()
        .map(|q| (q - p(100.0, 0.0)).norm())
        .fold(f64::INFINITY, f64::min);
    assert!(corner < 2.5, "{track:?}");
    assert!(
        (track.position_at(130.0) - p(100.0, 30.0)).norm() < 1.5,
        "{track:?}"
    );
    assert!(
        (track.position_at(160.0) - p(100.0, 30.0)).norm() < 1e-9,
        "{track:?}"
    );
}

/// A vehicle told to hold after a fix under way drove on until the hold came: it is pictured
/// where its plan had it then, not at that fix, until a fix taken after the hold places it
/// (and, the hold confirmed, predicts it standing there). Lost, it stays at its last fix.
#[test]
fn a_vehicle_told_to_hold_is_pictured_where_its_plan_had_it_at_the_hold() {
    let ids = vec!["a".to_string()];
    let mut f = Fleet::new(&ids, &[straight(0.0)], 50.0, 60.0);
    f.report(
        report("a", 0, 20.0, [20.0, 0.0, 0.0], VehicleStatus::Underway),
        1,
    );
    // Told to hold at t = 45 s: 25 m on along its plan at 1 m/s.
    f.vehicles[0].holding = true;
    f.vehicles[0].held_since_s = Some(45.0);
    let at = f.vehicles[0].standing();
    assert!((at - Vec3::new(45.0, 0.0, 0.0)).norm() < 1e-6, "{at:?}");
    // Until the vehicle confirms the hold, it is predicted to keep going.
    let p = &f.predictions(50.0)[0];
    assert!(
        (p.position_at(80.0) - Vec3::new(80.0, 0.0, 0.0)).norm() < 1e-6,
        "{p:?}"
    );
    let resume = f.vehicles[0].resume_s().unwrap_or(f64::NAN);
    assert!((resume - 45.0).abs() < 1e-6, "{resume}");
    // Its first holding fix, a little short of that, places it, standing.
    f.report(
        report("a", 1, 60.0, [44.0, 0.5, 0.0], VehicleStatus::Holding),
        2,
    );
    let at = f.vehicles[0].standing();
    assert!((at - Vec3::new(44.0, 0.5, 0.0)).norm() < 1e-9, "{at:?}");
    let p = &f.predictions(60.0)[0];
    for t in [60.0, 80.0, 110.0] {
        assert!((p.position_at(t) - at).norm() < 1e-9, "{t}: {p:?}");
    }
    // A lost vehicle is not known to have driven on.
    let mut g = Fleet::new(&ids, &[straight(0.0)], 50.0, 60.0);
    g.report(
        report("a", 0, 20.0, [20.0, 0.0, 0.0], VehicleStatus::Underway),
        1,
    );
    g.vehicles[0].lost = true;
    let p = &g.predictions(50.0)[0];
    assert!((p.position_at(60.0) - Vec3::new(20.0, 0.0, 0.0)).norm() < 1e-9);
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

/// A vehicle told to hold is predicted to keep going along its plan until a report of its own
/// says it holds: a real vehicle may not have heard, or refused.
#[test]
fn a_hold_counts_in_the_prediction_only_once_the_vehicle_confirms_it() {
    let ids = vec!["a".to_string()];
    let mut f = Fleet::new(&ids, &[straight(0.0)], 50.0, 60.0);
    f.report(
        report("a", 0, 10.0, [10.0, 0.0, 0.0], VehicleStatus::Underway),
        1,
    );
    f.vehicles[0].holding = true;
    f.vehicles[0].held_since_s = Some(10.0);
    let ahead = |f: &Fleet| f.predictions_over(10.0, 40.0)[0].position_at(50.0).x;
    // Told, not confirmed: 40 s on at 1 m/s.
    assert!((ahead(&f) - 50.0).abs() < 1e-6, "{}", ahead(&f));
    f.report(
        report("a", 1, 11.0, [11.0, 0.0, 0.0], VehicleStatus::Underway),
        2,
    );
    assert!(!f.vehicles[0].hold_confirmed());
    f.report(
        report("a", 2, 12.0, [11.5, 0.0, 0.0], VehicleStatus::Holding),
        3,
    );
    assert!(f.vehicles[0].hold_confirmed());
    assert!(
        (ahead(&f) - 11.5).abs() < 1e-6,
        "stands where it stopped: {}",
        ahead(&f)
    );
}

/// The later vehicle gives way; one just told to hold settles the conflict unless it gives the
/// hold up, does not answer in time, or stands where the other must go round it.
#[test]
fn a_conflict_waits_for_a_held_vehicles_answer_before_the_other_gives_way() {
    use shoal_common::execution::{CommandReport, CommandState, VehicleCommand};
    let ids = vec!["a".to_string(), "b".to_string()];
    let mut f = Fleet::new(&ids, &[straight(0.0), straight(10.0)], 50.0, 60.0);
    let c = Conflict {
        a: 0,
        b: 1,
        min_distance_m: 10.0,
        at_s: 50.0,
    };
    let patience = Duration::from_secs(3);
    // Neither has reported: at the start an order sent now may reach no agent; later, one
    // that never reported cannot be commanded.
    assert_eq!(f.gives_way(&c, patience, true), None);
    assert_eq!(f.gives_way(&c, patience, false), None);
    f.report(
        report("a", 0, 1.0, [1.0, 0.0, 0.0], VehicleStatus::Underway),
        1,
    );
    assert_eq!(f.gives_way(&c, patience, true), None);
    assert_eq!(f.gives_way(&c, patience, false), Some(0));
    let mut r = report("b", 0, 1.0, [1.0, 10.0, 0.0], VehicleStatus::Underway);
    f.report(r.clone(), 1);
    assert_eq!(f.gives_way(&c, patience, true), Some(1));
    f.vehicles[1].holding = true;
    f.vehicles[1].held_since_s = Some(10.0);
    f.vehicles[1].held_at = Some(Instant::now());
    // Told, no answer yet: nobody else is told anything.
    assert_eq!(f.gives_way(&c, patience, false), None);
    // No answer within the patience: the other gives way.
    assert_eq!(f.gives_way(&c, Duration::ZERO, false), Some(0));
    let hold = |state, given_s| CommandReport {
        command: VehicleCommand::Hold,
        state,
        detail: String::new(),
        given_s,
    };
    let mut answer = |f: &mut Fleet, seq: u64, command: CommandReport| {
        if command.state == CommandState::Confirmed {
            r.state.status = VehicleStatus::Holding;
        }
        r.seq = seq;
        r.state.t_s = 10.0 + seq as f64;
        r.command = Some(command);
        f.report(r.clone(), seq + 1);
    };
    // Pending, and failed with a fallback under way: no answer yet.
    answer(&mut f, 1, hold(CommandState::Pending, 10.0));
    assert_eq!(f.gives_way(&c, patience, false), None);
    answer(&mut f, 2, hold(CommandState::Failed, 10.0));
    assert_eq!(f.gives_way(&c, patience, false), None);
    // An earlier hold given up is no answer to this one.
    answer(&mut f, 3, hold(CommandState::GaveUp, 4.0));
    assert!(!f.vehicles[1].hold_refused());
    assert_eq!(f.gives_way(&c, patience, false), None);
    // This one given up (its clock a little behind): the other gives way at once.
    answer(&mut f, 4, hold(CommandState::GaveUp, 9.5));
    assert!(f.vehicles[1].hold_refused());
    assert_eq!(f.gives_way(&c, patience, false), Some(0));
    // Confirmed and still in the way: the other goes round where it stands.
    answer(&mut f, 5, hold(CommandState::Confirmed, 10.0));
    assert!(f.vehicles[1].hold_confirmed());
    assert_eq!(f.gives_way(&c, patience, false), Some(0));
    // Neither can: lost and holding.
    f.vehicles[0].lost = true;
    assert_eq!(f.gives_way(&c, patience, false), None);
}
