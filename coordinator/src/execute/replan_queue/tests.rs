//! Unit tests of `execute::replan_queue`.

use super::super::queue::ReplanQueue;
use super::*;
use shoal_common::execution::VehicleStatus;
use shoal_common::geometry::Vec3;
use shoal_common::scenario::{Obstacle, ObstacleKind};

fn waiting(vehicle: usize, ms: u64) -> Waiting {
    Waiting {
        vehicle,
        why: String::new(),
        obstacle_received: None,
        budget: Duration::from_millis(ms),
    }
}

#[test]
fn a_replan_waits_for_the_rest_of_the_one_under_way_and_the_budgets_ahead_of_it() {
    let mut q = ReplanQueue::default();
    assert_eq!(q.wait_for(0), Duration::ZERO);
    assert!(!q.busy(0));
    q.waiting.push_back(waiting(2, 300));
    q.waiting.push_back(waiting(3, 600));
    // Nothing under way: the budgets of the two ahead, 300 + 600 ms.
    assert_eq!(q.wait_for(2), Duration::from_millis(900));
    assert_eq!(q.wait_for(1), Duration::from_millis(300));
    let (_tx, rx) = mpsc::channel();
    // Started 1.2 s ago with a 1 s budget: overdue, nothing left of it.
    q.under_way = Some(UnderWay {
        asked: waiting(1, 1000),
        t0: 0.0,
        course: Trajectory {
            times: Vec::new(),
            points: Vec::new(),
        },
        was_holding: false,
        was_standing: false,
        obstacles: 0,
        started: Instant::now() - Duration::from_millis(1200),
        result: rx,
        stop: Arc::new(AtomicBool::new(false)),
    });
    assert_eq!(q.wait_for(1), Duration::from_millis(300));
    // Started 400 ms ago with a 2.4 s budget: 2 s or a little less left.
    if let Some(u) = q.under_way.as_mut() {
        u.started = Instant::now() - Duration::from_millis(400);
        u.asked.budget = Duration::from_millis(2400);
    }
    let w = q.wait_for(0);
    assert!(
        w <= Duration::from_millis(2000) && w > Duration::from_millis(1900),
        "{w:?}"
    );
    assert!(q.busy(1) && q.busy(2) && q.busy(3) && !q.busy(0));
    // It is no held vehicle's retry: it does not yield.
    q.yield_retry();
    assert!(q.wait_for(0) > Duration::from_millis(1900));
    // Nor one told to hold that has not confirmed it: it is under way.
    if let Some(u) = q.under_way.as_mut() {
        u.was_holding = true;
    }
    q.yield_retry();
    assert!(q.under_way.as_ref().is_some_and(|u| !u.yielded()));
    // A standing vehicle's retry yields: nothing left of it to wait for.
    if let Some(u) = q.under_way.as_mut() {
        u.was_standing = true;
    }
    q.yield_retry();
    assert!(q.under_way.as_ref().is_some_and(|u| u.yielded()));
    assert_eq!(q.wait_for(0), Duration::ZERO);
    assert_eq!(q.wait_for(2), Duration::from_millis(900));
}

#[test]
fn a_vehicle_under_way_is_queued_before_every_held_vehicles_retry() {
    let mut q = ReplanQueue::default();
    assert_eq!(q.slot(|_| false), 0);
    // Vehicles 2 and 5 are under way, 3 and 4 hold.
    let holding = |j: usize| j == 3 || j == 4;
    for v in [2, 3, 5, 4] {
        q.waiting.push_back(waiting(v, 300));
    }
    // Before 3, the first held one.
    assert_eq!(q.slot(holding), 1);
    assert_eq!(q.slot(|_| false), 4);
    assert_eq!(q.slot(|_| true), 0);
}

