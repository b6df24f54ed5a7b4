//! Particle encoding (Zhi & Zuo 2024, eq. (3)–(4)) and timed trajectories.
//!
//! A vehicle's chromosome is `M` genes `g_j = (x_j, y_j, z_j, δ_j)`: an inner waypoint and its
//! status gene. Shoal uses the status gene as the *requested speed* on the leg that ends at
//! waypoint `j` (the last leg, into the goal, keeps `δ_M`), so the optimizer shapes the timing and
//! the vehicles can let each other pass. A fleet particle is the chromosomes of all vehicles, one
//! after the other (Fig. 3).
//!
//! In memory a chromosome stores its `3M` coordinates first (`x_1, y_1, z_1, …, z_M`) and its `M`
//! status genes after them, so the path and the speed profile are each one contiguous range that
//! a solver can move as a whole (see [`Layout::move_groups`]).
//!
//! Timing: the requested speeds are only a *profile*. [`retime`] scales the profile so the vehicle
//! arrives at the fleet's common arrival time, keeping every leg's speed inside the vehicle's range.

use crate::geometry::{leg_lengths, polyline_length, Vec3};
use crate::scenario::{Scenario, Vehicle};

mod timing;

pub use timing::{arrival_window, common_arrival, leg_times};

/// Genes per waypoint: x, y, z and the status gene δ.
pub const GENES_PER_WAYPOINT: usize = 4;

/// Where each vehicle's chromosome sits in a fleet particle.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Inner waypoints per vehicle (M).
    pub waypoints: usize,
    /// Number of vehicles (chromosomes).
    pub vehicles: usize,
}

impl Layout {
    /// Layout for a scenario.
    pub fn of(scenario: &Scenario) -> Layout {
        Layout {
            waypoints: scenario.optimizer.waypoints,
            vehicles: scenario.vehicles.len(),
        }
    }
    /// Genes in one chromosome.
    pub fn chromosome_len(&self) -> usize {
        self.waypoints * GENES_PER_WAYPOINT
    }
    /// Genes in one fleet particle.
    pub fn dim(&self) -> usize {
        self.chromosome_len() * self.vehicles
    }
    /// Gene range of vehicle `i`'s chromosome.
    pub fn chromosome(&self, i: usize) -> std::ops::Range<usize> {
        let n = self.chromosome_len();
        i * n..(i + 1) * n
    }
    /// The ranges a solver moves as a whole: each vehicle's waypoint coordinates, and each
    /// vehicle's speed genes. Kept apart so that speeds (metres per second, a range of about
    /// 1 m/s) and positions (a range of kilometres) do not throttle each other's steps.
    pub fn move_groups(&self) -> Vec<std::ops::Range<usize>> {
        let m = self.waypoints;
        (0..self.vehicles)
            .flat_map(|i| {
                let c = self.chromosome(i);
                [c.start..c.start + 3 * m, c.start + 3 * m..c.end]
            })
            .collect()
    }
    /// Lower and upper bound of every gene of a fleet particle: the scenario box for coordinates,
    /// the vehicle's speed range for δ.
    pub fn gene_bounds(&self, scenario: &Scenario) -> (Vec<f64>, Vec<f64>) {
        let mut lo = Vec::with_capacity(self.dim());
        let mut hi = Vec::with_capacity(self.dim());
        for v in &scenario.vehicles {
            // A crawler's z follows the seabed: its z genes are pinned (and ignored).
            let mut top = scenario.bounds.max;
            if v.kind == crate::scenario::VehicleKind::Crawler {
                top[2] = scenario.bounds.min[2];
            }
            for _ in 0..self.waypoints {
                lo.extend_from_slice(&scenario.bounds.min);
                hi.extend_from_slice(&top);
            }
            lo.extend(std::iter::repeat_n(v.speed_min_mps, self.waypoints));
            hi.extend(std::iter::repeat_n(v.speed_max_mps, self.waypoints));
        }
        (lo, hi)
    }
}

/// A vehicle's geometric path decoded from its chromosome: start, inner waypoints, goal, and the
/// requested speed of each leg (`points.len() − 1` legs).
#[derive(Debug, Clone, PartialEq)]
pub struct Path {
    /// Start, the M inner waypoints, goal.
    pub points: Vec<Vec3>,
    /// Requested speed per leg, m/s (from the status genes).
    pub speeds: Vec<f64>,
}

