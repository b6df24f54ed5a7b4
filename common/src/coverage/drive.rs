//! The trajectory a crawler executes on its coverage path (`shoal-coordinator run`): the path
//! driven at the tracking speed after its start delay, on the seabed map.
//!
//! The planner's path is exact (lines and arcs, [`CoveragePath`]); a vehicle link takes a timed
//! trajectory, straight lines at constant speed between samples. The path is sampled every
//! [`DRIVE_STEP_M`], each sample put on the map's seabed plus the crawler's sensor height, and
//! samples are dropped while the straight line that skips them stays within [`THIN_TOL_M`] of
//! every one (3-D, so the seabed's relief is kept). A straight row then needs a handful of
//! points instead of one per metre: 100 km of rows would otherwise be ~100,000 points, over the
//! message limit of the wire codec and slow for every cross-track lookup of the live picture.
//! Times stay those of the unthinned samples (constant speed), so a kept point is where the
//! crawler is due at that time, exactly.

use super::path::CoveragePath;
use super::TerrainMap25;
use crate::geometry::Vec3;
use crate::trajectory::Trajectory;

/// Sampling step along the path before thinning, metres: an arc of `R_min` = 4 m is then a
/// polygon within 3 cm of it (sagitta `s²/8R`).
pub const DRIVE_STEP_M: f64 = 1.0;
/// How far a thinned trajectory may be from the samples it skips, metres: well under the
/// crawler's tracking error (decimetres) and the fix noise, so thinning is not seen in the
/// cross-track figures.
pub const THIN_TOL_M: f64 = 0.05;
/// Longest run of samples one thinned leg may skip: bounds the work of the quadratic check
/// (a straight row is then a point every ~250 m).
const MAX_RUN: usize = 256;

/// `path` driven at `speed` m/s after `delay` s (held at its first point until then), each point
/// on `map`'s seabed plus `sensor_height_m`, thinned as the module says. Empty for an empty path.
pub fn drive_trajectory(
    path: &CoveragePath,
    map: &TerrainMap25,
    speed: f64,
    delay: f64,
    sensor_height_m: f64,
) -> Trajectory {
    let samples = path.sample(DRIVE_STEP_M);
    let speed = if speed.is_finite() && speed > 0.0 {
        speed
    } else {
        1.0
    };
    let delay = if delay.is_finite() {
        delay.max(0.0)
    } else {
        0.0
    };
    let times: Vec<f64> = samples.iter().map(|s| delay + s.s / speed).collect();
    let points: Vec<Vec3> = samples
        .iter()
        .map(|s| Vec3::new(s.x, s.y, map.elevation_at(s.x, s.y) + sensor_height_m))
        .collect();
    let keep = thin(&points, THIN_TOL_M);
    let mut out = Trajectory {
        times: Vec::with_capacity(keep.len() + 1),
        points: Vec::with_capacity(keep.len() + 1),
    };
    if let (Some(first), true) = (points.first(), delay > 0.0) {
        out.times.push(0.0);
        out.points.push(*first);
    }
    for k in keep {
        out.times.push(times[k]);
        out.points.push(points[k]);
    }
    out
}

/// Indices of `points` to keep: the first, the last, and greedily the farthest point each leg
/// can reach while every skipped point stays within `tol` of it (at most [`MAX_RUN`] apart).
pub(crate) fn thin(points: &[Vec3], tol: f64) -> Vec<usize> {
    if points.len() <= 2 {
        return (0..points.len()).collect();
    }
    let mut keep = vec![0];
    let mut a = 0;
    while a + 1 < points.len() {
        let mut b = a + 1;
        while b + 1 < points.len()
            && b + 1 - a <= MAX_RUN
            && (a + 1..=b)
                .all(|k| distance_to_segment(&points[k], &points[a], &points[b + 1]) <= tol)
        {
            b += 1;
        }
        keep.push(b);
        a = b;
    }
    keep
}

