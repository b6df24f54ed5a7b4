//! Tests of the Hybrid A* detour planner on hand-built maps.

use super::*;
use approx::assert_abs_diff_eq;
use std::f64::consts::PI;

type TestResult = Result<(), Box<dyn std::error::Error>>;

const R: f64 = 5.0;

fn params() -> HybridAStarParams {
    HybridAStarParams {
        min_turn_radius_m: R,
        ..HybridAStarParams::default()
    }
}

/// Free outside the axis-aligned square of half-side `half` centred at `(cx, cy)`.
fn outside_square(cx: f64, cy: f64, half: f64) -> impl Fn(f64, f64) -> bool {
    move |x: f64, y: f64| (x - cx).abs() > half || (y - cy).abs() > half
}

/// Asserts the path starts at `start`, its pieces join in position and heading, every sample
/// 0.5 m apart is free and inside `bounds`, and `|κ| ≤ 1/R`. Returns the end pose.
fn assert_valid(
    path: &CoveragePath,
    start: Pose2,
    free: &dyn Fn(f64, f64) -> bool,
    bounds: [f64; 4],
) -> Pose2 {
    let mut prev = start;
    for (kind, p) in &path.pieces {
        assert_eq!(*kind, PieceKind::Detour);
        let s = p.start();
        assert!(
            (s.x - prev.x).hypot(s.y - prev.y) < 1e-9,
            "gap {s:?} vs {prev:?}"
        );
        assert!(
            angle_diff(s.heading, prev.heading).abs() < 1e-9,
            "kink {s:?} vs {prev:?}"
        );
        assert!(
            p.curvature().abs() <= 1.0 / R + 1e-9,
            "κ = {}",
            p.curvature()
        );
        prev = p.end();
    }
    let samples = path.sample(0.5);
    for w in samples.windows(2) {
        assert!((w[1].x - w[0].x).hypot(w[1].y - w[0].y) <= 0.5 + 1e-9);
    }
    for s in &samples {
        assert!(free(s.x, s.y), "sample in an obstacle: {s:?}");
        let [x0, y0, x1, y1] = bounds;
        assert!(
            s.x >= x0 && s.x <= x1 && s.y >= y0 && s.y <= y1,
            "out of bounds {s:?}"
        );
        assert!(s.curvature.abs() <= 1.0 / R + 1e-9);
    }
    prev
}

fn assert_at(end: Pose2, goal: Pose2, tol: f64) {
    assert!(
        (end.x - goal.x).hypot(end.y - goal.y) <= tol,
        "end {end:?} goal {goal:?}"
    );
    assert!(
        angle_diff(end.heading, goal.heading).abs() <= tol.max(1e-9),
        "end {end:?}"
    );
}

#[test]
fn in_free_space_the_first_shot_is_the_dubins_path() -> TestResult {
    let start = Pose2::new(0.0, 0.0, 0.0);
    let goal = Pose2::new(60.0, 20.0, PI / 2.0);
    let bounds = [-50.0, -50.0, 150.0, 150.0];
    let free = |_: f64, _: f64| true;
    let res = plan(start, goal, &free, bounds, &params())?.ok_or("no path")?;
    let dubins = dubins::shortest_length(start, goal, R).ok_or("no Dubins")?;
    assert_eq!(res.expansions, 1);
    assert_abs_diff_eq!(res.path.length(), dubins, epsilon = 1e-9);
    let end = assert_valid(&res.path, start, &free, bounds);
    assert_at(end, goal, 1e-9);
    Ok(())
}

#[test]
fn in_free_space_the_search_alone_is_within_a_few_percent_of_dubins() -> TestResult {
    // Analytic expansion off: the primitives alone have to get within 2 m and 10° of the goal.
    // The fair yardstick is the Dubins length to where the search actually stopped.
    let p = HybridAStarParams {
        analytic_expansion_every: 0,
        goal_tolerance_m: 2.0,
        goal_heading_tolerance_rad: 10f64.to_radians(),
        ..params()
    };
    let free = |_: f64, _: f64| true;
    let bounds = [-50.0, -50.0, 150.0, 150.0];
    let start = Pose2::new(0.0, 0.0, 0.0);
    for goal in [
        Pose2::new(60.0, 20.0, PI / 2.0),
        Pose2::new(80.0, -10.0, 0.0),
        Pose2::new(20.0, 30.0, PI),
    ] {
        let res = plan(start, goal, &free, bounds, &p)?.ok_or("no path")?;
        let end = assert_valid(&res.path, start, &free, bounds);
        assert!((end.x - goal.x).hypot(end.y - goal.y) <= p.goal_tolerance_m + 1e-9);
        assert!(angle_diff(end.heading, goal.heading).abs() <= p.goal_heading_tolerance_rad);
        let dubins = dubins::shortest_length(start, end, R).ok_or("no Dubins")?;
        let ratio = res.path.length() / dubins;
        assert!(
            (1.0 - 1e-9..=1.05).contains(&ratio),
            "{goal:?}: ratio {ratio}"
        );
    }
    Ok(())
}

