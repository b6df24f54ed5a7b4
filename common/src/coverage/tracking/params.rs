//! Every constant of the tracking layer, with units, physical reason and default.

use super::types::TrackingError;
use serde::{Deserialize, Serialize};

/// Parameters of the closed-loop tracker. Defaults describe a heavy tracked nodule collector
/// (~12 m × 8 m, R_min = 5 m, 0.5–1 m/s) with a USBL/LBL + DVL-aided fix at 6000 m.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct TrackingParams {
    // ---- timing -------------------------------------------------------------------------------
    /// Control period T, s: one MPC solve per period. 1 s suits a crawler at ≤ 1 m/s.
    pub control_period_s: f64,
    /// Plant / EKF integration sub-step, s (≤ T; T is split into `ceil(T/dt)` equal sub-steps).
    pub substep_s: f64,
    /// The run stops unreached after `time_limit_factor × length / speed` (+60 s), -.
    pub time_limit_factor: f64,
    /// The end counts as reached within this distance of the last sample, m.
    pub end_tolerance_m: f64,
    /// Reference progress may move back at most this far along the path per projection, m.
    pub search_back_m: f64,
    /// Reference progress looks at most this far ahead per projection, m. Keep it below the arc
    /// length of a U-turn (π·R_min) so a projection never jumps into the next row.
    pub search_ahead_m: f64,

    // ---- commands and actuators ---------------------------------------------------------------
    /// Cruise (reference) track speed, m/s; the caller sets it.
    pub speed_mps: f64,
    /// Lowest commanded speed, m/s: a crawler keeps moving forward (no pivots, no reversing).
    pub min_speed_mps: f64,
    /// Highest commanded speed, m/s (drive power limit).
    pub max_speed_mps: f64,
    /// Minimum turning radius R_min of the planner, m; the caller sets it.
    pub min_turn_radius_m: f64,
    /// Extra curvature the tracker may use beyond 1/R_min to correct errors on arcs, fraction:
    /// `|ω| ≤ (1 + m)·v/R_min` (0.25 ⇒ a 4 m mechanical radius for a 5 m planning radius).
    pub curvature_margin: f64,
    /// Longitudinal acceleration limit, m/s² (heavy chassis on soft sediment).
    pub max_accel_mps2: f64,
    /// Yaw acceleration limit, rad/s² (track speed differential build-up).
    pub max_yaw_accel_radps2: f64,
    /// First-order lag of the track speed, s (hydraulic drive + chassis inertia); 0 = none.
    pub speed_lag_s: f64,
    /// First-order lag of the yaw rate, s; 0 = none.
    pub yaw_lag_s: f64,

    // ---- terrain–traction model (plant; the EKF and the MPC use the same nominal model) --------
    /// Slip ratio on level ground, - (sediment shear under the grousers).
    pub base_slip: f64,
    /// Extra slip per radian of uphill pitch, 1/rad.
    pub slip_pitch_gain: f64,
    /// Largest slip ratio, - (beyond it the crawler would be stuck).
    pub max_slip: f64,
    /// Gravity-induced sideslip gain k_d: lateral velocity `−k_d·v_x·sinφ`, - .
    pub drift_gain: f64,
    /// Yaw-rate loss in turns from track skidding, fraction (plant only: unknown to the MPC).
    pub turn_slip: f64,

    // ---- plant noise (first-order Gauss–Markov, correlation time below) ------------------------
    /// Standard deviation of the random slip ratio, -.
    pub slip_noise_std: f64,
    /// Standard deviation of the random lateral slip velocity, m/s.
    pub lateral_noise_std_mps: f64,
    /// Standard deviation of the random yaw rate, rad/s.
    pub yaw_noise_std_radps: f64,
    /// Correlation time of the slip noises, s (soil patches a few metres long).
    pub noise_corr_time_s: f64,

    // ---- sensors ------------------------------------------------------------------------------
    /// Position fix noise σ per axis, m (USBL/LBL + DVL-aided at 6000 m).
    pub fix_std_m: f64,
    /// Time between position fixes, s.
    pub fix_period_s: f64,
    /// Gyro-compass heading noise σ, rad (one reading per control period).
    pub heading_std_rad: f64,
    /// Gyro yaw-rate noise σ, rad/s (one reading per sub-step).
    pub gyro_std_radps: f64,

    // ---- TA-AEKF --------------------------------------------------------------------------------
    /// Position process noise density, m²/s (unmodelled motion).
    pub ekf_q_pos_m2ps: f64,
    /// Heading process noise density, rad²/s (on top of the gyro noise).
    pub ekf_q_heading_rad2ps: f64,
    /// Slip-residual process noise density, 1/s.
    pub ekf_q_slip_ps: f64,
    /// Drift-residual process noise density, m²/s³.
    pub ekf_q_drift_m2ps3: f64,
    /// Correlation time of the slip and drift residual states, s.
    pub ekf_bias_corr_time_s: f64,
    /// Terrain adaptation: `Q = Q0·(1 + k_q·|∇z|)`, per (m/m).
    pub ekf_slope_gain: f64,
    /// Sage–Husa forgetting factor b ∈ (0, 1) of the fix-noise estimator, -.
    pub ekf_sage_husa_b: f64,
    /// Lower clamp of the adapted fix variance, as a multiple of `fix_std_m²`.
    pub ekf_r_min_factor: f64,
    /// Upper clamp of the adapted fix variance, as a multiple of `fix_std_m²`.
    pub ekf_r_max_factor: f64,
    /// χ² gate (2 dof) on the fix innovation; above it R is inflated by `d²/gate`.
    pub ekf_gate_chi2: f64,

    // ---- V-MPC ----------------------------------------------------------------------------------
    /// Prediction horizon N_p, steps.
    pub horizon_steps: usize,
    /// Control horizon N_c ≤ N_p, steps (inputs held after it: move blocking).
    pub control_horizon: usize,
    /// Lateral-error weight on straights (κ = 0), 1/m².
    pub q_lat_straight: f64,
    /// Lateral-error weight on full-curvature arcs (|κ| = 1/R_min), 1/m².
    pub q_lat_arc: f64,
    /// Heading-error weight on straights, 1/rad².
    pub q_head_straight: f64,
    /// Heading-error weight on full-curvature arcs, 1/rad².
    pub q_head_arc: f64,
    /// Weight on the yaw-rate deviation from the reference feed-forward, s²/rad².
    pub r_yaw_rate: f64,
    /// Weight on the speed deviation from cruise, s²/m².
    pub r_speed: f64,
    /// Yaw-rate change weight on straights, s²/rad².
    pub rd_yaw_rate_straight: f64,
    /// Yaw-rate change weight on full-curvature arcs, s²/rad².
    pub rd_yaw_rate_arc: f64,
    /// Speed change weight, s²/m².
    pub rd_speed: f64,
    /// Multiplier of the state weights at the last horizon step, -.
    pub terminal_factor: f64,
    /// Interior-point iteration limit of the QP.
    pub qp_max_iter: u32,
    /// Absolute / relative gap and feasibility tolerance of the QP.
    pub qp_tolerance: f64,
}

