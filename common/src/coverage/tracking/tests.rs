//! Whole-loop tests: plant + TA-AEKF + V-MPC along synthetic coverage paths.

use super::reference::tests::two_rows_with_uturn;
use super::types::geometry::{CoveragePath, Piece, PieceKind};
use super::types::{PathSample, Pose2};
use super::*;
use std::f64::consts::{FRAC_PI_4, PI};
use std::sync::atomic::{AtomicBool, Ordering};

/// Two 200 m rows joined by a 5 m semicircle, with an S-shaped tangent-arc detour (four 45° arcs
/// of radius 5 m and two 6 m diagonals, ≈ 7.2 m sideways for 20 m) in the first row.
pub(crate) fn rows_uturn_and_detour() -> Vec<PathSample> {
    let r = 5.0;
    let mut pieces: Vec<(PieceKind, Piece)> = Vec::new();
    let lead = Piece::Line {
        from: [0.0, 0.0],
        to: [60.0, 0.0],
    };
    pieces.push((PieceKind::Straight, lead));
    let mut pose = lead.end();
    let push_arc = |pieces: &mut Vec<(PieceKind, Piece)>, pose: &mut Pose2, left: bool| {
        let arc = Piece::turn(*pose, r, FRAC_PI_4, left);
        pieces.push((PieceKind::Detour, arc));
        *pose = arc.end();
    };
    let push_line = |pieces: &mut Vec<(PieceKind, Piece)>, pose: &mut Pose2, len: f64| {
        let line = Piece::Line {
            from: [pose.x, pose.y],
            to: [
                pose.x + len * pose.heading.cos(),
                pose.y + len * pose.heading.sin(),
            ],
        };
        pieces.push((PieceKind::Detour, line));
        *pose = line.end();
    };
    push_arc(&mut pieces, &mut pose, true);
    push_line(&mut pieces, &mut pose, 6.0);
    push_arc(&mut pieces, &mut pose, false);
    push_line(&mut pieces, &mut pose, 20.0);
    push_arc(&mut pieces, &mut pose, false);
    push_line(&mut pieces, &mut pose, 6.0);
    push_arc(&mut pieces, &mut pose, true);
    let rest = Piece::Line {
        from: [pose.x, pose.y],
        to: [200.0, pose.y],
    };
    pieces.push((PieceKind::Straight, rest));
    let turn = Piece::turn(rest.end(), r, PI, true);
    pieces.push((PieceKind::UTurn, turn));
    let end = turn.end();
    pieces.push((
        PieceKind::Straight,
        Piece::Line {
            from: [end.x, end.y],
            to: [0.0, end.y],
        },
    ));
    CoveragePath { pieces }.sample(0.5)
}

/// Sinusoidal undulation with gradient magnitude up to ≈ 0.1 m/m:
/// z = 0.5·sin(2πx/45)·sin(2πy/35) + 0.25·sin(2π(x + 0.6y)/28).
pub(crate) fn undulation(x: f64, y: f64) -> [f64; 2] {
    let (k1, k2, k3) = (2.0 * PI / 45.0, 2.0 * PI / 35.0, 2.0 * PI / 28.0);
    let c3 = 0.25 * k3 * (k3 * (x + 0.6 * y)).cos();
    [
        0.5 * k1 * (k1 * x).cos() * (k2 * y).sin() + c3,
        0.5 * k2 * (k1 * x).sin() * (k2 * y).cos() + 0.6 * c3,
    ]
}

#[test]
fn the_test_terrain_has_the_intended_slopes() {
    let mut max = 0.0f64;
    for i in 0..400 {
        for j in 0..40 {
            let g = undulation(i as f64 * 0.5, j as f64 * 0.5 - 5.0);
            max = max.max(g[0].hypot(g[1]));
        }
    }
    assert!(max > 0.08 && max < 0.16, "max slope {max}");
}

