use std::path::Path;
use std::time::{Duration, Instant};

use shoal_common::scenario::{Bounds, Obstacle, ObstacleKind, Scenario};
use shoal_common::wire::open::Telemetry;

use super::*;

/// A 1 km cube.
fn cube() -> Bounds {
    Bounds {
        min: [0.0; 3],
        max: [1000.0; 3],
    }
}

/// A vehicle of 2 m/s (4 m/s over the ground with the factor of 2), 2 Hz telemetry, 10×.
fn limits() -> FixLimits {
    FixLimits {
        ground_speed_mps: 4.0,
        telemetry_hz: 2.0,
        time_scale: 10.0,
        bounds_margin_m: 100.0,
    }
}

fn report(seq: u64, t_s: f64, position: [f64; 3]) -> Telemetry {
    let mut t = crate::execute::live::test_telemetry("auv1", seq, t_s, position);
    t.sent_unix_us = 0;
    t.state.velocity = [0.0; 3];
    t
}

/// The last accepted fix: number 10 at (500, 500, 500), t = 100 s, 5 wall seconds ago.
fn last() -> Option<LastFix> {
    Some(LastFix {
        position: [500.0; 3],
        t_s: 100.0,
        seq: 10,
        wall_since_s: 5.0,
    })
}

/// Checks a report at mission time `t_s` (the coordinator's clock then at `t_s` too).
fn check(seq: u64, t_s: f64, position: [f64; 3]) -> Result<(), Reason> {
    check_fix(
        &report(seq, t_s, position),
        last(),
        &limits(),
        &cube(),
        t_s,
        0.0,
    )
    .map_err(|(r, _)| r)
}

#[test]
fn a_fix_100_m_from_the_last_after_1_s_is_a_jump_and_3_m_is_accepted() {
    // Reach after 1 s: 4 m/s × 1 s + 25 m of noise = 29 m.
    assert_eq!(check(11, 101.0, [600.0, 500.0, 500.0]), Err(Reason::Jump));
    assert_eq!(check(11, 101.0, [503.0, 500.0, 500.0]), Ok(()));
    assert_eq!(check(11, 101.0, [528.0, 500.0, 500.0]), Ok(()));
    assert_eq!(check(11, 101.0, [530.0, 500.0, 500.0]), Err(Reason::Jump));
    // After 10 s the reach is 65 m: 60 m is a drive, 70 m is not.
    assert_eq!(check(11, 110.0, [560.0, 500.0, 500.0]), Ok(()));
    assert_eq!(check(11, 110.0, [570.0, 500.0, 500.0]), Err(Reason::Jump));
}

#[test]
fn the_spoofed_fix_1_9_km_off_is_refused_and_a_first_fix_is_held_only_to_the_bounds() {
    let far = [500.0, 500.0 + 1900.0, 500.0];
    // Outside the 1 km cube by 1,400 m: the bounds catch it before the jump.
    assert_eq!(check(11, 101.0, far), Err(Reason::OutOfBounds));
    // 500 m off inside the cube, one second later: a jump.
    assert_eq!(check(11, 101.0, [500.0, 500.0, 0.0]), Err(Reason::Jump));
    // With nothing to compare with, a first fix anywhere inside the bounds is taken.
    let first = check_fix(
        &report(0, 1.0, [0.0; 3]),
        None,
        &limits(),
        &cube(),
        1.0,
        1.0,
    );
    assert_eq!(first.map_err(|(r, _)| r), Ok(()));
}

#[test]
fn fixes_more_than_the_margin_outside_the_bounds_are_refused() {
    // 99 m past x = 1000 (the last fix 599 m away after 200 s: a drive of 825 m is possible).
    assert_eq!(check(11, 300.0, [1099.0, 500.0, 500.0]), Ok(()));
    assert_eq!(
        check(11, 300.0, [1101.0, 500.0, 500.0]),
        Err(Reason::OutOfBounds)
    );
    // 80 m past two faces: √(80² + 80²) = 113.1 m outside.
    assert_eq!(
        check(11, 300.0, [1080.0, 1080.0, 500.0]),
        Err(Reason::OutOfBounds)
    );
}

#[test]
fn a_number_far_ahead_is_refused_and_u64_max_never_passes() {
    // 5 s at 2 Hz: 100 + 2 × 2 × 5 = 120 ahead of 10 → up to 130.
    assert_eq!(check(130, 101.0, [500.0; 3]), Ok(()));
    assert_eq!(check(131, 101.0, [500.0; 3]), Err(Reason::SeqAhead));
    assert_eq!(check(u64::MAX, 101.0, [500.0; 3]), Err(Reason::SeqAhead));
    // A first report 3 s into the execution: 100 + 2 × 2 × 3 = 112.
    let first = |seq| {
        check_fix(
            &report(seq, 1.0, [0.0; 3]),
            None,
            &limits(),
            &cube(),
            1.0,
            3.0,
        )
        .map_err(|(r, _)| r)
    };
    assert_eq!(first(112), Ok(()));
    assert_eq!(first(113), Err(Reason::SeqAhead));
}