impl Default for TrackingParams {
    fn default() -> Self {
        Self {
            control_period_s: 1.0,
            substep_s: 0.1,
            time_limit_factor: 3.0,
            end_tolerance_m: 3.0,
            search_back_m: 2.0,
            search_ahead_m: 8.0,
            speed_mps: 0.8,
            min_speed_mps: 0.2,
            max_speed_mps: 1.0,
            min_turn_radius_m: 5.0,
            curvature_margin: 0.25,
            max_accel_mps2: 0.05,
            max_yaw_accel_radps2: 0.08,
            speed_lag_s: 2.0,
            yaw_lag_s: 1.0,
            base_slip: 0.05,
            slip_pitch_gain: 1.5,
            max_slip: 0.5,
            drift_gain: 0.5,
            turn_slip: 0.05,
            slip_noise_std: 0.02,
            lateral_noise_std_mps: 0.01,
            yaw_noise_std_radps: 0.002,
            noise_corr_time_s: 5.0,
            fix_std_m: 0.5,
            fix_period_s: 1.0,
            heading_std_rad: 0.01,
            gyro_std_radps: 0.002,
            ekf_q_pos_m2ps: 1e-3,
            ekf_q_heading_rad2ps: 1e-6,
            ekf_q_slip_ps: 1e-4,
            ekf_q_drift_m2ps3: 1e-5,
            ekf_bias_corr_time_s: 120.0,
            ekf_slope_gain: 5.0,
            ekf_sage_husa_b: 0.98,
            ekf_r_min_factor: 0.25,
            ekf_r_max_factor: 4.0,
            ekf_gate_chi2: 13.8,
            horizon_steps: 12,
            control_horizon: 4,
            q_lat_straight: 2.0,
            q_lat_arc: 1.0,
            q_head_straight: 10.0,
            q_head_arc: 30.0,
            r_yaw_rate: 20.0,
            r_speed: 5.0,
            rd_yaw_rate_straight: 200.0,
            rd_yaw_rate_arc: 50.0,
            rd_speed: 50.0,
            terminal_factor: 3.0,
            qp_max_iter: 50,
            qp_tolerance: 1e-7,
        }
    }
}

fn invalid(field: &'static str, value: impl std::fmt::Display, reason: &str) -> TrackingError {
    TrackingError::InvalidParam {
        field,
        value: value.to_string(),
        reason: reason.to_string(),
    }
}

