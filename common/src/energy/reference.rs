//! The yardstick of an energy plan: the path of least length-and-energy cost (eq. (6) of Zhang
//! et al. 2022 at its initial weights, [`measure`]; for the length baseline, the shortest path)
//! a grid search finds in the same water, over the same seabed, within the same pitch
//! limits, outside the same hard obstacles — what Zhang et al. 2022's comparison (§4, Table 3)
//! measures its planners against each other by, here measured against a reference nobody's
//! swarm made.
//!
//! Dijkstra on a lattice of `cell` metres aligned with the start, with the moves `(i, j, k)`, `|i|,
//! |j| ≤ 3`, `|k| ≤ 1`, `gcd = 1`, whose pitch is within the vehicle's limits (the steepest is
//! 19.5°, so a 20° limit is nearly reached). A search state is a lattice point and the move that
//! led there, and a move may follow another only when an arc of the turning radius of eq. (5) fits
//! the corner (`corner_fits`). A move costs the work of eq. (10)–(11) summed over sub-steps of at
//! most one cell (the same [`EnergyModel::segment_work`](super::EnergyModel::segment_work) the
//! plan's figures use) and its length, weighed by [`measure`]; it is admissible when every sub-step
//! point is inside the bounds, outside every hard sphere and the terrain clearance above the
//! seabed. The lattice path is then string-pulled: a straight shortcut replaces a stretch when it
//! is admissible, costs less and its corners at both ends fit the turning radius.
//!
//! The reference is a polyline whose corners keep the radius, where the plan is a spline: its
//! stretches follow the lattice's directions before the string pulling, which can make it
//! dearer than the true optimum by a few per cent, and a plan can come out below it.

use std::collections::BinaryHeap;

use super::problem::{EnergyProblem, Objective};
use crate::geometry::Vec3;
use crate::gridsearch::gcd;
use crate::queue::Cheapest;
use crate::swarm::Problem;

/// Most lattice nodes a search may hold: each has a state per move (about 90 within a 20°
/// pitch limit), so 100 000 nodes take some 9 M states, 100 MB.
pub const MAX_REFERENCE_NODES: usize = 100_000;

/// A reference path and its measures.
#[derive(Debug, Clone, PartialEq)]
pub struct Reference {
    /// From the start to the goal.
    pub points: Vec<Vec3>,
    /// What the search minimised ([`measure`]).
    pub cost: f64,
    /// Its length, metres.
    pub length_m: f64,
    /// Its work, joules.
    pub energy_j: f64,
    /// The lattice's cell, metres.
    pub cell_m: f64,
}

/// The lattice.
struct Lattice<'a> {
    problem: &'a EnergyProblem,
    origin: Vec3,
    cell: f64,
    /// Index range along x, y, z (inclusive lower, exclusive upper), relative to the origin.
    lo: [i64; 3],
    size: [i64; 3],
}