#[test]
fn only_obstacles_published_since_the_start_are_checked_against_a_result(
) -> Result<(), Box<dyn std::error::Error>> {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/amp-pso-1.toml");
    let mut s = Scenario::load(std::path::Path::new(file))?;
    let rock = |id: &str, x: f64, kind: ObstacleKind| Obstacle {
        id: id.into(),
        kind,
        centre: [x, 3.0, 0.0],
        radius_m: 4.0,
        inflation_m: 1.0,
    };
    s.obstacles = vec![rock("old", 50.0, ObstacleKind::Hard)];
    // Along the x axis from 0 to 100 m: 3 m from each centre, inside 4 + 1 m.
    let t = Trajectory {
        times: vec![0.0, 100.0],
        points: vec![Vec3::new(0.0, 0.0, 0.0), Vec3::new(100.0, 0.0, 0.0)],
    };
    // The one known at the start is the replan's own business.
    assert!(!enters_new_obstacle(&t, &s, 1));
    assert!(enters_new_obstacle(&t, &s, 0));
    s.obstacles.push(rock("soft", 30.0, ObstacleKind::Soft));
    assert!(!enters_new_obstacle(&t, &s, 1));
    s.obstacles.push(rock("beyond", 130.0, ObstacleKind::Hard));
    // (130, 3) is 30.1 m from the end (100, 0).
    assert!(!enters_new_obstacle(&t, &s, 1));
    s.obstacles.push(rock("on it", 70.0, ObstacleKind::Hard));
    assert!(enters_new_obstacle(&t, &s, 1));
    assert!(!enters_new_obstacle(&t, &s, 4));
    Ok(())
}

#[test]
fn failed_retries_1_2_4_8_and_so_on_are_told() {
    let told: Vec<u32> = (1..=20).filter(|&n| told_retry(n)).collect();
    assert_eq!(told, vec![1, 2, 4, 8, 16]);
    // The 166 retries of a crawler held for good at 500× make 8 events.
    assert_eq!((1..=166).filter(|&n| told_retry(n)).count(), 8);
}

/// East at 1 m/s along y = 0 from x = 0 (plan time = x).
fn east() -> Trajectory {
    Trajectory {
        times: vec![0.0, 1000.0],
        points: vec![Vec3::zeros(), Vec3::new(1000.0, 0.0, 0.0)],
    }
}

/// A vehicle told at t = 100 s to hold, whose latest report (at t = 110 s, x = 110 m) has
/// `status`.
fn told_to_hold(status: VehicleStatus) -> Tracked {
    use crate::execute::fleet::Fleet;
    let mut f = Fleet::new(&["a".to_string()], &[east()], 50.0, 60.0);
    f.vehicles[0].holding = true;
    f.vehicles[0].held_since_s = Some(100.0);
    let mut t = crate::execute::live::test_telemetry("a", 1, 110.0, [110.0, 0.0, 0.0]);
    t.state.status = status;
    f.report(t, 1);
    f.vehicles[0].clone()
}

#[test]
fn a_vehicle_whose_hold_is_not_confirmed_is_replanned_from_its_course() {
    // Predicted on east at 1 m/s from x = 110 m at t = 110 s; the update takes effect at 140 s.
    let course = Trajectory {
        times: vec![110.0, 1000.0],
        points: vec![Vec3::new(110.0, 0.0, 0.0), Vec3::new(1000.0, 0.0, 0.0)],
    };
    let moving = ReplanStart::of(
        &told_to_hold(VehicleStatus::Underway),
        &course,
        110.0,
        140.0,
    );
    assert!(!moving.standing);
    assert!(
        (moving.p0 - Vec3::new(140.0, 0.0, 0.0)).norm() < 1e-9,
        "{moving:?}"
    );
    // Heading east: the position 5 s before t0 to the position at t0.
    let heading = moving.heading.unwrap_or_else(Vec3::zeros);
    assert!(
        (heading - Vec3::new(5.0, 0.0, 0.0)).norm() < 1e-9,
        "{moving:?}"
    );
    assert_eq!(moving.resume_s, None);
    // Standing on the hold it confirmed: no course to keep, and it resumes where it stopped.
    let still = Trajectory {
        times: vec![110.0, 1000.0],
        points: vec![Vec3::new(110.0, 0.0, 0.0); 2],
    };
    let standing = ReplanStart::of(&told_to_hold(VehicleStatus::Holding), &still, 110.0, 140.0);
    assert!(standing.standing);
    assert_eq!(standing.heading, None);
    let resume = standing.resume_s.unwrap_or(f64::NAN);
    assert!((resume - 110.0).abs() < 1e-6, "{standing:?}");
}

#[test]
fn a_retry_says_holding_only_of_a_vehicle_that_confirmed_its_hold() {
    assert_eq!(
        holding_words(&told_to_hold(VehicleStatus::Holding)),
        "keeps holding"
    );
    let moving = holding_words(&told_to_hold(VehicleStatus::Underway));
    assert!(moving.contains("not confirmed"), "{moving}");
}
