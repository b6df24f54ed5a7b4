//! Geometric primitives shared by every cost and check: points, segments against spheres, and the
//! closest approach of two points moving linearly over a time interval.
//!
//! Frame: x east, y north, z up (metres). All functions are exact closed forms, no sampling, so a
//! check built on them cannot miss a graze between samples.

/// A point or direction in the world frame, metres.
pub type Vec3 = nalgebra::Vector3<f64>;

/// Each leg's length along the polyline through `points`, in order, metres.
pub fn leg_lengths(points: &[Vec3]) -> impl Iterator<Item = f64> + '_ {
    points.windows(2).map(|w| (w[1] - w[0]).norm())
}

/// Length of the polyline through `points`, metres: its legs' lengths summed in order.
pub fn polyline_length(points: &[Vec3]) -> f64 {
    leg_lengths(points).sum()
}

/// The larger of `x` and `y` as `x > y ? x : y`: one `maxsd` instruction, where `f64::max`,
/// which passes a NaN over, takes three (a NaN in either gives `y`). The fitness's box tests run
/// for every vehicle at every fleet evaluation.
#[inline]
pub fn larger(x: f64, y: f64) -> f64 {
    if x > y {
        x
    } else {
        y
    }
}

/// The smaller of `x` and `y` as `x < y ? x : y`, one `minsd`, as [`larger`] the larger.
#[inline]
pub fn smaller(x: f64, y: f64) -> f64 {
    if x < y {
        x
    } else {
        y
    }
}

/// The lower corner of the box of `a` and `b`: each coordinate's [`smaller`]. The value of
/// nalgebra's `a.inf(b)` (a NaN in either gives `b`'s coordinate too), except that of two zeros
/// of opposite sign it gives `b`'s, not `a`'s, which no difference, square or comparison tells
/// apart; `inf`'s `x <= y ? x : y` takes four instructions per coordinate.
#[inline]
pub fn lower_corner(a: &Vec3, b: &Vec3) -> Vec3 {
    Vec3::new(smaller(a.x, b.x), smaller(a.y, b.y), smaller(a.z, b.z))
}

/// The upper corner of the box of `a` and `b`, as [`lower_corner`] the lower: nalgebra's
/// `a.sup(b)` but for the sign of a zero.
#[inline]
pub fn upper_corner(a: &Vec3, b: &Vec3) -> Vec3 {
    Vec3::new(larger(a.x, b.x), larger(a.y, b.y), larger(a.z, b.z))
}

/// Parameter `u ∈ [0, 1]` of the point of segment `a→b` closest to `p`.
///
/// Hu et al. 2023, eq. (31) writes the segment as a line `a + u (b − a)`; clamping `u` to `[0, 1]` keeps
/// the test to the segment itself (eq. (33) alone would test the infinite line).
pub fn closest_param(a: &Vec3, b: &Vec3, p: &Vec3) -> f64 {
    let k = b - a;
    let len2 = k.norm_squared();
    if len2 <= f64::EPSILON {
        return 0.0;
    }
    ((p - a).dot(&k) / len2).clamp(0.0, 1.0)
}

/// Shortest distance from point `p` to segment `a→b`, metres.
pub fn segment_point_distance(a: &Vec3, b: &Vec3, p: &Vec3) -> f64 {
    let u = closest_param(a, b, p);
    (a + (b - a) * u - p).norm()
}

/// Closest approach of a path (its points joined by straight legs) to `centre` seen from above,
/// metres: what decides whether a 2-D keep-out circle (a geofence, a map's exclusion zone)
/// would cut a path that keeps clear in 3-D. Infinite for no points.
pub fn horizontal_distance_to_path(points: &[Vec3], centre: [f64; 2]) -> f64 {
    let flat = |p: &Vec3| Vec3::new(p.x, p.y, 0.0);
    let c = Vec3::new(centre[0], centre[1], 0.0);
    match points {
        [] => f64::INFINITY,
        [only] => (flat(only) - c).norm(),
        _ => points
            .windows(2)
            .map(|w| segment_point_distance(&flat(&w[0]), &flat(&w[1]), &c))
            .fold(f64::INFINITY, f64::min),
    }
}

