//! The vocabulary of the tracking layer — terrain slope, samples, results, errors and small
//! numeric helpers — apart from `mod.rs` so that the plant, the filter, the controller and the
//! loop share it without depending on the module that declares them.

// The only place that names the path module.
pub(crate) use crate::coverage::path as geometry;
pub(crate) use geometry::{PathSample, Pose2};

use serde::{Deserialize, Serialize};

/// Terrain the tracker feels: gradient of the elevation (m/m) at `(x, y)`. The caller passes the
/// 2.5D map's full elevation gradient (seamounts + minor undulation).
pub trait TerrainSlope {
    /// `[∂z/∂x, ∂z/∂y]` at `(x, y)`, metres per metre.
    fn gradient(&self, x: f64, y: f64) -> [f64; 2];
}

impl<F: Fn(f64, f64) -> [f64; 2]> TerrainSlope for F {
    fn gradient(&self, x: f64, y: f64) -> [f64; 2] {
        self(x, y)
    }
}

/// A flat seabed (zero gradient everywhere).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FlatTerrain;

impl TerrainSlope for FlatTerrain {
    fn gradient(&self, _x: f64, _y: f64) -> [f64; 2] {
        [0.0, 0.0]
    }
}

/// One control instant of a tracking run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TrackedSample {
    /// Time since the start, seconds.
    pub t: f64,
    /// True pose of the vehicle (plant state).
    pub truth: Pose2,
    /// TA-AEKF estimate at the same instant (after the updates of the last period).
    pub estimate: Pose2,
    /// The last position fix received during the period that ended at `t`, if any, metres.
    pub fix: Option<[f64; 2]>,
    /// Signed cross-track error of the TRUE position to the reference polyline, metres; positive
    /// when the vehicle is to the left of the reference direction of travel.
    pub cross_track_m: f64,
    /// Speed command issued at `t` for the next period, m/s.
    pub speed_cmd: f64,
    /// Yaw-rate command issued at `t` for the next period, rad/s (counter-clockwise positive).
    pub yaw_rate_cmd: f64,
}

/// The outcome of a tracking run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrackingResult {
    /// One sample per control period, in time order.
    pub samples: Vec<TrackedSample>,
    /// Largest |cross-track error|, metres.
    pub max_abs_cte_m: f64,
    /// Median |cross-track error|, metres.
    pub median_abs_cte_m: f64,
    /// 95th percentile (nearest rank) of |cross-track error|, metres.
    pub p95_abs_cte_m: f64,
    /// Root mean square cross-track error, metres.
    pub rms_cte_m: f64,
    /// Number of QP solves attempted.
    pub qp_solves: usize,
    /// Number of QP solves that failed and fell back to the safe command.
    pub qp_failures: usize,
    /// Whether the vehicle reached the end of the reference before the time limit.
    pub reached_end: bool,
    /// Whether a stop request (Ctrl-C) ended the run before the vehicle reached the end or the
    /// time limit: the figures then cover the stretch driven so far.
    pub interrupted: bool,
    /// Simulated time, seconds.
    pub sim_time_s: f64,
}

/// Why a tracking run could not be done.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TrackingError {
    /// A parameter is out of its valid range.
    #[error("invalid tracking parameter `{field}` = {value}: {reason}")]
    InvalidParam {
        /// Field name in [`TrackingParams`](super::TrackingParams).
        field: &'static str,
        /// The offending value, printed.
        value: String,
        /// What was expected.
        reason: String,
    },
    /// The reference has no samples.
    #[error("the reference path is empty")]
    EmptyReference,
    /// A reference sample is unusable.
    #[error("invalid reference sample {index}: {reason}")]
    InvalidReference {
        /// Index of the offending sample.
        index: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// The terrain returned a non-finite gradient.
    #[error("terrain gradient at ({x:.3}, {y:.3}) is not finite: {gradient:?}")]
    InvalidTerrain {
        /// East, metres.
        x: f64,
        /// North, metres.
        y: f64,
        /// What the terrain returned.
        gradient: [f64; 2],
    },
    /// The simulation diverged (non-finite state).
    #[error("the simulation diverged at t = {t:.1} s: {what}")]
    Diverged {
        /// Time, seconds.
        t: f64,
        /// Which state became non-finite.
        what: String,
    },
}

/// A terrain gradient, checked to be finite.
pub(crate) fn checked_gradient(
    terrain: &dyn TerrainSlope,
    x: f64,
    y: f64,
) -> Result<[f64; 2], TrackingError> {
    let g = terrain.gradient(x, y);
    if g[0].is_finite() && g[1].is_finite() {
        Ok(g)
    } else {
        Err(TrackingError::InvalidTerrain { x, y, gradient: g })
    }
}

/// Wraps an angle to `(−π, π]`.
pub(crate) fn wrap_angle(a: f64) -> f64 {
    use std::f64::consts::PI;
    let mut w = a.rem_euclid(2.0 * PI);
    if w > PI {
        w -= 2.0 * PI;
    }
    w
}

/// One standard normal draw by Box–Muller (one of the pair; deterministic for a given RNG state).
pub(crate) fn gaussian<R: rand::Rng>(rng: &mut R) -> f64 {
    // u1 ∈ (0, 1] so that ln(u1) is finite.
    let u1: f64 = 1.0 - rng.random::<f64>();
    let u2: f64 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}
