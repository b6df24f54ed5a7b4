//! Analytic arc smoothing (CPP-DSMV, §2.2.3, "Detour path generation and analytical arc
//! smoothing"; the equations were lost in extraction and are rebuilt here).
//!
//! A detour leaves the row, runs parallel to it at a lateral offset `h` past the obstacle box, and
//! comes back. The coarse polygon's corners are replaced by tangent arcs of radius `R = R_min`, so
//! the curvature is `0` or `±1/R_min` everywhere — the crawler's bound `|κ| ≤ 1/R_min` — and the
//! construction is O(1), with no iterative optimisation. Two cases, as in the paper:
//!
//! ```text
//! case 1, h ≤ 2R:  two arcs, turning φ then −φ,  with  h = 2R(1 − cos φ)
//!                  ⇒ φ = arccos(1 − h / 2R),   run-up  D = 2R·sin φ,
//!                  the centres O₁, O₂ are ‖O₁O₂‖ = 2R apart (the arcs touch at the inflection)
//! case 2, h > 2R:  arc of π/2, straight of h − 2R across the rows, arc of −π/2;  D = 2R
//! ```
//!
//! `D` is the distance along the row the lane change takes, so a detour whose offset line must be
//! reached at the box's near edge starts `D` before it. A U-turn between rows `2R` apart is the
//! semicircle of radius `R` (Figure 2); a turn that skips to the `j`-th next row is the
//! semicircle of radius `j·R`, which only lowers the curvature.

use std::f64::consts::{FRAC_PI_2, PI};

use super::path::{Piece, Pose2};

/// The run-up `D(h)` along the row of a lateral shift by `|h|` with radius `r` (module doc).
pub fn lane_change_run(h: f64, r: f64) -> f64 {
    let h = h.abs();
    if h <= 2.0 * r {
        2.0 * r * lane_change_angle(h, r).sin()
    } else {
        2.0 * r
    }
}

/// The arc angle `φ` of a lateral shift by `|h|` (case 1; `π/2` in case 2).
pub fn lane_change_angle(h: f64, r: f64) -> f64 {
    let h = h.abs();
    if h <= 2.0 * r {
        (1.0 - h / (2.0 * r)).clamp(-1.0, 1.0).acos()
    } else {
        FRAC_PI_2
    }
}

/// The tangent-arc lane change from `start` by `h` to the left of its heading (negative `h`: to
/// the right), radius `r`. It ends at the same heading, `D(h)` ahead and `h` to the side.
pub fn lane_change(start: Pose2, h: f64, r: f64) -> Vec<Piece> {
    if h.abs() < 1e-12 {
        return Vec::new();
    }
    let left = h > 0.0;
    let phi = lane_change_angle(h, r);
    let first = Piece::turn(start, r, phi, left);
    let mut pieces = vec![first];
    let mut pose = first.end();
    if h.abs() > 2.0 * r {
        let run = h.abs() - 2.0 * r;
        let to = [
            pose.x + run * pose.heading.cos(),
            pose.y + run * pose.heading.sin(),
        ];
        pieces.push(Piece::Line {
            from: pose.xy(),
            to,
        });
        pose = Pose2::new(to[0], to[1], pose.heading);
    }
    pieces.push(Piece::turn(pose, r, phi, !left));
    pieces
}

/// The U-turn semicircle from `start` to the row `offset` to its left (negative: right), radius
/// `|offset| / 2`.
pub fn u_turn(start: Pose2, offset: f64) -> Piece {
    Piece::turn(start, offset.abs() / 2.0, PI, offset > 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    fn end_of(pieces: &[Piece]) -> Pose2 {
        match pieces.last() {
            Some(p) => p.end(),
            None => panic!("no pieces"),
        }
    }

    fn assert_joined(pieces: &[Piece]) {
        for w in pieces.windows(2) {
            let (a, b) = (w[0].end(), w[1].start());
            assert_abs_diff_eq!(a.x, b.x, epsilon = 1e-9);
            assert_abs_diff_eq!(a.y, b.y, epsilon = 1e-9);
            assert_abs_diff_eq!((a.heading - b.heading).sin(), 0.0, epsilon = 1e-9);
        }
    }

    #[test]
    fn case_one_shift_of_r_uses_sixty_degree_arcs() {
        // h = R = 5: cos φ = 1 − 1/2 ⇒ φ = 60°, D = 2·5·sin 60° = 8.660 m.
        let r = 5.0;
        assert_abs_diff_eq!(lane_change_angle(5.0, r), PI / 3.0, epsilon = 1e-12);
        assert_abs_diff_eq!(
            lane_change_run(5.0, r),
            8.660_254_037_844_386,
            epsilon = 1e-12
        );
        let pieces = lane_change(Pose2::new(0.0, 0.0, 0.0), 5.0, r);
        assert_eq!(pieces.len(), 2);
        assert_joined(&pieces);
        let end = end_of(&pieces);
        assert_abs_diff_eq!(end.x, 8.660_254_037_844_386, epsilon = 1e-9);
        assert_abs_diff_eq!(end.y, 5.0, epsilon = 1e-9);
        assert_abs_diff_eq!(end.heading, 0.0, epsilon = 1e-9);
        // ‖O₁O₂‖ = 2R.
        match (pieces[0], pieces[1]) {
            (Piece::Arc { centre: a, .. }, Piece::Arc { centre: b, .. }) => {
                assert_abs_diff_eq!((a[0] - b[0]).hypot(a[1] - b[1]), 10.0, epsilon = 1e-9);
            }
            other => panic!("{other:?}"),
        }
        for p in &pieces {
            assert_abs_diff_eq!(p.curvature().abs(), 0.2, epsilon = 1e-12);
        }
    }

    #[test]
    fn case_two_shift_runs_straight_across_between_quarter_arcs() {
        // h = 30 > 2R = 10 heading west, shifted to the right (north): arcs of 90°, 20 m across.
        let pieces = lane_change(Pose2::new(100.0, 0.0, PI), -30.0, 5.0);
        assert_eq!(pieces.len(), 3);
        assert_joined(&pieces);
        assert_abs_diff_eq!(pieces[1].length(), 20.0, epsilon = 1e-9);
        let end = end_of(&pieces);
        assert_abs_diff_eq!(end.x, 90.0, epsilon = 1e-9);
        assert_abs_diff_eq!(end.y, 30.0, epsilon = 1e-9);
        assert_abs_diff_eq!(end.heading.cos(), -1.0, epsilon = 1e-9);
        assert_abs_diff_eq!(lane_change_run(30.0, 5.0), 10.0, epsilon = 1e-12);
    }

    #[test]
    fn u_turn_reverses_heading_two_radii_over() {
        let east = u_turn(Pose2::new(0.0, 0.0, 0.0), 10.0);
        assert_abs_diff_eq!(east.end().y, 10.0, epsilon = 1e-9);
        assert_abs_diff_eq!(east.end().x, 0.0, epsilon = 1e-9);
        assert_abs_diff_eq!(east.end().heading.cos(), -1.0, epsilon = 1e-9);
        assert_abs_diff_eq!(east.length(), 5.0 * PI, epsilon = 1e-9);
        let west = u_turn(Pose2::new(0.0, 0.0, PI), -30.0);
        assert_abs_diff_eq!(west.end().y, 30.0, epsilon = 1e-9);
        assert_abs_diff_eq!(west.curvature(), -1.0 / 15.0, epsilon = 1e-12);
    }
}