#[test]
fn a_mission_time_more_than_10_wall_seconds_off_the_clock_is_refused() {
    // At 10×, 10 wall seconds are 100 mission seconds.
    let at = |t_s: f64| {
        check_fix(
            &report(11, t_s, [500.0; 3]),
            last(),
            &limits(),
            &cube(),
            500.0,
            0.0,
        )
        .map_err(|(r, _)| r)
    };
    assert_eq!(at(599.0), Ok(()));
    assert_eq!(at(601.0), Err(Reason::ClockOff));
    assert_eq!(at(399.0), Err(Reason::ClockOff));
}

#[test]
fn a_vehicles_limits_come_from_its_top_speed_and_the_surface_current() -> Result<(), String> {
    let text = "name = \"p\"\n[bounds]\nmin = [0.0, 0.0, 0.0]\nmax = [2000.0, 2000.0, 400.0]\n\
         [fleet]\nd_min_m = 50.0\nmission_time_s = 1200.0\n[optimizer]\nwaypoints = 8\n\
         [currents]\nmodel = \"depth-decay\"\nsurface_velocity_mps = [0.3, 0.4]\n\
         [[vehicles]]\nid = \"auv1\"\nkind = \"auv\"\nstart = [100.0, 100.0, 200.0]\n\
         goal = [1900.0, 1900.0, 200.0]\nspeed_min_mps = 0.5\nspeed_max_mps = 2.5\n\
         max_turn_deg = 35.0\nmax_pitch_deg = 20.0\n";
    let s = Scenario::parse(text, Path::new("p.toml")).map_err(|e| e.to_string())?;
    let l = FixLimits::of(&s, 0, 2.0, 40.0, 25.0);
    // 2 × 2.5 m/s + |(0.3, 0.4)| = 5.5 m/s; 100 m + the 25 m deviation tolerance.
    assert!((l.ground_speed_mps - 5.5).abs() < 1e-12, "{l:?}");
    assert!((l.bounds_margin_m - 125.0).abs() < 1e-12, "{l:?}");
    Ok(())
}

fn obstacle(centre: [f64; 3], radius_m: f64, inflation_m: f64) -> Obstacle {
    Obstacle {
        id: "o".into(),
        kind: ObstacleKind::Hard,
        centre,
        radius_m,
        inflation_m,
    }
}

#[test]
fn an_obstacle_larger_than_the_bounds_diagonal_or_far_outside_them_is_refused() {
    // The cube's diagonal: 1000 √3 = 1732.05 m.
    let c = [500.0; 3];
    assert!(check_obstacle_scale(&obstacle(c, 1e300, 0.0), &cube()).is_err());
    assert!(check_obstacle_scale(&obstacle(c, 1700.0, 30.0), &cube()).is_ok());
    assert!(check_obstacle_scale(&obstacle(c, 1700.0, 40.0), &cube()).is_err());
    assert!(check_obstacle_scale(&obstacle([2700.0, 500.0, 500.0], 10.0, 5.0), &cube()).is_ok());
    let far = check_obstacle_scale(&obstacle([2800.0, 500.0, 500.0], 10.0, 5.0), &cube());
    assert!(
        far.as_ref()
            .is_err_and(|e| e.to_string().contains("1800 m outside")),
        "{far:?}"
    );
}

#[test]
fn the_token_bucket_lets_five_a_second_through_with_a_second_saved_up() {
    let t0 = Instant::now();
    let mut b = TokenBucket::new(5.0, 5.0);
    assert_eq!((0..6).filter(|_| b.take(t0)).count(), 5);
    // 0.2 s later: one more token.
    let t1 = t0 + Duration::from_millis(200);
    assert!(b.take(t1));
    assert!(!b.take(t1));
    // Ten seconds idle saves up five, not fifty.
    let t2 = t1 + Duration::from_secs(10);
    assert_eq!((0..10).filter(|_| b.take(t2)).count(), 5);
}

#[test]
fn refusals_are_counted_every_time_and_told_once_per_vehicle_and_reason_every_10_s() {
    let t0 = Instant::now();
    let mut g = Guard::default();
    assert!(g.refuse("auv1", Reason::Jump, t0));
    assert!(!g.refuse("auv1", Reason::Jump, t0 + Duration::from_secs(1)));
    assert!(g.refuse("auv1", Reason::SeqAhead, t0 + Duration::from_secs(1)));
    assert!(g.refuse("auv2", Reason::Jump, t0 + Duration::from_secs(1)));
    assert!(g.refuse("auv1", Reason::Jump, t0 + Duration::from_secs(10)));
    assert_eq!(g.refusals.jump, 4);
    assert_eq!(g.refusals.seq_ahead, 1);
    assert_eq!(g.refusals.total(), 5);
}
