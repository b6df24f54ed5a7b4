//! One leg of an inspection tour as a [`Problem`] (Hu et al. 2023, §IV-C): the path from one point to
//! the next through `n` intermediate waypoints, the shortest one (eq. (27)–(28)) whose segments
//! stay clear of every cage sphere (eq. (29)–(33)).
//!
//! Decision variables: the waypoints' coordinates, laid out axis by axis
//! (`[x_1 … x_n, y_1 … y_n, z_1 … z_n]`) so that the three [`Problem::move_groups`] are the x's,
//! the y's and the z's — the three "coordinate elements" DE-PSO mutates separately (eq. (20)).
//! Table 5's `path_num = 30` segments means `n = 29` waypoints ([`super::LegSettings::table5`]).
//! Moving whole axes (one random factor per axis, as eq. (18) writes r1, r2 per particle) keeps
//! paths smooth: with one factor per coordinate instead, every swarm ended 2–3 times longer on
//! group A's around-the-cage legs at Table 5 budgets (zig-zags), against 5–15 % above the
//! hugging-the-sphere bound this way.
//!
//! Cost: path length plus, for every segment that comes strictly closer than `r + clearance +`
//! [`CONTACT_GUARD_M`] to a cage centre (eq. (33) on the segment, tangency included through the
//! guard), [`HIT_PENALTY_M`] plus [`CHORD_WEIGHT`] times the length of the segment inside that
//! sphere. The constant makes any collision-free path better than any colliding one; the chord
//! term tells the swarm which colliding paths are nearly clear.
//!
//! Waypoints inside a cage sphere are moved radially onto its surface before the path is
//! evaluated (eq. (30), obstacle case). The repair is applied when evaluating, not to the
//! particle: [`LegProblem::path`] gives the repaired path of any position.

use rand::rngs::StdRng;
use rand::Rng;

use crate::geometry::{chord_inside_sphere, segment_hits_sphere, Vec3, CONTACT_GUARD_M};
use crate::swarm::Problem;

use super::cages::Cage;

/// Cost of one segment–sphere intersection, metres of path. Not in the seed (eq. (33) only marks
/// a segment infeasible); 10⁴ m is more than any detour inside Table 4's 700 m box can cost.
pub const HIT_PENALTY_M: f64 = 1.0e4;

/// Weight of the length of a segment inside a sphere in the penalty (not in the seed).
pub const CHORD_WEIGHT: f64 = 10.0;

/// A sphere the path must stay out of: a cage inflated by the planner's clearance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    /// Centre, metres.
    pub centre: Vec3,
    /// Radius, metres (cage radius plus clearance).
    pub radius_m: f64,
}

/// The cages as spheres of radius `R + clearance_m`.
pub fn safety_spheres(cages: &[Cage], clearance_m: f64) -> Vec<Sphere> {
    cages
        .iter()
        .map(|c| Sphere {
            centre: c.centre,
            radius_m: c.radius_m + clearance_m,
        })
        .collect()
}

/// How many spheres segment `a→b` enters (Hu et al. 2023, eq. (31)–(33) on the segment, with the
/// contact guard so a graze counts).
pub fn segment_hits(a: &Vec3, b: &Vec3, spheres: &[Sphere]) -> usize {
    spheres
        .iter()
        .filter(|s| segment_hits_sphere(a, b, &s.centre, s.radius_m + CONTACT_GUARD_M))
        .count()
}

/// Segment–sphere intersections along a polyline (every segment tested, not only its points).
pub fn intersections(path: &[Vec3], spheres: &[Sphere]) -> usize {
    path.windows(2)
        .map(|w| segment_hits(&w[0], &w[1], spheres))
        .sum()
}

/// True when no segment of `path` enters any sphere.
pub fn feasible(path: &[Vec3], spheres: &[Sphere]) -> bool {
    intersections(path, spheres) == 0
}

