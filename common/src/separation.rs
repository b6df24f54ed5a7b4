//! Spatial coupling on *timed* trajectories (Zhi & Zuo 2024, eq. (1), (11)): the distance between two
//! vehicles at the same instant, over the whole mission.
//!
//! Both trajectories are piecewise linear in time, so on every interval between consecutive sample
//! times of either vehicle their relative position is linear too, and the closest approach and the
//! time spent closer than `d_min` have closed forms ([`crate::geometry::closest_approach`],
//! [`crate::geometry::fraction_within`]). Nothing is sampled, so no graze between samples is missed.
//! A vehicle holds at its last sample after it arrives.

use crate::geometry::{fraction_within, Vec3};
use crate::trajectory::Trajectory;

/// How close two vehicles come, and for how long they breach the minimum separation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairSeparation {
    /// Smallest distance at any instant, metres.
    pub min_distance: f64,
    /// An instant at which the smallest distance occurs, seconds.
    pub min_time: f64,
    /// Total time during which the distance is below `d_min`, seconds.
    pub breach_s: f64,
}

/// A trajectory prepared for fast queries: each leg's start time, start point and velocity, so a
/// position is one multiply-add, with no search and no division.
#[derive(Debug, Clone)]
pub struct Motion<'a> {
    /// Leg start times, then the arrival time (one more than legs).
    times: &'a [f64],
    /// Leg start points, then the final point.
    points: &'a [Vec3],
    /// Velocity on each leg, m/s (zero for a leg of zero duration); borrowed when prepared once
    /// for many queries ([`Motion::prepared`]).
    velocities: std::borrow::Cow<'a, [Vec3]>,
    /// Fastest leg speed, m/s: bounds how fast a distance can shrink.
    max_speed: f64,
}

impl<'a> Motion<'a> {
    /// Prepares `t` (at least one sample).
    pub fn new(t: &'a Trajectory) -> Motion<'a> {
        let (velocities, max_speed) = Motion::velocities_of(t);
        Motion {
            times: &t.times,
            points: &t.points,
            velocities: std::borrow::Cow::Owned(velocities),
            max_speed,
        }
    }

    /// The trajectory through `points` at `times` (at least one sample) with its legs'
    /// velocities and top speed computed once by [`Motion::velocities_into`]: a trajectory
    /// queried many times is prepared without allocating.
    pub fn prepared(
        times: &'a [f64],
        points: &'a [Vec3],
        velocities: &'a [Vec3],
        max_speed: f64,
    ) -> Motion<'a> {
        Motion {
            times,
            points,
            velocities: std::borrow::Cow::Borrowed(velocities),
            max_speed,
        }
    }

    /// Each leg's velocity and the fastest leg's speed, m/s.
    pub fn velocities_of(t: &Trajectory) -> (Vec<Vec3>, f64) {
        let mut velocities = Vec::with_capacity(t.times.len().saturating_sub(1));
        let max_speed = Motion::velocities_into(&t.times, &t.points, &mut velocities);
        (velocities, max_speed)
    }

    /// [`Motion::velocities_of`] of the trajectory through `points` at `times`, appending the
    /// velocities to a buffer the caller reuses; returns the fastest leg's speed.
    pub fn velocities_into(times: &[f64], points: &[Vec3], out: &mut Vec<Vec3>) -> f64 {
        // The top speed's square root once, not every leg's: the root is monotonic and
        // correctly rounded, so the result is the same to the last bit.
        let mut max_speed2 = 0.0f64;
        for (tt, pp) in times.windows(2).zip(points.windows(2)) {
            let dt = tt[1] - tt[0];
            let v = if dt > 0.0 {
                (pp[1] - pp[0]) / dt
            } else {
                Vec3::zeros()
            };
            max_speed2 = max_speed2.max(v.norm_squared());
            out.push(v);
        }
        max_speed2.sqrt()
    }

    /// Position at `time` on leg `k` (or held at the end when `k` is past the last leg).
    #[inline]
    fn at(&self, k: usize, time: f64) -> Vec3 {
        match self.velocities.get(k) {
            Some(v) => self.points[k] + v * (time - self.times[k]),
            None => self.points[self.points.len() - 1],
        }
    }
}

/// Separation of `a` and `b` over `[0, max(arrival_a, arrival_b)]` against `d_min`.
pub fn pair_separation(a: &Trajectory, b: &Trajectory, d_min: f64) -> PairSeparation {
    if a.times.is_empty() || b.times.is_empty() {
        return PairSeparation {
            min_distance: f64::INFINITY,
            min_time: 0.0,
            breach_s: 0.0,
        };
    }
    motion_separation(&Motion::new(a), &Motion::new(b), d_min, true)
}

