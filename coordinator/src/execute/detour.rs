//! A coarse way round for a replan's warm start: when a new obstacle closes the
//! passage the current plan used, the plan's remainder — even with its waypoints pushed out of
//! the obstacle — leaves the swarm stuck against it, and a 300 ms swarm does not find the long
//! way round by itself. A* on a coarse 3-D grid over the scenario's bounds finds that way; the
//! grid path, shortened by line of sight, becomes one more warm particle, and the swarm smooths
//! it (turn and pitch limits, timing, the other vehicles).
//!
//! Cells whose centre is inside a hard obstacle's inflated sphere grown by [`GROW`] are
//! blocked; so the line-of-sight shortcuts, which test segments against the spheres grown by
//! [`SHORTCUT_GROW`], keep a little margin that resampling onto the swarm's waypoints (chords
//! between points of the path) then spends.
//!
//! A swimmer over a seabed keeps off it as it does off the obstacles: cells whose centre is less
//! than its clearance plus one layer above the seabed are blocked, and shortcuts keep the
//! clearance plus [`SEABED_MARGIN_M`] all along (sampled as the planner's cost samples it).
//!
//! The way must be one the vehicle can fly: its pitch limit (±20° in Zhi & Zuo 2024) is built into
//! the grid. Layers are `cell · tan(φ_max)` apart (a little less; a cell at most), every move
//! goes one cell sideways and at most one layer up or down, so no grid move is steeper than the
//! limit; a shortcut is taken only when it is no steeper either.

use std::collections::BinaryHeap;
use std::sync::atomic::{AtomicBool, Ordering};

use shoal_common::cost::SEABED_STEP_M;
use shoal_common::geometry::{segment_hits_sphere, Vec3};
use shoal_common::queue::Cheapest;
use shoal_common::scenario::Scenario;
use shoal_common::terrain::Terrain;

/// The seabed a vehicle keeps off and the height it keeps above it; `None` for a crawler (it
/// drives on it) or without a seabed.
pub type KeepOff<'a> = Option<(&'a Terrain, f64)>;

/// What vehicle `i` of `scenario` keeps off: the seabed, for a swimmer.
pub fn keep_off(scenario: &Scenario, i: usize) -> KeepOff<'_> {
    let crawler = scenario
        .vehicles
        .get(i)
        .is_none_or(|v| v.kind == shoal_common::scenario::VehicleKind::Crawler);
    if crawler {
        None
    } else {
        scenario.swimmer_seabed()
    }
}

/// Blocked cells: centre within this × the inflated radius of a hard obstacle.
const GROW: f64 = 1.15;
/// Line-of-sight shortcuts keep out of the inflated spheres grown by this.
const SHORTCUT_GROW: f64 = 1.08;
/// Metres over its clearance a line-of-sight shortcut keeps above the seabed, for the
/// resampling onto the swarm's waypoints.
const SEABED_MARGIN_M: f64 = 1.0;
/// Cells along the longer horizontal side of the bounds.
const CELLS: f64 = 40.0;
/// Nodes the search expands between two looks at its stop flag.
const STOP_EVERY: usize = 1024;
/// Layers are this fraction of the height a one-cell move may climb.
const LAYER_FRACTION: f64 = 0.95;

/// The grid over the scenario's bounds: node spacing per axis, `[cell, cell, layer]`.
struct Grid {
    min: Vec3,
    step: [f64; 3],
    n: [usize; 3],
    blocked: Vec<bool>,
}

impl Grid {
    fn new(scenario: &Scenario, max_pitch: f64, seabed: KeepOff) -> Grid {
        let min = Vec3::from(scenario.bounds.min);
        let extent = Vec3::from(scenario.bounds.max) - min;
        let cell = (extent.x.max(extent.y) / CELLS).max(1.0);
        // Steeper than 45° allowed: layers as far apart as cells (moves of up to 45°).
        let layer = (cell * LAYER_FRACTION * max_pitch.tan()).clamp(0.1, cell);
        let step = [cell, cell, layer];
        let n = [0, 1, 2].map(|k| ((extent[k] / step[k]).floor() as usize + 1).max(1));
        let mut g = Grid {
            min,
            step,
            n,
            blocked: vec![false; n[0] * n[1] * n[2]],
        };
        for k in 0..g.blocked.len() {
            let c = g.centre(k);
            g.blocked[k] = scenario
                .hard_obstacles()
                .any(|o| (c - o.centre()).norm() < GROW * o.inflated_radius())
                || seabed.is_some_and(|(t, keep)| c.z - t.elevation(c.x, c.y) < keep + layer);
        }
        g
    }

