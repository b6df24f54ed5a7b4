//! A crawler's way round an obstacle that appears while it drives (`shoal-coordinator run`).
//!
//! A coverage crawler (CPP-DSMV) lives on the seabed map: it may only drive where the planner
//! let it, at least the safety clearance from impassable ground and inside the area, and it
//! turns no tighter than its minimum radius. When a new hard obstacle blocks part of its
//! remaining path, the way round is searched on that same predicate, with the obstacle's
//! keep-out sphere (met at the crawler's height above the seabed) added to it, by the guided
//! Hybrid A* the coverage planner uses for its transits ([`super::reach::ReachGrid::guided_search`]).
//! The result is put on the seabed as the executed trajectory is ([`super::drive`]): sampled,
//! each point on the map plus the sensor height, and thinned.

use std::path::Path;

use super::boxes::Rect;
use super::drive::{thin, DRIVE_STEP_M, THIN_TOL_M};
use super::fleet::{FleetCoverage, FleetCoverageError};
use super::hybrid_astar::HybridAStarParams;
use super::path::Pose2;
use super::reach::ReachGrid;
use super::{Terrain25Error, TerrainMap25};
use crate::geometry::Vec3;
use crate::scenario::Scenario;

/// Search budget of one way round (expansions): as many as one transit of the coverage plan.
pub const WAY_ROUND_EXPANSIONS: usize = 50_000;

/// The ground a crawler fleet drives on, as the coverage planner saw it.
#[derive(Debug, Clone)]
pub struct CrawlerGround {
    /// The seabed map.
    pub map: TerrainMap25,
    /// The area the crawlers stay in (the scenario's horizontal bounds).
    pub area: Rect,
    /// Least distance of the crawler's centre from impassable cells, metres.
    pub safety_clearance_m: f64,
    /// Tightest turn, metres.
    pub min_turn_radius_m: f64,
    /// Height of the crawler's reference point (its trajectory) over the seabed, metres.
    pub sensor_height_m: f64,
}