/// [`pair_separation`] on prepared trajectories.
///
/// With `exact_min == false` (the fitness), stretches of time in which the pair provably stays at
/// least `d_min` apart are skipped: two vehicles `D` apart cannot close in below `d_min` sooner
/// than `(D − d_min) / (v_a,max + v_b,max)`. The breach time is still exact, and so is
/// `min_distance` when it is below `d_min`; otherwise it is only known to be at least `d_min`.
pub fn motion_separation(
    a: &Motion<'_>,
    b: &Motion<'_>,
    d_min: f64,
    exact_min: bool,
) -> PairSeparation {
    let mut best = PairSeparation {
        min_distance: f64::INFINITY,
        min_time: 0.0,
        breach_s: 0.0,
    };
    // Legs in progress: the last leg whose start time is <= t0 (legs of zero duration are
    // skipped because the next one starts at the same time).
    let (na, nb) = (a.velocities.len(), b.velocities.len());
    let (mut i, mut j) = (0usize, 0usize);
    let mut t0 = 0.0;
    let mut d0 = b.points[0] - a.points[0];
    consider_point(&mut best, &d0, t0);
    let d_min2 = d_min * d_min;
    let closing = a.max_speed + b.max_speed;
    let end = a.times[na].max(b.times[nb]);
    loop {
        while i < na && a.times[i + 1] <= t0 {
            i += 1;
        }
        while j < nb && b.times[j + 1] <= t0 {
            j += 1;
        }
        if !exact_min && closing > 0.0 {
            // Jump ahead only if the pair is far enough apart to stay clear past the next
            // breakpoint; the test is done in squares so most intervals pay no square root.
            let next = a
                .times
                .get(i + 1)
                .copied()
                .unwrap_or(f64::INFINITY)
                .min(b.times.get(j + 1).copied().unwrap_or(f64::INFINITY));
            let reach = d_min + closing * (next.min(end) - t0);
            let gap2 = d0.norm_squared();
            if gap2 > reach * reach {
                let safe_until = t0 + (gap2.sqrt() - d_min) / closing;
                if safe_until >= end {
                    break;
                }
                t0 = safe_until;
                while i < na && a.times[i + 1] <= t0 {
                    i += 1;
                }
                while j < nb && b.times[j + 1] <= t0 {
                    j += 1;
                }
                d0 = b.at(j, t0) - a.at(i, t0);
                continue;
            }
        }
        let t1 = match (i < na, j < nb) {
            (true, true) => a.times[i + 1].min(b.times[j + 1]),
            (true, false) => a.times[i + 1],
            (false, true) => b.times[j + 1],
            (false, false) => break,
        };
        let d1 = b.at(j, t1) - a.at(i, t1);
        let dt = t1 - t0;
        // Closest approach of d0 + s·k, s ∈ [0, 1], kept in squares and as a fraction
        // num / den so that the division happens only when a new minimum is found.
        let k = d1 - d0;
        let dk = d0.dot(&k);
        let kk = k.norm_squared();
        let (num, den, s) = if dk >= 0.0 || kk <= 0.0 {
            (d0.norm_squared(), 1.0, 0.0)
        } else if d1.dot(&k) <= 0.0 {
            (d1.norm_squared(), 1.0, 1.0)
        } else {
            (d0.norm_squared() * kk - dk * dk, kk, f64::NAN)
        };
        let num = num.max(0.0);
        if num < best.min_distance * best.min_distance * den {
            best.min_distance = (num / den).sqrt();
            let s = if s.is_nan() { -dk / kk } else { s };
            best.min_time = t0 + s * dt;
        }
        if num < d_min2 * den {
            best.breach_s += fraction_within(&d0, &d1, d_min) * dt;
        }
        t0 = t1;
        d0 = d1;
    }
    best
}

/// The smallest distance between `a` and `b` at any instant of `[from, to]` (`to` may be
/// infinite: both hold at their last points), by the same piecewise-linear motion as
/// [`motion_separation`] but over that window only. The broad phase's last test: a pair of
/// vehicles whose near windows all stay at least `d_min` apart has terms of exactly zero.
pub fn closest_within(a: &Motion<'_>, b: &Motion<'_>, from: f64, to: f64) -> f64 {
    let (na, nb) = (a.velocities.len(), b.velocities.len());
    let leg = |m: &Motion<'_>, n: usize, t: f64| {
        // The last leg starting at or before t (legs of zero duration skipped), or n (held).
        m.times[1..=n].partition_point(|&end| end <= t)
    };
    let (mut i, mut j) = (leg(a, na, from), leg(b, nb, from));
    let mut t0 = from;
    let mut d0 = b.at(j, t0) - a.at(i, t0);
    let mut best = d0.norm_squared();
    while t0 < to {
        let t1 = a
            .times
            .get(i + 1)
            .copied()
            .unwrap_or(f64::INFINITY)
            .min(b.times.get(j + 1).copied().unwrap_or(f64::INFINITY))
            .min(to);
        if !t1.is_finite() {
            break;
        }
        let d1 = b.at(j, t1) - a.at(i, t1);
        let gap = crate::geometry::closest_approach(&d0, &d1);
        best = best.min(gap * gap);
        t0 = t1;
        d0 = d1;
        while i < na && a.times[i + 1] <= t0 {
            i += 1;
        }
        while j < nb && b.times[j + 1] <= t0 {
            j += 1;
        }
    }
    best.sqrt()
}

