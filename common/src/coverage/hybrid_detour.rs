//! The Hybrid A* baseline detour (CPP-DSMV, §3: the search-based method the paper compares
//! against "under the identical Boustrophedon macro-routing").
//!
//! When a threat crosses the row, a Hybrid A* search ([`super::hybrid_astar`]) runs from a pose
//! two turning radii before the threat (or the vehicle, if closer) to the first admissible pose on
//! the row two radii past it, over the field's predicate — for the baseline, the dilated map
//! alone. If no path is found within the budget, or the goal would lie in the U-turn space, the
//! row ends in a virtual boundary as with the arc method, so both methods share every other
//! decision.

use super::boustrophedon::{BoundaryReason, DetourOutcome, DetourPlanner, Field, RowState};
use super::boxes::Rect;
use super::hybrid_astar::{self, HybridAStarParams};
use super::path::{Piece, Pose2};

/// Search budget of one detour (expansions).
const DETOUR_EXPANSIONS: usize = 20_000;

/// The baseline detour method.
pub struct HybridDetour;

impl DetourPlanner for HybridDetour {
    fn detour(&self, field: &Field<'_>, st: &RowState, threat: (Rect, f64, f64)) -> DetourOutcome {
        let (_, near, far) = threat;
        let r = field.params.min_turn_radius_m;
        let wall = |reason| DetourOutcome::Wall {
            wall_x: near - st.dir * (r + 1e-6),
            reason,
        };
        let start_x = {
            let x = near - st.dir * 2.0 * r;
            if st.dir * (x - st.x) < 0.0 {
                st.x
            } else {
                x
            }
        };
        // The first admissible point on the row two radii past the threat.
        let step = field.params.rollback_step_m;
        let mut goal_x = far + st.dir * 2.0 * r;
        while st.dir * (st.x_end - goal_x) >= 0.0 && !field.point_ok(goal_x, st.y) {
            goal_x += st.dir * step;
        }
        if st.dir * (st.x_end - goal_x) < 0.0 {
            return wall(BoundaryReason::DetourIntoUTurnSpace);
        }
        let heading = st.pose().heading;
        let params = HybridAStarParams {
            min_turn_radius_m: r,
            max_expansions: DETOUR_EXPANSIONS,
            ..HybridAStarParams::default()
        };
        let a = field.area;
        let free = |x: f64, y: f64| field.point_ok(x, y);
        let found = hybrid_astar::plan(
            Pose2::new(start_x, st.y, heading),
            Pose2::new(goal_x, st.y, heading),
            &free,
            [a.x0 - 1.0, a.y0 - 1.0, a.x1 + 1.0, a.y1 + 1.0],
            &params,
        );
        match found {
            Ok(Some(result)) => {
                let mut pieces = Vec::new();
                if (start_x - st.x).abs() > 1e-9 {
                    pieces.push(Piece::Line {
                        from: [st.x, st.y],
                        to: [start_x, st.y],
                    });
                }
                pieces.extend(result.path.pieces.into_iter().map(|(_, p)| p));
                // The search may stop within its goal tolerance: close onto the row exactly.
                match pieces.last().map(|p| p.end()) {
                    Some(end) if (end.y - st.y).abs() < 1e-6 => DetourOutcome::Bypass(pieces),
                    _ => wall(BoundaryReason::DetourBlocked),
                }
            }
            _ => wall(BoundaryReason::DetourBlocked),
        }
    }
}