#[test]
fn the_synthetic_path_is_closed_under_the_planner_geometry() {
    let path = rows_uturn_and_detour();
    let last = path[path.len() - 1];
    assert!(
        last.x.abs() < 1e-9 && (last.y - 10.0).abs() < 1e-9,
        "{last:?}"
    );
    let max_y = path
        .iter()
        .filter(|s| s.x < 150.0 && s.y < 9.0)
        .map(|s| s.y)
        .fold(0.0, f64::max);
    assert!((max_y - 7.17).abs() < 0.05, "detour offset {max_y}");
    assert!(path.iter().all(|s| s.curvature.abs() <= 0.2 + 1e-12));
}

#[test]
fn whole_loop_on_undulating_terrain_meets_the_cte_bounds() {
    let path = rows_uturn_and_detour();
    let p = TrackingParams::default();
    for seed in [1, 2, 3] {
        let res = track(&path, &undulation, &p, seed).unwrap_or_else(|e| panic!("{e}"));
        eprintln!(
            "seed {seed}: max {:.3} median {:.3} p95 {:.3} rms {:.3} m; {} QPs, {} failed; {:.0} s",
            res.max_abs_cte_m,
            res.median_abs_cte_m,
            res.p95_abs_cte_m,
            res.rms_cte_m,
            res.qp_solves,
            res.qp_failures,
            res.sim_time_s
        );
        assert!(res.reached_end);
        assert!(res.max_abs_cte_m < 4.0, "max |cte| {}", res.max_abs_cte_m);
        assert!(
            res.median_abs_cte_m < 0.5,
            "median |cte| {}",
            res.median_abs_cte_m
        );
        assert_eq!(res.qp_failures, 0);
        // Every command within the limits.
        let c = p.max_curvature();
        for w in res.samples.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            assert!(
                b.speed_cmd >= p.min_speed_mps - 1e-12 && b.speed_cmd <= p.max_speed_mps + 1e-12
            );
            assert!(b.yaw_rate_cmd.abs() <= c * b.speed_cmd + 1e-12);
            assert!((b.yaw_rate_cmd - a.yaw_rate_cmd).abs() <= p.max_yaw_accel_radps2 + 1e-12);
            assert!((b.speed_cmd - a.speed_cmd).abs() <= p.max_accel_mps2 + 1e-12);
        }
        // About the nominal duration (path ≈ 430 m at 0.8 m/s with ≈ 6–20 % slip).
        let nominal = 430.0 / p.speed_mps;
        assert!(res.sim_time_s > nominal && res.sim_time_s < 1.5 * nominal);
    }
}

#[test]
fn same_seed_same_samples_different_seed_different() {
    let path = rows_uturn_and_detour();
    let p = TrackingParams::default();
    let a = track(&path, &undulation, &p, 42).unwrap_or_else(|e| panic!("{e}"));
    let b = track(&path, &undulation, &p, 42).unwrap_or_else(|e| panic!("{e}"));
    let c = track(&path, &undulation, &p, 43).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(a, b);
    assert_ne!(a.samples, c.samples);
}

