//! Unit tests of the feasibility verdict, through the whole check.

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