impl Path {
    /// Decodes one chromosome (`genes.len() == 4 M`: coordinates, then speeds) for `vehicle`.
    pub fn decode(vehicle: &Vehicle, genes: &[f64]) -> Path {
        let m = genes.len() / GENES_PER_WAYPOINT;
        let mut points = Vec::with_capacity(m + 2);
        let mut speeds = Vec::with_capacity(m + 1);
        Path::decode_into(vehicle, genes, &mut points, &mut speeds);
        Path { points, speeds }
    }

    /// [`Path::decode`] appending to buffers the caller reuses: the points to `points`, the
    /// legs' speeds to `speeds`.
    pub fn decode_into(
        vehicle: &Vehicle,
        genes: &[f64],
        points: &mut Vec<Vec3>,
        speeds: &mut Vec<f64>,
    ) {
        let m = genes.len() / GENES_PER_WAYPOINT;
        let (coords, status) = genes.split_at(3 * m);
        points.push(vehicle.start());
        points.extend(coords.chunks_exact(3).map(|g| Vec3::new(g[0], g[1], g[2])));
        points.push(vehicle.goal());
        speeds.extend_from_slice(status);
        speeds.push(status.last().copied().unwrap_or(vehicle.speed_max_mps));
    }

    /// Length of every leg, metres.
    #[inline]
    pub fn leg_lengths(&self) -> Vec<f64> {
        leg_lengths(&self.points).collect()
    }

    /// Total length, metres.
    pub fn length(&self) -> f64 {
        polyline_length(&self.points)
    }
}

/// A timed trajectory: the vehicle moves in a straight line at constant speed between consecutive
/// samples, and holds at its last sample afterwards.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Trajectory {
    /// Sample times, seconds, non-decreasing, starting at 0.
    pub times: Vec<f64>,
    /// Sample positions, metres.
    pub points: Vec<Vec3>,
}

impl Trajectory {
    /// From `[t_s, x_m, y_m, z_m]` samples, the form `plan.json` and the wire use.
    pub fn from_samples(samples: &[[f64; 4]]) -> Trajectory {
        Trajectory {
            times: samples.iter().map(|s| s[0]).collect(),
            points: samples
                .iter()
                .map(|s| Vec3::new(s[1], s[2], s[3]))
                .collect(),
        }
    }

    /// Time of the last sample: the arrival at the goal, seconds.
    pub fn arrival(&self) -> f64 {
        self.times.last().copied().unwrap_or(0.0)
    }

    /// Position at time `t` (held before the first and after the last sample).
    pub fn position_at(&self, t: f64) -> Vec3 {
        let n = self.times.len();
        if n == 0 {
            return Vec3::zeros();
        }
        if t <= self.times[0] {
            return self.points[0];
        }
        if t >= self.times[n - 1] {
            return self.points[n - 1];
        }
        // First sample strictly after t; t lies in [times[k-1], times[k]).
        let k = self.times.partition_point(|&s| s <= t);
        let (t0, t1) = (self.times[k - 1], self.times[k]);
        let s = if t1 > t0 { (t - t0) / (t1 - t0) } else { 1.0 };
        self.points[k - 1] + (self.points[k] - self.points[k - 1]) * s
    }

    /// The trajectory from mission time `t` on: the position at `t`, then every later sample
    /// (times unchanged). Empty stays empty.
    pub fn since(&self, t: f64) -> Trajectory {
        if self.times.is_empty() {
            return self.clone();
        }
        let mut times = vec![t];
        let mut points = vec![self.position_at(t)];
        for (s, p) in self.times.iter().zip(&self.points) {
            if *s > t {
                times.push(*s);
                points.push(*p);
            }
        }
        Trajectory { times, points }
    }

    /// The trajectory up to mission time `t`: every earlier sample, then the position at `t`
    /// (times unchanged). Empty stays empty.
    pub fn until(&self, t: f64) -> Trajectory {
        if self.times.is_empty() {
            return self.clone();
        }
        let keep = self.times.partition_point(|&s| s < t);
        let mut times = self.times[..keep].to_vec();
        let mut points = self.points[..keep.min(self.points.len())].to_vec();
        times.push(t);
        points.push(self.position_at(t));
        Trajectory { times, points }
    }