impl Lattice<'_> {
    fn index(&self, c: [i64; 3]) -> Option<usize> {
        let mut n = 0i64;
        for a in (0..3).rev() {
            let k = c[a] - self.lo[a];
            if k < 0 || k >= self.size[a] {
                return None;
            }
            n = n * self.size[a] + k;
        }
        usize::try_from(n).ok()
    }

    fn coords(&self, n: usize) -> [i64; 3] {
        let mut n = n as i64;
        let mut c = [0; 3];
        for (k, (size, lo)) in c.iter_mut().zip(self.size.iter().zip(&self.lo)) {
            *k = n % size + lo;
            n /= size;
        }
        c
    }

    fn at(&self, c: [i64; 3]) -> Vec3 {
        self.origin + Vec3::new(c[0] as f64, c[1] as f64, c[2] as f64) * self.cell
    }

    /// A point the vehicle may be at: inside the bounds, out of every hard sphere, clear of
    /// the seabed.
    fn free(&self, p: &Vec3) -> bool {
        let (lo, hi) = (self.problem.lower(), self.problem.upper());
        let inside = (0..3).all(|a| p[a] >= lo[a] - 1e-9 && p[a] <= hi[a] + 1e-9);
        let model = &self.problem.model;
        let clear = model
            .terrain
            .as_ref()
            .is_none_or(|t| p.z - t.elevation(p.x, p.y) >= model.terrain_clearance_m);
        inside
            && clear
            && self
                .problem
                .hard
                .iter()
                .all(|s| (p - s.centre).norm() > s.radius)
    }

    /// The cost of the straight move `a → b` when it is admissible: within the pitch limits and
    /// free at every sub-step of at most one cell.
    fn straight(&self, a: &Vec3, b: &Vec3) -> Option<(f64, f64, f64)> {
        let d = b - a;
        let length = d.norm();
        let pitch = d.z.atan2(d.x.hypot(d.y)).to_degrees();
        let (lo, hi) = self.problem.model.pitch_range_deg;
        if length > 0.0 && !(lo - 1e-9..=hi + 1e-9).contains(&pitch) {
            return None;
        }
        let steps = (length / self.cell).ceil().max(1.0) as usize;
        let mut energy = 0.0;
        let mut prev = *a;
        for k in 1..=steps {
            let p = a + d * (k as f64 / steps as f64);
            if !self.free(&p) {
                return None;
            }
            let w = self.problem.model.segment_work(&prev, &p);
            energy += w.thrust_j + w.current_j;
            prev = p;
        }
        Some((measure(self.problem, length, energy), length, energy))
    }
}

/// What the reference minimises: for [`Objective::Full`], the path and energy terms of Zhang et
/// al. 2022's eq. (6) at their initial weights over the problem's scales (the radius and angle
/// terms are zero on a path that keeps the limits, and the self-adjusting weights of eq. (8) and
/// (12) move each weight by at most its range, 0.01 of 0.25 in Table 2, so this is eq. (6)
/// within a few per cent, and additive along a path as a grid search needs); the length for
/// [`Objective::Length`].
pub fn measure(problem: &EnergyProblem, length_m: f64, energy_j: f64) -> f64 {
    match problem.objective {
        Objective::Length => length_m,
        Objective::Full => {
            let (w, s) = (&problem.model.weights.init, &problem.scales);
            w[0] * length_m / s[0] + w[1] * energy_j / s[1]
        }
    }
}

/// The lattice moves within the pitch range `(lo, hi)` degrees.
fn moves(pitch_range: (f64, f64)) -> Vec<[i64; 3]> {
    let mut out = Vec::new();
    for i in -3i64..=3 {
        for j in -3i64..=3 {
            for k in -1i64..=1 {
                if gcd(gcd(i.abs(), j.abs()), k.abs()) != 1 {
                    continue;
                }
                let pitch = (k as f64).atan2((i as f64).hypot(j as f64)).to_degrees();
                if (pitch_range.0..=pitch_range.1).contains(&pitch) {
                    out.push([i, j, k]);
                }
            }
        }
    }
    out
}

