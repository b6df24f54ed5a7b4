//! Where the vehicle can go at all: the safety predicate rasterised over the area, its connected
//! regions, and grid distances to a goal.
//!
//! Transits between sweeps ([`super::sweeps`]) ask two questions a Hybrid A* search answers only
//! slowly: is the goal reachable (a search that fails explores the whole region first), and which
//! way round the obstacles is short. The raster answers the first by a region label (8-connected
//! free cells) and the second by a Dijkstra distance from the goal over free cells, used as the
//! search's guide (Dolgov et al.'s obstacle-aware heuristic).

use std::collections::BinaryHeap;

use crate::queue::Cheapest;

use super::boxes::Rect;
use super::hybrid_astar::{self, HybridAStarError, HybridAStarParams, HybridAStarResult};
use super::path::Pose2;

/// Weight on the grid-distance guide of a guided search (weighted A*: the path found is at most
/// this factor longer than the shortest, and found with far fewer expansions).
const GUIDE_WEIGHT: f64 = 1.5;

/// How far the grid guide of a search is expanded: this many times the chord plus a margin (a
/// way round an obstacle rarely exceeds twice the straight line; beyond it the guide reads flat
/// and the search is only slower, never wrong).
const GUIDE_REACH: f64 = 3.0;
const GUIDE_MARGIN_M: f64 = 200.0;

/// The safety predicate on a raster of square cells.
#[derive(Debug, Clone)]
pub struct ReachGrid {
    /// South-west corner.
    origin: [f64; 2],
    /// Cell size, metres.
    cell: f64,
    /// Columns and rows.
    nx: usize,
    ny: usize,
    /// Region label per cell; `u32::MAX` = not free.
    label: Vec<u32>,
}

/// The 8 neighbour offsets and their step lengths in cells.
const NEIGHBOURS: [(i64, i64, f64); 8] = [
    (1, 0, 1.0),
    (-1, 0, 1.0),
    (0, 1, 1.0),
    (0, -1, 1.0),
    (1, 1, std::f64::consts::SQRT_2),
    (1, -1, std::f64::consts::SQRT_2),
    (-1, 1, std::f64::consts::SQRT_2),
    (-1, -1, std::f64::consts::SQRT_2),
];

impl ReachGrid {
    /// Rasterises `free` over `area` at cell centres and labels the 8-connected free regions.
    pub fn new(area: Rect, cell: f64, free: &dyn Fn(f64, f64) -> bool) -> Self {
        let nx = ((area.x1 - area.x0) / cell).ceil().max(1.0) as usize;
        let ny = ((area.y1 - area.y0) / cell).ceil().max(1.0) as usize;
        let origin = [area.x0, area.y0];
        let mut label = vec![u32::MAX; nx * ny];
        let mut is_free = vec![false; nx * ny];
        for j in 0..ny {
            for i in 0..nx {
                let x = origin[0] + (i as f64 + 0.5) * cell;
                let y = origin[1] + (j as f64 + 0.5) * cell;
                is_free[j * nx + i] = free(x, y);
            }
        }
        let mut next = 0u32;
        let mut stack = Vec::new();
        for start in 0..nx * ny {
            if !is_free[start] || label[start] != u32::MAX {
                continue;
            }
            label[start] = next;
            stack.push(start);
            while let Some(k) = stack.pop() {
                let (i, j) = ((k % nx) as i64, (k / nx) as i64);
                for (di, dj, _) in NEIGHBOURS {
                    let (a, b) = (i + di, j + dj);
                    if a < 0 || b < 0 || a >= nx as i64 || b >= ny as i64 {
                        continue;
                    }
                    let n = b as usize * nx + a as usize;
                    if is_free[n] && label[n] == u32::MAX {
                        label[n] = next;
                        stack.push(n);
                    }
                }
            }
            next += 1;
        }
        Self {
            origin,
            cell,
            nx,
            ny,
            label,
        }
    }

