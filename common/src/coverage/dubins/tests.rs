//! Tests of the Dubins solver, with hand-computed lengths.

use super::*;
use approx::assert_abs_diff_eq;

type TestResult = Result<(), Box<dyn std::error::Error>>;

const R: f64 = 5.0;

/// Asserts the pieces start at `start`, join (position and heading), end at `goal` (1e-9), and
/// have `|κ| = 1/R` or 0.
fn assert_exact(pieces: &[Piece], start: Pose2, goal: Pose2, radius: f64) {
    let mut prev = start;
    for p in pieces {
        let s = p.start();
        assert!(
            (s.x - prev.x).hypot(s.y - prev.y) < 1e-9,
            "gap at {s:?} vs {prev:?}"
        );
        assert!(
            angle_diff(s.heading, prev.heading).abs() < 1e-9,
            "kink at {s:?}"
        );
        let k = p.curvature().abs();
        assert!(
            k == 0.0 || (k - 1.0 / radius).abs() < 1e-12,
            "curvature {k}"
        );
        prev = p.end();
    }
    assert!(
        (prev.x - goal.x).hypot(prev.y - goal.y) < 1e-9,
        "end {prev:?} goal {goal:?}"
    );
    assert!(
        angle_diff(prev.heading, goal.heading).abs() < 1e-9,
        "end {prev:?}"
    );
}

#[test]
fn a_goal_straight_ahead_is_one_line_of_the_chord_length() -> TestResult {
    let start = Pose2::new(0.0, 0.0, 0.0);
    let goal = Pose2::new(10.0, 0.0, 0.0);
    let path = shortest(start, goal, R).ok_or("no path")?;
    assert_abs_diff_eq!(path.length(), 10.0, epsilon = 1e-12);
    let pieces = path.pieces();
    assert_eq!(pieces.len(), 1);
    assert!(matches!(pieces[0], Piece::Line { .. }));
    assert_exact(&pieces, start, goal, R);
    assert_abs_diff_eq!(shortest_length(start, goal, R).ok_or("no length")?, 10.0);
    Ok(())
}

#[test]
fn a_goal_two_radii_to_the_left_heading_back_is_a_left_semicircle() -> TestResult {
    let start = Pose2::new(0.0, 0.0, 0.0);
    let goal = Pose2::new(0.0, 2.0 * R, PI);
    let path = shortest(start, goal, R).ok_or("no path")?;
    // Half a circle of radius R: π·R = 15.7080 m.
    assert_abs_diff_eq!(path.length(), PI * R, epsilon = 1e-9);
    let pieces = path.pieces();
    assert!(pieces.iter().all(|p| p.curvature() > 0.0), "{pieces:?}");
    assert_exact(&pieces, start, goal, R);
    Ok(())
}

#[test]
fn lsl_to_a_northbound_goal_up_and_to_the_left_has_the_tangent_length() -> TestResult {
    // Start circle centre (0, 5), goal circle centre (20 − 5, 20) = (15, 20): the outer tangent
    // runs at 45° for |(15, 15)| = 15√2, each arc turns π/4.
    // Length = 15√2 + 2·(π/4)·5 = 21.2132 + 7.8540 = 29.0672 m.
    let start = Pose2::new(0.0, 0.0, 0.0);
    let goal = Pose2::new(20.0, 20.0, PI / 2.0);
    let expected = 15.0 * 2f64.sqrt() + 2.5 * PI;
    let path = shortest(start, goal, R).ok_or("no path")?;
    assert_eq!(path.word, DubinsWord::Lsl);
    assert_abs_diff_eq!(path.length(), expected, epsilon = 1e-9);
    assert_abs_diff_eq!(path.lengths[0], 1.25 * PI, epsilon = 1e-9);
    assert_abs_diff_eq!(path.lengths[1], 15.0 * 2f64.sqrt(), epsilon = 1e-9);
    assert_exact(&path.pieces(), start, goal, R);
    // The mirror image is RSR of the same length.
    let mirror = Pose2::new(20.0, -20.0, -PI / 2.0);
    let path = shortest(start, mirror, R).ok_or("no path")?;
    assert_eq!(path.word, DubinsWord::Rsr);
    assert_abs_diff_eq!(path.length(), expected, epsilon = 1e-9);
    assert_exact(&path.pieces(), start, mirror, R);
    Ok(())
}