    fn index(&self, c: [usize; 3]) -> usize {
        (c[2] * self.n[1] + c[1]) * self.n[0] + c[0]
    }

    fn coords(&self, k: usize) -> [usize; 3] {
        [
            k % self.n[0],
            (k / self.n[0]) % self.n[1],
            k / (self.n[0] * self.n[1]),
        ]
    }

    fn centre(&self, k: usize) -> Vec3 {
        let c = self.coords(k);
        self.min
            + Vec3::new(
                c[0] as f64 * self.step[0],
                c[1] as f64 * self.step[1],
                c[2] as f64 * self.step[2],
            )
    }

    /// The nearest grid node to `p` (clamped into the grid).
    fn nearest(&self, p: Vec3) -> usize {
        let c = [0, 1, 2].map(|a| {
            let f = ((p[a] - self.min[a]) / self.step[a]).round();
            (f.max(0.0) as usize).min(self.n[a] - 1)
        });
        self.index(c)
    }

    /// The step cost between two neighbouring nodes, and the admissible estimate to the goal:
    /// the distance.
    fn cost(a: Vec3, b: Vec3) -> f64 {
        (b - a).norm()
    }

    /// A* from `from` to `to` over free nodes (the two end nodes are allowed even if blocked:
    /// the vehicle is where it is), as node centres; `None` also once `stop` is raised (looked
    /// at every [`STOP_EVERY`] nodes).
    fn search(&self, from: usize, to: usize, stop: Option<&AtomicBool>) -> Option<Vec<usize>> {
        let total = self.blocked.len();
        let mut best = vec![f64::INFINITY; total];
        let mut came = vec![usize::MAX; total];
        let mut open = BinaryHeap::new();
        let goal = self.centre(to);
        best[from] = 0.0;
        open.push(Cheapest(Grid::cost(self.centre(from), goal), from));
        let mut popped = 0usize;
        while let Some(Cheapest(_, k)) = open.pop() {
            if popped.is_multiple_of(STOP_EVERY) && stop.is_some_and(|s| s.load(Ordering::Relaxed))
            {
                return None;
            }
            popped += 1;
            if k == to {
                let mut path = vec![to];
                let mut at = to;
                while at != from {
                    at = came[at];
                    path.push(at);
                }
                path.reverse();
                return Some(path);
            }
            let c = self.coords(k);
            let here = self.centre(k);
            for dz in -1i64..=1 {
                for dy in -1i64..=1 {
                    for dx in -1i64..=1 {
                        // Always sideways: straight up or down is past any pitch limit.
                        if (dx, dy) == (0, 0) {
                            continue;
                        }
                        let step = [dx, dy, dz];
                        let next: Option<Vec<usize>> = (0..3)
                            .map(|a| {
                                let v = c[a] as i64 + step[a];
                                (v >= 0 && (v as usize) < self.n[a]).then_some(v as usize)
                            })
                            .collect();
                        let Some(next) = next else { continue };
                        let j = self.index([next[0], next[1], next[2]]);
                        if self.blocked[j] && j != to {
                            continue;
                        }
                        let there = self.centre(j);
                        let g = best[k] + Grid::cost(here, there);
                        if g < best[j] {
                            best[j] = g;
                            came[j] = k;
                            open.push(Cheapest(g + Grid::cost(there, goal), j));
                        }
                    }
                }
            }
        }
        None
    }
}

/// Whether the segment `a`–`b` stays out of every hard obstacle grown by `grow`.
fn clear(scenario: &Scenario, a: &Vec3, b: &Vec3, grow: f64) -> bool {
    !scenario
        .hard_obstacles()
        .any(|o| segment_hits_sphere(a, b, &o.centre(), grow * o.inflated_radius()))
}

/// Whether the segment `a`–`b` is flyable as one leg: clear (with the shortcut margin), no
/// steeper than `max_pitch` radians, and as high over the seabed as the vehicle keeps plus
/// [`SEABED_MARGIN_M`].
fn flyable(scenario: &Scenario, a: &Vec3, b: &Vec3, max_pitch: f64, seabed: KeepOff) -> bool {
    let d = b - a;
    d.z.abs() <= max_pitch.tan() * d.x.hypot(d.y) + 1e-9
        && clear(scenario, a, b, SHORTCUT_GROW)
        && seabed.is_none_or(|(t, keep)| {
            t.lowest_height_along(a, b, SEABED_STEP_M).0 >= keep + SEABED_MARGIN_M
        })
}

