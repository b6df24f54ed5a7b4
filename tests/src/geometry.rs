//! The checker's own geometry, written from scratch on `[f64; 3]` points: vector arithmetic,
//! point–segment distance, segment–sphere chords, and the turn and pitch of legs.
//!
//! Timed trajectories (`[t, x, y, z]` samples) and the separation of two of them are in
//! [`trajectory`], whose items are re-exported here; the vector arithmetic both build on is in
//! `vector`, re-exported too.

pub mod trajectory;
mod vector;

pub use trajectory::*;
pub use vector::*;

/// Horizontal length below which a leg has no horizontal extent (and so no heading), metres.
pub const MIN_HORIZONTAL_M: f64 = 1e-9;

/// Heading change from the horizontal direction `u` to `v`, degrees in `[0, 180]`; 0 when either
/// has no horizontal extent.
fn heading_change_2d(u: [f64; 2], v: [f64; 2]) -> f64 {
    let nu = u[0].hypot(u[1]);
    let nv = v[0].hypot(v[1]);
    if nu <= MIN_HORIZONTAL_M || nv <= MIN_HORIZONTAL_M {
        return 0.0;
    }
    let cos = ((u[0] * v[0] + u[1] * v[1]) / (nu * nv)).clamp(-1.0, 1.0);
    let sin = (u[0] * v[1] - u[1] * v[0]) / (nu * nv);
    sin.abs().atan2(cos).to_degrees()
}

/// Horizontal heading change at the single corner `a→b→c`, degrees in `[0, 180]`; 0 when either
/// leg has no horizontal extent.
///
/// This is the corner on its own; the turn of a trajectory skips legs without horizontal extent
/// (see [`max_turn_deg`]).
pub fn heading_change_deg(a: &P3, b: &P3, c: &P3) -> f64 {
    heading_change_2d([b[0] - a[0], b[1] - a[1]], [c[0] - b[0], c[1] - b[1]])
}

/// Largest turn of the polyline `pts`, degrees in `[0, 180]`.
///
/// The turn at a waypoint is the horizontal heading change between the nearest preceding leg
/// with horizontal extent (longer than [`MIN_HORIZONTAL_M`] in x–y) and the next such leg: legs
/// without horizontal extent (vertical or zero-length) are skipped over and do not hide a turn.
/// 0 when fewer than two legs have horizontal extent.
pub fn max_turn_deg(pts: &[P3]) -> f64 {
    let headings: Vec<[f64; 2]> = pts
        .windows(2)
        .map(|w| [w[1][0] - w[0][0], w[1][1] - w[0][1]])
        .filter(|d| d[0].hypot(d[1]) > MIN_HORIZONTAL_M)
        .collect();
    headings
        .windows(2)
        .map(|w| heading_change_2d(w[0], w[1]))
        .fold(0.0, f64::max)
}