/// `value` finite and `> 0`.
fn positive(field: &'static str, value: f64) -> Result<(), TrackingError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(invalid(field, value, "must be finite and > 0"))
    }
}

/// `value` finite and `≥ 0`.
fn non_negative(field: &'static str, value: f64) -> Result<(), TrackingError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(invalid(field, value, "must be finite and >= 0"))
    }
}

/// `value` finite and in `[lo, hi]`.
fn within(field: &'static str, value: f64, lo: f64, hi: f64) -> Result<(), TrackingError> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(())
    } else {
        Err(invalid(field, value, &format!("must be in [{lo}, {hi}]")))
    }
}

impl TrackingParams {
    /// Checks every field; the error names the first offending field and its value.
    pub fn validate(&self) -> Result<(), TrackingError> {
        positive("control_period_s", self.control_period_s)?;
        positive("substep_s", self.substep_s)?;
        if self.substep_s > self.control_period_s {
            return Err(invalid(
                "substep_s",
                self.substep_s,
                "must not exceed control_period_s",
            ));
        }
        if self.control_period_s / self.substep_s > 10_000.0 {
            return Err(invalid(
                "substep_s",
                self.substep_s,
                "more than 10000 sub-steps per control period",
            ));
        }
        within("time_limit_factor", self.time_limit_factor, 1.0, 1e3)?;
        positive("end_tolerance_m", self.end_tolerance_m)?;
        non_negative("search_back_m", self.search_back_m)?;
        positive("min_speed_mps", self.min_speed_mps)?;
        positive("max_speed_mps", self.max_speed_mps)?;
        if self.min_speed_mps > self.max_speed_mps {
            return Err(invalid(
                "min_speed_mps",
                self.min_speed_mps,
                "must not exceed max_speed_mps",
            ));
        }
        positive("speed_mps", self.speed_mps)?;
        if self.speed_mps < self.min_speed_mps || self.speed_mps > self.max_speed_mps {
            return Err(invalid(
                "speed_mps",
                self.speed_mps,
                &format!(
                    "must be in [min_speed_mps, max_speed_mps] = [{}, {}]",
                    self.min_speed_mps, self.max_speed_mps
                ),
            ));
        }
        positive("search_ahead_m", self.search_ahead_m)?;
        let per_step = 2.0 * self.max_speed_mps * self.control_period_s;
        if self.search_ahead_m < per_step {
            return Err(invalid(
                "search_ahead_m",
                self.search_ahead_m,
                &format!("must be at least 2 × max_speed_mps × control_period_s = {per_step}"),
            ));
        }
        positive("min_turn_radius_m", self.min_turn_radius_m)?;
        within("curvature_margin", self.curvature_margin, 0.0, 2.0)?;
        positive("max_accel_mps2", self.max_accel_mps2)?;
        positive("max_yaw_accel_radps2", self.max_yaw_accel_radps2)?;
        within("speed_lag_s", self.speed_lag_s, 0.0, 60.0)?;
        within("yaw_lag_s", self.yaw_lag_s, 0.0, 60.0)?;
        within("base_slip", self.base_slip, 0.0, 0.9)?;
        within("slip_pitch_gain", self.slip_pitch_gain, 0.0, 20.0)?;
        within("max_slip", self.max_slip, 0.0, 0.95)?;
        if self.base_slip > self.max_slip {
            return Err(invalid(
                "base_slip",
                self.base_slip,
                "must not exceed max_slip",
            ));
        }
        within("drift_gain", self.drift_gain, 0.0, 10.0)?;
        within("turn_slip", self.turn_slip, 0.0, 0.9)?;
        within("slip_noise_std", self.slip_noise_std, 0.0, 0.5)?;
        within(
            "lateral_noise_std_mps",
            self.lateral_noise_std_mps,
            0.0,
            1.0,
        )?;
        within("yaw_noise_std_radps", self.yaw_noise_std_radps, 0.0, 0.5)?;
        positive("noise_corr_time_s", self.noise_corr_time_s)?;
        positive("fix_std_m", self.fix_std_m)?;
        positive("fix_period_s", self.fix_period_s)?;
        positive("heading_std_rad", self.heading_std_rad)?;
        non_negative("gyro_std_radps", self.gyro_std_radps)?;
        non_negative("ekf_q_pos_m2ps", self.ekf_q_pos_m2ps)?;
        non_negative("ekf_q_heading_rad2ps", self.ekf_q_heading_rad2ps)?;
        non_negative("ekf_q_slip_ps", self.ekf_q_slip_ps)?;
        non_negative("ekf_q_drift_m2ps3", self.ekf_q_drift_m2ps3)?;
        positive("ekf_bias_corr_time_s", self.ekf_bias_corr_time_s)?;
        non_negative("ekf_slope_gain", self.ekf_slope_gain)?;
        if !(self.ekf_sage_husa_b.is_finite()
            && self.ekf_sage_husa_b > 0.0
            && self.ekf_sage_husa_b < 1.0)
        {
            return Err(invalid(
                "ekf_sage_husa_b",
                self.ekf_sage_husa_b,
                "must be in (0, 1)",
            ));
        }
        within("ekf_r_min_factor", self.ekf_r_min_factor, 1e-3, 1.0)?;
        within("ekf_r_max_factor", self.ekf_r_max_factor, 1.0, 1e3)?;
        positive("ekf_gate_chi2", self.ekf_gate_chi2)?;
        if self.horizon_steps == 0 || self.horizon_steps > 100 {
            return Err(invalid(
                "horizon_steps",
                self.horizon_steps,
                "must be in [1, 100]",
            ));
        }
        if self.control_horizon == 0 || self.control_horizon > self.horizon_steps {
            return Err(invalid(
                "control_horizon",
                self.control_horizon,
                &format!("must be in [1, horizon_steps = {}]", self.horizon_steps),
            ));
        }
        non_negative("q_lat_straight", self.q_lat_straight)?;
        non_negative("q_lat_arc", self.q_lat_arc)?;
        non_negative("q_head_straight", self.q_head_straight)?;
        non_negative("q_head_arc", self.q_head_arc)?;
        positive("r_yaw_rate", self.r_yaw_rate)?;
        positive("r_speed", self.r_speed)?;
        non_negative("rd_yaw_rate_straight", self.rd_yaw_rate_straight)?;
        non_negative("rd_yaw_rate_arc", self.rd_yaw_rate_arc)?;
        non_negative("rd_speed", self.rd_speed)?;
        within("terminal_factor", self.terminal_factor, 0.0, 1e3)?;
        if self.qp_max_iter == 0 {
            return Err(invalid("qp_max_iter", self.qp_max_iter, "must be >= 1"));
        }
        within("qp_tolerance", self.qp_tolerance, 1e-12, 1e-2)?;
        Ok(())
    }

