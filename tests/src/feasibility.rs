//! The plan's own verdict judged against the recomputed figures: `feasible` must agree with
//! `violations`, a feasible plan must break no constraint beyond the slack, and an infeasible one
//! must break (or come within the slack of breaking) at least one.

use crate::figures::{FleetFigures, VehicleFigures};
use crate::model::{Plan, PlanVehicle, Vehicle};
use crate::{MAX_ARRIVAL_SPREAD_S, SEPARATION_TOL, TOL};

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
mod tests {
    use crate::check;
    use crate::fixtures::{approx, plan_json, SCENARIO};

    #[test]
    fn feasible_with_violations_fails() -> Result<(), String> {
        let r = check(SCENARIO, &plan_json(1000.0, true, r#"["something"]"#, 0.0))?;
        assert!(
            r.failures.iter().any(|f| f.contains("feasible = true")),
            "{r}"
        );
        // Marked infeasible although nothing is broken.
        let r = check(SCENARIO, &plan_json(1000.0, false, r#"["something"]"#, 0.0))?;
        assert!(
            r.failures
                .iter()
                .any(|f| f.contains("every constraint met")),
            "{r}"
        );
        Ok(())
    }

    #[test]
    fn breaches_are_found() -> Result<(), String> {
        // Move b to y = 20: it passes 20 m from a (below d_min) and 80 m from H (clearance 60 m);
        // the reported figures were not updated, so they mismatch, and feasible is wrong.
        let text = plan_json(1000.0, true, "[]", 0.0).replace(", 200, 50]", ", 20, 50]");
        let scenario = SCENARIO
            .replace("[1000.0, 200.0, 50.0]", "[1000.0, 20.0, 50.0]")
            .replace("goal = [0.0, 200.0, 50.0]", "goal = [0.0, 20.0, 50.0]");
        let r = check(&scenario, &text)?;
        assert!(
            r.mismatches
                .iter()
                .any(|m| m.contains("fleet.min_separation_m")),
            "{r}"
        );
        assert!(
            r.failures.iter().any(|f| f.contains("min separation 20")),
            "{r}"
        );
        assert!(approx(
            r.fleet.min_separation_m.unwrap_or(f64::NAN),
            20.0,
            1e-9
        ));
        // Closer than 150 m while |1000 − 2t| < √(150² − 20²) ≈ 148.66 m: for 148.66 s.
        let expect = (150f64.powi(2) - 20f64.powi(2)).sqrt();
        assert!(
            approx(r.fleet.separation_breach_s, expect, 1e-6),
            "{}",
            r.fleet.separation_breach_s
        );
        Ok(())
    }
}
