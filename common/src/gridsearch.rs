//! A reference shortest admissible crawler path by grid search (the yardstick IPSO's
//! smoothed length is measured against, and a planner baseline in its own right).
//!
//! Dijkstra (as A*, with the horizontal distance to the goal as its heuristic) on a square grid
//! of `cell` metres over the area, with 32 move directions (every
//! offset `(i, j)` with `|i|, |j| ≤ 3` and `gcd(i, j) = 1`), so the direction of any straight
//! stretch is within 4.7° of a move and a grid path is at most ~0.35 % longer than the straight
//! stretch it follows. A move's cost is its 3D length on the draped terrain, measured over
//! sub-steps of at most one cell; a move is admissible when every sub-step stays outside every
//! hazard grown by `clearance` and no sub-step is steeper than `max_slope_deg` — the same rules
//! the crawler cost applies to the smoothed path.

use std::collections::BinaryHeap;

use crate::queue::Cheapest;

use crate::terrain::{Hazard, Terrain};

/// Greatest common divisor of two non-negative integers (a lattice move's reduced form).
pub(crate) fn gcd(a: i64, b: i64) -> i64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// The moves: every `(i, j)` with `|i|, |j| ≤ 3`, not both 0, `gcd(|i|, |j|) = 1`.
fn moves() -> Vec<(i64, i64)> {
    let mut out = Vec::new();
    for i in -3i64..=3 {
        for j in -3i64..=3 {
            if (i, j) != (0, 0) && gcd(i.abs(), j.abs()) == 1 {
                out.push((i, j));
            }
        }
    }
    out
}

/// What the search needs.
#[derive(Debug, Clone)]
pub struct GridSearch<'a> {
    /// The seabed.
    pub terrain: &'a Terrain,
    /// Hazards to keep out of.
    pub hazards: &'a [Hazard],
    /// Horizontal distance to keep from every hazard's edge, metres.
    pub clearance_m: f64,
    /// Steepest admissible sub-step, degrees.
    pub max_slope_deg: f64,
    /// Area: min x, min y, max x, max y.
    pub area: [f64; 4],
    /// Grid spacing, metres.
    pub cell_m: f64,
    /// Height of the path above the seabed, metres.
    pub sensor_height_m: f64,
}

/// A found path.
#[derive(Debug, Clone, PartialEq)]
pub struct GridPath {
    /// Horizontal waypoints from start to goal (grid nodes, start and goal snapped to the grid).
    pub points: Vec<[f64; 2]>,
    /// 3D length on the draped terrain, metres.
    pub length_m: f64,
}