#[test]
fn a_detour_round_a_twenty_metre_square_on_the_row_is_exact_and_free() -> TestResult {
    let start = Pose2::new(0.0, 0.0, 0.0);
    let goal = Pose2::new(100.0, 0.0, 0.0);
    let free = outside_square(50.0, 0.0, 10.0);
    let bounds = [-20.0, -60.0, 120.0, 60.0];
    // The defaults, and the finer 1 m cells / 2 m steps.
    let fine = HybridAStarParams {
        xy_resolution_m: 1.0,
        step_m: 2.0,
        ..params()
    };
    for p in [params(), fine] {
        let res = plan(start, goal, &free, bounds, &p)?.ok_or("no path")?;
        let end = assert_valid(&res.path, start, &free, bounds);
        assert_at(end, goal, 1e-9);
        // It must leave the row by more than the square's half-side, so it is longer than
        // 100 m, but a sensible detour is far shorter than going round twice.
        let len = res.path.length();
        assert!(len > 100.0 && len < 130.0, "length {len}");
        assert!(res.path.sample(0.5).iter().any(|s| s.y.abs() > 10.0));
        assert!(res.expansions <= p.max_expansions);
    }
    Ok(())
}

#[test]
fn a_blocked_u_turn_goes_wider_and_lands_on_the_next_row() -> TestResult {
    // Row end (80, 0) heading east, next row starts at (80, 10) heading west (2R apart). The
    // semicircle through (85, 5) is blocked by a box; the field ends at x = 110.
    let start = Pose2::new(80.0, 0.0, 0.0);
    let goal = Pose2::new(80.0, 10.0, PI);
    let free = |x: f64, y: f64| !((84.0..=88.0).contains(&x) && (2.0..=8.0).contains(&y));
    let bounds = [0.0, -30.0, 110.0, 40.0];
    let res = plan(start, goal, &free, bounds, &params())?.ok_or("no path")?;
    let end = assert_valid(&res.path, start, &free, bounds);
    assert_at(end, goal, 1e-9);
    assert!(res.path.length() > PI * R);
    Ok(())
}

#[test]
fn a_walled_off_goal_returns_none_within_the_budget() -> TestResult {
    // A ring 2 m thick round the goal: no way in.
    let goal = Pose2::new(50.0, 0.0, 0.0);
    let free = move |x: f64, y: f64| {
        let r = (x - goal.x).hypot(y - goal.y);
        !(8.0..=10.0).contains(&r)
    };
    let start = Pose2::new(0.0, 0.0, 0.0);
    let p = HybridAStarParams {
        max_expansions: 20_000,
        ..params()
    };
    // Budget exhausted on a wide map, open list exhausted on a tight one.
    assert_eq!(
        plan(start, goal, &free, [-20.0, -40.0, 120.0, 40.0], &p)?,
        None
    );
    assert_eq!(plan(start, goal, &free, [-5.0, -5.0, 30.0, 5.0], &p)?, None);
    Ok(())
}

#[test]
fn blocked_or_outside_endpoints_give_none() -> TestResult {
    let free = outside_square(0.0, 0.0, 3.0);
    let bounds = [-50.0, -50.0, 50.0, 50.0];
    let ok = Pose2::new(-20.0, 0.0, 0.0);
    let inside = Pose2::new(1.0, 0.0, 0.0);
    let outside = Pose2::new(60.0, 0.0, 0.0);
    assert_eq!(plan(inside, ok, &free, bounds, &params())?, None);
    assert_eq!(plan(ok, inside, &free, bounds, &params())?, None);
    assert_eq!(plan(ok, outside, &free, bounds, &params())?, None);
    Ok(())
}

