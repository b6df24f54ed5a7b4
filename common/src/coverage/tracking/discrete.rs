//! Exact zero-order-hold discretisation of the V-MPC error model (CPP-DSMV, §2.3.2), see
//! [`super::mpc`] for the continuous model.

use super::params::TrackingParams;
use nalgebra::SMatrix;

/// What the controller knows about one horizon stage k (reference point at predicted progress).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StageRef {
    /// Reference curvature κ_k, 1/m.
    pub curvature: f64,
    /// Predicted traction efficiency η_k = cosθ·(1 − s), -.
    pub efficiency: f64,
    /// Predicted lateral drift w_y,k, m/s (terrain law + EKF residual).
    pub drift: f64,
}

/// Model states: e_y, e_ψ, ω_a, v_a.
pub(crate) const NZ: usize = 4;
/// Augmented exponential size: 4 states + 2 inputs + 1 disturbance.
pub(crate) const NA: usize = 7;
/// The augmented 7×7 matrix.
pub(crate) type Aug = SMatrix<f64, NA, NA>;

/// Matrix exponential by scaling and squaring with a degree-10 Taylor series.
pub(crate) fn expm(m: &Aug) -> Aug {
    let norm = (0..NA)
        .map(|i| (0..NA).map(|j| m[(i, j)].abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let mut s = 0;
    if norm > 0.5 {
        s = ((norm / 0.5).log2().ceil() as i32).clamp(0, 60);
    }
    let a = m / 2f64.powi(s);
    let mut term = Aug::identity();
    let mut sum = Aug::identity();
    for k in 1..=10 {
        term = term * a / k as f64;
        sum += term;
    }
    for _ in 0..s {
        sum = sum * sum;
    }
    sum
}

/// Quantisation of the discretisation cache key: η to 1/400, κ to 1e-5 1/m (a 0.1 % change of
/// `a = η·v_r` or of a 5 m radius is far below the model's own uncertainty).
pub(crate) const ETA_QUANT: f64 = 400.0;
pub(crate) const KAPPA_QUANT: f64 = 1e5;
/// Entries kept in the discretisation cache (FIFO).
pub(crate) const CACHE_LEN: usize = 48;

/// Cache key of a stage: quantised (κ, η).
pub(crate) fn stage_key(stage: &StageRef) -> (i64, i64) {
    (
        (stage.curvature * KAPPA_QUANT).round() as i64,
        (stage.efficiency * ETA_QUANT).round() as i64,
    )
}

/// Discrete model of one stage at the quantised key: the 7×7 exponential whose rows 0..4 hold
/// A_d (columns 0..4), B_d (columns 4, 5) and the response to a unit drift (column 6).
pub(crate) fn discretise(key: (i64, i64), p: &TrackingParams) -> Aug {
    let t = p.control_period_s;
    let k = key.0 as f64 / KAPPA_QUANT;
    let eta = key.1 as f64 / ETA_QUANT;
    let a = eta * p.speed_mps;
    let tw = p.yaw_lag_s.max(1e-3 * t);
    let tv = p.speed_lag_s.max(1e-3 * t);
    let mut m = Aug::zeros();
    m[(0, 1)] = a;
    m[(0, 6)] = 1.0;
    m[(1, 0)] = -k * k * a;
    m[(1, 2)] = 1.0;
    m[(1, 3)] = -k * eta;
    m[(2, 2)] = -1.0 / tw;
    m[(2, 4)] = 1.0 / tw;
    m[(3, 3)] = -1.0 / tv;
    m[(3, 5)] = 1.0 / tv;
    expm(&(m * t))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expm_matches_a_rotation_and_a_decay() {
        // exp([[0, w], [−w, 0]]·t) is a rotation by −w·t; exp(−λt) on the lag diagonal.
        let mut m = Aug::zeros();
        let (w, lam, t) = (0.7, 1.3, 2.0);
        m[(0, 1)] = w * t;
        m[(1, 0)] = -w * t;
        m[(2, 2)] = -lam * t;
        let e = expm(&m);
        assert!((e[(0, 0)] - (w * t).cos()).abs() < 1e-12);
        assert!((e[(0, 1)] - (w * t).sin()).abs() < 1e-12);
        assert!((e[(1, 0)] + (w * t).sin()).abs() < 1e-12);
        assert!((e[(2, 2)] - (-lam * t).exp()).abs() < 1e-12);
        assert!((e[(6, 6)] - 1.0).abs() < 1e-12);
    }
}