/// A way from `from` to `to` round the scenario's hard obstacles (and over the seabed a
/// swimmer keeps off, [`keep_off`]), no steeper than `max_pitch_deg` (see the module doc): the
/// corners of the shortened grid path, from `from` to `to`. `None` when the grid has no way, or
/// once `stop` is raised (a held vehicle's retry yielding, `replan_queue`: the search takes a
/// few hundred milliseconds on Zhi & Zuo's scenarios).
pub fn detour(
    scenario: &Scenario,
    from: Vec3,
    to: Vec3,
    max_pitch_deg: f64,
    seabed: KeepOff,
    stop: Option<&AtomicBool>,
) -> Option<Vec<Vec3>> {
    let max_pitch = max_pitch_deg.to_radians();
    if flyable(scenario, &from, &to, max_pitch, seabed) {
        return Some(vec![from, to]);
    }
    let grid = Grid::new(scenario, max_pitch, seabed);
    let cells = grid.search(grid.nearest(from), grid.nearest(to), stop)?;
    let mut raw = vec![from];
    // The end nodes stand for `from` and `to` themselves; when both are in one cell (a climb
    // steeper than the pitch limit, in place) there is nothing between them.
    let inner = cells.get(1..cells.len().saturating_sub(1)).unwrap_or(&[]);
    raw.extend(inner.iter().map(|&k| grid.centre(k)));
    raw.push(to);
    // Line of sight: from each corner, jump to the farthest point still in view.
    let mut out = vec![from];
    let mut i = 0;
    while i + 1 < raw.len() {
        let mut j = raw.len() - 1;
        while j > i + 1 && !flyable(scenario, &raw[i], &raw[j], max_pitch, seabed) {
            j -= 1;
        }
        out.push(raw[j]);
        i = j;
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use shoal_common::scenario::{Obstacle, ObstacleKind};

    fn scenario(obstacles: &[([f64; 3], f64)]) -> Result<Scenario, Box<dyn std::error::Error>> {
        let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/amp-pso-1.toml");
        let mut s = Scenario::load(std::path::Path::new(file))?;
        s.bounds.min = [0.0, 0.0, 0.0];
        s.bounds.max = [2000.0, 2000.0, 400.0];
        s.obstacles = obstacles
            .iter()
            .enumerate()
            .map(|(k, (c, r))| Obstacle {
                id: format!("o{k}"),
                kind: ObstacleKind::Hard,
                centre: *c,
                radius_m: *r,
                inflation_m: 50.0,
            })
            .collect();
        Ok(s)
    }

    /// `count` pairs of spheres (150 m, at z = 100 and 300) along x = 1000 from y = 0, `step`
    /// apart.
    fn wall(count: usize, step: f64) -> Vec<([f64; 3], f64)> {
        (0..count)
            .flat_map(|k| {
                let y = step * k as f64;
                [([1000.0, y, 100.0], 150.0), ([1000.0, y, 300.0], 150.0)]
            })
            .collect()
    }

    /// From one side of the wall to the other, at mid-height.
    fn across() -> (Vec3, Vec3) {
        (
            Vec3::new(200.0, 500.0, 200.0),
            Vec3::new(1800.0, 500.0, 200.0),
        )
    }

    fn length(p: &[Vec3]) -> f64 {
        p.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
    }

    #[test]
    fn a_clear_line_is_its_own_detour() -> Result<(), Box<dyn std::error::Error>> {
        let s = scenario(&[([1000.0, 1500.0, 200.0], 100.0)])?;
        let (a, b) = (
            Vec3::new(100.0, 500.0, 200.0),
            Vec3::new(1900.0, 500.0, 200.0),
        );
        assert_eq!(detour(&s, a, b, 20.0, None, None), Some(vec![a, b]));
        Ok(())
    }

    #[test]
    fn a_climb_in_place_steeper_than_the_pitch_limit_does_not_panic(
    ) -> Result<(), Box<dyn std::error::Error>> {
        // From and to in one grid cell, 5 m apart vertically: not flyable at 20°, and the grid
        // search is one cell long.
        let s = scenario(&[])?;
        let (a, b) = (
            Vec3::new(500.0, 500.0, 200.0),
            Vec3::new(500.0, 500.0, 205.0),
        );
        if let Some(path) = detour(&s, a, b, 20.0, None, None) {
            assert_eq!((path.first(), path.last()), (Some(&a), Some(&b)));
        }
        Ok(())
    }

    #[test]
    fn a_wall_of_spheres_is_gone_round_by_its_open_end() -> Result<(), Box<dyn std::error::Error>> {
        // A wall across x = 1000 from y = 0 to y = 1250 (spheres of 150 + 50 m every 250 m),
        // floor to surface (400 m high column, the spheres reach both): the only way from
        // (200, 500) to (1800, 500) is round its north end. At z = 200, between the two
        // spheres' centres, the inflated wall ends at y = 1250 + √(200² − 100²) ≈ 1423.
        let s = scenario(&wall(6, 250.0))?;
        let (a, b) = across();
        let path = detour(&s, a, b, 20.0, None, None).ok_or("no detour")?;
        assert_eq!(path.first(), Some(&a));
        assert_eq!(path.last(), Some(&b));
        for w in path.windows(2) {
            assert!(clear(&s, &w[0], &w[1], 1.0), "{path:?}");
        }
        let north = path.iter().map(|p| p.y).fold(f64::MIN, f64::max);
        assert!(north > 1423.0, "{path:?}");
        // A raised stop flag ends the search (a straight line, above, needs none).
        assert_eq!(
            detour(&s, a, b, 20.0, None, Some(&AtomicBool::new(true))),
            None
        );
        // Round the end: at least 2 × √(800² + 923²) ≈ 2443 m (two straight lines to the
        // wall's end); the grid and the shortcuts' margin add a little, never much.
        let l = length(&path);
        assert!((2443.0..2900.0).contains(&l), "{l} m: {path:?}");
        Ok(())
    }

    #[test]
    fn no_way_through_a_closed_wall() -> Result<(), Box<dyn std::error::Error>> {
        // Spheres every 200 m along x = 1000, at both heights, over the whole width.
        let s = scenario(&wall(11, 200.0))?;
        let (a, b) = across();
        assert_eq!(detour(&s, a, b, 20.0, None, None), None);
        Ok(())
    }

    #[test]
    fn a_climb_too_steep_for_the_pitch_limit_winds_up_within_it(
    ) -> Result<(), Box<dyn std::error::Error>> {
        // 400 m up over 200 m: 63°. At 20° the way needs ≥ 400 / tan 20° ≈ 1099 m of
        // horizontal travel, ≥ 400 / sin 20° ≈ 1170 m in all.
        let s = scenario(&[])?;
        let (a, b) = (
            Vec3::new(100.0, 1000.0, 0.0),
            Vec3::new(300.0, 1000.0, 400.0),
        );
        let path = detour(&s, a, b, 20.0, None, None).ok_or("no way up")?;
        assert_eq!((path.first(), path.last()), (Some(&a), Some(&b)));
        let legs = path.len() - 1;
        for (k, w) in path.windows(2).enumerate() {
            let d = w[1] - w[0];
            let pitch = d.z.abs().atan2(d.x.hypot(d.y)).to_degrees();
            // The two legs joining the ends to the grid may be a few metres steep.
            if k > 0 && k + 1 < legs {
                assert!(pitch <= 20.0 + 1e-6, "leg {k}: {pitch}° in {path:?}");
            }
        }
        let l = length(&path);
        assert!((1150.0..2500.0).contains(&l), "{l} m: {path:?}");
        Ok(())
    }

    /// A 250 m hill (σ = 300 m) under the line from (0, 1000, 100) to (2000, 1000, 100), in the
    /// 400 m box with no obstacle: a swimmer keeping 2 m off the seabed gets a way over or
    /// round it whose every leg keeps 3 m (its clearance plus the shortcut margin) and its
    /// 20° pitch limit; a crawler's (nothing to keep off) is the straight line.
    #[test]
    fn a_swimmer_goes_over_or_round_the_seabed() -> Result<(), Box<dyn std::error::Error>> {
        let hill = Terrain::Hills(vec![shoal_common::terrain::Mountain {
            centre: [1000.0, 1000.0],
            height_m: 250.0,
            spread_m: [300.0, 300.0],
        }]);
        let s = scenario(&[])?;
        let (a, b) = (
            Vec3::new(0.0, 1000.0, 100.0),
            Vec3::new(2000.0, 1000.0, 100.0),
        );
        assert!(hill.lowest_height_along(&a, &b, 1.0).0 < -100.0);
        let way = detour(&s, a, b, 20.0, Some((&hill, 2.0)), None).ok_or("no way over the hill")?;
        assert!(way.len() > 2, "{way:?}");
        assert_eq!((way[0], way[way.len() - 1]), (a, b));
        for w in way.windows(2) {
            let (h, p) = hill.lowest_height_along(&w[0], &w[1], 1.0);
            assert!(h >= 3.0 - 1e-9, "{h} m above the seabed at {p:?}: {way:?}");
            let d = w[1] - w[0];
            assert!(
                d.z.abs() <= 20f64.to_radians().tan() * d.x.hypot(d.y) + 1e-6,
                "{way:?}"
            );
        }
        assert_eq!(detour(&s, a, b, 20.0, None, None), Some(vec![a, b]));
        Ok(())
    }
}