#[test]
fn identical_inputs_give_identical_outputs() -> TestResult {
    let start = Pose2::new(0.0, 3.0, 0.1);
    let goal = Pose2::new(100.0, -2.0, -0.2);
    let free =
        |x: f64, y: f64| outside_square(50.0, 0.0, 10.0)(x, y) && (x - 75.0).hypot(y - 12.0) > 6.0;
    let bounds = [-20.0, -60.0, 120.0, 60.0];
    let a = plan(start, goal, &free, bounds, &params())?.ok_or("no path")?;
    for _ in 0..3 {
        let b = plan(start, goal, &free, bounds, &params())?.ok_or("no path")?;
        assert_eq!(a, b);
    }
    assert_valid(&a.path, start, &free, bounds);
    Ok(())
}

#[test]
fn invalid_parameters_name_the_field_and_the_value() {
    let cases: Vec<(HybridAStarParams, &str, &str)> = vec![
        (
            HybridAStarParams {
                min_turn_radius_m: -5.0,
                ..params()
            },
            "min_turn_radius_m",
            "-5",
        ),
        (
            HybridAStarParams {
                step_m: f64::NAN,
                ..params()
            },
            "step_m",
            "NaN",
        ),
        (
            HybridAStarParams {
                step_m: 1.0,
                ..params()
            },
            "step_m",
            "1",
        ),
        (
            HybridAStarParams {
                steering_branches: 4,
                ..params()
            },
            "steering_branches",
            "4",
        ),
        (
            HybridAStarParams {
                xy_resolution_m: 0.0,
                ..params()
            },
            "xy_resolution_m",
            "0",
        ),
        (
            HybridAStarParams {
                heading_bins: 2,
                ..params()
            },
            "heading_bins",
            "2",
        ),
        (
            HybridAStarParams {
                max_expansions: 0,
                ..params()
            },
            "max_expansions",
            "0",
        ),
        (
            HybridAStarParams {
                goal_tolerance_m: -1.0,
                ..params()
            },
            "goal_tolerance_m",
            "-1",
        ),
        (
            HybridAStarParams {
                goal_heading_tolerance_rad: 4.0,
                ..params()
            },
            "goal_heading_tolerance_rad",
            "4",
        ),
        (
            HybridAStarParams {
                steer_penalty: -0.5,
                ..params()
            },
            "steer_penalty",
            "-0.5",
        ),
        (
            HybridAStarParams {
                steer_change_penalty: f64::INFINITY,
                ..params()
            },
            "steer_change_penalty",
            "inf",
        ),
    ];
    for (p, field, value) in cases {
        let err = p
            .validate()
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(
            err.contains(&format!("`{field}` = {value}:")),
            "{field}: {err}"
        );
    }
    assert_eq!(HybridAStarParams::default().validate(), Ok(()));
}

#[test]
fn bad_poses_and_bounds_are_errors() {
    let free = |_: f64, _: f64| true;
    let p = params();
    let ok = Pose2::new(0.0, 0.0, 0.0);
    let b = [-10.0, -10.0, 10.0, 10.0];
    let nan = Pose2::new(0.0, f64::NAN, 0.0);
    assert!(matches!(
        plan(nan, ok, &free, b, &p),
        Err(HybridAStarError::NonFinitePose { which: "start", .. })
    ));
    assert!(matches!(
        plan(ok, Pose2::new(0.0, 0.0, f64::INFINITY), &free, b, &p),
        Err(HybridAStarError::NonFinitePose { which: "goal", .. })
    ));
    for bad in [[10.0, -10.0, -10.0, 10.0], [-10.0, f64::NAN, 10.0, 10.0]] {
        assert!(matches!(
            plan(ok, ok, &free, bad, &p),
            Err(HybridAStarError::InvalidBounds { .. })
        ));
    }
    let bad_params = HybridAStarParams {
        steering_branches: 0,
        ..p
    };
    assert!(matches!(
        plan(ok, ok, &free, b, &bad_params),
        Err(HybridAStarError::InvalidParam {
            field: "steering_branches",
            ..
        })
    ));
}

#[test]
fn open_list_order_is_f_then_h_then_age() {
    let mut heap = BinaryHeap::new();
    heap.push(Open {
        f: 2.0,
        h: 1.0,
        seq: 0,
        node: 0,
    });
    heap.push(Open {
        f: 1.0,
        h: 1.0,
        seq: 1,
        node: 1,
    });
    heap.push(Open {
        f: 1.0,
        h: 0.5,
        seq: 2,
        node: 2,
    });
    heap.push(Open {
        f: 1.0,
        h: 0.5,
        seq: 3,
        node: 3,
    });
    let order: Vec<usize> = std::iter::from_fn(|| heap.pop().map(|o| o.node)).collect();
    assert_eq!(order, vec![2, 3, 1, 0]);
}