#[test]
fn lsr_between_circles_twenty_metres_apart_has_the_inner_tangent_length() -> TestResult {
    // Heading east to (16, 22) heading east: left circle centre (0, 5), right circle centre
    // (16, 17), 20 m apart along atan2(12, 16) = 36.87°. The inner tangent is
    // √(20² − (2R)²) = 10√3 long and leaves at ψ = 36.87° + asin(2R/20) = 36.87° + 30°; both
    // arcs turn ψ. Length = 10√3 + 2·R·ψ = 17.3205 + 11.6711 = 28.9916 m.
    let start = Pose2::new(0.0, 0.0, 0.0);
    let goal = Pose2::new(16.0, 22.0, 0.0);
    let psi = 12f64.atan2(16.0) + PI / 6.0;
    let expected = 10.0 * 3f64.sqrt() + 2.0 * R * psi;
    let path = shortest(start, goal, R).ok_or("no path")?;
    assert_eq!(path.word, DubinsWord::Lsr);
    assert_abs_diff_eq!(path.length(), expected, epsilon = 1e-9);
    assert_abs_diff_eq!(path.lengths[0], R * psi, epsilon = 1e-9);
    assert_exact(&path.pieces(), start, goal, R);
    Ok(())
}

#[test]
fn turning_round_on_the_spot_is_a_three_arc_word_of_seven_thirds_pi_r() -> TestResult {
    // Same position, heading reversed. RLR: right circle centre (0, −5), goal right circle
    // centre (0, 5), 2R apart; the middle left circle touches both, so the three centres make an
    // equilateral triangle with sides 2R (middle centre (5√3, 0)). The first and last arcs turn
    // π/3, the middle one 2π − π/3 = 5π/3: length = 7π/3·R = 36.6519 m (LRL is its mirror).
    let start = Pose2::new(0.0, 0.0, 0.0);
    let goal = Pose2::new(0.0, 0.0, PI);
    let path = shortest(start, goal, R).ok_or("no path")?;
    assert!(
        matches!(path.word, DubinsWord::Rlr | DubinsWord::Lrl),
        "{path:?}"
    );
    assert_abs_diff_eq!(path.length(), 7.0 * PI / 3.0 * R, epsilon = 1e-9);
    assert_abs_diff_eq!(path.lengths[0], PI / 3.0 * R, epsilon = 1e-9);
    assert_exact(&path.pieces(), start, goal, R);
    // Two metres behind with the same heading: no three-arc shortcut, it is a loop
    // (LSL/RSR: two semicircles and the 2 m between them = 2πR + 2).
    let behind = Pose2::new(-2.0, 0.0, 0.0);
    let path = shortest(start, behind, R).ok_or("no path")?;
    assert_abs_diff_eq!(path.length(), TAU * R + 2.0, epsilon = 1e-9);
    assert_exact(&path.pieces(), start, behind, R);
    Ok(())
}

#[test]
fn every_candidate_on_a_grid_of_poses_ends_exactly_at_the_goal() {
    let start = Pose2::new(3.0, -1.0, 0.7);
    let mut words_seen = std::collections::BTreeSet::new();
    let mut count = 0;
    for ix in -6..=6 {
        for iy in -6..=6 {
            for ih in 0..12 {
                let goal = Pose2::new(
                    3.0 + 3.7 * ix as f64,
                    -1.0 + 3.3 * iy as f64,
                    -PI + TAU * ih as f64 / 12.0,
                );
                let all = candidates(start, goal, R);
                assert!(!all.is_empty(), "no word for {goal:?}");
                let best = shortest_length(start, goal, R).unwrap_or(f64::NAN);
                let chord = (goal.x - start.x).hypot(goal.y - start.y);
                assert!(
                    best >= chord - 1e-9,
                    "Dubins {best} shorter than chord {chord}"
                );
                for c in &all {
                    assert!(c.lengths.iter().all(|&l| l >= 0.0));
                    assert!(c.length() >= best - 1e-12);
                    assert_exact(&c.pieces(), start, goal, R);
                    words_seen.insert(format!("{:?}", c.word));
                    count += 1;
                }
                let s = shortest(start, goal, R).map(|p| p.length());
                assert_eq!(s, Some(best));
            }
        }
    }
    assert_eq!(words_seen.len(), 6, "{words_seen:?}");
    assert!(count > 13 * 13 * 12 * 4);
}

#[test]
fn the_same_pose_gives_an_empty_path_and_bad_input_gives_none() {
    let p = Pose2::new(1.0, 2.0, 3.0);
    let path = shortest(p, p, R);
    assert_eq!(path.map(|d| d.length()), Some(0.0));
    assert_eq!(path.map(|d| d.pieces().len()), Some(0));
    assert!(shortest(p, p, 0.0).is_none());
    assert!(shortest(p, p, f64::NAN).is_none());
    assert!(shortest(Pose2::new(f64::NAN, 0.0, 0.0), p, R).is_none());
    assert!(shortest_length(p, Pose2::new(0.0, f64::INFINITY, 0.0), R).is_none());
}
