//! Settings and errors of the Hybrid A* detour planner ([`super::plan`]), kept apart so the
//! search file stays short. Re-exported from `hybrid_astar`.

use crate::coverage::path::Pose2;
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, SQRT_2};

/// Search settings. The defaults suit a crawler with `R_min = 5 m` detouring round obstacles
/// tens of metres across.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HybridAStarParams {
    /// Minimum turning radius `R_min`, metres: the tightest arc a primitive or Dubins leg uses.
    pub min_turn_radius_m: f64,
    /// Arc length of one motion primitive, metres; at least `√2·xy_resolution_m` so that every
    /// primitive leaves its start cell whatever the heading.
    pub step_m: f64,
    /// Number of curvatures per expansion, odd so that straight (κ = 0) is one of them.
    pub steering_branches: usize,
    /// Side of a closed-set cell, metres.
    pub xy_resolution_m: f64,
    /// Heading bins of the closed set over 2π.
    pub heading_bins: usize,
    /// Expansion budget; `plan` returns `Ok(None)` when it is used up.
    pub max_expansions: usize,
    /// Distance within which a popped state counts as at the goal, metres (only used when no
    /// Dubins shot lands first; such a path ends near, not on, the goal).
    pub goal_tolerance_m: f64,
    /// Heading difference within which a popped state counts as at the goal, radians.
    pub goal_heading_tolerance_rad: f64,
    /// Try the Dubins shot every this many expansions (and at every expansion within `4·R` of
    /// the goal); `0` turns the analytic expansion off.
    pub analytic_expansion_every: usize,
    /// Extra cost per step for changing steering, as a fraction of `step_m` per unit change of
    /// the normalised steer `u = κ·R ∈ [−1, 1]`: discourages weaving.
    pub steer_change_penalty: f64,
    /// Extra cost per step for steering at all, as a fraction of `step_m` times `|u|`: prefers
    /// straight driving, which sweeps a clean swath.
    pub steer_penalty: f64,
}

impl Default for HybridAStarParams {
    fn default() -> Self {
        Self {
            // A heavy tracked crawler; rows are 2·R_min = 10 m apart in CPP-DSMV's pattern.
            min_turn_radius_m: 5.0,
            // ≥ √2·xy_resolution_m; a full-lock step turns 0.6 rad (34°), half lock 17°.
            step_m: 3.0,
            // Full lock, half lock and straight on each side.
            steering_branches: 5,
            // The closed-set cell, not the map cell (the map is sampled every 0.5 m regardless).
            // Measured on a 40 × 40 m square over 120 m: 2 m cells with 3 m steps expand ~6×
            // fewer states than 1 m cells with 2 m steps for a detour 0.2 m longer.
            xy_resolution_m: 2.0,
            // 5° bins, finer than the 17° heading change of a half-lock step.
            heading_bins: 72,
            // ~3 000 expansions for a 40 × 40 m obstacle, ~14 000 for 80 × 80 m: headroom for
            // larger ones while bounding a hopeless search to a fraction of a second.
            max_expansions: 50_000,
            // Only matters when no Dubins shot fits; one metre is well inside a 10 m row spacing.
            goal_tolerance_m: 1.0,
            goal_heading_tolerance_rad: 5f64.to_radians(),
            // Shots are cheap next to expansions; a failed one stops at the first collision.
            analytic_expansion_every: 10,
            // Small: enough to break ties towards smooth paths without bending long ones.
            steer_change_penalty: 0.2,
            steer_penalty: 0.05,
        }
    }
}

/// Why `plan` refused its input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HybridAStarError {
    /// A parameter is out of range.
    #[error("hybrid A* parameter `{field}` = {value}: {reason}")]
    InvalidParam {
        /// Field name in [`HybridAStarParams`].
        field: &'static str,
        /// The offending value, formatted.
        value: String,
        /// What it must be.
        reason: &'static str,
    },
    /// The start or goal pose has a NaN or infinite component.
    #[error("hybrid A* {which} pose is not finite: {pose:?}")]
    NonFinitePose {
        /// `"start"` or `"goal"`.
        which: &'static str,
        /// The pose as given.
        pose: Pose2,
    },
    /// The bounds are not finite, not ordered, or too large for the cell grid.
    #[error("hybrid A* bounds {bounds:?} (xmin, ymin, xmax, ymax): {reason}")]
    InvalidBounds {
        /// The bounds as given.
        bounds: [f64; 4],
        /// What is wrong.
        reason: &'static str,
    },
}

fn bad(
    field: &'static str,
    value: impl std::fmt::Display,
    reason: &'static str,
) -> HybridAStarError {
    HybridAStarError::InvalidParam {
        field,
        value: value.to_string(),
        reason,
    }
}

impl HybridAStarParams {
    /// Checks every field; the error names the first bad field and its value.
    pub fn validate(&self) -> Result<(), HybridAStarError> {
        let positive = |field, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(bad(field, v, "must be finite and > 0"))
            }
        };
        let non_negative = |field, v: f64| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(bad(field, v, "must be finite and >= 0"))
            }
        };
        positive("min_turn_radius_m", self.min_turn_radius_m)?;
        positive("xy_resolution_m", self.xy_resolution_m)?;
        positive("step_m", self.step_m)?;
        if self.step_m < SQRT_2 * self.xy_resolution_m {
            return Err(bad(
                "step_m",
                self.step_m,
                "must be >= sqrt(2) * xy_resolution_m so every primitive leaves its cell",
            ));
        }
        let b = self.steering_branches;
        if b.is_multiple_of(2) || !(3..=101).contains(&b) {
            return Err(bad("steering_branches", b, "must be odd and in 3..=101"));
        }
        if !(8..=3600).contains(&self.heading_bins) {
            return Err(bad(
                "heading_bins",
                self.heading_bins,
                "must be in 8..=3600",
            ));
        }
        if !(1..=100_000_000).contains(&self.max_expansions) {
            return Err(bad(
                "max_expansions",
                self.max_expansions,
                "must be in 1..=100000000",
            ));
        }
        non_negative("goal_tolerance_m", self.goal_tolerance_m)?;
        let h = self.goal_heading_tolerance_rad;
        if !(h.is_finite() && (0.0..=PI).contains(&h)) {
            return Err(bad("goal_heading_tolerance_rad", h, "must be in [0, pi]"));
        }
        non_negative("steer_change_penalty", self.steer_change_penalty)?;
        non_negative("steer_penalty", self.steer_penalty)
    }
}