/// Extra distance, metres, the planner's penalties demand beyond a hard limit (an obstacle's
/// inflated radius, a hazard's edge). A path the optimizer drives onto the limit itself would
/// otherwise pass or fail on the last bit of rounding, and a checker that computes the same
/// distance another way could see it 1e-13 m inside: with this guard whatever the planner accepts
/// is strictly clear for every checker.
pub const CONTACT_GUARD_M: f64 = 1e-6;

/// True when segment `a→b` comes strictly closer than `radius` to `centre` anywhere along it.
///
/// This is Hu et al. 2023, eq. (31)–(33) restricted to the segment: the quadratic
/// `λ1 u² + λ2 u + λ3 − r² = 0` has a root in `[0, 1]` exactly when the clamped closest point lies
/// inside the sphere. Touching the surface (distance == radius) is not a collision.
pub fn segment_hits_sphere(a: &Vec3, b: &Vec3, centre: &Vec3, radius: f64) -> bool {
    segment_point_distance(a, b, centre) < radius
}

/// Length of the part of segment `a→b` that lies inside the sphere (`centre`, `radius`), metres.
///
/// Solves `|a + u k − c|² = r²` for `u` (Hu et al. 2023, eq. (32): `λ1 = |k|²`, `λ2 = 2 k·(a − c)`,
/// `λ3 = |a − c|² − r²`) and clips the root interval to `[0, 1]`.
pub fn chord_inside_sphere(a: &Vec3, b: &Vec3, centre: &Vec3, radius: f64) -> f64 {
    let k = b - a;
    let l1 = k.norm_squared();
    if l1 <= f64::EPSILON {
        return 0.0;
    }
    let ac = a - centre;
    let l2 = 2.0 * k.dot(&ac);
    let l3 = ac.norm_squared() - radius * radius;
    let disc = l2 * l2 - 4.0 * l1 * l3;
    if disc <= 0.0 {
        return 0.0;
    }
    let sq = disc.sqrt();
    let u0 = ((-l2 - sq) / (2.0 * l1)).max(0.0);
    let u1 = ((-l2 + sq) / (2.0 * l1)).min(1.0);
    if u1 <= u0 {
        0.0
    } else {
        (u1 - u0) * l1.sqrt()
    }
}

/// Closest approach of two points that move linearly over `[0, dt]`.
///
/// `d0` is the relative position (second minus first) at the start and `d1` at the end; the
/// relative position is `d0 + (d1 − d0) s` for `s ∈ [0, 1]`. Returns the minimum distance, metres.
pub fn closest_approach(d0: &Vec3, d1: &Vec3) -> f64 {
    segment_point_distance(d0, d1, &Vec3::zeros())
}

/// Fraction of `[0, 1]` during which the relative position `d0 + (d1 − d0) s` is strictly closer
/// than `limit` to the origin (the time share of a separation breach on one linear interval).
pub fn fraction_within(d0: &Vec3, d1: &Vec3, limit: f64) -> f64 {
    let len = (d1 - d0).norm();
    if len <= f64::EPSILON {
        return if d0.norm() < limit { 1.0 } else { 0.0 };
    }
    chord_inside_sphere(d0, d1, &Vec3::zeros(), limit) / len
}

/// Heading change at the corner `a→b→c` in the horizontal plane, radians in `[0, π]`.
///
/// The turn limit of Zhi & Zuo 2024, §4.1.3 (θ ∈ [−35°, 35°]) is a yaw limit; depth changes are the pitch
/// limit's business. A leg with no horizontal extent has no heading and gives no turn.
pub fn heading_change(a: &Vec3, b: &Vec3, c: &Vec3) -> f64 {
    let (ux, uy) = (b.x - a.x, b.y - a.y);
    let (vx, vy) = (c.x - b.x, c.y - b.y);
    let nu = (ux * ux + uy * uy).sqrt();
    let nv = (vx * vx + vy * vy).sqrt();
    if nu <= 1e-9 || nv <= 1e-9 {
        return 0.0;
    }
    let cross = ux * vy - uy * vx;
    let dot = ux * vx + uy * vy;
    cross.atan2(dot).abs()
}