/// The reference of `problem` on a lattice of `cell_m`; `None` when no admissible lattice path
/// joins the start to the goal, or the lattice would hold more than [`MAX_REFERENCE_NODES`].
pub fn reference(problem: &EnergyProblem, cell_m: f64) -> Option<Reference> {
    let (lower, upper) = (problem.lower(), problem.upper());
    if cell_m.is_nan() || cell_m <= 0.0 || lower.len() < 3 {
        return None;
    }
    let origin = problem.start;
    let mut lo = [0i64; 3];
    let mut size = [0i64; 3];
    let mut nodes = 1usize;
    for a in 0..3 {
        lo[a] = ((lower[a] - origin[a]) / cell_m).ceil() as i64;
        let hi = ((upper[a] - origin[a]) / cell_m).floor() as i64;
        size[a] = (hi - lo[a] + 1).max(1);
        nodes = nodes.saturating_mul(size[a] as usize);
    }
    if nodes > MAX_REFERENCE_NODES {
        return None;
    }
    let lattice = Lattice {
        problem,
        origin,
        cell: cell_m,
        lo,
        size,
    };
    let snap = |p: &Vec3| -> [i64; 3] {
        let mut c = [0; 3];
        for a in 0..3 {
            c[a] = ((p[a] - origin[a]) / cell_m)
                .round()
                .clamp(lo[a] as f64, (lo[a] + size[a] - 1) as f64) as i64;
        }
        c
    };
    let (s, g) = (
        lattice.index([0, 0, 0])?,
        lattice.index(snap(&problem.goal))?,
    );
    let grid = search(&lattice, s, g)?;
    let mut points: Vec<Vec3> = grid
        .iter()
        .map(|n| lattice.at(lattice.coords(*n)))
        .collect();
    if let Some(last) = points.last_mut() {
        // The snapped goal is within half a cell's diagonal of the true one.
        if lattice.straight(last, &problem.goal).is_some() {
            points.push(problem.goal);
        }
    }
    let points = pulled(&lattice, points);
    let mut out = Reference {
        points: Vec::new(),
        cost: 0.0,
        length_m: 0.0,
        energy_j: 0.0,
        cell_m,
    };
    for w in points.windows(2) {
        let (c, l, e) = lattice.straight(&w[0], &w[1])?;
        out.cost += c;
        out.length_m += l;
        out.energy_j += e;
    }
    out.points = points;
    Some(out)
}

/// Dijkstra from node `s` to node `g` over states (node, move that led there): a move may follow
/// another only when an arc of the turning radius fits the corner ([`turns`]). The node sequence, or `None`.
fn search(lattice: &Lattice, s: usize, g: usize) -> Option<Vec<usize>> {
    let offsets = moves(lattice.problem.model.pitch_range_deg);
    let follows = turns(
        &offsets,
        lattice.cell,
        lattice.problem.model.min_turn_radius_m,
    );
    let m = offsets.len();
    let nodes = lattice.size.iter().product::<i64>() as usize;
    // State `node · (m + 1) + k`: at `node`, arrived by move `k` (`m`: the start, no heading).
    let state = |node: usize, k: usize| node * (m + 1) + k;
    let mut dist = vec![f64::INFINITY; nodes * (m + 1)];
    let mut from = vec![usize::MAX; nodes * (m + 1)];
    // The cost of move `k` out of `node`, computed once (NaN: not yet; ∞: inadmissible).
    let mut edge = vec![f64::NAN; nodes * m];
    let mut heap = BinaryHeap::new();
    dist[state(s, m)] = 0.0;
    heap.push(Cheapest(0.0, state(s, m)));
    let mut reached = None;
    while let Some(Cheapest(d, here)) = heap.pop() {
        let (u, arrived) = (here / (m + 1), here % (m + 1));
        if u == g {
            reached = Some(here);
            break;
        }
        if d > dist[here] {
            continue;
        }
        let cu = lattice.coords(u);
        for k in (0..m).filter(|k| arrived == m || follows[arrived * m + k]) {
            let o = offsets[k];
            let c = [cu[0] + o[0], cu[1] + o[1], cu[2] + o[2]];
            let Some(v) = lattice.index(c) else {
                continue;
            };
            if edge[u * m + k].is_nan() {
                edge[u * m + k] = lattice
                    .straight(&lattice.at(cu), &lattice.at(c))
                    .map_or(f64::INFINITY, |e| e.0);
            }
            let next = state(v, k);
            let w = d + edge[u * m + k];
            if w < dist[next] {
                dist[next] = w;
                from[next] = here;
                heap.push(Cheapest(w, next));
            }
        }
    }
    let mut at = reached?;
    let mut path = vec![at / (m + 1)];
    while at != state(s, m) {
        at = from[at];
        path.push(at / (m + 1));
    }
    path.reverse();
    Some(path)
}

/// `follows[a · m + b]`: move `b` may follow move `a` ([`corner_fits`]).
fn turns(offsets: &[[i64; 3]], cell: f64, min_radius: f64) -> Vec<bool> {
    let v = |o: &[i64; 3]| Vec3::new(o[0] as f64, o[1] as f64, o[2] as f64) * cell;
    let mut out = Vec::with_capacity(offsets.len() * offsets.len());
    for a in offsets {
        for b in offsets {
            out.push(corner_fits(&-v(a), &Vec3::zeros(), &v(b), min_radius));
        }
    }
    out
}

