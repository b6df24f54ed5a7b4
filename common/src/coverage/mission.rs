//! One coverage mission end to end (CPP-DSMV, §3): build the 2.5D map, plan the Boustrophedon
//! coverage, simulate its closed-loop tracking, and measure the figures of Table 2 and Figure 7.
//! The `plan` command, the `bench-coverage` command and the tests all run this.

use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::boxes::Rect;
use super::metrics::{coverage, exact_clearance, CoverageCount, Distribution};
use super::params::DetourMethod;
use super::path::{PathSample, PieceKind};
use super::sweeps::{plan_coverage, CoveragePlan};
use super::tracking::{track_with_progress, TrackingResult};
use super::{Terrain25Error, TerrainMap25};
use crate::scenario::CoverageSettings;

/// Clearance values below this are computed exactly (the histogram's range).
const EXACT_CLEARANCE_BELOW_M: f64 = 40.0;

/// Spacing of the samples the figures are measured on, metres.
pub const MEASURE_STEP_M: f64 = 1.0;

/// Spacing of the path points written into the report for plotting, metres.
const PLOT_STEP_M: f64 = 4.0;

/// Why a coverage mission could not run.
#[derive(Debug, thiserror::Error)]
pub enum CoverageError {
    /// The map or the planner settings.
    #[error(transparent)]
    Terrain(#[from] Terrain25Error),
    /// The tracking simulation.
    #[error("tracking: {0}")]
    Tracking(String),
}

/// The tracking half of the report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrackingReport {
    /// |cross-track error| distribution, metres (Figure 7c).
    pub cross_track: Distribution,
    /// Largest |cross-track error|, metres.
    pub max_abs_cte_m: f64,
    /// Median |cross-track error|, metres.
    pub median_abs_cte_m: f64,
    /// RMS cross-track error, metres.
    pub rms_cte_m: f64,
    /// QPs solved / failed (a failed one falls back to the previous command).
    pub qp_solves: usize,
    /// QPs that failed.
    pub qp_failures: usize,
    /// Whether the simulated vehicle reached the path's end.
    pub reached_end: bool,
    /// Whether Ctrl-C ended the simulation early: the figures cover the stretch driven so far
    /// and say nothing about the rest of the path.
    pub interrupted: bool,
    /// Simulated mission time, seconds.
    pub sim_time_s: f64,
    /// Wall time of the simulation, seconds.
    pub wall_time_s: f64,
}

/// Everything a coverage mission measured (`plan.json`'s `coverage` object).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CoverageReport {
    /// `arcs` (CPP-DSMV's method) or `hybrid-a-star` (the baseline).
    pub method: DetourMethod,
    /// Seed of the synthetic seabed (absent for a heightmap).
    pub terrain_seed: Option<u64>,
    /// The area covered.
    pub area: Rect,
    /// Share of impassable cells of the map.
    pub impassable_fraction: f64,
    /// Wall time of the planner alone (boxes, sweeps, transits), seconds.
    pub planning_time_s: f64,
    /// Coverage of the area by the planned path's swath.
    pub coverage: CoverageCount,
    /// Swath width used for the coverage count (the row spacing `2·R_min`), metres.
    pub swath_m: f64,
    /// Path length, metres, and by state: straight, detour, U-turn, transit.
    pub path_length_m: f64,
    /// Lengths by state `[straight, detour, u_turn, transit]`, metres.
    pub length_by_kind_m: [f64; 4],
    /// Rows, sweeps and decision counts
    /// `[detours, virtual boundaries, row skips, transits, unreached, stranded]`.
    pub rows: usize,
    /// Sweeps run.
    pub sweeps: usize,
    /// Decision counts (see above).
    pub event_counts: [usize; 6],
    /// Clearance of the planned path to impassable cells, metres (Figure 7a).
    pub clearance: Distribution,
    /// The safety clearance the figures are judged against, metres.
    pub safety_clearance_m: f64,
    /// Planned-path samples closer than the safety clearance to an impassable cell.
    pub samples_below_clearance: usize,
    /// Slope under the planned path, degrees (Figure 7b).
    pub slope: Distribution,
    /// Largest |curvature| of the planned path, 1/m.
    pub max_curvature: f64,
    /// The closed-loop tracking (absent when `track = false`).
    pub tracking: Option<TrackingReport>,
    /// The merged, inflated no-go boxes.
    pub boxes: Vec<Rect>,
    /// Every decision of the planner.
    pub events: Vec<super::boustrophedon::PlannerEvent>,
    /// The planned path every 4 m, for plotting.
    pub planned_path: Vec<[f64; 2]>,
    /// The tracked (true) path every 4 m, for plotting.
    pub tracked_path: Vec<[f64; 2]>,
}

/// What lies under a path's samples: clearance to impassable cells (Figure 7a) and slope
/// (Figure 7b), and how many samples are closer than the safety clearance.
pub struct PathUnder {
    /// Clearance distribution, metres (exact below 40 m).
    pub clearance: Distribution,
    /// Slope distribution, degrees.
    pub slope: Distribution,
    /// Samples closer than the safety clearance.
    pub below: usize,
}

impl PathUnder {
    /// Measures `samples` on `map` against `safety_clearance_m`.
    pub fn measure(map: &TerrainMap25, samples: &[PathSample], safety_clearance_m: f64) -> Self {
        let clearances: Vec<f64> = samples
            .iter()
            .map(|s| exact_clearance(map, s.x, s.y, EXACT_CLEARANCE_BELOW_M))
            .collect();
        let below = clearances
            .iter()
            .filter(|&&c| c < safety_clearance_m - 1e-9)
            .count();
        let slopes: Vec<f64> = samples.iter().map(|s| map.slope_at(s.x, s.y)).collect();
        let max_slope = map.limits().critical_slope_deg;
        PathUnder {
            clearance: Distribution::new(&clearances, 0.0, EXACT_CLEARANCE_BELOW_M, 40),
            slope: Distribution::new(&slopes, 0.0, max_slope.max(1.0), 30),
            below,
        }
    }
}