impl GridSearch<'_> {
    fn free(&self, x: f64, y: f64) -> bool {
        self.hazards.iter().all(|h| {
            let d = (x - h.centre[0]).hypot(y - h.centre[1]);
            d >= h.radius_m + self.clearance_m
        })
    }

    /// 3D length of the straight move from `a` to `b`, or `None` when it is not admissible.
    fn move_cost(&self, a: [f64; 2], b: [f64; 2]) -> Option<f64> {
        let horizontal = (b[0] - a[0]).hypot(b[1] - a[1]);
        let steps = (horizontal / self.cell_m).ceil().max(1.0) as usize;
        let tan_max = self.max_slope_deg.to_radians().tan();
        let mut length = 0.0;
        let mut prev = (a, self.terrain.elevation(a[0], a[1]));
        for k in 1..=steps {
            let f = k as f64 / steps as f64;
            let p = [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])];
            if !self.free(p[0], p[1]) {
                return None;
            }
            let z = self.terrain.elevation(p[0], p[1]);
            let h = horizontal / steps as f64;
            let dz = z - prev.1;
            if dz.abs() > tan_max * h + 1e-12 {
                return None;
            }
            length += (h * h + dz * dz).sqrt();
            prev = (p, z);
        }
        Some(length)
    }

    /// The shortest admissible path from `start` to `goal`, or `None` if there is none.
    pub fn shortest(&self, start: [f64; 2], goal: [f64; 2]) -> Option<GridPath> {
        let [x0, y0, x1, y1] = self.area;
        if !(self.cell_m > 0.0 && x1 > x0 && y1 > y0) {
            return None;
        }
        let cols = ((x1 - x0) / self.cell_m).floor() as i64 + 1;
        let rows = ((y1 - y0) / self.cell_m).floor() as i64 + 1;
        let node = |c: i64, r: i64| (r * cols + c) as usize;
        let at = |n: usize| {
            let (c, r) = (n as i64 % cols, n as i64 / cols);
            [x0 + c as f64 * self.cell_m, y0 + r as f64 * self.cell_m]
        };
        let snap = |p: [f64; 2]| {
            let c = ((p[0] - x0) / self.cell_m)
                .round()
                .clamp(0.0, (cols - 1) as f64) as i64;
            let r = ((p[1] - y0) / self.cell_m)
                .round()
                .clamp(0.0, (rows - 1) as f64) as i64;
            node(c, r)
        };
        let (s, g) = (snap(start), snap(goal));
        let n = (cols * rows) as usize;
        let mut dist = vec![f64::INFINITY; n];
        let mut from = vec![usize::MAX; n];
        let mut heap = BinaryHeap::new();
        // A*: a move costs its 3D length on the terrain, never less than its horizontal one, so
        // the horizontal distance to the goal is a consistent heuristic and the first time the
        // goal is taken its distance is Dijkstra's, with far fewer nodes opened.
        let goal_at = at(g);
        let h = |n: usize| {
            let p = at(n);
            (p[0] - goal_at[0]).hypot(p[1] - goal_at[1])
        };
        dist[s] = 0.0;
        heap.push(Cheapest(h(s), s));
        let offsets = moves();
        while let Some(Cheapest(f, u)) = heap.pop() {
            if u == g {
                break;
            }
            let d = dist[u];
            if f > d + h(u) + 1e-9 {
                continue;
            }
            let (cu, ru) = (u as i64 % cols, u as i64 / cols);
            for &(i, j) in &offsets {
                let (c, r) = (cu + i, ru + j);
                if c < 0 || r < 0 || c >= cols || r >= rows {
                    continue;
                }
                let v = node(c, r);
                let Some(w) = self.move_cost(at(u), at(v)) else {
                    continue;
                };
                if d + w < dist[v] {
                    dist[v] = d + w;
                    from[v] = u;
                    heap.push(Cheapest(d + w + h(v), v));
                }
            }
        }
        if !dist[g].is_finite() {
            return None;
        }
        let mut points = vec![at(g)];
        let mut u = g;
        while u != s {
            u = from[u];
            points.push(at(u));
        }
        points.reverse();
        Some(GridPath {
            points,
            length_m: dist[g],
        })
    }

    /// Any-angle refinement of a grid path (string pulling): from each kept point, jump to the
    /// farthest later point the straight move to which is still admissible. The result is
    /// admissible under the same rules and never longer, so it removes most of the grid's
    /// direction bias (up to 0.35 % on long straight stretches).
    pub fn shortcut(&self, path: &GridPath) -> GridPath {
        let pts = &path.points;
        if pts.len() < 3 {
            return path.clone();
        }
        let mut out = vec![pts[0]];
        let mut length = 0.0;
        let mut i = 0;
        while i + 1 < pts.len() {
            // The next point is always reachable (it was a grid move).
            let mut best = (i + 1, self.move_cost(pts[i], pts[i + 1]).unwrap_or(0.0));
            for j in i + 2..pts.len() {
                if let Some(c) = self.move_cost(pts[i], pts[j]) {
                    best = (j, c);
                }
            }
            out.push(pts[best.0]);
            length += best.1;
            i = best.0;
        }
        GridPath {
            points: out,
            length_m: length,
        }
    }

    /// The reference path of a crawler (`crate::scenario::Scenario::crawler_model`): its
    /// hazards with `clearance_m` from their edges, its pitch limit as the slope limit, on a
    /// grid of `cell_m`, refined by [`Self::shortcut`]. `None` when no path exists.
    pub fn crawler_reference(
        model: &crate::crawler::CrawlerModel,
        cell_m: f64,
        clearance_m: f64,
    ) -> Option<(GridPath, GridPath)> {
        let search = GridSearch {
            terrain: &model.terrain,
            hazards: &model.hazards,
            clearance_m,
            max_slope_deg: model.max_slope_deg,
            area: model.area,
            cell_m,
            sensor_height_m: model.sensor_height_m,
        };
        let grid = search.shortest(model.start, model.goal)?;
        let refined = search.shortcut(&grid);
        Some((grid, refined))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::terrain::HeightGrid;

    /// Level ground (eq. (2)'s first term has no coefficient, so no analytic relief is flat).
    fn flat() -> Terrain {
        grid(vec![0.0; 25], 5)
    }

    /// A `n × n` grid of 10 m cells over the 40 m area.
    fn grid(heights: Vec<f64>, n: usize) -> Terrain {
        match HeightGrid::new([0.0, 0.0], 40.0 / (n - 1) as f64, n, n, heights) {
            Ok(g) => Terrain::Grid(g),
            Err(e) => panic!("{e}"),
        }
    }

    fn search<'a>(t: &'a Terrain, h: &'a [Hazard]) -> GridSearch<'a> {
        GridSearch {
            terrain: t,
            hazards: h,
            clearance_m: 1.0,
            max_slope_deg: 15.0,
            area: [0.0, 0.0, 40.0, 40.0],
            cell_m: 0.5,
            sensor_height_m: 0.5,
        }
    }

    #[test]
    fn there_are_32_moves() {
        assert_eq!(moves().len(), 32);
    }

    #[test]
    fn on_flat_ground_the_grid_path_is_within_half_a_percent_of_straight() {
        let t = flat();
        // A direction no move follows exactly: atan(13/37) ≈ 19.4°.
        let p = search(&t, &[])
            .shortest([1.0, 1.0], [38.0, 14.0])
            .ok_or("no path");
        let Ok(p) = p else { panic!("no path") };
        let straight = 37.0f64.hypot(13.0);
        assert!(p.length_m >= straight - 1e-9, "{}", p.length_m);
        assert!(
            p.length_m <= straight * 1.005,
            "{} vs {straight}",
            p.length_m
        );
        assert_eq!(p.points.first(), Some(&[1.0, 1.0]));
        assert_eq!(p.points.last(), Some(&[38.0, 14.0]));
        // String pulling on open flat ground leaves the straight line itself.
        let s = search(&t, &[]).shortcut(&p);
        assert_eq!(s.points, vec![[1.0, 1.0], [38.0, 14.0]]);
        assert!((s.length_m - straight).abs() < 1e-9, "{}", s.length_m);
    }

    #[test]
    fn hazards_are_skirted_with_clearance_and_walls_block() {
        let t = flat();
        let h = [Hazard {
            id: "h".into(),
            centre: [20.0, 20.0],
            radius_m: 5.0,
            height_m: 1.0,
        }];
        let Some(p) = search(&t, &h).shortest([2.0, 20.0], [38.0, 20.0]) else {
            panic!("no path")
        };
        for q in &p.points {
            assert!((q[0] - 20.0).hypot(q[1] - 20.0) >= 6.0 - 1e-9, "{q:?}");
        }
        // Around a circle of radius 6: 36 m straight, the detour adds a few metres only.
        assert!(p.length_m > 36.0 && p.length_m < 40.0, "{}", p.length_m);
        // Refined: no longer, still clear of the grown hazard at every sub-step.
        let s = search(&t, &h).shortcut(&p);
        assert!(s.length_m <= p.length_m + 1e-9 && s.points.len() < p.points.len());
        for w in s.points.windows(2) {
            let c = crate::terrain::hazard_clearance(&h[0], w[0], w[1]);
            assert!(c >= 1.0 - 0.05, "{c}");
        }
        // The exact geodesic around a 6 m circle from 18 m away on each side:
        // 2·√(18² − 6²) + 6·(π − 2·acos(6/18)) = 33.94 + 3.99 = 37.93 m; the refined path
        // only cuts corners between sub-step checks (0.5 m), so it lies within 1 %.
        let geodesic = 2.0 * (18f64.powi(2) - 36.0).sqrt()
            + 6.0 * (std::f64::consts::PI - 2.0 * (6.0f64 / 18.0).acos());
        assert!(
            (s.length_m - geodesic).abs() < 0.01 * geodesic,
            "{} vs {geodesic}",
            s.length_m
        );
        // A hill steeper than the limit everywhere near its top blocks the straight line; a
        // 30 m wide hazard wall across the whole area blocks everything.
        let wall: Vec<Hazard> = (0..5)
            .map(|k| Hazard {
                id: format!("w{k}"),
                centre: [20.0, k as f64 * 10.0],
                radius_m: 6.0,
                height_m: 1.0,
            })
            .collect();
        assert!(search(&t, &wall)
            .shortest([2.0, 20.0], [38.0, 20.0])
            .is_none());
        // A 9 × 9 grid (5 m cells) with one node 10 m high in the middle: the cells around it
        // slope at up to 63°, far over the 15° limit.
        let mut heights = vec![0.0; 81];
        heights[4 * 9 + 4] = 10.0;
        let hill = grid(heights, 9);
        let Some(p) = search(&hill, &[]).shortest([2.0, 20.0], [38.0, 20.0]) else {
            panic!("no path")
        };
        assert!(
            p.points.iter().any(|q| (q[1] - 20.0).abs() > 3.0),
            "went over the hill"
        );
    }
}
