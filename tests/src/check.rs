//! The check itself: parses both files, recomputes every figure, lists each reported figure that
//! disagrees with the recomputation (mismatches) and each broken contract rule (failures: echoed
//! scenario values, vehicle set and order, start and goal, timing, leg speeds, the fleet's
//! closest-approach claim and the plan's `feasible` verdict).

use crate::feasibility::claim_failures;
use crate::figures::{fleet_figures, vehicle_figures};
use crate::geometry::{self, dist, point};
use crate::model::{
    parse_plan, parse_scenario, parse_scenario_file, Plan, PlanVehicle, Scenario, Vehicle,
};
use crate::report::Report;
use crate::tolerance::{close, SEPARATION_TOL, TOL};

/// True when `x` lies in `[lo − slack, hi + slack]`: for figures that are ill-conditioned where a
/// path grazes a surface, checked against the range their recomputation spans under a 1 µm
/// perturbation of that surface.
fn within(x: f64, [lo, hi]: [f64; 2], slack: f64) -> bool {
    x >= lo - slack && x <= hi + slack
}

/// Parses both files and checks the plan against the scenario.
pub fn check(scenario_toml: &str, plan_json: &str) -> Result<Report, String> {
    let scenario = parse_scenario(scenario_toml)?;
    let plan = parse_plan(plan_json)?;
    Ok(check_parsed(&scenario, &plan))
}

/// Reads the scenario file at `scenario_path` (with its measured seabed, if any: see
/// [`parse_scenario_file`]) and checks the plan against it.
pub fn check_file(scenario_path: &std::path::Path, plan_json: &str) -> Result<Report, String> {
    let scenario = parse_scenario_file(scenario_path)?;
    let plan = parse_plan(plan_json)?;
    Ok(check_parsed(&scenario, &plan))
}

