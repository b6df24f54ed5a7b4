//! Several crawlers over one area (CPP-DSMV plans one; Shoal's fleet splits the work).
//!
//! The area is cut into strips of whole Boustrophedon rows, one per crawler in scenario order
//! from the south ([`strips`]), so the fleet drives exactly the rows one crawler would. Each strip
//! is planned alone — by its crawler's agent, or here on its own thread — with the whole seabed
//! map (a detour may leave the strip only as far as the planner lets it leave any area). The
//! strips are a function of the scenario, so every process derives the same ones.
//!
//! Separation over time: each crawler drives its path at the tracking speed after a start
//! delay; the timed paths are compared at the same instant over the whole mission
//! ([`crate::separation`], exact between samples, a crawler holds at its end). Adjacent strips
//! share an edge where the southern crawler finishes while the northern one started long ago, so
//! conflicts are rare, but a transit back south or a short strip can make one. They are resolved
//! by delaying starts ([`separate`]); a conflict no delay resolves is reported, never hidden.

use std::path::Path;
use std::sync::atomic::AtomicBool;

use serde::{Deserialize, Serialize};

use super::boxes::Rect;
use super::metrics::{coverage, CoverageCount, Distribution};
use super::mission::{
    build_map, run_coverage, CoverageError, CoverageReport, PathUnder, MEASURE_STEP_M,
};
use super::path::CoveragePath;
use super::{Terrain25Error, TerrainMap25};
use crate::geometry::Vec3;
use crate::scenario::{CoverageSettings, Scenario, VehicleKind};
use crate::separation::{all_pairs, PairSeparation};
use crate::trajectory::Trajectory;

/// Path spacing of the timed trajectories, metres (positions are exact between samples).
const TIMED_STEP_M: f64 = 2.0;
/// Rounds of the start-delay search.
const DELAY_ROUNDS: usize = 24;
/// Multiples of the delay step tried for each vehicle of the worst pair in a round.
const DELAY_MULTIPLES: [f64; 8] = [1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0];

/// Why a scenario has no fleet coverage job.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FleetCoverageError {
    /// The scenario has no `[coverage]` table.
    #[error("scenario {0:?} has no [coverage] table")]
    NoCoverageTable(String),
    /// A vehicle is not a crawler.
    #[error("vehicles: {0:?} is not a crawler; a [coverage] mission drives crawlers only")]
    NotACrawler(String),
    /// The area is too narrow for one row per crawler.
    #[error(
        "[coverage] fleet strips: the area holds {rows} rows {spacing} m apart: too few for {crawlers} crawlers (each needs one row at least)"
    )]
    TooFewRows {
        /// Rows the area holds.
        rows: usize,
        /// Row spacing, metres.
        spacing: f64,
        /// Crawlers in the fleet.
        crawlers: usize,
    },
}

/// Why a strip plan that came from elsewhere is refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BadStripPlan {
    /// It covers another area than its strip.
    #[error(
        "a plan of the area [{}, {}] × [{}, {}], not of its strip [{}, {}] × [{}, {}]",
        area.x0, area.x1, area.y0, area.y1, strip.x0, strip.x1, strip.y0, strip.y1
    )]
    OtherArea {
        /// The area the plan covers.
        area: Rect,
        /// The strip it was asked for.
        strip: Rect,
    },
    /// Its path has a non-finite number or a non-positive arc radius.
    #[error("a path with a non-finite number or a non-positive arc radius")]
    InvalidPath,
}

/// Splits `area` into `n` strips of whole rows `spacing` apart, south to north; the first
/// `rows mod n` strips take one row more, the last strip also takes the sliver above the last
/// row. Fails when the area holds fewer rows than crawlers.
pub fn strips(area: Rect, n: usize, spacing: f64) -> Result<Vec<Rect>, FleetCoverageError> {
    let rows = ((area.y1 - area.y0) / spacing + 1e-9).floor().max(0.0) as usize;
    if n == 0 || rows < n {
        return Err(FleetCoverageError::TooFewRows {
            rows,
            spacing,
            crawlers: n,
        });
    }
    let (base, extra) = (rows / n, rows % n);
    let mut out = Vec::with_capacity(n);
    let mut r0 = 0;
    for k in 0..n {
        let r1 = r0 + base + usize::from(k < extra);
        let y0 = area.y0 + r0 as f64 * spacing;
        let y1 = if k + 1 == n {
            area.y1
        } else {
            area.y0 + r1 as f64 * spacing
        };
        out.push(Rect::new(area.x0, y0, area.x1, y1));
        r0 = r1;
    }
    Ok(out)
}