    /// The cell holding `(x, y)`.
    fn index(&self, x: f64, y: f64) -> Option<usize> {
        let i = ((x - self.origin[0]) / self.cell).floor();
        let j = ((y - self.origin[1]) / self.cell).floor();
        if i < 0.0 || j < 0.0 || i >= self.nx as f64 || j >= self.ny as f64 {
            return None;
        }
        Some(j as usize * self.nx + i as usize)
    }

    /// The free region holding `(x, y)`, if its cell is free.
    pub fn region(&self, x: f64, y: f64) -> Option<u32> {
        self.index(x, y)
            .and_then(|k| self.label.get(k).copied())
            .filter(|&l| l != u32::MAX)
    }

    /// Whether two points lie in the same free region.
    pub fn connected(&self, a: [f64; 2], b: [f64; 2]) -> bool {
        matches!((self.region(a[0], a[1]), self.region(b[0], b[1])), (Some(p), Some(q)) if p == q)
    }

    /// A forward-only path from `from` to `goal` on `free` within `bounds` (see
    /// [`hybrid_astar::plan`]), searched only when the two lie in the same free region of this
    /// grid and guided by the grid distance to the goal, weighted by `GUIDE_WEIGHT` (1.5): a
    /// transit or a way round needs to be found fast, not to be shortest. `Ok(None)` when the
    /// two are not connected or the search finds nothing within `params.max_expansions`.
    pub fn guided_search(
        &self,
        from: Pose2,
        goal: Pose2,
        free: &dyn Fn(f64, f64) -> bool,
        bounds: [f64; 4],
        params: &HybridAStarParams,
    ) -> Result<Option<HybridAStarResult>, HybridAStarError> {
        if !self.connected(from.xy(), goal.xy()) {
            return Ok(None);
        }
        let chord = (goal.x - from.x).hypot(goal.y - from.y);
        let guide =
            self.distance_between(goal.xy(), from.xy(), GUIDE_REACH * chord + GUIDE_MARGIN_M);
        let guide = |x: f64, y: f64| GUIDE_WEIGHT * guide.at(x, y);
        hybrid_astar::plan_guided(from, goal, free, bounds, params, &guide)
    }

    /// Grid distances (metres) from `goal` over free cells, expanded until `limit` metres;
    /// cells beyond read as `limit`, blocked or other-region cells as `+∞`.
    pub fn distance_from(&self, goal: [f64; 2], limit: f64) -> GridDistance<'_> {
        self.distance_toward(goal, None, limit)
    }

    /// [`Self::distance_from`] for a search that starts at `start`: once the start's cell is
    /// reached at distance `d`, the expansion stops at `min(limit, 1.5·d + 40 m)` — a search
    /// guided toward the goal rarely strays farther, and beyond it the guide reads flat (slower,
    /// never wrong).
    pub fn distance_between(
        &self,
        goal: [f64; 2],
        start: [f64; 2],
        limit: f64,
    ) -> GridDistance<'_> {
        self.distance_toward(goal, Some(start), limit)
    }

    fn distance_toward(
        &self,
        goal: [f64; 2],
        start: Option<[f64; 2]>,
        limit: f64,
    ) -> GridDistance<'_> {
        let start = start.and_then(|p| self.index(p[0], p[1]));
        let mut limit = limit;
        let mut dist = vec![f64::INFINITY; self.nx * self.ny];
        let mut heap = BinaryHeap::new();
        if let Some(g) = self
            .index(goal[0], goal[1])
            .filter(|&k| self.label[k] != u32::MAX)
        {
            dist[g] = 0.0;
            heap.push(Cheapest(0.0, g));
        }
        while let Some(Cheapest(d, k)) = heap.pop() {
            if d > dist[k] || d > limit {
                continue;
            }
            if Some(k) == start {
                limit = limit.min(1.5 * d + 40.0);
            }
            let (i, j) = ((k % self.nx) as i64, (k / self.nx) as i64);
            for (di, dj, len) in NEIGHBOURS {
                let (a, b) = (i + di, j + dj);
                if a < 0 || b < 0 || a >= self.nx as i64 || b >= self.ny as i64 {
                    continue;
                }
                let n = b as usize * self.nx + a as usize;
                let nd = d + len * self.cell;
                if self.label[n] != u32::MAX && nd < dist[n] && nd <= limit {
                    dist[n] = nd;
                    heap.push(Cheapest(nd, n));
                }
            }
        }
        GridDistance {
            grid: self,
            dist,
            limit,
        }
    }
}