/// Builds the 2.5D map of a scenario's `[coverage]` table (`dir` resolves `heightmap`).
pub fn build_map(
    settings: &CoverageSettings,
    seed: u64,
    dir: &Path,
) -> Result<TerrainMap25, Terrain25Error> {
    match &settings.heightmap {
        Some(file) => TerrainMap25::load(&dir.join(file), &settings.limits),
        None => TerrainMap25::generate(&settings.terrain, &settings.limits, seed),
    }
}

/// Runs the mission on `map` over `area`; `progress(stage, fraction)` reports the tracking.
/// A raised `stop` (Ctrl-C) cuts the tracking simulation short (the plan itself takes well under
/// a second and is always finished): see [`TrackingReport::interrupted`].
pub fn run_coverage(
    settings: &CoverageSettings,
    map: &TerrainMap25,
    area: Rect,
    terrain_seed: Option<u64>,
    tracking_seed: u64,
    stop: Option<&AtomicBool>,
    progress: &mut dyn FnMut(&str, f64),
) -> Result<(CoverageReport, CoveragePlan), CoverageError> {
    let params = &settings.planner;
    progress("planning", 0.0);
    let started = Instant::now();
    let plan = plan_coverage(map, area, params)?;
    let planning_time_s = started.elapsed().as_secs_f64();
    progress("planning", 1.0);
    let samples = plan.path.sample(MEASURE_STEP_M);
    let swath = params.row_spacing();
    let under = PathUnder::measure(map, &samples, params.safety_clearance_m);
    let tracking = if settings.track && !samples.is_empty() {
        let started = Instant::now();
        let terrain = |x: f64, y: f64| elevation_gradient(map, x, y);
        let result = track_with_progress(
            &samples,
            &terrain,
            &settings.tracking_params(),
            tracking_seed,
            stop,
            &mut |f| progress("tracking", f),
        )
        .map_err(|e| CoverageError::Tracking(e.to_string()))?;
        Some((result, started.elapsed().as_secs_f64()))
    } else {
        None
    };
    let report = CoverageReport {
        method: params.detour,
        terrain_seed,
        area,
        impassable_fraction: map.impassable_fraction(),
        planning_time_s,
        coverage: coverage(&samples, map, area, swath, 1.0),
        swath_m: swath,
        path_length_m: plan.path.length(),
        length_by_kind_m: plan.path.length_by_kind(),
        rows: plan.rows,
        sweeps: plan.sweeps,
        event_counts: plan.event_counts(),
        clearance: under.clearance,
        safety_clearance_m: params.safety_clearance_m,
        samples_below_clearance: under.below,
        slope: under.slope,
        max_curvature: samples
            .iter()
            .map(|s| s.curvature.abs())
            .fold(0.0, f64::max),
        tracking: tracking.as_ref().map(|(r, wall)| tracking_report(r, *wall)),
        boxes: plan.boxes.clone(),
        events: plan.events.clone(),
        planned_path: thin(&samples),
        tracked_path: tracking.as_ref().map_or_else(Vec::new, |(r, _)| {
            let mut out = Vec::new();
            let mut last: Option<[f64; 2]> = None;
            for s in &r.samples {
                let p = [s.truth.x, s.truth.y];
                if last.is_none_or(|q| (p[0] - q[0]).hypot(p[1] - q[1]) >= PLOT_STEP_M) {
                    out.push(p);
                    last = Some(p);
                }
            }
            out
        }),
    };
    Ok((report, plan))
}

/// The planned path every [`PLOT_STEP_M`] (turns keep their shape at 4 m with `R_min` ≥ 4 m).
fn thin(samples: &[PathSample]) -> Vec<[f64; 2]> {
    let mut out = Vec::new();
    let mut next = 0.0;
    for s in samples {
        if s.s >= next || s.kind == PieceKind::UTurn {
            out.push([s.x, s.y]);
            next = s.s + PLOT_STEP_M;
        }
    }
    if let Some(last) = samples.last() {
        out.push([last.x, last.y]);
    }
    out
}

/// Elevation gradient (m/m) by central differences of the bilinear elevation over ±1 m: the
/// full seabed (seamount flanks and minor undulation) the tracks feel.
pub fn elevation_gradient(map: &TerrainMap25, x: f64, y: f64) -> [f64; 2] {
    let h = 1.0;
    [
        (map.elevation_at(x + h, y) - map.elevation_at(x - h, y)) / (2.0 * h),
        (map.elevation_at(x, y + h) - map.elevation_at(x, y - h)) / (2.0 * h),
    ]
}

fn tracking_report(r: &TrackingResult, wall_time_s: f64) -> TrackingReport {
    let abs: Vec<f64> = r.samples.iter().map(|s| s.cross_track_m.abs()).collect();
    TrackingReport {
        cross_track: Distribution::new(&abs, 0.0, 4.0, 40),
        max_abs_cte_m: r.max_abs_cte_m,
        median_abs_cte_m: r.median_abs_cte_m,
        rms_cte_m: r.rms_cte_m,
        qp_solves: r.qp_solves,
        qp_failures: r.qp_failures,
        reached_end: r.reached_end,
        interrupted: r.interrupted,
        sim_time_s: r.sim_time_s,
        wall_time_s,
    }
}
