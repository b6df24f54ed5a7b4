//! The geometry the server does for the page, against values worked out by hand.

use approx::assert_abs_diff_eq;
use shoal_common::execution::picture::Progress;
use shoal_common::execution::VehicleState;
use shoal_common::terrain::Mountain;
use shoal_common::wire::open::OPEN_VERSION;

use super::*;

fn row(vehicle: &str, at: Option<[f64; 3]>, status: VehicleStatus, lag_s: f64) -> VehicleStatusRow {
    VehicleStatusRow {
        vehicle: vehicle.into(),
        state: at.map(|position| VehicleState {
            t_s: 0.0,
            position,
            velocity: [0.0; 3],
            heading_deg: 0.0,
            depth_m: None,
            altitude_m: None,
            battery: 1.0,
            status,
            arrived_s: None,
        }),
        progress: Some(Progress {
            along_m: 0.0,
            fraction: 0.0,
            plan_time_s: 0.0,
            cross_track_m: 0.0,
            lag_s,
            eta_s: 0.0,
        }),
        revision: 0,
        silent_s: 0.0,
        command: None,
        lost: false,
    }
}

/// East along y = 0 at 2 m/s: (0, 0, 10) at t = 0, (200, 0, 10) at t = 100.
fn east() -> Trajectory {
    Trajectory::from_samples(&[[0.0, 0.0, 0.0, 10.0], [100.0, 200.0, 0.0, 10.0]])
}

#[test]
fn a_vehicle_on_its_way_is_predicted_along_its_plan_at_its_lag() {
    let plan = east();
    let on_time = row("a", Some([1.0, 1.0, 10.0]), VehicleStatus::Underway, 0.0);
    // At t = 30 on time: 60 m along.
    assert_eq!(
        predicted_place(&on_time, Some(&plan), 30.0),
        Some([60.0, 0.0, 10.0])
    );
    // 10 s late: where the plan is at t = 20, 40 m along.
    let late = row("a", Some([1.0, 1.0, 10.0]), VehicleStatus::Underway, 10.0);
    assert_eq!(
        predicted_place(&late, Some(&plan), 30.0),
        Some([40.0, 0.0, 10.0])
    );
    // Past the plan's end: at its end.
    assert_eq!(
        predicted_place(&on_time, Some(&plan), 500.0),
        Some([200.0, 0.0, 10.0])
    );
    // Not heard yet: on its plan, on time.
    let silent = row("a", None, VehicleStatus::Underway, 0.0);
    assert_eq!(
        predicted_place(&silent, Some(&plan), 50.0),
        Some([100.0, 0.0, 10.0])
    );
    assert_eq!(predicted_place(&silent, None, 50.0), None);
}

#[test]
fn a_standing_vehicle_is_predicted_where_it_was_seen() {
    let plan = east();
    for status in [
        VehicleStatus::Holding,
        VehicleStatus::Fault,
        VehicleStatus::Arrived,
    ] {
        let r = row("a", Some([7.0, 8.0, 9.0]), status, 0.0);
        assert_eq!(
            predicted_place(&r, Some(&plan), 30.0),
            Some([7.0, 8.0, 9.0])
        );
    }
    let mut lost = row("a", Some([7.0, 8.0, 9.0]), VehicleStatus::Underway, 0.0);
    lost.lost = true;
    assert_eq!(
        predicted_place(&lost, Some(&plan), 30.0),
        Some([7.0, 8.0, 9.0])
    );
    // Lost before its first report: where the coordinator has it, at its plan's start.
    let mut never_heard = row("a", None, VehicleStatus::Underway, 0.0);
    never_heard.lost = true;
    assert_eq!(
        predicted_place(&never_heard, Some(&plan), 30.0),
        Some([0.0, 0.0, 10.0])
    );
}

#[test]
fn the_predicted_closest_approach_names_both_places_and_whether_it_conflicts() {
    let mut plans = BTreeMap::new();
    plans.insert("a".to_string(), east());
    // b comes west along y = 30 from x = 200 at 2 m/s.
    plans.insert(
        "b".to_string(),
        Trajectory::from_samples(&[[0.0, 200.0, 30.0, 10.0], [100.0, 0.0, 30.0, 10.0]]),
    );
    let status = FleetStatus {
        version: OPEN_VERSION,
        mission: "m".into(),
        t_s: 0.0,
        d_min_m: 50.0,
        vehicles: vec![
            row("a", Some([0.0, 0.0, 10.0]), VehicleStatus::Underway, 0.0),
            row("b", Some([200.0, 30.0, 10.0]), VehicleStatus::Underway, 0.0),
        ],
        current_min_separation_m: None,
        current_pair: None,
        predicted: Some(Conflict {
            a: 0,
            b: 1,
            min_distance_m: 30.0,
            at_s: 50.0,
        }),
        horizon_s: 180.0,
    };
    let p = predicted_view(&status, &plans);
    assert_eq!(
        p,
        Some(PredictedView {
            vehicles: ["a".into(), "b".into()],
            places: [[100.0, 0.0, 10.0], [100.0, 30.0, 10.0]],
            min_distance_m: 30.0,
            at_s: 50.0,
            conflict: true,
        })
    );
    let mut far = status.clone();
    far.predicted = far.predicted.map(|c| Conflict {
        min_distance_m: 60.0,
        ..c
    });
    assert_eq!(
        predicted_view(&far, &plans).map(|p| p.conflict),
        Some(false)
    );
    let mut bad = status;
    bad.predicted = bad.predicted.map(|c| Conflict { b: 5, ..c });
    assert_eq!(predicted_view(&bad, &plans), None, "an index out of range");
}

#[test]
fn the_seabed_is_sampled_over_the_bounds_and_its_silhouette_is_the_highest_over_y() {
    // One hill of 100 m at (0, 0), spread 100 m: e^-1 of it one spread away.
    let hill = Terrain::Hills(vec![Mountain {
        centre: [0.0, 0.0],
        height_m: 100.0,
        spread_m: [100.0, 100.0],
    }]);
    let bounds = Bounds {
        min: [-100.0, 0.0, 0.0],
        max: [100.0, 100.0, 500.0],
    };
    let s = seabed_view(&hill, &bounds, 3);
    assert_eq!(s.xs, [-100.0, 0.0, 100.0]);
    assert_eq!(s.ys, [0.0, 50.0, 100.0]);
    let e = (-1.0f64).exp();
    // Row y = 0: e^-1, 1, e^-1 of 100 m.
    assert_abs_diff_eq!(s.z[0][0], 100.0 * e, epsilon = 1e-9);
    assert_abs_diff_eq!(s.z[0][1], 100.0, epsilon = 1e-9);
    // Row y = 50 at x = 0: e^-0.25.
    assert_abs_diff_eq!(s.z[1][1], 100.0 * (-0.25f64).exp(), epsilon = 1e-9);
    // Row y = 100 at x = 100: e^-2.
    assert_abs_diff_eq!(s.z[2][2], 100.0 * (-2.0f64).exp(), epsilon = 1e-9);
    // The silhouette is the y = 0 row, the hill's crest line.
    for i in 0..3 {
        assert_abs_diff_eq!(s.profile[i], s.z[0][i], epsilon = 1e-12);
    }
}