    /// This trajectory up to where `next` begins, then `next`: what a vehicle under way is sent
    /// when its rest is replanned from a time ahead of now, so it keeps to its old course until
    /// the new one starts instead of being pulled straight to the new start. The samples of
    /// `self` strictly before `next`'s first time are kept; an empty `next` changes nothing.
    pub fn followed_by(&self, next: &Trajectory) -> Trajectory {
        let Some(&start) = next.times.first() else {
            return self.clone();
        };
        let keep = self.times.partition_point(|&t| t < start);
        let mut times = self.times[..keep].to_vec();
        let mut points = self.points[..keep.min(self.points.len())].to_vec();
        times.extend_from_slice(&next.times);
        points.extend_from_slice(&next.points);
        Trajectory { times, points }
    }

    /// Speed on each leg, m/s (zero for a leg of zero duration and length).
    pub fn leg_speeds(&self) -> Vec<f64> {
        self.times
            .windows(2)
            .zip(self.points.windows(2))
            .map(|(t, p)| {
                let dt = t[1] - t[0];
                let d = (p[1] - p[0]).norm();
                if dt > 0.0 {
                    d / dt
                } else {
                    0.0
                }
            })
            .collect()
    }
}

/// The shortest path the vehicle's pitch limit allows from start to goal, metres: the straight
/// line when its slope is within the limit, else `|Δz| / sin(φ_max)` (a path winding enough to
/// climb at exactly the limit). Obstacles and turns can only make it longer.
pub fn shortest_pitch_feasible_length(vehicle: &Vehicle) -> f64 {
    let d = vehicle.goal() - vehicle.start();
    let horizontal = (d.x * d.x + d.y * d.y).sqrt();
    let phi = vehicle.max_pitch_deg.to_radians();
    if d.z.abs() <= horizontal * phi.tan() {
        d.norm()
    } else {
        d.z.abs() / phi.sin()
    }
}

/// Horizontal distance a path must cover for its climb to stay within the pitch limit, metres:
/// `|Δz| / tan(φ_max)`, or the straight horizontal distance if that is more.
pub fn required_horizontal_length(vehicle: &Vehicle) -> f64 {
    let d = vehicle.goal() - vehicle.start();
    let horizontal = (d.x * d.x + d.y * d.y).sqrt();
    horizontal.max(d.z.abs() / vehicle.max_pitch_deg.to_radians().tan())
}

/// Times `path` so the vehicle arrives at `target` seconds, with every leg's speed inside
/// `[v_min, v_max]` and the legs' speeds in the proportions the status genes request as far as
/// the limits allow.
///
/// Each leg's pace (s/m) is `clamp(α / δ_j, 1/v_max, 1/v_min)`; the total time `T(α)` is
/// continuous, piecewise linear and non-decreasing in `α`, so a Newton step on the current linear
/// piece, safeguarded by a bisection bracket, lands on the exact `α` in a few steps. If the target
/// is out of reach the vehicle flies the whole path at `v_max` (too late) or `v_min` (too early).
pub fn retime(path: &Path, vehicle: &Vehicle, target: f64) -> Trajectory {
    let lengths = path.leg_lengths();
    retime_legs(path.clone(), &lengths, vehicle, target)
}