/// A fleet coverage job: what every process derives from the scenario.
#[derive(Debug, Clone)]
pub struct FleetCoverage {
    /// The `[coverage]` table.
    pub settings: CoverageSettings,
    /// The whole area (the scenario's horizontal bounds).
    pub area: Rect,
    /// One strip per vehicle, scenario order.
    pub strips: Vec<Rect>,
    /// Vehicle ids, scenario order.
    pub ids: Vec<String>,
    /// Seed of the synthetic seabed.
    pub terrain_seed: u64,
    /// Seed of vehicle 0's tracking noise (vehicle `i` uses this plus `i`).
    pub tracking_seed: u64,
    /// Minimum separation, metres (`fleet.d_min_m`).
    pub d_min_m: f64,
}

impl FleetCoverage {
    /// The job of a scenario with a `[coverage]` table and crawlers only.
    pub fn new(scenario: &Scenario) -> Result<FleetCoverage, FleetCoverageError> {
        let settings = scenario
            .coverage
            .clone()
            .ok_or_else(|| FleetCoverageError::NoCoverageTable(scenario.name.clone()))?;
        if let Some(v) = scenario
            .vehicles
            .iter()
            .find(|v| v.kind != VehicleKind::Crawler)
        {
            return Err(FleetCoverageError::NotACrawler(v.id.clone()));
        }
        let b = &scenario.bounds;
        let area = Rect::new(b.min[0], b.min[1], b.max[0], b.max[1]);
        let strips = strips(
            area,
            scenario.vehicles.len(),
            settings.planner.row_spacing(),
        )?;
        Ok(FleetCoverage {
            terrain_seed: settings.terrain_seed.unwrap_or(scenario.optimizer.seed),
            tracking_seed: scenario.optimizer.seed,
            settings,
            area,
            strips,
            ids: scenario.vehicles.iter().map(|v| v.id.clone()).collect(),
            d_min_m: scenario.fleet.d_min_m,
        })
    }

    /// The seabed map (`dir` resolves a heightmap file).
    pub fn map(&self, dir: &Path) -> Result<TerrainMap25, Terrain25Error> {
        build_map(&self.settings, self.terrain_seed, dir)
    }

    /// Plans (and, when the scenario says so, tracks) vehicle `i`'s strip on `map`; a raised
    /// `stop` cuts the tracking short (see [`run_coverage`]).
    pub fn plan_vehicle(
        &self,
        map: &TerrainMap25,
        i: usize,
        stop: Option<&AtomicBool>,
        progress: &mut dyn FnMut(&str, f64),
    ) -> Result<StripPlan, CoverageError> {
        let strip = self.strips.get(i).copied().ok_or_else(|| {
            CoverageError::Terrain(Terrain25Error::InvalidParam {
                field: "strip".into(),
                what: format!("no strip {i} in a fleet of {}", self.strips.len()),
            })
        })?;
        let terrain_seed = self
            .settings
            .heightmap
            .is_none()
            .then_some(self.terrain_seed);
        let seed = self.tracking_seed.wrapping_add(i as u64);
        let (report, plan) = run_coverage(
            &self.settings,
            map,
            strip,
            terrain_seed,
            seed,
            stop,
            progress,
        )?;
        Ok(StripPlan {
            report,
            path: plan.path,
        })
    }
}

/// One crawler's strip: its figures and its exact path.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StripPlan {
    /// The figures of the strip, as a one-crawler mission reports them.
    pub report: CoverageReport,
    /// The planned path.
    pub path: CoveragePath,
}

impl StripPlan {
    /// Checks a strip plan that came from elsewhere: planned for `strip`, every number finite.
    pub fn check(&self, strip: Rect) -> Result<(), BadStripPlan> {
        let a = self.report.area;
        let off = [
            a.x0 - strip.x0,
            a.y0 - strip.y0,
            a.x1 - strip.x1,
            a.y1 - strip.y1,
        ];
        if off.iter().any(|d| d.is_nan() || d.abs() > 1e-6) {
            return Err(BadStripPlan::OtherArea { area: a, strip });
        }
        if !self.path.is_valid() {
            return Err(BadStripPlan::InvalidPath);
        }
        Ok(())
    }
}