/// Why a scenario gives no ground to reroute crawlers on.
#[derive(Debug, thiserror::Error)]
pub enum NoGround {
    /// The scenario is no crawler coverage mission.
    #[error(transparent)]
    Job(#[from] FleetCoverageError),
    /// Its seabed map cannot be built.
    #[error("the [coverage] map: {0}")]
    Map(#[from] Terrain25Error),
}

impl CrawlerGround {
    /// The ground of a scenario with a `[coverage]` table; `dir` resolves a heightmap file.
    pub fn of(scenario: &Scenario, dir: &Path) -> Result<CrawlerGround, NoGround> {
        let job = FleetCoverage::new(scenario)?;
        let map = job.map(dir)?;
        Ok(CrawlerGround {
            map,
            area: job.area,
            safety_clearance_m: job.settings.planner.safety_clearance_m,
            min_turn_radius_m: job.settings.planner.min_turn_radius_m,
            sensor_height_m: scenario.crawler.sensor_height_m,
        })
    }

    /// Where the crawler's reference point is when its centre is at `(x, y)`.
    pub fn point(&self, x: f64, y: f64) -> Vec3 {
        Vec3::new(x, y, self.map.elevation_at(x, y) + self.sensor_height_m)
    }

    /// Whether the crawler's centre may be at `(x, y)` on the map alone: inside the area and
    /// at least the safety clearance from impassable ground (the coverage planner's test).
    pub fn passable(&self, x: f64, y: f64) -> bool {
        self.area.holds(x, y) && self.map.clearance_to_impassable(x, y) >= self.safety_clearance_m
    }

    /// Whether a straight drive from `a` to `b` (checked every half metre) stays on ground the
    /// crawler may drive: inside the area and at least the safety clearance from impassable
    /// ground. From a start already closer than that, or outside the area (a crawler off its
    /// path), the drive may not come closer to impassable ground than the start is, nor go
    /// farther outside the area, and never onto impassable ground. Clearances are compared
    /// with half a metre of slack: the planner checks its own path every metre and thins it by
    /// 5 cm, so a leg of a plan may dip that little under the clearance between its checks.
    pub fn drivable(&self, a: &Vec3, b: &Vec3) -> bool {
        const STEP_M: f64 = 0.5;
        const SLACK_M: f64 = 0.5;
        let clearance = |x: f64, y: f64| self.map.clearance_to_impassable(x, y);
        let outside = |x: f64, y: f64| {
            let r = &self.area;
            let dx = (r.x0 - x).max(x - r.x1).max(0.0);
            let dy = (r.y0 - y).max(y - r.y1).max(0.0);
            dx.hypot(dy)
        };
        let need = self.safety_clearance_m.min(clearance(a.x, a.y));
        let out_at_start = outside(a.x, a.y);
        let n = ((b.x - a.x).hypot(b.y - a.y) / STEP_M).ceil().max(1.0) as usize;
        (0..=n).all(|k| {
            let u = k as f64 / n as f64;
            let (x, y) = (a.x + u * (b.x - a.x), a.y + u * (b.y - a.y));
            let c = clearance(x, y);
            c > 0.0 && c >= need - SLACK_M && outside(x, y) <= out_at_start + 1e-9
        })
    }

    /// The ways round the places where `keep_out` (given the crawler's reference point) is
    /// true: the free ground is rasterised once here, for every way asked of the result.
    pub fn ways_round<'g>(&'g self, keep_out: &'g dyn Fn(&Vec3) -> bool) -> WaysRound<'g> {
        let free = move |x: f64, y: f64| self.passable(x, y) && !keep_out(&self.point(x, y));
        let reach = ReachGrid::new(self.area, self.map.cell_m(), &free);
        WaysRound {
            ground: self,
            keep_out,
            reach,
        }
    }
}

/// Ways round a keep-out on a crawler's ground (see [`CrawlerGround::ways_round`]).
pub struct WaysRound<'g> {
    ground: &'g CrawlerGround,
    keep_out: &'g dyn Fn(&Vec3) -> bool,
    reach: ReachGrid,
}

impl WaysRound<'_> {
    /// A forward-only way from `from` to `to` (poses: heading in radians, counter-clockwise
    /// from east) that stays [`CrawlerGround::passable`] and off the keep-out, turning no
    /// tighter than the minimum radius. Points on the seabed plus the sensor height, from
    /// `from` to within a metre of `to` (exactly on it when the search ends by a Dubins shot),
    /// thinned to [`THIN_TOL_M`] (a caller's keep-out wants that margin). `None` when the two
    /// are not connected or the search finds no way within [`WAY_ROUND_EXPANSIONS`].
    pub fn between(&self, from: Pose2, to: Pose2) -> Option<Vec<Vec3>> {
        let g = self.ground;
        let free = |x: f64, y: f64| g.passable(x, y) && !(self.keep_out)(&g.point(x, y));
        let params = HybridAStarParams {
            min_turn_radius_m: g.min_turn_radius_m,
            max_expansions: WAY_ROUND_EXPANSIONS,
            ..HybridAStarParams::default()
        };
        let a = &g.area;
        // 1 m outside the area, so a pose on its edge is inside the search grid; `free` keeps
        // the path in the area.
        let bounds = [a.x0 - 1.0, a.y0 - 1.0, a.x1 + 1.0, a.y1 + 1.0];
        let found = self
            .reach
            .guided_search(from, to, &free, bounds, &params)
            .ok()
            .flatten()?;
        let points: Vec<Vec3> = found
            .path
            .sample(DRIVE_STEP_M)
            .iter()
            .map(|s| g.point(s.x, s.y))
            .collect();
        let kept: Vec<Vec3> = thin(&points, THIN_TOL_M)
            .into_iter()
            .map(|k| points[k])
            .collect();
        (kept.len() >= 2).then_some(kept)
    }
}

#[cfg(test)]
mod tests;
