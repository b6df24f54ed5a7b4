//! Spatial coupling on *timed* trajectories (seed 004 eq. (1), (11)): the distance between two
//! vehicles at the same instant, over the whole mission.
//!
//! Both trajectories are piecewise linear in time, so on every interval between consecutive sample
//! times of either vehicle their relative position is linear too, and the closest approach and the
//! time spent closer than `d_min` have closed forms ([`crate::geometry::closest_approach`],
//! [`crate::geometry::fraction_within`]). Nothing is sampled, so no graze between samples is missed.
//! A vehicle holds at its last sample after it arrives.

use crate::geometry::{closest_approach, fraction_within, Vec3};
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

/// Walks a trajectory forward in time without searching: the planner's hottest loop asks for
/// positions at increasing times only.
struct Cursor<'a> {
    t: &'a Trajectory,
    /// Index of the first sample strictly after the last time asked for.
    next: usize,
}

impl<'a> Cursor<'a> {
    fn new(t: &'a Trajectory) -> Cursor<'a> {
        Cursor { t, next: 0 }
    }

    /// Time of the next sample after `now`, if any.
    fn next_time(&mut self, now: f64) -> Option<f64> {
        while self.next < self.t.times.len() && self.t.times[self.next] <= now {
            self.next += 1;
        }
        self.t.times.get(self.next).copied()
    }

    /// Position at `time`, which must not be earlier than the last time given to `next_time`.
    fn position(&self, time: f64) -> Vec3 {
        let (times, points) = (&self.t.times, &self.t.points);
        let k = self.next;
        if k == 0 {
            return points.first().copied().unwrap_or_else(Vec3::zeros);
        }
        if k >= times.len() {
            return points[times.len() - 1];
        }
        let (t0, t1) = (times[k - 1], times[k]);
        if time >= t1 {
            return points[k];
        }
        let s = if t1 > t0 {
            (time - t0) / (t1 - t0)
        } else {
            1.0
        };
        points[k - 1] + (points[k] - points[k - 1]) * s
    }
}

/// Separation of `a` and `b` over `[0, max(arrival_a, arrival_b)]` against `d_min`.
pub fn pair_separation(a: &Trajectory, b: &Trajectory, d_min: f64) -> PairSeparation {
    let mut best = PairSeparation {
        min_distance: f64::INFINITY,
        min_time: 0.0,
        breach_s: 0.0,
    };
    let (mut ca, mut cb) = (Cursor::new(a), Cursor::new(b));
    let mut t0 = 0.0;
    let mut d0 = b.position_at(0.0) - a.position_at(0.0);
    consider_point(&mut best, &d0, t0);
    // Walk the merged sample times of both trajectories.
    loop {
        let t1 = match (ca.next_time(t0), cb.next_time(t0)) {
            (Some(ta), Some(tb)) => ta.min(tb),
            (Some(ta), None) => ta,
            (None, Some(tb)) => tb,
            (None, None) => break,
        };
        // Both cursors now point past t0 and at or before t1.
        let d1 = cb.position(t1) - ca.position(t1);
        let dt = t1 - t0;
        let m = closest_approach(&d0, &d1);
        if m < best.min_distance {
            best.min_distance = m;
            // Time of closest approach on this interval.
            let k = d1 - d0;
            let s = if k.norm_squared() > 0.0 {
                (-d0.dot(&k) / k.norm_squared()).clamp(0.0, 1.0)
            } else {
                0.0
            };
            best.min_time = t0 + s * dt;
        }
        if m < d_min {
            best.breach_s += fraction_within(&d0, &d1, d_min) * dt;
        }
        t0 = t1;
        d0 = d1;
    }
    best
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

    proptest! {
        #[test]
        fn separation_is_symmetric_and_non_negative(
            pa in proptest::collection::vec((-100.0f64..100.0, -100.0f64..100.0, -100.0f64..100.0), 2..6),
            pb in proptest::collection::vec((-100.0f64..100.0, -100.0f64..100.0, -100.0f64..100.0), 2..6),
            dt in proptest::collection::vec(0.1f64..30.0, 6),
        ) {
            let mk = |p: &Vec<(f64, f64, f64)>, off: usize| {
                let mut t = 0.0;
                let mut times = vec![0.0];
                for k in 1..p.len() { t += dt[(k + off) % dt.len()]; times.push(t); }
                Trajectory { times, points: p.iter().map(|q| Vec3::new(q.0, q.1, q.2)).collect() }
            };
            let (a, b) = (mk(&pa, 0), mk(&pb, 3));
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