/// [`retime`] with the leg lengths already known, taking the path's points over.
pub fn retime_legs(path: Path, lengths: &[f64], vehicle: &Vehicle, target: f64) -> Trajectory {
    let Path { points, mut speeds } = path;
    let mut times = Vec::with_capacity(points.len());
    leg_times(lengths, &mut speeds, vehicle, target, &mut times);
    Trajectory { times, points }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    fn vehicle() -> Vehicle {
        Vehicle {
            id: "a".into(),
            kind: crate::scenario::VehicleKind::Auv,
            start: [0.0, 0.0, 0.0],
            goal: [300.0, 0.0, 0.0],
            speed_min_mps: 0.5,
            speed_max_mps: 1.5,
            max_turn_deg: 35.0,
            max_pitch_deg: 20.0,
            turn_radius_m: None,
        }
    }

    #[test]
    fn the_rest_since_a_time_starts_where_the_trajectory_is_then() {
        let v = |x: f64| Vec3::new(x, 0.0, 0.0);
        let t = Trajectory {
            times: vec![0.0, 100.0, 200.0],
            points: vec![v(0.0), v(100.0), v(300.0)],
        };
        let r = t.since(150.0);
        assert_eq!(r.times, vec![150.0, 200.0]);
        assert_eq!(r.points, vec![v(200.0), v(300.0)]);
        // Before the start: the start and every sample; after the end: the end alone.
        assert_eq!(t.since(-10.0).times, vec![-10.0, 0.0, 100.0, 200.0]);
        assert_eq!(t.since(500.0).points, vec![v(300.0)]);
        let empty = Trajectory {
            times: vec![],
            points: vec![],
        };
        assert_eq!(empty.since(1.0), empty);
    }

    #[test]
    fn the_trajectory_until_a_time_ends_where_it_is_then() {
        let v = |x: f64| Vec3::new(x, 0.0, 0.0);
        let t = Trajectory {
            times: vec![0.0, 100.0, 200.0],
            points: vec![v(0.0), v(100.0), v(300.0)],
        };
        let r = t.until(150.0);
        assert_eq!(r.times, vec![0.0, 100.0, 150.0]);
        assert_eq!(r.points, vec![v(0.0), v(100.0), v(200.0)]);
        // On a sample: that sample once; past the end: every sample, then the end held.
        assert_eq!(t.until(100.0).times, vec![0.0, 100.0]);
        assert_eq!(
            t.until(500.0).points,
            vec![v(0.0), v(100.0), v(300.0), v(300.0)]
        );
        // Before the start: the start alone; a clip of both ends is since then until.
        assert_eq!(t.until(-10.0).points, vec![v(0.0)]);
        assert_eq!(
            t.since(50.0).until(150.0).points,
            vec![v(50.0), v(100.0), v(200.0)]
        );
        let empty = Trajectory {
            times: vec![],
            points: vec![],
        };
        assert_eq!(empty.until(1.0), empty);
    }

    #[test]
    fn a_replan_is_spliced_onto_the_course_flown_until_it_begins() {
        let v = |x: f64| Vec3::new(x, 0.0, 0.0);
        let old = Trajectory {
            times: vec![0.0, 100.0, 200.0, 300.0],
            points: vec![v(0.0), v(100.0), v(200.0), v(300.0)],
        };
        let new = Trajectory {
            times: vec![150.0, 250.0],
            points: vec![Vec3::new(150.0, 5.0, 0.0), Vec3::new(150.0, 105.0, 0.0)],
        };
        let s = old.followed_by(&new);
        assert_eq!(s.times, vec![0.0, 100.0, 150.0, 250.0]);
        assert_eq!(s.points[..2], old.points[..2]);
        assert_eq!(s.points[2..], new.points[..]);
        // Before the new start the vehicle is where the old plan had it; after, on the new one.
        assert!((s.position_at(50.0) - v(50.0)).norm() < 1e-12);
        assert!((s.position_at(200.0) - Vec3::new(150.0, 55.0, 0.0)).norm() < 1e-12);
        // A sample at the very start time is replaced; an empty replan changes nothing.
        let at = Trajectory {
            times: vec![100.0, 200.0],
            points: vec![v(100.0), v(0.0)],
        };
        assert_eq!(old.followed_by(&at).times, vec![0.0, 100.0, 200.0]);
        assert_eq!(
            old.followed_by(&Trajectory {
                times: vec![],
                points: vec![]
            }),
            old
        );
    }

    #[test]
    fn decode_places_start_genes_goal_and_speeds() {
        let v = vehicle();
        let p = Path::decode(&v, &[100.0, 0.0, 0.0, 200.0, 0.0, 0.0, 1.0, 0.5]);
        assert_eq!(p.points.len(), 4);
        assert_eq!(p.points[1], Vec3::new(100.0, 0.0, 0.0));
        assert_eq!(p.speeds, vec![1.0, 0.5, 0.5]);
        assert_abs_diff_eq!(p.length(), 300.0);
    }

    #[test]
    fn layout_bounds_cover_box_and_speed_range() {
        let l = Layout {
            waypoints: 2,
            vehicles: 3,
        };
        assert_eq!(l.dim(), 24);
        assert_eq!(l.chromosome(1), 8..16);
    }

    #[test]
    fn retime_hits_target_keeping_speed_ratios() {
        let v = vehicle();
        // Legs 100, 100, 100 m with requested speeds 1.0, 0.5, 0.5: paces 1, 2, 2 s/m.
        let p = Path::decode(&v, &[100.0, 0.0, 0.0, 200.0, 0.0, 0.0, 1.0, 0.5]);
        // Target 400 s: α (100·1 + 100·2 + 100·2) = 400 → α = 0.8 → paces 0.8, 1.6, 1.6 s/m,
        // all inside [1/1.5, 1/0.5] = [0.667, 2].
        let t = retime(&p, &v, 400.0);
        assert_abs_diff_eq!(t.arrival(), 400.0, epsilon = 1e-9);
        assert_abs_diff_eq!(t.times[1], 80.0, epsilon = 1e-9);
        assert_abs_diff_eq!(t.times[2], 240.0, epsilon = 1e-9);
        // Target 300 s: α·1 would give pace < 0.667 on the fast leg → clamped at 0.667 s/m
        // (1.5 m/s); the other two share the rest: 66.67 + 200 α·2 = 300 → α = 0.5833.
        let t = retime(&p, &v, 300.0);
        assert_abs_diff_eq!(t.arrival(), 300.0, epsilon = 1e-9);
        let s = t.leg_speeds();
        assert_abs_diff_eq!(s[0], 1.5, epsilon = 1e-9);
        assert_abs_diff_eq!(s[1], s[2], epsilon = 1e-9);
        assert!(s.iter().all(|&x| (0.5 - 1e-12..=1.5 + 1e-12).contains(&x)));
    }

    #[test]
    fn retime_out_of_reach_flies_at_the_limit() {
        let v = vehicle();
        let p = Path::decode(&v, &[100.0, 0.0, 0.0, 200.0, 0.0, 0.0, 1.0, 0.5]);
        // 300 m at 1.5 m/s takes 200 s at best.
        assert_abs_diff_eq!(retime(&p, &v, 100.0).arrival(), 200.0, epsilon = 1e-9);
        // ... and 600 s at worst.
        assert_abs_diff_eq!(retime(&p, &v, 1000.0).arrival(), 600.0, epsilon = 1e-9);
    }

    #[test]
    fn pitch_limited_lengths_by_hand() {
        let mut v = vehicle();
        // (0,0,0) → (300,0,0): flat, the straight line.
        assert_abs_diff_eq!(shortest_pitch_feasible_length(&v), 300.0, epsilon = 1e-9);
        assert_abs_diff_eq!(required_horizontal_length(&v), 300.0, epsilon = 1e-9);
        // Climb 300 m over 300 m (45°) with a 30° limit: 300 / sin 30° = 600 m of path, of which
        // 300 / tan 30° = 519.6 m horizontal.
        v.goal = [300.0, 0.0, 300.0];
        v.max_pitch_deg = 30.0;
        assert_abs_diff_eq!(shortest_pitch_feasible_length(&v), 600.0, epsilon = 1e-9);
        assert_abs_diff_eq!(
            required_horizontal_length(&v),
            300.0 * 3f64.sqrt(),
            epsilon = 1e-9
        );
        // A 60° limit allows the 45° straight line.
        v.max_pitch_deg = 60.0;
        assert_abs_diff_eq!(
            shortest_pitch_feasible_length(&v),
            300.0 * 2f64.sqrt(),
            epsilon = 1e-9
        );
    }

    #[test]
    fn window_and_common_arrival() {
        let v = vehicle();
        assert_eq!(arrival_window(300.0, &v), (200.0, 600.0));
        assert_eq!(common_arrival(250.0, [200.0, 240.0]), 250.0);
        assert_eq!(common_arrival(250.0, [200.0, 280.0]), 280.0);
    }

    #[test]
    fn position_is_linear_between_samples_and_held_after() {
        let t = Trajectory {
            times: vec![0.0, 10.0, 30.0],
            points: vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(10.0, 0.0, 0.0),
                Vec3::new(10.0, 20.0, 0.0),
            ],
        };
        assert_eq!(t.position_at(5.0), Vec3::new(5.0, 0.0, 0.0));
        assert_eq!(t.position_at(20.0), Vec3::new(10.0, 10.0, 0.0));
        assert_eq!(t.position_at(99.0), Vec3::new(10.0, 20.0, 0.0));
        assert_eq!(t.position_at(-1.0), Vec3::new(0.0, 0.0, 0.0));
        assert_eq!(t.leg_speeds(), vec![1.0, 1.0]);
    }
}
