//! The short human summary `plan` prints on stdout.

use std::fmt::Write;

use shoal_common::plan::Plan;

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
    for n in &plan.notices {
        let _ = writeln!(s, "note: {n}");
    }
    for v in &plan.violations {
        let _ = writeln!(s, "VIOLATION: {v}");
    }
    s
}
