//! Clamped, uniform B-spline curves (Lu et al. 2023, §2.4, eq. (12)–(13)): the smoothed path of a
//! crawler is the cubic B-spline of its control points, and it is the curve — not the control
//! polygon — that collision, slope and hazard checks and the reported length use.
//!
//! Knots: the end knots are repeated `k + 1` times (the curve starts at the first control point
//! and ends at the last) and the inner knots are evenly spaced in [0, 1] ("quasi-uniform", as the
//! paper has it). With fewer than `k + 1` control points the degree drops to `points − 1` (two
//! points give their straight segment).

use crate::geometry::Vec3;

/// The clamped uniform knot vector of `n` control points and degree `k` (`n + k + 1` knots in
/// [0, 1]); `k` is lowered to `n − 1` when there are too few points.
pub fn clamped_knots(n: usize, k: usize) -> Vec<f64> {
    let k = k.min(n.saturating_sub(1));
    let inner = n.saturating_sub(k + 1);
    let mut knots = Vec::with_capacity(n + k + 1);
    knots.extend(std::iter::repeat_n(0.0, k + 1));
    for j in 1..=inner {
        knots.push(j as f64 / (inner + 1) as f64);
    }
    knots.extend(std::iter::repeat_n(1.0, k + 1));
    knots
}

/// `N_{i,k}(u)` by the Cox–de Boor recursion (Lu et al. 2023, eq. (13)); a 0/0 term counts as 0.
/// `N_{i,0}` is 1 on the half-open span `[u_i, u_{i+1})`, and on the last non-empty span also at
/// its right end, so that the basis sums to 1 on the whole of [0, 1] (the paper's closed spans
/// would count a knot twice).
pub fn basis(i: usize, k: usize, u: f64, knots: &[f64]) -> f64 {
    if k == 0 {
        let (a, b) = (knots[i], knots[i + 1]);
        let last_span = b == 1.0 && a < b && knots[i + 1..].iter().all(|t| *t == 1.0);
        return if (a <= u && u < b) || (last_span && u == 1.0) {
            1.0
        } else {
            0.0
        };
    }
    let mut value = 0.0;
    let left = knots[i + k] - knots[i];
    if left > 0.0 {
        value += (u - knots[i]) / left * basis(i, k - 1, u, knots);
    }
    let right = knots[i + k + 1] - knots[i + 1];
    if right > 0.0 {
        value += (knots[i + k + 1] - u) / right * basis(i + 1, k - 1, u, knots);
    }
    value
}

/// The curve point at `u` ∈ [0, 1] (clamped into it): eq. (12), `p(u) = Σ p_i N_{i,k}(u)`.
pub fn point(control: &[Vec3], k: usize, u: f64) -> Vec3 {
    let n = control.len();
    if n == 0 {
        return Vec3::zeros();
    }
    let k = k.min(n - 1);
    let knots = clamped_knots(n, k);
    let u = if u.is_finite() {
        u.clamp(0.0, 1.0)
    } else {
        0.0
    };
    control
        .iter()
        .enumerate()
        .fold(Vec3::zeros(), |acc, (i, p)| {
            acc + p * basis(i, k, u, &knots)
        })
}

