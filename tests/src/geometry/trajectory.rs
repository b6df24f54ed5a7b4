//! Timed trajectories for the checker: a vehicle flies straight at constant speed between
//! consecutive `[t, x, y, z]` samples and holds at its first and last sample outside them. Here:
//! position at an instant, and the exact closest approach and breach time of two vehicles (with a
//! sampled closest approach to cross-check it).

use super::vector::{closest_param, dist, lerp, norm, param_interval_within, sub, P3};

/// Position part of a sample.
pub fn point(sample: &[f64; 4]) -> P3 {
    [sample[1], sample[2], sample[3]]
}

/// Position at time `t`: linear between samples, held before the first and after the last.
/// At a sample time shared by several samples (a zero-duration leg) the last one is used.
pub fn position_at(traj: &[[f64; 4]], t: f64) -> P3 {
    let (Some(first), Some(last)) = (traj.first(), traj.last()) else {
        return [f64::NAN; 3];
    };
    if t < first[0] {
        return point(first);
    }
    if t >= last[0] {
        return point(last);
    }
    for w in traj.windows(2) {
        if w[0][0] <= t && t < w[1][0] {
            let s = (t - w[0][0]) / (w[1][0] - w[0][0]);
            return lerp(&point(&w[0]), &point(&w[1]), s);
        }
    }
    point(last)
}

/// The straight piece a trajectory flies over `[t0, t1]`, where `(t0, t1)` contains no sample
/// time: its positions at `t0` and `t1` (limits from inside the interval).
pub fn piece(traj: &[[f64; 4]], t0: f64, t1: f64) -> (P3, P3) {
    let tm = 0.5 * (t0 + t1);
    let (Some(first), Some(last)) = (traj.first(), traj.last()) else {
        return ([f64::NAN; 3], [f64::NAN; 3]);
    };
    if tm <= first[0] {
        return (point(first), point(first));
    }
    if tm >= last[0] {
        return (point(last), point(last));
    }
    for w in traj.windows(2) {
        let (ta, tb) = (w[0][0], w[1][0]);
        if ta <= tm && tm < tb {
            let (a, b) = (point(&w[0]), point(&w[1]));
            let at = |t: f64| lerp(&a, &b, (t - ta) / (tb - ta));
            return (at(t0), at(t1));
        }
    }
    (point(last), point(last))
}

/// Where the last sample of a trajectory is timed (0 for an empty one).
pub fn arrival(traj: &[[f64; 4]]) -> f64 {
    traj.last().map_or(0.0, |s| s[0])
}

/// The instants at which the relative motion of `a` and `b` may change: 0, every sample time
/// in `[0, T]` of either trajectory and `T`, the later arrival; sorted, without duplicates.
pub fn breakpoints(a: &[[f64; 4]], b: &[[f64; 4]]) -> Vec<f64> {
    let end = arrival(a).max(arrival(b)).max(0.0);
    let mut ts: Vec<f64> = a
        .iter()
        .chain(b.iter())
        .map(|s| s[0])
        .filter(|t| t.is_finite() && *t >= 0.0 && *t <= end)
        .chain([0.0, end])
        .collect();
    ts.sort_by(f64::total_cmp);
    ts.dedup();
    ts
}

/// Closest approach of two vehicles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Approach {
    /// Smallest distance, metres.
    pub distance: f64,
    /// An instant at which it occurs, seconds.
    pub time: f64,
}

/// Exact closest approach of `a` and `b` over `[0, max arrival]`.
///
/// Between consecutive breakpoints both vehicles move linearly, so their relative position
/// `d(s) = d0 + (d1 − d0) s`, `s ∈ [0, 1]`, is linear too and its smallest norm is at the
/// clamped projection of the origin onto that segment.
pub fn min_separation(a: &[[f64; 4]], b: &[[f64; 4]]) -> Approach {
    let mut best = Approach {
        distance: dist(&position_at(a, 0.0), &position_at(b, 0.0)),
        time: 0.0,
    };
    for (t0, t1, d0, d1) in relative_pieces(a, b) {
        let s = closest_param(&d0, &d1, &[0.0; 3]);
        let d = norm(&lerp(&d0, &d1, s));
        if d < best.distance {
            best = Approach {
                distance: d,
                time: t0 + s * (t1 - t0),
            };
        }
    }
    best
}