/// Horizontal extent below which a leg has no heading, metres.
pub const MIN_HEADING_EXTENT: f64 = 1e-9;

/// The heading changes along a path, radians in `[0, π]`, one per pair of consecutive legs
/// *that have a heading*: legs with no horizontal extent (vertical, or a repeated waypoint) are
/// skipped over, so they cannot hide the turn between the legs around them.
pub fn turns(points: &[Vec3]) -> impl Iterator<Item = f64> + '_ {
    let mut prev: Option<(f64, f64)> = None;
    points.windows(2).filter_map(move |w| {
        let (x, y) = (w[1].x - w[0].x, w[1].y - w[0].y);
        if (x * x + y * y).sqrt() <= MIN_HEADING_EXTENT {
            return None;
        }
        let turn = prev.map(|(px, py)| (px * y - py * x).atan2(px * x + py * y).abs());
        prev = Some((x, y));
        turn
    })
}

/// Pitch of segment `a→b` in radians, `atan2(Δz, horizontal length)`, in `[−π/2, π/2]`.
pub fn pitch(a: &Vec3, b: &Vec3) -> f64 {
    let d = b - a;
    let h = (d.x * d.x + d.y * d.y).sqrt();
    if h <= 1e-12 && d.z.abs() <= 1e-12 {
        return 0.0;
    }
    d.z.atan2(h)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_paths_closest_approach_from_above_ignores_depth() {
        // Legs (0,0,-50) → (100,0,-10) → (100,100,-10); centre (50, 30): 30 m from the first
        // leg, hypot(50, 30) = 58.3 m from the second's start; depth plays no part.
        let path = [
            Vec3::new(0.0, 0.0, -50.0),
            Vec3::new(100.0, 0.0, -10.0),
            Vec3::new(100.0, 100.0, -10.0),
        ];
        assert!((horizontal_distance_to_path(&path, [50.0, 30.0]) - 30.0).abs() < 1e-12);
        assert!((horizontal_distance_to_path(&path, [130.0, 60.0]) - 30.0).abs() < 1e-12);
        assert!((horizontal_distance_to_path(&path[..1], [3.0, 4.0]) - 5.0).abs() < 1e-12);
        assert_eq!(horizontal_distance_to_path(&[], [0.0, 0.0]), f64::INFINITY);
    }
    use approx::assert_abs_diff_eq;

    fn v(x: f64, y: f64, z: f64) -> Vec3 {
        Vec3::new(x, y, z)
    }

    #[test]
    fn point_to_segment_distance_by_hand() {
        // Perpendicular foot inside the segment: (5, 3, 0) above the x axis segment → 3.
        assert_abs_diff_eq!(
            segment_point_distance(&v(0., 0., 0.), &v(10., 0., 0.), &v(5., 3., 0.)),
            3.0,
            epsilon = 1e-12
        );
        // Foot beyond the end: nearest is the end point (10,0,0); distance to (13,4,0) is 5.
        assert_abs_diff_eq!(
            segment_point_distance(&v(0., 0., 0.), &v(10., 0., 0.), &v(13., 4., 0.)),
            5.0,
            epsilon = 1e-12
        );
        // Degenerate segment is a point.
        assert_abs_diff_eq!(
            segment_point_distance(&v(1., 1., 1.), &v(1., 1., 1.), &v(1., 1., 3.)),
            2.0,
            epsilon = 1e-12
        );
    }

    #[test]
    fn segment_sphere_hits_only_along_the_segment() {
        let c = v(5., 2., 0.);
        // The segment passes 2 m from the centre: hits r = 2.5, misses r = 1.5, touches r = 2.
        assert!(segment_hits_sphere(
            &v(0., 0., 0.),
            &v(10., 0., 0.),
            &c,
            2.5
        ));
        assert!(!segment_hits_sphere(
            &v(0., 0., 0.),
            &v(10., 0., 0.),
            &c,
            1.5
        ));
        assert!(!segment_hits_sphere(
            &v(0., 0., 0.),
            &v(10., 0., 0.),
            &c,
            2.0
        ));
        // Both end points are outside the sphere, yet the middle crosses it: a waypoint-only
        // test would miss this collision.
        let far = v(5., 0., 0.);
        assert!(segment_hits_sphere(
            &v(0., 0., 0.),
            &v(10., 0., 0.),
            &far,
            1.0
        ));
        // The infinite line would hit, the segment stops short of the sphere.
        assert!(!segment_hits_sphere(
            &v(0., 0., 0.),
            &v(10., 0., 0.),
            &v(20., 0., 0.),
            5.0
        ));
    }

    #[test]
    fn chord_length_by_hand() {
        // Line through the centre of a sphere of radius 3: chord 6.
        assert_abs_diff_eq!(
            chord_inside_sphere(&v(-10., 0., 0.), &v(10., 0., 0.), &v(0., 0., 0.), 3.0),
            6.0,
            epsilon = 1e-9
        );
        // Offset 3 from the centre of a radius-5 sphere: half chord 4 → chord 8.
        assert_abs_diff_eq!(
            chord_inside_sphere(&v(-10., 3., 0.), &v(10., 3., 0.), &v(0., 0., 0.), 5.0),
            8.0,
            epsilon = 1e-9
        );
        // Segment ending at the centre: only the half from the surface to the centre, 5.
        assert_abs_diff_eq!(
            chord_inside_sphere(&v(-10., 0., 0.), &v(0., 0., 0.), &v(0., 0., 0.), 5.0),
            5.0,
            epsilon = 1e-9
        );
        // Miss.
        assert_abs_diff_eq!(
            chord_inside_sphere(&v(-10., 6., 0.), &v(10., 6., 0.), &v(0., 0., 0.), 5.0),
            0.0,
            epsilon = 1e-12
        );
    }

    #[test]
    fn closest_approach_of_crossing_vehicles() {
        // Relative position goes from (-10, 4, 0) to (10, 4, 0): closest 4 at mid-interval.
        assert_abs_diff_eq!(
            closest_approach(&v(-10., 4., 0.), &v(10., 4., 0.)),
            4.0,
            epsilon = 1e-12
        );
        // Within 5 m while |x| < 3, i.e. 6 m of a 20 m relative path: 30 % of the interval.
        assert_abs_diff_eq!(
            fraction_within(&v(-10., 4., 0.), &v(10., 4., 0.), 5.0),
            0.3,
            epsilon = 1e-12
        );
        // Stationary relative position: all or nothing.
        assert_abs_diff_eq!(fraction_within(&v(3., 0., 0.), &v(3., 0., 0.), 5.0), 1.0);
        assert_abs_diff_eq!(fraction_within(&v(6., 0., 0.), &v(6., 0., 0.), 5.0), 0.0);
    }

    #[test]
    fn turns_skip_legs_without_a_heading() {
        let deg = |pts: &[Vec3]| turns(pts).map(f64::to_degrees).collect::<Vec<_>>();
        // East, up (vertical), west: the vertical leg does not hide the U-turn.
        let t = deg(&[
            v(0., 0., 0.),
            v(10., 0., 0.),
            v(10., 0., 10.),
            v(0., 0., 10.),
        ]);
        assert_eq!(t.len(), 1);
        assert_abs_diff_eq!(t[0], 180.0, epsilon = 1e-9);
        // East, a repeated waypoint, north: 90°.
        let t = deg(&[
            v(0., 0., 0.),
            v(10., 0., 0.),
            v(10., 0., 0.),
            v(10., 10., 0.),
        ]);
        assert_eq!(t.len(), 1);
        assert_abs_diff_eq!(t[0], 90.0, epsilon = 1e-9);
        // Straight line: one corner, 0°.
        let t = deg(&[v(0., 0., 0.), v(1., 0., 0.), v(2., 0., 1.)]);
        assert_eq!(t.len(), 1);
        assert_abs_diff_eq!(t[0], 0.0, epsilon = 1e-9);
        // Fewer than two legs with a heading: no turn at all.
        assert!(deg(&[v(0., 0., 0.), v(0., 0., 5.), v(3., 0., 5.)]).is_empty());
    }

    #[test]
    fn heading_and_pitch_by_hand() {
        // East then north-east: 45° turn, either direction counts as positive.
        let t = heading_change(&v(0., 0., 0.), &v(1., 0., 0.), &v(2., 1., 0.));
        assert_abs_diff_eq!(t.to_degrees(), 45.0, epsilon = 1e-9);
        let t = heading_change(&v(0., 0., 0.), &v(1., 0., 0.), &v(2., -1., 5.));
        assert_abs_diff_eq!(t.to_degrees(), 45.0, epsilon = 1e-9);
        // Reversal is 180°.
        let t = heading_change(&v(0., 0., 0.), &v(1., 0., 0.), &v(0., 0., 0.));
        assert_abs_diff_eq!(t.to_degrees(), 180.0, epsilon = 1e-9);
        // 3-4-5: rise 3 over horizontal 4 → atan(0.75) = 36.87°.
        assert_abs_diff_eq!(
            pitch(&v(0., 0., 0.), &v(4., 0., 3.)).to_degrees(),
            36.869_897_645_844_02,
            epsilon = 1e-9
        );
        assert_abs_diff_eq!(
            pitch(&v(0., 0., 3.), &v(0., 4., 0.)).to_degrees(),
            -36.869_897_645_844_02,
            epsilon = 1e-9
        );
    }

    #[test]
    fn box_corners_by_hand() {
        let (a, b) = (v(1., -2., 3.), v(-1., 5., 3.));
        assert_eq!(lower_corner(&a, &b), v(-1., -2., 3.));
        assert_eq!(upper_corner(&a, &b), v(1., 5., 3.));
        // A NaN gives the second point's coordinate, as nalgebra's inf and sup do.
        let nan = v(f64::NAN, 0., 0.);
        assert_eq!(lower_corner(&nan, &a).x, 1.0);
        assert!(lower_corner(&a, &nan).x.is_nan());
        assert!(upper_corner(&a, &nan).x.is_nan());
    }

    mod corners {
        use super::*;
        use proptest::prelude::*;

        /// Ordinary coordinates, zeros of either sign, NaN and an infinity.
        fn coordinate(infinity: f64) -> impl Strategy<Value = f64> {
            prop_oneof![
                -1e4..1e4f64,
                Just(0.0),
                Just(-0.0),
                Just(f64::NAN),
                Just(infinity)
            ]
        }

        proptest! {
            #[test]
            fn box_corners_are_nalgebras_but_for_the_sign_of_a_zero(
                a in prop::array::uniform3(coordinate(f64::INFINITY)),
                b in prop::array::uniform3(coordinate(f64::NEG_INFINITY)),
            ) {
                let (a, b) = (Vec3::from(a), Vec3::from(b));
                let same = |ours: Vec3, theirs: Vec3| {
                    ours.iter().zip(theirs.iter()).all(|(x, y)| {
                        x.to_bits() == y.to_bits()
                            || (x.is_nan() && y.is_nan())
                            || (*x == 0.0 && *y == 0.0)
                    })
                };
                prop_assert!(same(lower_corner(&a, &b), a.inf(&b)), "{:?} {:?}", a, b);
                prop_assert!(same(upper_corner(&a, &b), a.sup(&b)), "{:?} {:?}", a, b);
            }
        }
    }
}
