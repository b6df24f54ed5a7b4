//! The coverage planner's settings (CPP-DSMV, §2.2, Table 1 — whose values were lost; each default
//! says where it comes from).

use serde::{Deserialize, Serialize};

use super::Terrain25Error;

/// How a blocked stretch of a row is bypassed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DetourMethod {
    /// CPP-DSMV's method: merged inflated boxes, coarse polygon, analytic tangent arcs, virtual
    /// boundaries.
    #[default]
    Arcs,
    /// The paper's baseline: a Hybrid A* search on the dilated no-go map between a pose before
    /// and a pose after the blocked stretch, under the same Boustrophedon macro-routing.
    HybridAStar,
}

/// Settings of the Boustrophedon coverage planner.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CoverageParams {
    /// `R_min`, metres. Rows are `2·R_min` apart (CPP-DSMV, §2.2.1). Default 5 m: a ~12 m, 8 m wide
    /// tracked collector skid-steers about a point a little outside its inner track; heavier
    /// turning tears the sediment, which is why the paper bounds curvature at all.
    pub min_turn_radius_m: f64,
    /// Safety clearance `d_s` from the vehicle's centre line to any impassable cell, metres.
    /// Default 8 m, the paper's (§3, Figure 7a): half the width (4 m) plus a 4 m tracking margin.
    pub safety_clearance_m: f64,
    /// Length of the perception corridor ahead of the vehicle, metres. Default 50 m: what a
    /// forward-looking multibeam / imaging sonar on a crawler resolves reliably at the seabed.
    pub perception_range_m: f64,
    /// Boxes closer than this are fused, metres; `None` = the row spacing `2·R_min` (a gap
    /// narrower than one swath is not worth threading).
    pub merge_gap_m: Option<f64>,
    /// Largest lateral offset of a detour, metres; a box needing more is met with a virtual
    /// boundary. Default 60 m (six rows): beyond that the detour re-drives a large area already
    /// planned for other rows.
    pub max_detour_offset_m: f64,
    /// Spacing of the samples every generated piece is checked at, metres. Default 0.5 m, a
    /// quarter of the 2 m terrain cell.
    pub check_step_m: f64,
    /// Step of the virtual-boundary rollback search along the row, metres. Default 1 m.
    pub rollback_step_m: f64,
    /// How many rows a turn may skip when no turn into the next row is clear. Default 3.
    pub max_row_skip: usize,
    /// The detour method (`arcs` or `hybrid-a-star`).
    pub detour: DetourMethod,
    /// Hybrid A* expansions one transit between sweeps may use (0 = no transits: one sweep, as
    /// in the paper). Default 20 000: a transit the guided search has not found by then is almost
    /// always a pocket a forward-only vehicle cannot turn into.
    pub transit_expansions: usize,
    /// Expansions all transits of one plan may use together; the rest is reported unreached.
    /// Default 300 000 (about a second of search on one core).
    pub transit_budget: usize,
}

impl Default for CoverageParams {
    fn default() -> Self {
        Self {
            min_turn_radius_m: 5.0,
            safety_clearance_m: 8.0,
            perception_range_m: 50.0,
            merge_gap_m: None,
            max_detour_offset_m: 60.0,
            check_step_m: 0.5,
            rollback_step_m: 1.0,
            max_row_skip: 3,
            detour: DetourMethod::Arcs,
            transit_expansions: 20_000,
            transit_budget: 300_000,
        }
    }
}

impl CoverageParams {
    /// Row spacing `2·R_min`, metres.
    pub fn row_spacing(&self) -> f64 {
        2.0 * self.min_turn_radius_m
    }

    /// The merge gap in use, metres.
    pub fn merge_gap(&self) -> f64 {
        self.merge_gap_m.unwrap_or_else(|| self.row_spacing())
    }

    /// Checks every field; errors name the field and the value.
    pub fn validate(&self) -> Result<(), Terrain25Error> {
        let checks: [(&str, f64, bool); 6] = [
            ("min_turn_radius_m", self.min_turn_radius_m, false),
            ("safety_clearance_m", self.safety_clearance_m, true),
            ("perception_range_m", self.perception_range_m, false),
            ("max_detour_offset_m", self.max_detour_offset_m, true),
            ("check_step_m", self.check_step_m, false),
            ("rollback_step_m", self.rollback_step_m, false),
        ];
        for (field, v, zero_ok) in checks {
            if !(v.is_finite() && (v > 0.0 || (zero_ok && v == 0.0))) {
                let want = if zero_ok { "≥ 0" } else { "> 0" };
                return Err(Terrain25Error::InvalidParam {
                    field: field.to_string(),
                    what: format!("{v} must be finite and {want}"),
                });
            }
        }
        if let Some(g) = self.merge_gap_m {
            if !(g.is_finite() && g >= 0.0) {
                return Err(Terrain25Error::InvalidParam {
                    field: "merge_gap_m".into(),
                    what: format!("{g} must be finite and ≥ 0"),
                });
            }
        }
        if self.check_step_m > self.min_turn_radius_m {
            return Err(Terrain25Error::InvalidParam {
                field: "check_step_m".into(),
                what: format!(
                    "{} is coarser than the turning radius {}",
                    self.check_step_m, self.min_turn_radius_m
                ),
            });
        }
        Ok(())
    }
}