/// Between consecutive breakpoints of `a` and `b`, the relative position `b − a` moves linearly:
/// `(t0, t1, d(t0), d(t1))` for each such piece.
fn relative_pieces<'a>(
    a: &'a [[f64; 4]],
    b: &'a [[f64; 4]],
) -> impl Iterator<Item = (f64, f64, P3, P3)> + 'a {
    let ts = breakpoints(a, b);
    (1..ts.len()).map(move |k| {
        let (t0, t1) = (ts[k - 1], ts[k]);
        let (a0, a1) = piece(a, t0, t1);
        let (b0, b1) = piece(b, t0, t1);
        (t0, t1, sub(&b0, &a0), sub(&b1, &a1))
    })
}

/// Total time in `[0, max arrival]` during which `a` and `b` are strictly closer than `limit`.
pub fn breach_time(a: &[[f64; 4]], b: &[[f64; 4]], limit: f64) -> f64 {
    let mut total = 0.0;
    for (t0, t1, d0, d1) in relative_pieces(a, b) {
        let (s0, s1) = param_interval_within(&d0, &d1, &[0.0; 3], limit);
        total += (s1 - s0).max(0.0) * (t1 - t0);
    }
    total
}

/// Closest approach found by sampling `[0, max arrival]` every `step` seconds (and at the end):
/// an upper bound of [`min_separation`], for cross-checking it.
pub fn sampled_min_separation(a: &[[f64; 4]], b: &[[f64; 4]], step: f64) -> Approach {
    let end = arrival(a).max(arrival(b)).max(0.0);
    let n = if step > 0.0 {
        (end / step).ceil() as usize
    } else {
        0
    };
    let mut best = Approach {
        distance: f64::INFINITY,
        time: 0.0,
    };
    for k in 0..=n {
        let t = (k as f64 * step).min(end);
        let d = dist(&position_at(a, t), &position_at(b, t));
        if d < best.distance {
            best = Approach {
                distance: d,
                time: t,
            };
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn approx(a: f64, b: f64, eps: f64) -> bool {
        (a - b).abs() <= eps
    }

    #[test]
    fn position_holds_before_and_after() {
        let t = [[0., 0., 0., 0.], [10., 10., 0., 0.], [20., 10., 20., 0.]];
        assert_eq!(position_at(&t, -5.0), [0., 0., 0.]);
        assert_eq!(position_at(&t, 5.0), [5., 0., 0.]);
        assert_eq!(position_at(&t, 15.0), [10., 10., 0.]);
        assert_eq!(position_at(&t, 20.0), [10., 20., 0.]);
        assert_eq!(position_at(&t, 1e6), [10., 20., 0.]);
    }

    #[test]
    fn head_on_crossing_30_m_apart() {
        // a east along y = 0, b west along y = 30, both at 1 m/s: closest at t = 500, 30 m,
        // between samples (there are none in between).
        let a = [[0., 0., 0., -50.], [1000., 1000., 0., -50.]];
        let b = [[0., 1000., 30., -50.], [1000., 0., 30., -50.]];
        let m = min_separation(&a, &b);
        assert!(approx(m.distance, 30.0, 1e-9), "{m:?}");
        assert!(approx(m.time, 500.0, 1e-9), "{m:?}");
        // Closer than 50 m while the x gap 1000 − 2t is within ±√(50² − 30²) = ±40 m: 40 s.
        assert!(approx(breach_time(&a, &b, 50.0), 40.0, 1e-9));
        assert_eq!(breach_time(&a, &b, 30.0), 0.0);
        // Sampling every second finds the same (t = 500 is a sample).
        assert!(approx(
            sampled_min_separation(&a, &b, 1.0).distance,
            30.0,
            1e-9
        ));
    }

    #[test]
    fn early_arrival_holds_at_goal_while_the_other_passes() {
        // a: (0,0,0) → (100,0,0) by t = 100, then holds. b: (400,20,0) → (0,20,0) at 1 m/s.
        // Before t = 100 the gap is ≥ 200 m; afterwards b passes the parked a at t = 300, 20 m away.
        // A checker that stopped at the earlier arrival would report 200 m.
        let a = [[0., 0., 0., 0.], [100., 100., 0., 0.]];
        let b = [[0., 400., 20., 0.], [400., 0., 20., 0.]];
        let m = min_separation(&a, &b);
        assert!(approx(m.distance, 20.0, 1e-9), "{m:?}");
        assert!(approx(m.time, 300.0, 1e-9), "{m:?}");
        // Symmetric.
        let m2 = min_separation(&b, &a);
        assert!(approx(m2.distance, 20.0, 1e-9) && approx(m2.time, 300.0, 1e-9));
        // Within 25 m while |x − 100| < 15: t in (285, 315): 30 s.
        assert!(approx(breach_time(&a, &b, 25.0), 30.0, 1e-9));
    }

    #[test]
    fn closest_approach_between_samples_of_both() {
        // a has a corner at t = 50, b at t = 70: the merged breakpoints are 0, 50, 70, 100.
        // a: (0,0,0) → (50,0,0) → (50,50,0); b: (100,25,0) → (30,25,0) → (30, 25, 30).
        // On [50, 70] a = (50, t − 50, 0) and b = (100 − t, 25, 0), so b − a = (50 − t, 75 − t, 0),
        // shortest at t = 62.5: 12.5·√2 ≈ 17.7 m. ([0, 50] gives ≥ 25 m, [70, 100] ≥ 20.3 m.)
        let a = [[0., 0., 0., 0.], [50., 50., 0., 0.], [100., 50., 50., 0.]];
        let b = [
            [0., 100., 25., 0.],
            [70., 30., 25., 0.],
            [100., 30., 25., 30.],
        ];
        let m = min_separation(&a, &b);
        assert!(approx(m.distance, 12.5 * 2f64.sqrt(), 1e-9), "{m:?}");
        assert!(approx(m.time, 62.5, 1e-9), "{m:?}");
        let s = sampled_min_separation(&a, &b, 0.5);
        assert!(approx(s.distance, m.distance, 1e-9), "{s:?}");
    }

    /// Deterministic pseudo-random numbers in [0, 1) (no RNG crate needed).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn random_trajectory(rng: &mut Lcg, n: usize, speed: f64) -> Vec<[f64; 4]> {
        let mut t = 0.0;
        let mut p = [rng.next() * 400.0, rng.next() * 400.0, rng.next() * 100.0];
        let mut out = vec![[t, p[0], p[1], p[2]]];
        for _ in 1..n {
            let q = [rng.next() * 400.0, rng.next() * 400.0, rng.next() * 100.0];
            let v = speed * (0.5 + rng.next());
            t += dist(&p, &q) / v;
            p = q;
            out.push([t, p[0], p[1], p[2]]);
        }
        out
    }

    #[test]
    fn exact_separation_agrees_with_dense_sampling() {
        let mut rng = Lcg(7);
        for _ in 0..200 {
            let na = 2 + (rng.next() * 8.0) as usize;
            let nb = 2 + (rng.next() * 8.0) as usize;
            let a = random_trajectory(&mut rng, na, 2.0);
            let b = random_trajectory(&mut rng, nb, 2.0);
            let exact = min_separation(&a, &b);
            // The exact minimum is a lower bound of any sample and realised at its instant.
            let at = dist(&position_at(&a, exact.time), &position_at(&b, exact.time));
            assert!(approx(at, exact.distance, 1e-9), "{exact:?} vs {at}");
            for step in [1.0, 0.1] {
                let dense = sampled_min_separation(&a, &b, step);
                assert!(
                    exact.distance <= dense.distance + 1e-9,
                    "{exact:?} > {dense:?}"
                );
                // Relative speed ≤ 2 · 3 m/s, so the nearest sample is at most 6 · step / 2 worse.
                assert!(
                    dense.distance - exact.distance <= 3.0 * step + 1e-9,
                    "{exact:?} vs {dense:?} at {step} s"
                );
            }
        }
    }
}
