use super::*;
use crate::coverage::path::{Piece, PieceKind};
use approx::assert_abs_diff_eq;

fn line(from: [f64; 2], to: [f64; 2]) -> CoveragePath {
    CoveragePath {
        pieces: vec![(PieceKind::Straight, Piece::Line { from, to })],
    }
}

#[test]
fn strips_share_whole_rows_south_to_north() {
    // 1000 m / 10 m = 100 rows: 34, 33, 33.
    let s = match strips(Rect::new(0.0, 0.0, 1000.0, 1000.0), 3, 10.0) {
        Ok(s) => s,
        Err(e) => panic!("{e}"),
    };
    let ys: Vec<[f64; 2]> = s.iter().map(|r| [r.y0, r.y1]).collect();
    assert_eq!(ys, vec![[0.0, 340.0], [340.0, 670.0], [670.0, 1000.0]]);
    assert!(s.iter().all(|r| r.x0 == 0.0 && r.x1 == 1000.0));
    // 105 m holds 10 rows; the last strip keeps the 5 m sliver.
    let s = match strips(Rect::new(0.0, 0.0, 50.0, 105.0), 4, 10.0) {
        Ok(s) => s,
        Err(e) => panic!("{e}"),
    };
    let ys: Vec<[f64; 2]> = s.iter().map(|r| [r.y0, r.y1]).collect();
    assert_eq!(
        ys,
        vec![[0.0, 30.0], [30.0, 60.0], [60.0, 80.0], [80.0, 105.0]]
    );
    assert!(strips(Rect::new(0.0, 0.0, 50.0, 105.0), 11, 10.0).is_err());
    assert!(strips(Rect::new(0.0, 0.0, 50.0, 105.0), 0, 10.0).is_err());
}

#[test]
fn a_delayed_path_holds_at_its_start() {
    let t = timed_trajectory(&line([0.0, 0.0], [100.0, 0.0]), 0.5, 10.0);
    assert_abs_diff_eq!(t.times[0], 0.0);
    assert_abs_diff_eq!(t.times[1], 10.0);
    assert_abs_diff_eq!(t.points[0].x, 0.0);
    assert_abs_diff_eq!(t.points[1].x, 0.0);
    assert_abs_diff_eq!(
        t.times[t.times.len() - 1],
        10.0 + 100.0 / 0.5,
        epsilon = 1e-9
    );
    assert_abs_diff_eq!(t.points[t.points.len() - 1].x, 100.0, epsilon = 1e-9);
    let t = timed_trajectory(&line([0.0, 0.0], [100.0, 0.0]), 0.5, 0.0);
    assert_abs_diff_eq!(t.times[0], 0.0);
    assert_abs_diff_eq!(t.times[1], TIMED_STEP_M / 0.5, epsilon = 1e-9);
}

#[test]
fn crossing_crawlers_are_separated_by_a_start_delay() {
    // A drives (0,0) -> (100,0), B (50,-50) -> (50,50), both at 1 m/s: they meet at (50,0)
    // at t = 50. The delay step is max(2·10 / 1, 60) = 60 s. Delaying A by 60 s: for t in
    // [60, 100] A = (t − 60, 0), B = (50, t − 50), d² = (110 − t)² + (t − 50)², least at
    // t = 80: √1800 = 42.426 m; before, B passes 50 m from A's start; after, B holds at
    // (50, 50) while A drives on (distance ≥ 50 m).
    let a = line([0.0, 0.0], [100.0, 0.0]);
    let b = line([50.0, -50.0], [50.0, 50.0]);
    let s = separate(&[&a, &b], 1.0, 10.0);
    assert_eq!(s.start_delays_s, vec![60.0, 0.0]);
    assert_abs_diff_eq!(s.min_distance_m, 1800f64.sqrt(), epsilon = 1e-6);
    assert_abs_diff_eq!(s.at_s, 80.0, epsilon = 1e-6);
    assert_abs_diff_eq!(s.breach_s, 0.0);
    assert_eq!(s.closest_pair, [0, 1]);
    assert_abs_diff_eq!(s.finish_s[0], 160.0, epsilon = 1e-9);
    assert_abs_diff_eq!(s.finish_s[1], 100.0, epsilon = 1e-9);
}

