//! Unit tests of `execute::fleet` about holds: where a held vehicle is pictured and predicted,
//! and who gives way while its answer is awaited.

use super::tests::{corner, p, report, straight};
use super::*;

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
