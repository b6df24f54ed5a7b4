//! Cage-inspection tours, Hu et al. 2023 (Hu et al. 2023): an AUV leaves a base, visits two inspection
//! points on opposite sides of every spherical net cage and returns, on the shortest path that
//! never touches a cage.
//!
//! Two layers, as in the seed:
//! 1. the visiting order, by the swap-operator PSO (§III-B, Table 3) on straight-line distances
//!    ([`SwapPso`]);
//! 2. every leg between consecutive visits, by a continuous swarm (DE-PSO, LDIW-PSO or LCPSO,
//!    Table 5) over the leg's intermediate waypoints with the cages as spherical obstacles
//!    ([`LegProblem`], §IV-C).
//!
//! [`plan_tour`] puts them together and reports the seed's Table 6 measures (path growth over
//! the straight tour and its rate). [`split_points`] shares the points among several AUVs.

pub(crate) mod cages;
mod figures;
mod fleet;
mod leg;
mod order;
mod plan;
mod split;

pub use crate::swarm::catalog::{leg_algorithm, LegAlgorithm};
pub use cages::{
    cage_group_a, cage_group_b, inspection_points, paper_base, paper_bounds, Cage, FirstPoint,
    InspectionPoint, MONITOR_STANDOFF_M,
};
pub use figures::TourFigures;
pub use fleet::{shares, FleetTours, NoTours};
pub use leg::{
    feasible, intersections, safety_spheres, segment_hits, LegProblem, Sphere, CHORD_WEIGHT,
    HIT_PENALTY_M,
};
pub use order::{
    distance_matrix, open_order_length, optimal_tour_length, swap_sequence, tour_length, two_opt,
    Ordered, SwapPso, MAX_EXACT_POINTS,
};
pub use plan::{
    plan_leg, plan_tour, summed_curve, Leg, LegSettings, TourPlan, TourSettings, LEG_CLEARANCE_M,
};
pub use split::{short_tour, split_points};

#[cfg(test)]
mod tests;