/// |pitch| of the leg `a→b`, degrees in `[0, 90]`; 0 for a leg of zero length.
pub fn abs_pitch_deg(a: &P3, b: &P3) -> f64 {
    let d = sub(b, a);
    let h = d[0].hypot(d[1]);
    if h == 0.0 && d[2] == 0.0 {
        return 0.0;
    }
    d[2].abs().atan2(h).to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn approx(a: f64, b: f64, eps: f64) -> bool {
        (a - b).abs() <= eps
    }

    #[test]
    fn segment_distance_by_hand() {
        // Foot inside the segment.
        assert!(approx(
            segment_point_distance(&[0., 0., 0.], &[10., 0., 0.], &[5., 3., 0.]),
            3.0,
            1e-12
        ));
        // Foot beyond the end: the end point (10, 0, 0) is 5 m from (13, 4, 0).
        assert!(approx(
            segment_point_distance(&[0., 0., 0.], &[10., 0., 0.], &[13., 4., 0.]),
            5.0,
            1e-12
        ));
        // Foot before the start, in 3-D: the start (0, 0, 0) is √(4 + 9 + 36) = 7 m away.
        assert!(approx(
            segment_point_distance(&[0., 0., 0.], &[0., 10., 0.], &[-2., -3., 6.]),
            7.0,
            1e-12
        ));
        // A degenerate segment is a point.
        assert!(approx(
            segment_point_distance(&[1., 1., 1.], &[1., 1., 1.], &[1., 1., 3.]),
            2.0,
            1e-12
        ));
    }

    #[test]
    fn chord_by_hand() {
        // Through the centre of a 30 m sphere: 60 m inside.
        assert!(approx(
            chord_inside_sphere(&[0., 0., 0.], &[1000., 0., 0.], &[500., 0., 0.], 30.0),
            60.0,
            1e-9
        ));
        // Offset 18 m from a 30 m sphere: 2·√(30² − 18²) = 48 m.
        assert!(approx(
            chord_inside_sphere(&[0., 0., 0.], &[1000., 0., 0.], &[500., 18., 0.], 30.0),
            48.0,
            1e-9
        ));
        // Ends inside: from the centre outwards only 30 m count; segment too short: 10 m.
        assert!(approx(
            chord_inside_sphere(&[500., 0., 0.], &[1000., 0., 0.], &[500., 0., 0.], 30.0),
            30.0,
            1e-9
        ));
        assert!(approx(
            chord_inside_sphere(&[495., 0., 0.], &[505., 0., 0.], &[500., 0., 0.], 30.0),
            10.0,
            1e-9
        ));
        // Misses.
        assert_eq!(
            chord_inside_sphere(&[0., 0., 0.], &[1000., 0., 0.], &[500., 40., 0.], 30.0),
            0.0
        );
    }

    #[test]
    fn turn_and_pitch_by_hand() {
        // 45° left turn, 90° right turn, U-turn.
        assert!(approx(
            heading_change_deg(&[0., 0., 0.], &[10., 0., 0.], &[20., 10., 0.]),
            45.0,
            1e-9
        ));
        assert!(approx(
            heading_change_deg(&[0., 0., 0.], &[10., 0., 5.], &[10., -10., 9.]),
            90.0,
            1e-9
        ));
        assert!(approx(
            heading_change_deg(&[0., 0., 0.], &[10., 0., 0.], &[0., 0., 0.]),
            180.0,
            1e-9
        ));
        // A vertical leg has no heading: no turn at either end of it.
        assert_eq!(
            heading_change_deg(&[0., 0., 0.], &[10., 0., 0.], &[10., 0., 10.]),
            0.0
        );
        assert_eq!(
            heading_change_deg(&[10., 0., 0.], &[10., 0., 10.], &[10., 10., 10.]),
            0.0
        );
        // Pitch: 45° up, 30° down (dz = −10, horizontal 10√3), vertical, still.
        assert!(approx(
            abs_pitch_deg(&[0., 0., 0.], &[10., 0., 10.]),
            45.0,
            1e-9
        ));
        assert!(approx(
            abs_pitch_deg(&[0., 0., 10.], &[0., 10. * 3f64.sqrt(), 0.]),
            30.0,
            1e-9
        ));
        assert!(approx(
            abs_pitch_deg(&[0., 0., 0.], &[0., 0., -3.]),
            90.0,
            1e-9
        ));
        assert_eq!(abs_pitch_deg(&[1., 2., 3.], &[1., 2., 3.]), 0.0);
    }

    #[test]
    fn max_turn_skips_a_vertical_leg() {
        // East, straight up, west: the vertical leg has no heading, the turn across it is 180°.
        let pts = [[10., 0., 0.], [20., 0., 0.], [20., 0., 10.], [10., 0., 10.]];
        assert!(approx(max_turn_deg(&pts), 180.0, 1e-9));
        // The corner function alone sees no turn at either end of the vertical leg.
        assert_eq!(heading_change_deg(&pts[0], &pts[1], &pts[2]), 0.0);
        assert_eq!(heading_change_deg(&pts[1], &pts[2], &pts[3]), 0.0);
    }

    #[test]
    fn max_turn_skips_a_zero_length_leg() {
        // East, a repeated point, north: 90°.
        let pts = [[0., 0., 0.], [10., 0., 0.], [10., 0., 0.], [10., 10., 0.]];
        assert!(approx(max_turn_deg(&pts), 90.0, 1e-9));
        // Several legs without horizontal extent in a row are skipped as well.
        let pts = [
            [0., 0., 0.],
            [10., 0., 0.],
            [10., 0., 0.],
            [10., 0., 5.],
            [10., 0., 5.],
            [20., 10., 5.],
        ];
        assert!(approx(max_turn_deg(&pts), 45.0, 1e-9));
    }

    #[test]
    fn max_turn_takes_the_largest_corner() {
        // Corners of 45° (left), 45° (right, back to east) and a U-turn: the largest counts.
        let pts = [
            [0., 0., 0.],
            [10., 0., 0.],
            [20., 10., 0.],
            [30., 10., 0.],
            [20., 10., 0.],
        ];
        assert!(approx(max_turn_deg(&pts), 180.0, 1e-9));
        // Without the U-turn: 45°.
        let pts = [[0., 0., 0.], [10., 0., 0.], [20., 10., 0.], [30., 10., 0.]];
        assert!(approx(max_turn_deg(&pts), 45.0, 1e-9));
    }

    #[test]
    fn max_turn_needs_two_horizontal_legs() {
        assert_eq!(max_turn_deg(&[]), 0.0);
        assert_eq!(max_turn_deg(&[[1., 2., 3.]]), 0.0);
        assert_eq!(max_turn_deg(&[[0., 0., 0.], [10., 0., 0.]]), 0.0);
        // One horizontal leg between vertical ones, and purely vertical motion.
        let pts = [[0., 0., 0.], [0., 0., 10.], [10., 0., 10.], [10., 0., 0.]];
        assert_eq!(max_turn_deg(&pts), 0.0);
        let pts = [[0., 0., 0.], [0., 0., 10.], [0., 0., 0.], [0., 0., 0.]];
        assert_eq!(max_turn_deg(&pts), 0.0);
        // Straight on with a climb in between: no turn.
        let pts = [[0., 0., 0.], [10., 0., 0.], [10., 0., 20.], [30., 0., 20.]];
        assert!(approx(max_turn_deg(&pts), 0.0, 1e-9));
    }
}