#[test]
fn a_conflict_no_delay_resolves_is_reported() {
    // Head-on on one line: whoever waits, the other drives into its parking spot.
    let a = line([0.0, 0.0], [100.0, 0.0]);
    let b = line([100.0, 0.0], [0.0, 0.0]);
    let s = separate(&[&a, &b], 1.0, 10.0);
    assert!(s.min_distance_m < 10.0, "{s:?}");
    assert!(s.breach_s > 0.0, "{s:?}");
}

#[test]
fn far_apart_crawlers_start_together() {
    let a = line([0.0, 0.0], [100.0, 0.0]);
    let b = line([0.0, 200.0], [100.0, 200.0]);
    let s = separate(&[&a, &b], 0.5, 50.0);
    assert_eq!(s.start_delays_s, vec![0.0, 0.0]);
    assert_abs_diff_eq!(s.min_distance_m, 200.0, epsilon = 1e-9);
    let one = separate(&[&a], 0.5, 50.0);
    assert!(one.min_distance_m.is_infinite());
}

#[test]
fn a_stop_cuts_only_the_tracking_short() {
    let map = crate::coverage::test_map(30, vec![0.0; 900]);
    let settings = CoverageSettings::default();
    assert!(settings.track);
    let strip = Rect::new(0.0, 0.0, 58.0, 30.0);
    let run = |stop: bool| {
        let flag = AtomicBool::new(stop);
        match run_coverage(&settings, &map, strip, None, 1, Some(&flag), &mut |_, _| {}) {
            Ok((report, _)) => report,
            Err(e) => panic!("{e}"),
        }
    };
    let (whole, cut) = (run(false), run(true));
    let (Some(w), Some(c)) = (&whole.tracking, &cut.tracking) else {
        panic!("not tracked");
    };
    assert!(w.reached_end && !w.interrupted);
    assert!(c.interrupted && !c.reached_end);
    assert_eq!(c.qp_solves, 0);
    assert!(w.qp_solves > 0);
    // The plan and its figures are those of the whole run.
    assert_eq!(cut.planned_path, whole.planned_path);
    assert_eq!(cut.coverage, whole.coverage);
    assert_eq!(cut.path_length_m, whole.path_length_m);
    assert_eq!(cut.samples_below_clearance, whole.samples_below_clearance);
}

#[test]
fn a_strip_plan_from_elsewhere_is_checked_before_use() {
    let map = crate::coverage::test_map(30, vec![0.0; 900]);
    let settings = CoverageSettings {
        track: false,
        ..CoverageSettings::default()
    };
    let strip = Rect::new(0.0, 0.0, 58.0, 30.0);
    let (report, plan) = match run_coverage(&settings, &map, strip, None, 1, None, &mut |_, _| {}) {
        Ok(r) => r,
        Err(e) => panic!("{e}"),
    };
    let good = StripPlan {
        report,
        path: plan.path,
    };
    assert_eq!(good.check(strip), Ok(()));
    // Planned for another strip.
    assert!(good.check(Rect::new(0.0, 30.0, 58.0, 58.0)).is_err());
    // A non-finite number or a zero radius in the path.
    let mut bad = good.clone();
    bad.path.pieces.push((
        PieceKind::Straight,
        Piece::Line {
            from: [0.0, f64::NAN],
            to: [1.0, 0.0],
        },
    ));
    assert!(bad.check(strip).is_err());
    let mut bad = good.clone();
    bad.path.pieces.push((
        PieceKind::UTurn,
        Piece::Arc {
            centre: [0.0, 0.0],
            radius: 0.0,
            start_angle: 0.0,
            sweep: 1.0,
        },
    ));
    assert!(bad.check(strip).is_err());
}
