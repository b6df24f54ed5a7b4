//! The plan's own verdict judged against the recomputed figures: `feasible` must agree with
//! `violations`, a feasible plan must break no constraint beyond the slack, and an infeasible one
//! must break (or come within the slack of breaking) at least one.

use crate::figures::{FleetFigures, VehicleFigures};
use crate::model::{Plan, PlanVehicle, Vehicle};
use crate::tolerance::{MAX_ARRIVAL_SPREAD_S, SEPARATION_TOL, TOL};

/// Failures of the plan's `feasible` and `violations` claims, given the scenario vehicles paired
/// with their plan entries, their recomputed figures (same order) and the fleet figures.
pub(crate) fn claim_failures(
    plan: &Plan,
    d_min: f64,
    pairs: &[(&Vehicle, &PlanVehicle)],
    figures: &[VehicleFigures],
    fleet: &FleetFigures,
    crawler_broken: &[String],
) -> Vec<String> {
    let mut failures = Vec::new();
    if plan.feasible != plan.violations.is_empty() {
        failures.push(format!(
            "feasible = {} but violations = {:?}",
            plan.feasible, plan.violations
        ));
    }
    // Constraints broken beyond the slack (what a feasible plan must not have) ...
    let mut broken = crawler_broken.to_vec();
    // ... and constraints broken or within the slack of breaking (an infeasible plan needs one).
    let mut marginal = Vec::new();
    for ((v, pv), f) in pairs.iter().zip(figures) {
        let id = &v.id;
        if f.hard_collisions > 0 {
            broken.push(format!("{id} has {} hard collisions", f.hard_collisions));
        }
        if f.max_turn_deg > v.max_turn_deg + TOL {
            broken.push(format!(
                "{id} turns {}° > {}°",
                f.max_turn_deg, v.max_turn_deg
            ));
        }
        if f.max_turn_deg > v.max_turn_deg - TOL {
            marginal.push(format!("{id} turn"));
        }
        if f.max_pitch_deg > v.max_pitch_deg + TOL {
            broken.push(format!(
                "{id} pitches {}° > {}°",
                f.max_pitch_deg, v.max_pitch_deg
            ));
        }
        if f.max_pitch_deg > v.max_pitch_deg - TOL {
            marginal.push(format!("{id} pitch"));
        }
        if !f.inside_bounds {
            broken.push(format!("{id} leaves the bounds"));
        }
        let ends_ok = pv
            .trajectory
            .first()
            .is_some_and(|s| v.end_distance(s, &v.start) <= TOL)
            && pv
                .trajectory
                .last()
                .is_some_and(|s| v.end_distance(s, &v.goal) <= TOL);
        if !ends_ok {
            broken.push(format!("{id} does not run from start to goal"));
        }
        if f.leg_speeds_mps
            .iter()
            .any(|&(_, s)| s < v.speed_min_mps + TOL || s > v.speed_max_mps - TOL)
        {
            marginal.push(format!("{id} speed"));
        }
    }
    if let Some(m) = fleet.min_separation_m {
        if m < d_min - SEPARATION_TOL {
            broken.push(format!("min separation {m} m < d_min {d_min} m"));
        }
        if m < d_min + SEPARATION_TOL {
            marginal.push("separation".to_string());
        }
    }
    if fleet.arrival_spread_s > MAX_ARRIVAL_SPREAD_S + TOL {
        broken.push(format!("arrival spread {} s > 1 s", fleet.arrival_spread_s));
    }
    if fleet.arrival_spread_s > MAX_ARRIVAL_SPREAD_S - TOL {
        marginal.push("arrival spread".to_string());
    }
    if plan.feasible && !broken.is_empty() {
        failures.push(format!(
            "plan is marked feasible but the checker finds: {}",
            broken.join("; ")
        ));
    }
    if !plan.feasible && broken.is_empty() && marginal.is_empty() {
        failures.push(format!(
            "plan is marked infeasible ({:?}) but the checker finds every constraint met",
            plan.violations
        ));
    }
    failures
}

#[cfg(test)]
mod tests;