/// Checks a parsed plan against a parsed scenario.
pub fn check_parsed(scenario: &Scenario, plan: &Plan) -> Report {
    let mut mismatches = Vec::new();
    let mut failures = Vec::new();
    let num = |out: &mut Vec<String>, what: String, reported: f64, recomputed: f64, abs: f64| {
        if !close(reported, recomputed, abs) {
            out.push(format!(
                "{what}: reported {reported} but recomputed {recomputed} (difference {:e})",
                reported - recomputed
            ));
        }
    };

    // Echoed scenario values.
    if plan.scenario != scenario.name {
        failures.push(format!(
            "plan.scenario is {:?} but the scenario is named {:?}",
            plan.scenario, scenario.name
        ));
    }
    num(
        &mut mismatches,
        "d_min_m".into(),
        plan.d_min_m,
        scenario.fleet.d_min_m,
        TOL,
    );
    num(
        &mut mismatches,
        "mission_time_s".into(),
        plan.mission_time_s,
        scenario.fleet.mission_time_s,
        TOL,
    );

    // Vehicles: match plan entries to scenario vehicles by id.
    for pv in &plan.vehicles {
        if !scenario.vehicles.iter().any(|v| v.id == pv.id) {
            failures.push(format!("plan vehicle {:?} is not in the scenario", pv.id));
        }
    }
    let plan_ids: Vec<&str> = plan.vehicles.iter().map(|v| v.id.as_str()).collect();
    let scenario_ids: Vec<&str> = scenario.vehicles.iter().map(|v| v.id.as_str()).collect();
    if plan_ids != scenario_ids {
        failures.push(format!(
            "plan vehicles are {plan_ids:?}, expected {scenario_ids:?} (scenario order)"
        ));
    }
    let mut pairs: Vec<(&Vehicle, &PlanVehicle)> = Vec::new();
    for v in &scenario.vehicles {
        match plan.vehicles.iter().find(|p| p.id == v.id) {
            Some(p) => pairs.push((v, p)),
            None => failures.push(format!("vehicle {} is missing from the plan", v.id)),
        }
    }

    let mut figures = Vec::with_capacity(pairs.len());
    let mut crawler_broken = Vec::new();
    for (v, pv) in &pairs {
        let id = &v.id;
        let traj = &pv.trajectory;
        if traj.is_empty() {
            failures.push(format!("{id}: empty trajectory"));
        }
        if traj.iter().flatten().any(|x| !x.is_finite()) {
            failures.push(format!("{id}: trajectory has a non-finite value"));
        }
        let f = vehicle_figures(id, traj, scenario);

        // Reported versus recomputed.
        num(
            &mut mismatches,
            format!("{id}.length_m"),
            pv.length_m,
            f.length_m,
            TOL,
        );
        num(
            &mut mismatches,
            format!("{id}.arrival_s"),
            pv.arrival_s,
            f.arrival_s,
            TOL,
        );
        num(
            &mut mismatches,
            format!("{id}.max_turn_deg"),
            pv.max_turn_deg,
            f.max_turn_deg,
            TOL,
        );
        num(
            &mut mismatches,
            format!("{id}.max_pitch_deg"),
            pv.max_pitch_deg,
            f.max_pitch_deg,
            TOL,
        );
        num(
            &mut mismatches,
            format!("{id}.min_speed_mps"),
            pv.min_speed_mps,
            f.min_speed_mps,
            TOL,
        );
        num(
            &mut mismatches,
            format!("{id}.max_speed_mps"),
            pv.max_speed_mps,
            f.max_speed_mps,
            TOL,
        );
        let [lo, hi] = f.soft_exposure_range_m;
        if !within(pv.soft_exposure_m, [lo, hi], TOL) {
            mismatches.push(format!(
                "{id}.soft_exposure_m: reported {} but recomputed {} ({lo} to {hi} with the soft spheres {TOL} m smaller or larger)",
                pv.soft_exposure_m, f.soft_exposure_m
            ));
        }
        match (pv.min_clearance_m, f.min_clearance_m) {
            (Some(r), Some(c)) => num(&mut mismatches, format!("{id}.min_clearance_m"), r, c, TOL),
            (None, None) => {}
            (r, c) => mismatches.push(format!(
                "{id}.min_clearance_m: reported {r:?} but recomputed {c:?}"
            )),
        }
        if pv.hard_collisions != f.hard_collisions {
            mismatches.push(format!(
                "{id}.hard_collisions: reported {} but recomputed {}",
                pv.hard_collisions, f.hard_collisions
            ));
        }

        // Contract rules that hold for every plan.
        if let (Some(first), Some(last)) = (traj.first(), traj.last()) {
            let ds = v.end_distance(first, &v.start);
            if ds > TOL {
                failures.push(format!(
                    "{id}: trajectory starts at {:?}, {ds} m from its start {:?}",
                    point(first),
                    v.start
                ));
            }
            let dg = v.end_distance(last, &v.goal);
            if dg > TOL {
                failures.push(format!(
                    "{id}: trajectory ends at {:?}, {dg} m from its goal {:?}",
                    point(last),
                    v.goal
                ));
            }
            if first[0].abs() > TOL {
                failures.push(format!(
                    "{id}: trajectory starts at t = {} s, not 0",
                    first[0]
                ));
            }
        }
        if let Some(k) = traj.windows(2).position(|w| w[1][0] < w[0][0]) {
            failures.push(format!(
                "{id}: time goes backwards from sample {k} (t = {}) to sample {} (t = {})",
                traj[k][0],
                k + 1,
                traj[k + 1][0]
            ));
        }
        for &(k, s) in &f.leg_speeds_mps {
            if s < v.speed_min_mps - TOL || s > v.speed_max_mps + TOL {
                failures.push(format!(
                    "{id}: leg {k} (sample {k} to {}) at {s} m/s, outside {}–{} m/s",
                    k + 1,
                    v.speed_min_mps,
                    v.speed_max_mps
                ));
            }
        }
        if v.is_crawler() {
            let c = crate::crawler::check(scenario, v, traj, pv.crawler.as_ref());
            mismatches.extend(c.mismatches);
            crawler_broken.extend(c.broken);
        }
        if !v.is_crawler() {
            // An energy plan keeps its own clearance (Zhang et al. 2022); a fleet AUV the seabed's.
            let required = match (&pv.energy, &scenario.energy, &scenario.seabed) {
                (Some(_), Some(e), _) => e.terrain_clearance_m,
                (Some(_), None, _) => 2.0,
                (None, _, Some(s)) => s.auv_clearance_m.unwrap_or(2.0),
                (None, _, None) => 2.0,
            };
            let c = crate::crawler::check_swimmer_seabed(
                scenario,
                id,
                traj,
                required,
                pv.min_seabed_clearance_m,
            );
            mismatches.extend(c.mismatches);
            crawler_broken.extend(c.broken);
        }
        if let Some(e) = &pv.energy {
            let c = crate::mobility::check_energy(scenario, v, traj, e);
            mismatches.extend(c.mismatches);
            crawler_broken.extend(c.broken);
        }
        if let Some(t) = &pv.tour {
            let c = crate::mobility::check_tour(v, traj, t);
            mismatches.extend(c.mismatches);
            crawler_broken.extend(c.broken);
        }
        figures.push(f);
    }
    let tours: Vec<(&str, &crate::sections::PlanTour)> = plan
        .vehicles
        .iter()
        .filter_map(|v| v.tour.as_ref().map(|t| (v.id.as_str(), t)))
        .collect();
    if !tours.is_empty() {
        crawler_broken.extend(crate::mobility::check_coverage(scenario, &tours));
    }

    // Fleet.
    let reported_hard: usize = plan.vehicles.iter().map(|v| v.hard_collisions).sum();
    if plan.fleet.hard_collisions != reported_hard {
        mismatches.push(format!(
            "fleet.hard_collisions: reported {} but the vehicles' hard_collisions sum to {reported_hard}",
            plan.fleet.hard_collisions
        ));
    }
    let trajs: Vec<(&str, &[[f64; 4]])> = pairs
        .iter()
        .map(|(v, p)| (v.id.as_str(), p.trajectory.as_slice()))
        .collect();
    let fleet = fleet_figures(
        &trajs,
        scenario.fleet.d_min_m,
        figures.iter().map(|f| f.hard_collisions).sum(),
    );
    if plan.fleet.hard_collisions != fleet.hard_collisions {
        mismatches.push(format!(
            "fleet.hard_collisions: reported {} but recomputed {}",
            plan.fleet.hard_collisions, fleet.hard_collisions
        ));
    }
    num(
        &mut mismatches,
        "fleet.arrival_spread_s".into(),
        plan.fleet.arrival_spread_s,
        fleet.arrival_spread_s,
        TOL,
    );
    let [lo, hi] = fleet.separation_breach_range_s;
    let breach = plan.fleet.separation_breach_s;
    if !within(breach, [lo, hi], SEPARATION_TOL) {
        mismatches.push(format!(
            "fleet.separation_breach_s: reported {breach} but recomputed {} ({lo} to {hi} with d_min {TOL} m lower or higher)",
            fleet.separation_breach_s
        ));
    }
    match (plan.fleet.min_separation_m, fleet.min_separation_m) {
        (Some(r), Some(c)) => num(
            &mut mismatches,
            "fleet.min_separation_m".into(),
            r,
            c,
            SEPARATION_TOL,
        ),
        (None, None) => {}
        (r, c) => mismatches.push(format!(
            "fleet.min_separation_m: reported {r:?} but recomputed {c:?}"
        )),
    }
    // The reported pair and instant must realise the reported minimum (ties may pick any pair).
    if let Some(reported) = plan.fleet.min_separation_m {
        let pair = plan.fleet.min_separation_pair.as_ref().and_then(|[x, y]| {
            let a = trajs.iter().find(|(id, _)| id == x)?;
            let b = trajs.iter().find(|(id, _)| id == y)?;
            Some((x, y, a.1, b.1))
        });
        match pair {
            None => failures.push(format!(
                "fleet.min_separation_pair {:?} does not name two vehicles of the plan",
                plan.fleet.min_separation_pair
            )),
            Some((x, y, a, b)) => {
                let exact = geometry::min_separation(a, b).distance;
                num(
                    &mut mismatches,
                    format!("fleet.min_separation_m (as the closest approach of {x} and {y})"),
                    reported,
                    exact,
                    SEPARATION_TOL,
                );
                match plan.fleet.min_separation_time_s {
                    Some(t) => {
                        let at = dist(&geometry::position_at(a, t), &geometry::position_at(b, t));
                        num(
                            &mut mismatches,
                            format!("fleet.min_separation_m (distance of {x} and {y} at the reported t = {t} s)"),
                            reported,
                            at,
                            SEPARATION_TOL,
                        );
                    }
                    None => failures.push("fleet.min_separation_time_s is null".to_string()),
                }
            }
        }
    }

    failures.extend(claim_failures(
        plan,
        scenario.fleet.d_min_m,
        &pairs,
        &figures,
        &fleet,
        &crawler_broken,
    ));

    Report {
        vehicles: figures,
        fleet,
        mismatches,
        failures,
    }
}