/// `path` driven at `speed` after `delay` seconds (held at its start until then), z = 0: the
/// crawlers share one seabed, so their separation is horizontal.
pub fn timed_trajectory(path: &CoveragePath, speed: f64, delay: f64) -> Trajectory {
    delayed(&undelayed(path, speed), delay)
}

/// `path` driven at `speed` from t = 0.
fn undelayed(path: &CoveragePath, speed: f64) -> Trajectory {
    let samples = path.sample(TIMED_STEP_M);
    Trajectory {
        times: samples.iter().map(|s| s.s / speed).collect(),
        points: samples.iter().map(|s| Vec3::new(s.x, s.y, 0.0)).collect(),
    }
}

/// `t` started `delay` seconds later, held at its first point until then.
fn delayed(t: &Trajectory, delay: f64) -> Trajectory {
    let mut out = Trajectory {
        times: Vec::with_capacity(t.times.len() + 1),
        points: Vec::with_capacity(t.points.len() + 1),
    };
    if let (Some(first), true) = (t.points.first(), delay > 0.0) {
        out.times.push(0.0);
        out.points.push(*first);
    }
    out.times.extend(t.times.iter().map(|time| delay + time));
    out.points.extend_from_slice(&t.points);
    out
}

/// The fleet's separation over time, with the start delays that achieved it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FleetSeparation {
    /// Minimum separation required, metres.
    pub d_min_m: f64,
    /// Smallest distance between two crawlers at the same instant, metres (∞ with one crawler).
    pub min_distance_m: f64,
    /// The pair (vehicle indices) at that distance.
    pub closest_pair: [usize; 2],
    /// When, seconds from the mission's start.
    pub at_s: f64,
    /// Total time any pair spends closer than `d_min_m`, seconds.
    pub breach_s: f64,
    /// Start delay of each crawler, seconds.
    pub start_delays_s: Vec<f64>,
    /// When each crawler finishes its strip, seconds.
    pub finish_s: Vec<f64>,
}

/// Badness of a set of pair separations: pairs closer than `d_min`, then breach time.
fn score(pairs: &[((usize, usize), PairSeparation)], d_min: f64) -> (usize, f64) {
    (
        pairs.iter().filter(|(_, p)| p.min_distance < d_min).count(),
        pairs.iter().map(|(_, p)| p.breach_s).sum(),
    )
}

/// Times the paths at `speed` and delays starts until every pair keeps `d_min`: each round
/// delays one crawler of the worst pair by 1, 2, 4, … or 128 steps of `max(2·d_min / speed, 60 s)`,
/// whichever improves the fleet most; it stops when no pair breaches or nothing improves.
pub fn separate(paths: &[&CoveragePath], speed: f64, d_min: f64) -> FleetSeparation {
    let n = paths.len();
    // Sampled once; each candidate set of delays only shifts the times.
    let base: Vec<Trajectory> = paths.iter().map(|p| undelayed(p, speed)).collect();
    let shifted = |delays: &[f64]| -> Vec<Trajectory> {
        base.iter()
            .zip(delays)
            .map(|(t, &d)| delayed(t, d))
            .collect()
    };
    let step = (2.0 * d_min / speed).max(60.0);
    let mut delays = vec![0.0; n];
    let mut pairs = all_pairs(&shifted(&delays), d_min);
    for _ in 0..DELAY_ROUNDS {
        let now = score(&pairs, d_min);
        if now.0 == 0 && now.1 <= 0.0 {
            break;
        }
        let Some(&((i, j), _)) = pairs.iter().max_by(|a, b| {
            (d_min - a.1.min_distance)
                .total_cmp(&(d_min - b.1.min_distance))
                .then(a.1.breach_s.total_cmp(&b.1.breach_s))
        }) else {
            break;
        };
        let mut best: Option<((usize, f64), Vec<f64>, Vec<_>)> = None;
        for v in [i, j] {
            for m in DELAY_MULTIPLES {
                let mut d = delays.clone();
                d[v] += m * step;
                let p = all_pairs(&shifted(&d), d_min);
                let s = score(&p, d_min);
                let better = |than: (usize, f64)| s.0 < than.0 || (s.0 == than.0 && s.1 < than.1);
                if better(now) && best.as_ref().is_none_or(|b| better(b.0)) {
                    best = Some((s, d, p));
                }
            }
        }
        match best {
            Some((_, d, p)) => {
                delays = d;
                pairs = p;
            }
            None => break,
        }
    }
    let closest = pairs
        .iter()
        .min_by(|a, b| a.1.min_distance.total_cmp(&b.1.min_distance));
    FleetSeparation {
        d_min_m: d_min,
        min_distance_m: closest.map_or(f64::INFINITY, |c| c.1.min_distance),
        closest_pair: closest.map_or([0, 0], |c| [c.0 .0, c.0 .1]),
        at_s: closest.map_or(0.0, |c| c.1.min_time),
        breach_s: score(&pairs, d_min).1,
        finish_s: paths
            .iter()
            .zip(&delays)
            .map(|(p, d)| d + p.length() / speed)
            .collect(),
        start_delays_s: delays,
    }
}