/// Distance from `p` to the segment `a`–`b`, metres.
fn distance_to_segment(p: &Vec3, a: &Vec3, b: &Vec3) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).norm()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coverage::path::{Piece, PieceKind, Pose2};
    use crate::coverage::test_map;
    use approx::assert_abs_diff_eq;

    /// A flat map at height 0, 200 m × 200 m.
    fn flat() -> Result<TerrainMap25, String> {
        Ok(test_map(100, vec![0.0; 100 * 100]))
    }

    fn line(from: [f64; 2], to: [f64; 2]) -> Piece {
        Piece::Line { from, to }
    }

    #[test]
    fn a_straight_row_is_two_points_timed_at_the_speed_and_on_the_seabed() -> Result<(), String> {
        let map = flat()?;
        let path = CoveragePath {
            pieces: vec![(PieceKind::Straight, line([10.0, 10.0], [110.0, 10.0]))],
        };
        let t = drive_trajectory(&path, &map, 0.5, 0.0, 1.5);
        assert_eq!(t.points.len(), 2);
        assert_abs_diff_eq!(t.times[0], 0.0, epsilon = 1e-9);
        assert_abs_diff_eq!(t.times[1], 200.0, epsilon = 1e-9); // 100 m at 0.5 m/s
        assert_abs_diff_eq!(t.points[1].x, 110.0, epsilon = 1e-9);
        assert_abs_diff_eq!(t.points[1].z, 1.5, epsilon = 1e-9); // seabed 0 + sensor 1.5
        Ok(())
    }

    /// On a seabed rising 0.1 m per metre east the row is still one leg (a straight line in
    /// 3-D), each end at its own height; on a seabed with a 1 m step in the middle it is not.
    #[test]
    fn the_seabed_relief_is_kept() -> Result<(), String> {
        let n = 100;
        let ramp: Vec<f64> = (0..n * n).map(|k| 0.1 * 2.0 * (k % n) as f64).collect();
        let map = test_map(n, ramp);
        let path = CoveragePath {
            pieces: vec![(PieceKind::Straight, line([20.0, 10.0], [120.0, 10.0]))],
        };
        let t = drive_trajectory(&path, &map, 0.5, 0.0, 0.0);
        assert_eq!(t.points.len(), 2);
        assert_abs_diff_eq!(t.points[1].z - t.points[0].z, 10.0, epsilon = 1e-6);
        let step: Vec<f64> = (0..n * n)
            .map(|k| if k % n >= 35 { 1.0 } else { 0.0 })
            .collect();
        let t = drive_trajectory(&path, &test_map(n, step), 0.5, 0.0, 0.0);
        assert!(t.points.len() >= 4, "{}", t.points.len());
        for w in t.points.windows(2) {
            assert!((w[1].z - w[0].z).abs() <= 1.0 + 1e-9);
        }
        Ok(())
    }

    #[test]
    fn a_delay_holds_at_the_start_and_shifts_every_time() -> Result<(), String> {
        let map = flat()?;
        let path = CoveragePath {
            pieces: vec![(PieceKind::Straight, line([10.0, 10.0], [30.0, 10.0]))],
        };
        let t = drive_trajectory(&path, &map, 0.5, 60.0, 0.0);
        assert_eq!(t.times.len(), 3);
        assert_abs_diff_eq!(t.times[0], 0.0, epsilon = 1e-9);
        assert_abs_diff_eq!(t.times[1], 60.0, epsilon = 1e-9);
        assert_abs_diff_eq!(t.times[2], 100.0, epsilon = 1e-9); // 60 + 20 m / 0.5 m/s
        assert_abs_diff_eq!((t.points[0] - t.points[1]).norm(), 0.0, epsilon = 1e-12);
        Ok(())
    }

    /// A U-turn of radius 5 m keeps every sample (none can go within the tolerance), stays
    /// within the tolerance of the arc everywhere, and takes the arc length over the speed; one
    /// of radius 50 m drops samples.
    #[test]
    fn a_turn_keeps_its_shape_within_the_tolerance() -> Result<(), String> {
        let map = flat()?;
        let start = Pose2::new(50.0, 50.0, 0.0);
        let turn = Piece::turn(start, 5.0, std::f64::consts::PI, true);
        let path = CoveragePath {
            pieces: vec![(PieceKind::UTurn, turn)],
        };
        let t = drive_trajectory(&path, &map, 0.5, 0.0, 0.0);
        let arc = 5.0 * std::f64::consts::PI;
        assert_abs_diff_eq!(*t.times.last().unwrap_or(&0.0), arc / 0.5, epsilon = 1e-9);
        // 16 chords of 0.98 m: skipping a sample makes a 2 m chord, 10 cm (s²/8R) off the arc,
        // over the tolerance, so every sample stays.
        assert_eq!(t.points.len(), 17);
        for s in path.sample(0.25) {
            let p = Vec3::new(s.x, s.y, 0.0);
            let d = t
                .points
                .windows(2)
                .map(|w| distance_to_segment(&p, &w[0], &w[1]))
                .fold(f64::INFINITY, f64::min);
            // The tolerance, plus the sagitta of the 1 m chords the samples make.
            assert!(d <= THIN_TOL_M + 0.03, "{d} at s = {}", s.s);
        }
        let wide = CoveragePath {
            pieces: vec![(
                PieceKind::UTurn,
                Piece::turn(start, 50.0, std::f64::consts::PI, true),
            )],
        };
        // 158 samples; a chord may span sqrt(8 · 50 · 0.05) ≈ 4.5 m, so about a quarter stay.
        let n = drive_trajectory(&wide, &map, 0.5, 0.0, 0.0).points.len();
        assert!((30..80).contains(&n), "{n}");
        Ok(())
    }

    #[test]
    fn the_distance_to_a_segment_is_to_its_nearest_point() {
        let a = Vec3::new(0.0, 0.0, 0.0);
        let b = Vec3::new(10.0, 0.0, 0.0);
        assert_abs_diff_eq!(
            distance_to_segment(&Vec3::new(5.0, 3.0, 4.0), &a, &b),
            5.0,
            epsilon = 1e-12
        );
        assert_abs_diff_eq!(
            distance_to_segment(&Vec3::new(-3.0, 4.0, 0.0), &a, &b),
            5.0,
            epsilon = 1e-12
        );
        assert_abs_diff_eq!(
            distance_to_segment(&Vec3::new(1.0, 1.0, 0.0), &a, &a),
            2f64.sqrt(),
            epsilon = 1e-12
        );
    }
}