/// `samples` points (at least 2) evenly spaced in the parameter, from the first control point to
/// the last.
pub fn sample(control: &[Vec3], k: usize, samples: usize) -> Vec<Vec3> {
    let m = samples.max(2);
    (0..m)
        .map(|j| point(control, k, j as f64 / (m - 1) as f64))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::polyline_length;
    use approx::assert_abs_diff_eq;

    fn v(x: f64, y: f64, z: f64) -> Vec3 {
        Vec3::new(x, y, z)
    }

    #[test]
    fn knots_are_clamped_and_uniform() {
        assert_eq!(
            clamped_knots(6, 3),
            vec![0.0, 0.0, 0.0, 0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0, 1.0, 1.0, 1.0]
        );
        assert_eq!(
            clamped_knots(4, 3),
            vec![0.0; 4]
                .into_iter()
                .chain(vec![1.0; 4])
                .collect::<Vec<_>>()
        );
        // Two points: degree 1, the segment.
        assert_eq!(clamped_knots(2, 3), vec![0.0, 0.0, 1.0, 1.0]);
    }

    #[test]
    fn four_points_give_the_cubic_bezier_by_hand() {
        // With 4 control points and k = 3 the curve is the Bézier curve:
        // p(½) = (P0 + 3 P1 + 3 P2 + P3) / 8.
        let c = [v(0., 0., 0.), v(1., 2., 0.), v(3., 2., 1.), v(4., 0., 1.)];
        let p = point(&c, 3, 0.5);
        assert_abs_diff_eq!(p.x, (0.0 + 3.0 + 9.0 + 4.0) / 8.0, epsilon = 1e-12);
        assert_abs_diff_eq!(p.y, (0.0 + 6.0 + 6.0 + 0.0) / 8.0, epsilon = 1e-12);
        assert_abs_diff_eq!(p.z, (0.0 + 0.0 + 3.0 + 1.0) / 8.0, epsilon = 1e-12);
    }

    #[test]
    fn the_curve_starts_and_ends_on_the_end_points_and_the_basis_sums_to_one() {
        let c = [
            v(0., 0., 0.),
            v(10., 5., 1.),
            v(20., -5., 2.),
            v(30., 8., 0.),
            v(40., 0., 3.),
            v(50., 2., 1.),
        ];
        let s = sample(&c, 3, 41);
        assert_eq!(s.len(), 41);
        assert_abs_diff_eq!((s[0] - c[0]).norm(), 0.0, epsilon = 1e-12);
        assert_abs_diff_eq!((s[40] - c[5]).norm(), 0.0, epsilon = 1e-12);
        let knots = clamped_knots(6, 3);
        for j in 0..=20 {
            let u = j as f64 / 20.0;
            let sum: f64 = (0..6).map(|i| basis(i, 3, u, &knots)).sum();
            assert_abs_diff_eq!(sum, 1.0, epsilon = 1e-12);
        }
        // Convex hull: every sample inside the control points' box.
        for p in &s {
            assert!(p.x >= -1e-9 && p.x <= 50.0 + 1e-9);
            assert!(p.y >= -5.0 - 1e-9 && p.y <= 8.0 + 1e-9);
        }
    }

    #[test]
    fn collinear_control_points_give_a_straight_curve_no_longer_than_the_polygon() {
        let c: Vec<Vec3> = (0..7)
            .map(|i| v(i as f64 * 3.0, i as f64 * 4.0, 0.0))
            .collect();
        let s = sample(&c, 3, 50);
        for p in &s {
            // On the line y = 4/3 x.
            assert_abs_diff_eq!(p.y, p.x * 4.0 / 3.0, epsilon = 1e-9);
        }
        assert_abs_diff_eq!(polyline_length(&s), 30.0, epsilon = 1e-9);
        // A bent polygon: the smoothed curve cuts the corners.
        let bent = [
            v(0., 0., 0.),
            v(10., 10., 0.),
            v(20., 0., 0.),
            v(30., 10., 0.),
        ];
        let curve = polyline_length(&sample(&bent, 3, 200));
        assert!(curve < polyline_length(&bent), "{curve}");
        assert!(curve > 30.0);
    }

    #[test]
    fn degenerate_inputs_do_not_panic() {
        assert_eq!(point(&[], 3, 0.5), Vec3::zeros());
        let one = [v(1., 2., 3.)];
        assert_eq!(sample(&one, 3, 5), vec![one[0]; 5]);
        let two = [v(0., 0., 0.), v(2., 0., 0.)];
        assert_abs_diff_eq!(point(&two, 3, 0.25).x, 0.5, epsilon = 1e-12);
        assert_abs_diff_eq!(point(&two, 3, f64::NAN).x, 0.0, epsilon = 1e-12);
    }
}
