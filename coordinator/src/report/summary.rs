//! The short human summary `plan` prints on stdout.

use std::fmt::Write;

use shoal_common::plan::{Plan, VehiclePlan};

/// `v` with `digits` decimals, or "–" when there is none (the tables of `plan`, `status` and
/// `bench-coverage`).
pub(crate) fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or_else(|| "–".to_string(), |x| format!("{x:.digits$}"))
}

/// Renders the per-vehicle table, the fleet figures, notices and violations.
pub fn summary(plan: &Plan) -> String {
    let mut s = String::new();
    let verdict = if plan.feasible {
        "FEASIBLE"
    } else {
        "INFEASIBLE"
    };
    let _ = writeln!(
        s,
        "Plan {} — {} (seed {}, {}): {verdict}, fitness {:.4}, {:.2} s, {} evaluations",
        plan.scenario,
        plan.algorithm,
        plan.seed,
        plan.mode,
        plan.fitness,
        plan.runtime_s,
        plan.evaluations
    );
    let _ = writeln!(
        s,
        "Mission time {:.0} s; every vehicle is timed to arrive at {:.1} s",
        plan.mission_time_s, plan.common_arrival_s
    );
    let _ = writeln!(
        s,
        "{:<10} {:>9} {:>10} {:>12} {:>9} {:>10} {:>13} {:>5}",
        "vehicle",
        "length_m",
        "arrival_s",
        "clearance_m",
        "turn_deg",
        "pitch_deg",
        "speed_mps",
        "hits"
    );
    for v in &plan.vehicles {
        let _ = writeln!(
            s,
            "{:<10} {:>9.1} {:>10.1} {:>12} {:>9.1} {:>10.1} {:>6.3}-{:<6.3} {:>5}",
            v.id,
            v.length_m,
            v.arrival_s,
            opt(v.min_clearance_m, 1),
            v.max_turn_deg,
            v.max_pitch_deg,
            v.min_speed_mps,
            v.max_speed_mps,
            v.hard_collisions
        );
    }
    let f = &plan.fleet;
    let pair = f
        .min_separation_pair
        .as_ref()
        .map_or(String::new(), |[a, b]| {
            format!(" ({a}–{b} at t = {} s)", opt(f.min_separation_time_s, 0))
        });
    let _ = writeln!(
        s,
        "Fleet: min separation {} m{pair} vs d_min {:.0} m; hard collisions {}; arrival spread {:.3} s",
        opt(f.min_separation_m, 1),
        plan.d_min_m,
        f.hard_collisions,
        f.arrival_spread_s
    );
    for v in &plan.vehicles {
        if let Some(line) = capability_line(v) {
            let _ = writeln!(s, "{line}");
        }
    }
    for n in &plan.notices {
        let _ = writeln!(s, "note: {n}");
    }
    for v in &plan.violations {
        let _ = writeln!(s, "VIOLATION: {v}");
    }
    s
}

/// The figures of a vehicle's own planner, one line: a crawler's Lu et al. 2023 terms, an energy
/// plan's Zhang et al. 2022 terms, an inspection tour's Hu et al. 2023 figures, an AUV's height above a seabed;
/// `None` for a plain Zhi & Zuo 2024 swimmer.
fn capability_line(v: &VehiclePlan) -> Option<String> {
    let mut parts = Vec::new();
    if let Some(c) = &v.crawler {
        parts.push(format!(
            "on the seabed: undulation {:.2} m, energy {:.2} kWh, slip {:.3}, hazard clearance {} m, steepest {:.1}° (limit {:.1}°)",
            c.undulation_m,
            c.energy_kwh,
            c.slip_cost,
            opt(c.min_hazard_clearance_m, 1),
            c.max_slope_deg,
            c.slope_limit_deg
        ));
    }
    if let Some(e) = &v.energy {
        parts.push(format!(
            "energy plan: q_e {:.0} kJ, f_f {:.1}, tightest turn {:.1} m, pitch {:.1}° to {:.1}°, up to {:.2} m/s through the water",
            e.q_e / 1000.0,
            e.f_f,
            e.min_turn_radius_m,
            e.min_pitch_deg,
            e.max_pitch_deg,
            e.max_water_speed_mps
        ));
    }
    if let Some(t) = &v.tour {
        parts.push(format!(
            "tour: {} points, {:.1} m ({:.1} m straight, growth {:.1} %), {} cage intersections",
            t.order.len(),
            t.tour_length_m,
            t.straight_tour_length_m,
            100.0 * t.growth_rate,
            t.cage_intersections
        ));
    }
    if let Some(h) = v.min_seabed_clearance_m {
        parts.push(format!("at least {h:.1} m above the seabed"));
    }
    (!parts.is_empty()).then(|| format!("  {}: {}", v.id, parts.join("; ")))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vehicle(extra: &str) -> Result<VehiclePlan, serde_json::Error> {
        serde_json::from_str(&format!(
            r#"{{"id": "v", "trajectory": [], "length_m": 0.0, "arrival_s": 0.0,
                "max_turn_deg": 0.0, "max_pitch_deg": 0.0, "min_speed_mps": 0.0,
                "max_speed_mps": 0.0, "min_clearance_m": null, "hard_collisions": 0,
                "soft_exposure_m": 0.0{extra}}}"#
        ))
    }

    #[test]
    fn a_vehicles_own_figures_get_one_line() -> Result<(), serde_json::Error> {
        assert_eq!(capability_line(&vehicle("")?), None);
        let auv = vehicle(r#", "min_seabed_clearance_m": 38.16"#)?;
        assert_eq!(
            capability_line(&auv).as_deref(),
            Some("  v: at least 38.2 m above the seabed")
        );
        let crawler = vehicle(
            r#", "crawler": {"length_m": 281.2, "undulation_m": 1.333, "energy_kwh": 15.432,
                "slip_cost": 0.0, "min_hazard_clearance_m": 10.04, "hazard_intrusions": 0,
                "max_slope_deg": 0.54, "slope_limit_deg": 15.0, "off_seabed_m": 0.0}"#,
        )?;
        assert_eq!(
            capability_line(&crawler).as_deref(),
            Some("  v: on the seabed: undulation 1.33 m, energy 15.43 kWh, slip 0.000, hazard clearance 10.0 m, steepest 0.5° (limit 15.0°)")
        );
        Ok(())
    }
}