/// One crawler in the fleet's report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VehicleStrip {
    /// Vehicle id.
    pub vehicle: String,
    /// Its strip.
    pub strip: Rect,
    /// Its strip's figures (coverage counted over the strip).
    pub report: CoverageReport,
}

/// Everything a fleet coverage mission measured (`plan.json`'s `fleet` object). The fleet-wide
/// figures are recomputed here from the paths and the map, not taken from the strips' reports.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FleetCoverageReport {
    /// The whole area.
    pub area: Rect,
    /// Coverage of the whole area by all crawlers' swaths.
    pub coverage: CoverageCount,
    /// Swath width, metres.
    pub swath_m: f64,
    /// Longest strip planning time (strips are planned in parallel), seconds.
    pub planning_time_s: f64,
    /// Sum of the path lengths, metres.
    pub path_length_m: f64,
    /// Clearance of every crawler's path to impassable cells, metres.
    pub clearance: Distribution,
    /// Slope under every crawler's path, degrees.
    pub slope: Distribution,
    /// The safety clearance, metres.
    pub safety_clearance_m: f64,
    /// Path samples closer than the safety clearance, all crawlers.
    pub samples_below_clearance: usize,
    /// |cross-track error| of all tracked paths (quantiles to one 0.1 m bin), when tracked.
    pub cross_track: Option<Distribution>,
    /// Driving speed of the timed paths, m/s.
    pub speed_mps: f64,
    /// Separation over time.
    pub separation: FleetSeparation,
    /// The crawlers, scenario order.
    pub vehicles: Vec<VehicleStrip>,
}

/// The fleet's report from each vehicle's strip plan (scenario order).
pub fn assemble(
    job: &FleetCoverage,
    map: &TerrainMap25,
    plans: Vec<StripPlan>,
) -> FleetCoverageReport {
    let params = &job.settings.planner;
    let speed = job.settings.tracking.speed_mps;
    let samples: Vec<_> = plans
        .iter()
        .flat_map(|p| p.path.sample(MEASURE_STEP_M))
        .collect();
    let under = PathUnder::measure(map, &samples, params.safety_clearance_m);
    let tracked: Vec<&Distribution> = plans
        .iter()
        .filter_map(|p| p.report.tracking.as_ref().map(|t| &t.cross_track))
        .collect();
    let paths: Vec<&CoveragePath> = plans.iter().map(|p| &p.path).collect();
    let separation = separate(&paths, speed, job.d_min_m);
    FleetCoverageReport {
        area: job.area,
        coverage: coverage(&samples, map, job.area, params.row_spacing(), 1.0),
        swath_m: params.row_spacing(),
        planning_time_s: plans
            .iter()
            .map(|p| p.report.planning_time_s)
            .fold(0.0, f64::max),
        path_length_m: plans.iter().map(|p| p.path.length()).sum(),
        clearance: under.clearance,
        slope: under.slope,
        safety_clearance_m: params.safety_clearance_m,
        samples_below_clearance: under.below,
        cross_track: Distribution::merge(&tracked),
        speed_mps: speed,
        separation,
        vehicles: plans
            .into_iter()
            .zip(&job.ids)
            .zip(&job.strips)
            .map(|((p, id), strip)| VehicleStrip {
                vehicle: id.clone(),
                strip: *strip,
                report: p.report,
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests;