/// Distances from one goal (see [`ReachGrid::distance_from`]).
pub struct GridDistance<'g> {
    grid: &'g ReachGrid,
    dist: Vec<f64>,
    limit: f64,
}

impl GridDistance<'_> {
    /// The distance at `(x, y)`, less one cell diagonal so it stays a fair guide off-centre.
    pub fn at(&self, x: f64, y: f64) -> f64 {
        let slack = std::f64::consts::SQRT_2 * self.grid.cell;
        match self.grid.index(x, y).and_then(|k| self.dist.get(k)) {
            Some(d) if d.is_finite() => (d - slack).max(0.0),
            Some(_) if self.grid.region(x, y).is_some() => self.limit,
            _ => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn a_wall_splits_regions_and_the_distance_goes_round_its_gap() {
        // A 40 × 40 m area, 1 m cells; a wall at x ∈ [19, 21) for y ≥ 10, and a closed pocket.
        let free = |x: f64, y: f64| !((19.0..21.0).contains(&x) && y >= 10.0);
        let grid = ReachGrid::new(Rect::new(0.0, 0.0, 40.0, 40.0), 1.0, &free);
        assert!(grid.connected([5.5, 30.5], [35.5, 30.5]));
        assert_eq!(grid.region(20.0, 30.0), None);
        let d = grid.distance_from([5.5, 30.5], 500.0);
        // Straight along a row: exactly 10 cells.
        assert_abs_diff_eq!(d.dist[30 * 40 + 15], 10.0, epsilon = 1e-9);
        // Across the wall the path goes round its south end: far longer than the 30 m chord.
        assert!(d.dist[30 * 40 + 35] > 50.0, "{}", d.dist[30 * 40 + 35]);
        let sealed = |x: f64, y: f64| !((10.0..12.0).contains(&x) || (10.0..12.0).contains(&y));
        let grid = ReachGrid::new(Rect::new(0.0, 0.0, 40.0, 40.0), 1.0, &sealed);
        assert!(!grid.connected([5.5, 5.5], [30.5, 30.5]));
    }

    #[test]
    fn a_guide_toward_a_start_stops_half_again_beyond_it() {
        // An open 100 × 10 m strip of 1 m cells; goal at x = 0.5, start 20 cells east: the
        // start is 20 m away, so the expansion stops at 1.5·20 + 40 = 70 m.
        let grid = ReachGrid::new(Rect::new(0.0, 0.0, 100.0, 10.0), 1.0, &|_, _| true);
        let full = grid.distance_from([0.5, 5.5], 500.0);
        let near = grid.distance_between([0.5, 5.5], [20.5, 5.5], 500.0);
        let row = 5 * 100;
        for i in [0usize, 10, 20, 50, 70] {
            assert_abs_diff_eq!(near.dist[row + i], full.dist[row + i], epsilon = 1e-9);
        }
        assert_abs_diff_eq!(full.dist[row + 90], 90.0, epsilon = 1e-9);
        assert!(near.dist[row + 90].is_infinite());
        // Beyond the stop the guide reads flat at the stop, below the true 90 m.
        assert_abs_diff_eq!(near.at(90.5, 5.5), 70.0, epsilon = 1e-9);
    }
}