#[cfg(test)]
mod tests {
    use crate::check;
    use crate::fixtures::{approx, plan_json, SCENARIO};

    #[test]
    fn consistent_plan_is_clean() -> Result<(), String> {
        let r = check(SCENARIO, &plan_json(1000.0, true, "[]", 0.0))?;
        assert!(r.is_clean(), "{r}");
        assert_eq!(
            r.vehicles[0]
                .min_clearance_m
                .map(|c| (c * 1e9).round() / 1e9),
            Some(40.0)
        );
        assert!(approx(r.vehicles[1].soft_exposure_m, 40.0, 1e-9));
        assert_eq!(
            r.fleet.min_separation_pair,
            Some(["a".to_string(), "b".to_string()])
        );
        assert!(approx(
            r.fleet.min_separation_time_s.unwrap_or(f64::NAN),
            500.0,
            1e-9
        ));
        Ok(())
    }

    #[test]
    fn wrong_figure_is_a_mismatch() -> Result<(), String> {
        let r = check(SCENARIO, &plan_json(1001.0, true, "[]", 0.0))?;
        assert!(r.failures.is_empty(), "{r}");
        assert_eq!(r.mismatches.len(), 1, "{r}");
        assert!(r.mismatches[0].contains("a.length_m"), "{r}");
        assert!(r.mismatches[0].contains("1001"), "{r}");
        Ok(())
    }