#[test]
fn offset_start_converges_in_the_full_loop() {
    let line = Piece::Line {
        from: [0.0, 0.0],
        to: [200.0, 0.0],
    };
    let path = CoveragePath {
        pieces: vec![(PieceKind::Straight, line)],
    }
    .sample(1.0);
    let p = TrackingParams::default();
    let res = track_from_pose(
        &path,
        &undulation,
        &p,
        5,
        Some(Pose2::new(0.0, 3.0, 0.0)),
        None,
        &mut |_| {},
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(res.reached_end);
    assert!((res.samples[0].cross_track_m - 3.0).abs() < 1e-9);
    let late: Vec<f64> = res
        .samples
        .iter()
        .filter(|s| s.truth.x > 60.0)
        .map(|s| s.cross_track_m.abs())
        .collect();
    let worst = late.iter().copied().fold(0.0, f64::max);
    assert!(worst < 0.6, "after 60 m: max |cte| {worst}");
}

#[test]
fn progress_is_monotone_and_ends_at_one() {
    let path = two_rows_with_uturn(60.0, 5.0);
    let mut seen: Vec<f64> = Vec::new();
    let res = track_with_progress(
        &path,
        &FlatTerrain,
        &TrackingParams::default(),
        3,
        None,
        &mut |f| seen.push(f),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(res.reached_end);
    assert!(!res.interrupted);
    assert!(seen.len() > 10);
    assert!(seen.windows(2).all(|w| w[1] >= w[0]));
    assert!(seen.iter().all(|f| (0.0..=1.0).contains(f)));
    assert_eq!(seen.last().copied(), Some(1.0));
}

#[test]
fn a_stop_ends_the_run_after_the_current_control_period() {
    let path = two_rows_with_uturn(60.0, 5.0);
    let p = TrackingParams::default();
    let whole = track(&path, &FlatTerrain, &p, 3).unwrap_or_else(|e| panic!("{e}"));
    // Raised from the start: only the first sample, nothing driven.
    let stop = AtomicBool::new(true);
    let none = track_with_progress(&path, &FlatTerrain, &p, 3, Some(&stop), &mut |_| {})
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(none.interrupted && !none.reached_end);
    assert_eq!(none.samples.len(), 1);
    assert_eq!(none.qp_solves, 0);
    assert_eq!(none.sim_time_s, 0.0);
    // Raised once a quarter of the path is done: the run ends at the next control period
    // with the same samples as the whole run up to there (the stop does not touch the RNG);
    // the last one holds the previous command instead of solving for a new one.
    let stop = AtomicBool::new(false);
    let mut seen = Vec::new();
    let cut = track_with_progress(&path, &FlatTerrain, &p, 3, Some(&stop), &mut |f| {
        seen.push(f);
        if f >= 0.25 {
            stop.store(true, Ordering::Relaxed);
        }
    })
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(cut.interrupted && !cut.reached_end);
    assert!(cut.samples.len() > 1 && cut.samples.len() < whole.samples.len() / 2);
    let n = cut.samples.len();
    assert_eq!(cut.samples[..n - 1], whole.samples[..n - 1]);
    assert_eq!(cut.samples[n - 1].truth, whole.samples[n - 1].truth);
    assert!((cut.sim_time_s - cut.samples[cut.samples.len() - 1].t).abs() < 1e-12);
    // No closing 1.0: the path was not finished.
    assert!(
        seen.last().is_some_and(|f| *f >= 0.25 && *f < 1.0),
        "{seen:?}"
    );
    // Never raised: the same run as without a flag.
    let idle = AtomicBool::new(false);
    let same = track_with_progress(&path, &FlatTerrain, &p, 3, Some(&idle), &mut |_| {})
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(same, whole);
}

#[test]
fn a_bogged_vehicle_stops_at_the_time_limit() {
    let path = two_rows_with_uturn(60.0, 5.0);
    let p = TrackingParams {
        base_slip: 0.9,
        max_slip: 0.9,
        ..TrackingParams::default()
    };
    let res = track(&path, &FlatTerrain, &p, 1).unwrap_or_else(|e| panic!("{e}"));
    assert!(!res.reached_end);
    let limit = p.time_limit_factor * (120.0 + 5.0 * PI) / p.speed_mps + 60.0;
    assert!(res.sim_time_s >= limit && res.sim_time_s < limit + p.control_period_s + 1e-9);
}

#[test]
fn errors_are_reported() {
    let p = TrackingParams::default();
    assert_eq!(
        track(&[], &FlatTerrain, &p, 0).err(),
        Some(TrackingError::EmptyReference)
    );
    let path = two_rows_with_uturn(20.0, 5.0);
    let bad = TrackingParams {
        min_turn_radius_m: 0.0,
        ..TrackingParams::default()
    };
    match track(&path, &FlatTerrain, &bad, 0) {
        Err(TrackingError::InvalidParam { field, value, .. }) => {
            assert_eq!((field, value.as_str()), ("min_turn_radius_m", "0"));
        }
        other => panic!("unexpected {other:?}"),
    }
    let nan_terrain = |_x: f64, _y: f64| [f64::NAN, 0.0];
    assert!(matches!(
        track(&path, &nan_terrain, &p, 0),
        Err(TrackingError::InvalidTerrain { .. })
    ));
    // A single-sample reference is reached at once.
    let one = [path[0]];
    let res = track(&one, &FlatTerrain, &p, 0).unwrap_or_else(|e| panic!("{e}"));
    assert!(res.reached_end);
    assert_eq!(res.samples.len(), 1);
}