/// One leg between two points as a box-bounded problem.
#[derive(Debug, Clone)]
pub struct LegProblem {
    /// Where the leg starts.
    pub start: Vec3,
    /// Where it ends.
    pub end: Vec3,
    /// Number of intermediate waypoints n.
    pub waypoints: usize,
    /// Spheres to stay out of.
    pub spheres: Vec<Sphere>,
    box_lo: Vec3,
    box_hi: Vec3,
    lower: Vec<f64>,
    upper: Vec<f64>,
}

impl LegProblem {
    /// The leg `start → end` with `waypoints` intermediate points in `bounds` (the scenario's
    /// box; inverted axes are put in order and the box is widened to hold both end points).
    pub fn new(
        start: Vec3,
        end: Vec3,
        spheres: Vec<Sphere>,
        bounds: (Vec3, Vec3),
        waypoints: usize,
    ) -> LegProblem {
        let lo = bounds.0.inf(&bounds.1).inf(&start).inf(&end);
        let hi = bounds.0.sup(&bounds.1).sup(&start).sup(&end);
        let mut lower = Vec::with_capacity(3 * waypoints);
        let mut upper = Vec::with_capacity(3 * waypoints);
        for axis in 0..3 {
            lower.extend(std::iter::repeat_n(lo[axis], waypoints));
            upper.extend(std::iter::repeat_n(hi[axis], waypoints));
        }
        LegProblem {
            start,
            end,
            waypoints,
            spheres,
            box_lo: lo,
            box_hi: hi,
            lower,
            upper,
        }
    }

    /// Waypoint `k` of position `x` as given (before the repair).
    fn raw_waypoint(&self, x: &[f64], k: usize) -> Vec3 {
        let n = self.waypoints;
        let at = |i: usize| x.get(i).copied().unwrap_or(0.0);
        Vec3::new(at(k), at(n + k), at(2 * n + k))
    }

    /// Hu et al. 2023, eq. (30), obstacle case: a point inside a sphere is moved radially onto its
    /// surface (2 guards outside, so the point itself is clear); a point at the very centre
    /// moves up (+z). A few passes settle overlapping spheres; the point stays in the box.
    pub fn repair_point(&self, p: Vec3) -> Vec3 {
        let mut p = p;
        for _ in 0..3 {
            let mut moved = false;
            for s in &self.spheres {
                let d = p - s.centre;
                let dist = d.norm();
                if dist < s.radius_m + CONTACT_GUARD_M {
                    let dir = if dist > 1e-12 { d / dist } else { Vec3::z() };
                    p = s.centre + dir * (s.radius_m + 2.0 * CONTACT_GUARD_M);
                    moved = true;
                }
            }
            p = p.sup(&self.box_lo).inf(&self.box_hi);
            if !moved {
                break;
            }
        }
        p
    }

    /// The full polyline of position `x`: start, the repaired waypoints, end.
    pub fn path(&self, x: &[f64]) -> Vec<Vec3> {
        let mut path = Vec::with_capacity(self.waypoints + 2);
        path.push(self.start);
        for k in 0..self.waypoints {
            path.push(self.repair_point(self.raw_waypoint(x, k)));
        }
        path.push(self.end);
        path
    }

    /// Cost of a polyline: length plus the intersection penalties (see the module notes).
    pub fn path_cost(&self, path: &[Vec3]) -> f64 {
        let mut cost = 0.0;
        for w in path.windows(2) {
            cost += (w[1] - w[0]).norm();
            for s in &self.spheres {
                let r = s.radius_m + CONTACT_GUARD_M;
                if segment_hits_sphere(&w[0], &w[1], &s.centre, r) {
                    cost += HIT_PENALTY_M
                        + CHORD_WEIGHT * chord_inside_sphere(&w[0], &w[1], &s.centre, r);
                }
            }
        }
        cost
    }

    /// Segment–sphere intersections of a polyline against this leg's spheres.
    pub fn intersections(&self, path: &[Vec3]) -> usize {
        intersections(path, &self.spheres)
    }

    /// True when no segment of `path` enters a sphere.
    pub fn feasible(&self, path: &[Vec3]) -> bool {
        feasible(path, &self.spheres)
    }