    /// Largest commanded curvature `(1 + m)/R_min`, 1/m.
    pub fn max_curvature(&self) -> f64 {
        (1.0 + self.curvature_margin) / self.min_turn_radius_m
    }

    /// Number of sub-steps per control period and the sub-step length, s.
    pub fn substeps(&self) -> (usize, f64) {
        let n = (self.control_period_s / self.substep_s - 1e-9)
            .ceil()
            .max(1.0) as usize;
        (n, self.control_period_s / n as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid() {
        assert_eq!(TrackingParams::default().validate(), Ok(()));
    }

    fn field_of(err: TrackingError) -> (&'static str, String) {
        match err {
            TrackingError::InvalidParam { field, value, .. } => (field, value),
            other => panic!("unexpected error {other:?}"),
        }
    }

    #[test]
    fn errors_name_the_field_and_the_value() {
        let p = TrackingParams {
            fix_std_m: -0.5,
            ..TrackingParams::default()
        };
        let err = p.validate().err().unwrap_or(TrackingError::EmptyReference);
        let msg = err.to_string();
        assert!(msg.contains("fix_std_m") && msg.contains("-0.5"), "{msg}");
        assert_eq!(field_of(err), ("fix_std_m", "-0.5".to_string()));

        let p = TrackingParams {
            speed_mps: 1.5,
            ..TrackingParams::default()
        };
        let (field, value) = field_of(p.validate().err().unwrap_or(TrackingError::EmptyReference));
        assert_eq!((field, value.as_str()), ("speed_mps", "1.5"));

        let p = TrackingParams {
            control_horizon: 20,
            ..TrackingParams::default()
        };
        let (field, value) = field_of(p.validate().err().unwrap_or(TrackingError::EmptyReference));
        assert_eq!((field, value.as_str()), ("control_horizon", "20"));

        let p = TrackingParams {
            substep_s: f64::NAN,
            ..TrackingParams::default()
        };
        let (field, value) = field_of(p.validate().err().unwrap_or(TrackingError::EmptyReference));
        assert_eq!((field, value.as_str()), ("substep_s", "NaN"));

        let p = TrackingParams {
            ekf_sage_husa_b: 1.0,
            ..TrackingParams::default()
        };
        let (field, _) = field_of(p.validate().err().unwrap_or(TrackingError::EmptyReference));
        assert_eq!(field, "ekf_sage_husa_b");
    }

    #[test]
    fn substeps_split_the_period_evenly() {
        let p = TrackingParams {
            control_period_s: 1.0,
            substep_s: 0.3,
            ..TrackingParams::default()
        };
        let (n, dt) = p.substeps();
        assert_eq!(n, 4);
        assert!((dt - 0.25).abs() < 1e-12);
        let (n, dt) = TrackingParams::default().substeps();
        assert_eq!(n, 10);
        assert!((dt - 0.1).abs() < 1e-12);
    }
}