    #[test]
    fn soft_exposure_is_checked_with_slack_only_where_a_leg_grazes() -> Result<(), String> {
        let exposure = |text: &str, reported: &str| {
            text.replace(
                r#""soft_exposure_m": 40}"#,
                &format!(r#""soft_exposure_m": {reported}}}"#),
            )
        };
        let plan = plan_json(1000.0, true, "[]", 0.0);
        // b through S's centre: 40 m inside, and 40.001 m is wrong.
        let r = check(SCENARIO, &exposure(&plan, "40.001"))?;
        assert_eq!(r.mismatches.len(), 1, "{r}");
        assert!(r.mismatches[0].contains("b.soft_exposure_m"), "{r}");
        // S moved 20 m off b's line: b's leg touches the inflated sphere (20 m) at one point.
        // Grown by 1 µm it would hold a chord of 2·√(20.000001² − 20²) = 0.01265 m, so anything
        // from 0 to that is a correct report, and 0.02 m is not.
        let grazed = SCENARIO.replace("[250.0, 200.0, 50.0]", "[250.0, 220.0, 50.0]");
        let r = check(&grazed, &exposure(&plan, "0"))?;
        assert!(r.is_clean(), "{r}");
        let [lo, hi] = r.vehicles[1].soft_exposure_range_m;
        assert!(approx(lo, 0.0, 1e-12), "{lo}");
        assert!(approx(hi, 0.012649, 1e-6), "{hi}");
        assert!(check(&grazed, &exposure(&plan, "0.0126"))?.is_clean());
        let r = check(&grazed, &exposure(&plan, "0.02"))?;
        assert!(
            r.mismatches
                .iter()
                .any(|m| m.contains("b.soft_exposure_m: reported 0.02")),
            "{r}"
        );
        Ok(())
    }

    #[test]
    fn breach_time_is_checked_with_slack_only_where_a_pair_grazes_d_min() -> Result<(), String> {
        // a and b pass 200 m apart at 2 m/s relative; with d_min = 200 m they just touch it.
        // With d_min 1 µm larger they would be inside for √(200.000001² − 200²) = 0.02 s.
        let scenario = SCENARIO.replace("d_min_m = 150.0", "d_min_m = 200.0");
        let plan = |breach: &str| {
            plan_json(1000.0, true, "[]", 0.0)
                .replace(r#""d_min_m": 150.0"#, r#""d_min_m": 200.0"#)
                .replace(
                    r#""separation_breach_s": 0,"#,
                    &format!(r#""separation_breach_s": {breach},"#),
                )
        };
        let r = check(&scenario, &plan("0"))?;
        assert!(r.is_clean(), "{r}");
        let [lo, hi] = r.fleet.separation_breach_range_s;
        assert!(approx(lo, 0.0, 1e-12), "{lo}");
        assert!(approx(hi, 0.02, 1e-6), "{hi}");
        assert!(check(&scenario, &plan("0.015"))?.is_clean());
        let r = check(&scenario, &plan("0.5"))?;
        assert!(
            r.mismatches
                .iter()
                .any(|m| m.contains("fleet.separation_breach_s: reported 0.5")),
            "{r}"
        );
        // Away from a graze the slack is the separation tolerance (1 ms) only: with
        // d_min = 150 m the pair never breaches, and 2 ms is wrong.
        let r = check(
            SCENARIO,
            &plan_json(1000.0, true, "[]", 0.0).replace(
                r#""separation_breach_s": 0,"#,
                r#""separation_breach_s": 0.002,"#,
            ),
        )?;
        assert_eq!(r.mismatches.len(), 1, "{r}");
        Ok(())
    }

    #[test]
    fn missing_the_goal_fails() -> Result<(), String> {
        // b stops 10 m short: its length, speed and exposure no longer match either.
        let r = check(SCENARIO, &plan_json(1000.0, true, "[]", 10.0))?;
        assert!(
            r.failures.iter().any(|f| f.contains("b: trajectory ends")),
            "{r}"
        );
        assert!(
            r.failures.iter().any(|f| f.contains("marked feasible")),
            "{r}"
        );
        assert!(r.mismatches.iter().any(|m| m.contains("b.length_m")), "{r}");
        Ok(())
    }

    #[test]
    fn parse_errors_are_errors() {
        assert!(check("name = 1", "{}").is_err());
        assert!(check(SCENARIO, "{\"scenario\": \"hand\"}").is_err());
    }
}