/// Whether the corner at `b` of the polyline `a → b → c` can be flown on an arc of
/// `min_radius` tangent to both legs within their halves: `R · tan(θ / 2) ≤ min(|ab|, |bc|) / 2`
/// for a turn of θ. (The circle through the three points, which the plan's dense samples are
/// measured by, says nothing about a corner of long legs: a hairpin of 17 m legs lies on a
/// circle of 18 m.)
fn corner_fits(a: &Vec3, b: &Vec3, c: &Vec3, min_radius: f64) -> bool {
    let (u, v) = (b - a, c - b);
    let (lu, lv) = (u.norm(), v.norm());
    if lu == 0.0 || lv == 0.0 {
        return true;
    }
    let cos = (u.dot(&v) / (lu * lv)).clamp(-1.0, 1.0);
    let half = 0.5 * cos.acos();
    if half >= std::f64::consts::FRAC_PI_2 - 1e-9 {
        return false;
    }
    min_radius * half.tan() <= 0.5 * lu.min(lv) + 1e-9
}

/// String pulling: from each kept point, the farthest later point whose straight move is
/// admissible and no dearer than the stretch it replaces.
fn pulled(lattice: &Lattice, points: Vec<Vec3>) -> Vec<Vec3> {
    if points.len() < 3 {
        return points;
    }
    // Cost of the stretch from point 0 to point k along the path.
    let mut along = vec![0.0; points.len()];
    for k in 1..points.len() {
        along[k] = along[k - 1]
            + lattice
                .straight(&points[k - 1], &points[k])
                .map_or(f64::INFINITY, |c| c.0);
    }
    let radius = lattice.problem.model.min_turn_radius_m;
    let mut out = vec![points[0]];
    let mut i = 0;
    while i + 1 < points.len() {
        let mut next = i + 1;
        for k in (i + 2..points.len()).rev() {
            let cheaper = lattice
                .straight(&points[i], &points[k])
                .is_some_and(|(c, _, _)| c <= along[k] - along[i] + 1e-9);
            // The turns at both ends of the shortcut keep the radius.
            let before =
                out.len() < 2 || corner_fits(&out[out.len() - 2], &points[i], &points[k], radius);
            let after = k + 1 == points.len()
                || corner_fits(&points[i], &points[k], &points[k + 1], radius);
            if cheaper && before && after {
                next = k;
                break;
            }
        }
        out.push(points[next]);
        i = next;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::vehicle_toml;
    use crate::scenario::Scenario;

    fn scenario(extra: &str) -> Scenario {
        let text = format!(
            "name = \"reference\"\n[bounds]\nmin = [0.0, 0.0, 0.0]\nmax = [100.0, 100.0, 100.0]\n\
             {}[fleet]\nd_min_m = 0.0\nmission_time_s = 300.0\n[optimizer]\n\
             algorithm = \"epa-pso\"\n{extra}",
            vehicle_toml("auv1", [10.0, 50.0, 50.0], [90.0, 50.0, 50.0])
        );
        match Scenario::parse(&text, std::path::Path::new("reference.toml")) {
            Ok(s) => s,
            Err(e) => panic!("{e}"),
        }
    }

    #[test]
    fn in_still_open_water_the_reference_is_the_straight_line() {
        let s = scenario("");
        let p = EnergyProblem::new(&s, 0, Objective::Length).ok();
        let r = p.as_ref().and_then(|p| reference(p, 4.0));
        let Some(r) = r else { panic!("no reference") };
        assert!((r.length_m - 80.0).abs() < 1e-9, "{r:?}");
        assert_eq!(r.points.len(), 2, "{r:?}");
        // Level flight, no current, at any ground speed v for 80 / v seconds:
        // X_R(0) · v · 80 / v = 5.3 N × 80 m = 424 J.
        assert!((r.energy_j - 424.0).abs() < 1e-9, "{r:?}");
    }

    #[test]
    fn a_climb_steeper_than_the_pitch_limit_is_spread_out() {
        // 40 m up over 20 m: 63° straight; the shortest admissible path is at least
        // 40 / sin 20° = 117 m long.
        let mut s = scenario("");
        s.vehicles[0].goal = [30.0, 50.0, 90.0];
        let p = EnergyProblem::new(&s, 0, Objective::Length).ok();
        let r = p.as_ref().and_then(|p| reference(p, 4.0));
        let Some(r) = r else { panic!("no reference") };
        let bound = 40.0 / 20f64.to_radians().sin();
        assert!(r.length_m >= bound - 1e-6, "{} < {bound}", r.length_m);
        assert!(
            r.length_m <= bound * 1.06,
            "{} far over {bound}",
            r.length_m
        );
        for w in r.points.windows(2) {
            let d = w[1] - w[0];
            let pitch = d.z.atan2(d.x.hypot(d.y)).to_degrees();
            assert!(pitch <= 20.0 + 1e-9, "pitch {pitch}");
        }
        // The climb turns round, and every corner fits an arc of the turning radius.
        let radius = p.as_ref().map_or(f64::NAN, |p| p.model.min_turn_radius_m);
        assert!(radius > 1.0, "{radius}");
        for w in r.points.windows(3) {
            assert!(corner_fits(&w[0], &w[1], &w[2], radius), "{w:?}");
        }
    }

    #[test]
    fn a_hard_sphere_is_gone_round_near_the_tangent_bound() {
        // A 20 m sphere centred on the straight line: in its plane the shortest way round is
        // two tangents and an arc, 2·√(40² − 20²) + 20·π/3 = 90.22 m.
        let s = scenario(
            "[[obstacles]]\nid = \"rock\"\nkind = \"hard\"\ncentre = [50.0, 50.0, 50.0]\nradius_m = 20.0\ninflation_m = 0.0\n",
        );
        let p = EnergyProblem::new(&s, 0, Objective::Length).ok();
        let r = p.as_ref().and_then(|p| reference(p, 4.0));
        let Some(r) = r else { panic!("no reference") };
        let bound =
            2.0 * (40f64.powi(2) - 20f64.powi(2)).sqrt() + 20.0 * std::f64::consts::PI / 3.0;
        assert!(r.length_m >= bound - 1e-6, "{} < {bound}", r.length_m);
        assert!(
            r.length_m <= bound * 1.03,
            "{} far over {bound}",
            r.length_m
        );
    }

    #[test]
    fn the_lattice_is_bounded() {
        let s = scenario("");
        let p = EnergyProblem::new(&s, 0, Objective::Length).ok();
        assert!(
            p.as_ref().and_then(|p| reference(p, 2.0)).is_none(),
            "132 651 nodes"
        );
        assert!(p.as_ref().and_then(|p| reference(p, -1.0)).is_none());
    }

    #[test]
    fn a_corner_fits_its_arc_by_hand() {
        let (a, b) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(10.0, 0.0, 0.0));
        // A right angle: R · tan 45° = R ≤ 5 m, half the shorter leg.
        let c = Vec3::new(10.0, 10.0, 0.0);
        assert!(corner_fits(&a, &b, &c, 5.0));
        assert!(!corner_fits(&a, &b, &c, 5.01));
        // Straight on always fits; a hairpin never does, whatever the legs.
        assert!(corner_fits(&a, &b, &Vec3::new(30.0, 0.0, 0.0), 1e6));
        assert!(!corner_fits(&a, &b, &Vec3::new(-5.0, 0.0, 0.0), 0.01));
        // 60°: R · tan 30° ≤ 2 (the 4 m leg): R ≤ 3.46 m.
        let c = b + Vec3::new(2.0, 12f64.sqrt(), 0.0);
        assert!(corner_fits(&a, &b, &c, 3.46) && !corner_fits(&a, &b, &c, 3.47));
    }
}