    /// The position whose waypoints are `points` (length n), in this problem's layout.
    pub fn position_of(&self, points: &[Vec3]) -> Vec<f64> {
        let mut x = vec![0.0; 3 * self.waypoints];
        for (k, p) in points.iter().take(self.waypoints).enumerate() {
            for axis in 0..3 {
                x[axis * self.waypoints + k] = p[axis];
            }
        }
        x
    }
}

impl Problem for LegProblem {
    fn lower(&self) -> &[f64] {
        &self.lower
    }
    fn upper(&self) -> &[f64] {
        &self.upper
    }
    fn cost(&self, x: &[f64]) -> f64 {
        self.path_cost(&self.path(x))
    }
    fn move_groups(&self) -> Vec<std::ops::Range<usize>> {
        let n = self.waypoints;
        if n == 0 {
            return Vec::new();
        }
        vec![0..n, n..2 * n, 2 * n..3 * n]
    }
    /// Initial paths: a detour through one uniform random via point in the box, the waypoints
    /// spread evenly by length along `start → via → end`. The seed draws every coordinate
    /// uniformly (eq. (14)), which for 29 waypoints gives zig-zags tens of times longer than the
    /// leg; one-via detours are in the same box, cover every side of every cage, and are smooth,
    /// so the swarm starts from paths worth refining.
    fn sample(&self, rng: &mut StdRng) -> Vec<f64> {
        let u = Vec3::new(rng.random(), rng.random(), rng.random());
        let via = self.box_lo + (self.box_hi - self.box_lo).component_mul(&u);
        let (l1, l2) = ((via - self.start).norm(), (self.end - via).norm());
        let total = l1 + l2;
        let pts: Vec<Vec3> = (1..=self.waypoints)
            .map(|k| {
                let s = total * k as f64 / (self.waypoints + 1) as f64;
                if total <= 0.0 {
                    self.start
                } else if s <= l1 {
                    self.start + (via - self.start) * (s / l1.max(f64::MIN_POSITIVE))
                } else {
                    via + (self.end - via) * ((s - l1) / l2.max(f64::MIN_POSITIVE))
                }
            })
            .collect();
        self.position_of(&pts)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{leg_lengths, polyline_length};
    use approx::assert_abs_diff_eq;
    use rand::SeedableRng;

    fn v(x: f64, y: f64, z: f64) -> Vec3 {
        Vec3::new(x, y, z)
    }

    /// One sphere of radius 10 at (50, 0, 0) in a 200 m box; leg (0,0,0) → (100,0,0).
    fn one_sphere(waypoints: usize) -> LegProblem {
        let s = vec![Sphere {
            centre: v(50., 0., 0.),
            radius_m: 10.0,
        }];
        let bounds = (v(-100., -100., -100.), v(200., 100., 100.));
        LegProblem::new(v(0., 0., 0.), v(100., 0., 0.), s, bounds, waypoints)
    }

    #[test]
    fn a_segment_through_the_centre_is_penalised_by_hand() {
        let p = one_sphere(0);
        let straight = [p.start, p.end];
        assert_eq!(p.intersections(&straight), 1);
        assert!(!p.feasible(&straight));
        // 100 m + 10⁴ + 10 × chord 2(10 + 1e-6).
        let want = 100.0 + HIT_PENALTY_M + CHORD_WEIGHT * 2.0 * (10.0 + CONTACT_GUARD_M);
        assert_abs_diff_eq!(p.path_cost(&straight), want, epsilon = 1e-6);
        assert_abs_diff_eq!(p.cost(&[]), want, epsilon = 1e-6);
    }

    #[test]
    fn a_detour_over_the_sphere_costs_its_length() {
        // One waypoint at (50, 0, 30): two legs of √(50² + 30²) = 58.3095…, each passing 25.7 m
        // from the centre (foot at u = 2500/3400).
        let p = one_sphere(1);
        let x = p.position_of(&[v(50., 0., 30.)]);
        assert_eq!(x, vec![50.0, 0.0, 30.0]);
        let path = p.path(&x);
        assert_eq!(p.intersections(&path), 0);
        assert_abs_diff_eq!(p.cost(&x), 2.0 * 3400f64.sqrt(), epsilon = 1e-9);
        assert_abs_diff_eq!(polyline_length(&path), 116.619_037_896_906, epsilon = 1e-9);
    }

    #[test]
    fn a_grazing_segment_is_penalised_and_a_clear_one_is_not() {
        let p = one_sphere(0);
        // Passing exactly at the radius (tangent): inside the guard, so it counts (eq. (33):
        // Δ = 0 is infeasible).
        let tangent = [v(0., 10., 0.), v(100., 10., 0.)];
        assert_eq!(p.intersections(&tangent), 1);
        assert!(p.path_cost(&tangent) > 100.0 + HIT_PENALTY_M);
        // 1 mm outside: clear, cost is the length.
        let clear = [v(0., 10.001, 0.), v(100., 10.001, 0.)];
        assert_eq!(p.intersections(&clear), 0);
        assert_abs_diff_eq!(p.path_cost(&clear), 100.0, epsilon = 1e-12);
    }

    #[test]
    fn a_segment_whose_middle_enters_is_caught() {
        let p = one_sphere(0);
        // Both end points far outside; the segment passes 5 m from the centre: chord 2√(r² − 25).
        let seg = [v(0., 5., 0.), v(100., 5., 0.)];
        assert!((seg[0] - p.spheres[0].centre).norm() > 10.0);
        assert_eq!(p.intersections(&seg), 1);
        let r = 10.0 + CONTACT_GUARD_M;
        let chord = 2.0 * (r * r - 25.0).sqrt();
        assert_abs_diff_eq!(chord, 17.320_508, epsilon = 1e-5);
        assert_abs_diff_eq!(
            p.path_cost(&seg),
            100.0 + HIT_PENALTY_M + CHORD_WEIGHT * chord,
            epsilon = 1e-9
        );
    }

    #[test]
    fn waypoints_inside_a_sphere_are_absorbed_onto_its_surface() {
        let p = one_sphere(1);
        // (53, 4, 0) is 5 m from the centre: moved along (3, 4, 0)/5 to radius 10 (+2 guards).
        let q = p.repair_point(v(53., 4., 0.));
        let r = 10.0 + 2.0 * CONTACT_GUARD_M;
        assert_abs_diff_eq!(q, v(50. + 0.6 * r, 0.8 * r, 0.), epsilon = 1e-9);
        // At the centre: straight up.
        assert_abs_diff_eq!(
            p.repair_point(v(50., 0., 0.)),
            v(50., 0., r),
            epsilon = 1e-9
        );
        // Outside: untouched.
        assert_eq!(p.repair_point(v(0., 50., 0.)), v(0., 50., 0.));
    }

    #[test]
    fn samples_are_smooth_detours_in_the_box() {
        let p = one_sphere(9);
        let mut rng = StdRng::seed_from_u64(1);
        for _ in 0..50 {
            let x = p.sample(&mut rng);
            assert_eq!(x.len(), 27);
            for (d, xi) in x.iter().enumerate() {
                assert!(*xi >= p.lower()[d] && *xi <= p.upper()[d]);
            }
            // Evenly spread by length along start → via → end: every segment but the one that
            // cuts the via corner has the same length, the longest.
            let raw: Vec<Vec3> = std::iter::once(p.start)
                .chain((0..9).map(|k| p.raw_waypoint(&x, k)))
                .chain(std::iter::once(p.end))
                .collect();
            let lens: Vec<f64> = leg_lengths(&raw).collect();
            let longest = lens.iter().copied().fold(0.0, f64::max);
            let equal = lens.iter().filter(|l| (*l - longest).abs() < 1e-6).count();
            assert!(equal >= 9, "{lens:?}");
            assert!(polyline_length(&raw) >= 100.0 - 1e-9);
        }
        assert_eq!(p.move_groups(), vec![0..9, 9..18, 18..27]);
    }
}