fn consider_point(best: &mut PairSeparation, d: &Vec3, t: f64) {
    let n = d.norm();
    if n < best.min_distance {
        best.min_distance = n;
        best.min_time = t;
    }
}

/// Separation of every pair `(i, j)`, `i < j`, in row order.
pub fn all_pairs(trajectories: &[Trajectory], d_min: f64) -> Vec<((usize, usize), PairSeparation)> {
    let mut out = Vec::new();
    for i in 0..trajectories.len() {
        for j in i + 1..trajectories.len() {
            out.push((
                (i, j),
                pair_separation(&trajectories[i], &trajectories[j], d_min),
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;
    use proptest::prelude::*;

    fn traj(samples: &[(f64, [f64; 3])]) -> Trajectory {
        Trajectory {
            times: samples.iter().map(|s| s.0).collect(),
            points: samples.iter().map(|s| Vec3::from(s.1)).collect(),
        }
    }

    #[test]
    fn head_on_crossing_by_hand() {
        // A goes east along y = 0, B goes west along y = 30, both at 1 m/s, passing at t = 50.
        let a = traj(&[(0.0, [0., 0., 0.]), (100.0, [100., 0., 0.])]);
        let b = traj(&[(0.0, [100., 30., 0.]), (100.0, [0., 30., 0.])]);
        let s = pair_separation(&a, &b, 50.0);
        assert_abs_diff_eq!(s.min_distance, 30.0, epsilon = 1e-9);
        assert_abs_diff_eq!(s.min_time, 50.0, epsilon = 1e-9);
        // Closer than 50 m while the x gap (closing at 2 m/s) is under 40 m: 40 s in all.
        assert_abs_diff_eq!(s.breach_s, 40.0, epsilon = 1e-9);
    }

    #[test]
    fn closest_within_a_window_by_hand() {
        // The head-on crossing below: x gap 100 − 2t, y gap 30, held apart after t = 100.
        let a = traj(&[(0.0, [0., 0., 0.]), (100.0, [100., 0., 0.])]);
        let b = traj(&[(0.0, [100., 30., 0.]), (100.0, [0., 30., 0.])]);
        let (ma, mb) = (Motion::new(&a), Motion::new(&b));
        let at_40 = (20f64 * 20.0 + 30.0 * 30.0).sqrt();
        assert_abs_diff_eq!(closest_within(&ma, &mb, 0.0, 40.0), at_40, epsilon = 1e-9);
        assert_abs_diff_eq!(closest_within(&ma, &mb, 40.0, 60.0), 30.0, epsilon = 1e-9);
        assert_abs_diff_eq!(
            closest_within(&ma, &mb, 60.0, f64::INFINITY),
            at_40,
            epsilon = 1e-9
        );
        // After both arrive they hold 100 m apart in x.
        let held = (100f64 * 100.0 + 30.0 * 30.0).sqrt();
        assert_abs_diff_eq!(
            closest_within(&ma, &mb, 150.0, f64::INFINITY),
            held,
            epsilon = 1e-9
        );
    }

    #[test]
    fn same_path_different_times_is_not_a_collision() {
        // Both fly the same line, B 60 s behind A at 1 m/s: always 60 m apart until A holds at
        // its goal, then B closes in and stops 0 m away (same goal) at t = 160.
        let a = traj(&[(0.0, [0., 0., 0.]), (100.0, [100., 0., 0.])]);
        let b = traj(&[(0.0, [-60., 0., 0.]), (160.0, [100., 0., 0.])]);
        let s = pair_separation(&a, &b, 50.0);
        assert_abs_diff_eq!(s.min_distance, 0.0, epsilon = 1e-9);
        assert_abs_diff_eq!(s.min_time, 160.0, epsilon = 1e-9);
        // 60 m gap until t = 100; then B closes at 1 m/s and is within 50 m from t = 110.
        assert_abs_diff_eq!(s.breach_s, 50.0, epsilon = 1e-9);
    }

    #[test]
    fn waypoints_of_equal_index_would_mislead() {
        // Waypoint 1 of both is the same point, but A is there at t = 10 and B at t = 90.
        let a = traj(&[
            (0.0, [0., 0., 0.]),
            (10.0, [10., 0., 0.]),
            (100.0, [10., 90., 0.]),
        ]);
        let b = traj(&[
            (0.0, [10., 90., 0.]),
            (90.0, [10., 0., 0.]),
            (100.0, [20., 0., 0.]),
        ]);
        let s = pair_separation(&a, &b, 5.0);
        // On the x = 10 line A is at y = t − 10 (t ≥ 10) and B at y = 90 − t (t ≤ 90): they
        // meet at t = 50, y = 40.
        assert_abs_diff_eq!(s.min_distance, 0.0, epsilon = 1e-9);
        assert_abs_diff_eq!(s.min_time, 50.0, epsilon = 1e-9);
    }

    /// A trajectory through `points` whose leg durations cycle through `dt` from `offset`.
    fn timed(points: &[(f64, f64, f64)], dt: &[f64], offset: usize) -> Trajectory {
        let mut t = 0.0;
        let mut times = vec![0.0];
        for k in 1..points.len() {
            t += dt[(k + offset) % dt.len()];
            times.push(t);
        }
        Trajectory {
            times,
            points: points.iter().map(|q| Vec3::new(q.0, q.1, q.2)).collect(),
        }
    }

    proptest! {
        #[test]
        fn separation_is_symmetric_and_non_negative(
            pa in proptest::collection::vec((-100.0f64..100.0, -100.0f64..100.0, -100.0f64..100.0), 2..6),
            pb in proptest::collection::vec((-100.0f64..100.0, -100.0f64..100.0, -100.0f64..100.0), 2..6),
            dt in proptest::collection::vec(0.1f64..30.0, 6),
        ) {
            let (a, b) = (timed(&pa, &dt, 0), timed(&pb, &dt, 3));
            let ab = pair_separation(&a, &b, 20.0);
            let ba = pair_separation(&b, &a, 20.0);
            prop_assert!(ab.min_distance >= 0.0);
            prop_assert!((ab.min_distance - ba.min_distance).abs() < 1e-9);
            prop_assert!((ab.breach_s - ba.breach_s).abs() < 1e-9);
            // The exact minimum is never above any sampled distance.
            let horizon = a.arrival().max(b.arrival());
            for k in 0..=200 {
                let t = horizon * k as f64 / 200.0;
                let d = (a.position_at(t) - b.position_at(t)).norm();
                prop_assert!(ab.min_distance <= d + 1e-9);
            }
        }

        #[test]
        fn skipping_safe_stretches_keeps_breaches_exact(
            pa in proptest::collection::vec((-100.0f64..100.0, -100.0f64..100.0, -10.0f64..10.0), 2..8),
            pb in proptest::collection::vec((-100.0f64..100.0, -100.0f64..100.0, -10.0f64..10.0), 2..8),
            dt in proptest::collection::vec(0.1f64..30.0, 8),
            d_min in 1.0f64..60.0,
        ) {
            let (a, b) = (timed(&pa, &dt, 0), timed(&pb, &dt, 5));
            let (ma, mb) = (Motion::new(&a), Motion::new(&b));
            let exact = motion_separation(&ma, &mb, d_min, true);
            let fast = motion_separation(&ma, &mb, d_min, false);
            prop_assert!((exact.breach_s - fast.breach_s).abs() < 1e-6);
            if exact.min_distance < d_min {
                prop_assert!((exact.min_distance - fast.min_distance).abs() < 1e-9);
            } else {
                prop_assert!(fast.min_distance >= d_min - 1e-9);
            }
        }

        #[test]
        fn stationary_vehicles_are_their_point_distance(
            p in (-100.0f64..100.0, -100.0f64..100.0, -100.0f64..100.0),
            q in (-100.0f64..100.0, -100.0f64..100.0, -100.0f64..100.0),
            hold in 1.0f64..100.0,
        ) {
            let a = traj(&[(0.0, [p.0, p.1, p.2]), (hold, [p.0, p.1, p.2])]);
            let b = traj(&[(0.0, [q.0, q.1, q.2])]);
            let d = (Vec3::new(p.0, p.1, p.2) - Vec3::new(q.0, q.1, q.2)).norm();
            let s = pair_separation(&a, &b, 10.0);
            prop_assert!((s.min_distance - d).abs() < 1e-9);
            let expect = if d < 10.0 { hold } else { 0.0 };
            prop_assert!((s.breach_s - expect).abs() < 1e-9);
        }
    }
}
