//! AUVs in currents (Zhang et al. 2022, EPA-PSO) and cage-inspection tours (Hu et al. 2023, DE-PSO) end to end:
//! the real binary plans the shipped scenarios and every plan passes the independent checker,
//! which recomputes the turning radius, pitch and seabed clearance of an energy plan and the
//! inspection points of a tour from the trajectories.

mod common;

use common::{key, plan, plan_and_check, scenario, TestResult};
use serde_json::Value;

fn vehicle(json: &Value, k: usize) -> &Value {
    &key(json, "vehicles")[k]
}

fn num(v: &Value, field: &str) -> f64 {
    match v[field].as_f64() {
        Some(x) => x,
        None => panic!("{field} is not a number in {v}"),
    }
}

#[test]
fn epa_pso_saves_energy_and_keeps_the_mobility_limits() -> TestResult {
    let short = ["--iterations", "40", "--seed", "2"];
    let dir = tempfile::tempdir()?;
    let epa = plan_and_check("epa-pso", dir.path(), &short)?;
    assert_eq!(key(&epa, "feasible").as_bool(), Some(true));
    let e = &vehicle(&epa, 0)["energy"];
    // Turning radius and pitch limits kept on every point (Zhang et al. 2022, eq. (5)).
    assert_eq!((num(e, "q_r"), num(e, "q_a")), (0.0, 0.0), "{e}");
    assert!(num(e, "min_turn_radius_m") >= 8.0);
    assert!(num(e, "max_pitch_deg") <= 20.0 && num(e, "min_pitch_deg") >= -20.0);
    // A 72 m climb at ≤ 20° needs at least 72 / sin 20° = 210.5 m of path.
    assert!(num(e, "q_path") > 210.5, "{e}");
    // eq. (18) from the reported terms.
    let f_f = (num(e, "q_path") + num(e, "q_e") + num(e, "q_r") + num(e, "q_a")) / 4.0;
    assert!((num(e, "f_f") - f_f).abs() < 1e-6 * f_f);
    let svg = std::fs::read_to_string(dir.path().join("plan.svg"))?;
    assert!(svg.contains("current"), "no current-field view in the SVG");

    // The length-only baseline flies the straight line: short, too steep, far more energy.
    let dir = tempfile::tempdir()?;
    let pso = plan_and_check(
        "epa-pso",
        dir.path(),
        &[
            "--algorithm",
            "pso-length",
            "--iterations",
            "40",
            "--seed",
            "2",
        ],
    )?;
    assert_eq!(key(&pso, "feasible").as_bool(), Some(false));
    let p = &vehicle(&pso, 0)["energy"];
    assert!(num(p, "q_a") > 0.0 && num(p, "q_path") < 95.0, "{p}");
    assert!(
        num(e, "q_e") < 0.4 * num(p, "q_e"),
        "EPA-PSO q_e {} vs PSO {}",
        num(e, "q_e"),
        num(p, "q_e")
    );
    Ok(())
}

#[test]
fn a_plan_that_needs_more_than_the_top_speed_through_the_water_is_infeasible() -> TestResult {
    // The plan holds 1.5 m/s over ground; against the 1.41 m/s surface current that takes up
    // to ~2.9 m/s through the water, which a vehicle of 1.5 m/s top speed cannot make.
    let dir = tempfile::tempdir()?;
    let toml = std::fs::read_to_string(scenario("epa-pso"))?;
    let slow = toml.replacen("speed_max_mps = 3.0", "speed_max_mps = 1.5", 1);
    assert_ne!(slow, toml, "the shipped scenario's top speed moved");
    let file = dir.path().join("slow.toml");
    std::fs::write(&file, slow)?;
    let r = plan(&file, dir.path(), &["--iterations", "10", "-q"]);
    assert_eq!(r.code(), Some(3), "{r}");
    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("plan.json"))?)?;
    let violations = key(&json, "violations").to_string();
    assert!(
        violations.contains("through the water")
            && violations.contains("vehicles[0].speed_max_mps"),
        "{violations}"
    );
    // The independent checker recomputes the water speed from the trajectory and eq. (2): it
    // agrees with the verdict, refuses the same plan claimed feasible ...
    let text = std::fs::read_to_string(&file)?;
    let report = shoal_tests::check(&text, &json.to_string())?;
    assert!(report.is_clean(), "{report:?}");
    let mut claimed = json.clone();
    claimed["feasible"] = Value::from(true);
    claimed["violations"] = serde_json::json!([]);
    let report = shoal_tests::check(&text, &claimed.to_string())?;
    assert!(
        report
            .failures
            .iter()
            .any(|f| f.contains("through the water")),
        "{report:?}"
    );
    // ... and a reported water speed that is not the trajectory's.
    let mut lied = json.clone();
    lied["vehicles"][0]["energy"]["max_water_speed_mps"] = Value::from(1.2);
    let report = shoal_tests::check(&text, &lied.to_string())?;
    assert!(
        report
            .mismatches
            .iter()
            .any(|m| m.contains("max_water_speed_mps")),
        "{report:?}"
    );
    // The shipped vehicle (3 m/s through the water) flies the same plan.
    let dir = tempfile::tempdir()?;
    let json = plan_and_check("epa-pso", dir.path(), &["--iterations", "10"])?;
    assert_eq!(key(&json, "feasible").as_bool(), Some(true), "{json}");
    Ok(())
}

#[test]
fn energy_planners_refuse_a_distributed_run_and_fleets() -> TestResult {
    let dir = tempfile::tempdir()?;
    // Without --in-process the coordinator would wait for agents: it refuses at once instead.
    let mut cmd = std::process::Command::new(common::coordinator());
    common::without_shoal_env(&mut cmd);
    let out = cmd
        .arg("plan")
        .arg(scenario("epa-pso"))
        .arg("--out")
        .arg(dir.path())
        .output()?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("add --in-process"), "{stderr}");
    // A fleet scenario cannot take a single-AUV planner.
    let r = plan(
        &scenario("amp-pso-1"),
        dir.path(),
        &["--algorithm", "epa-pso"],
    );
    assert_ne!(r.code(), Some(0));
    assert!(
        r.stderr.contains("optimizer.algorithm") && r.stderr.contains("plans one AUV"),
        "{r}"
    );
    Ok(())
}

#[test]
fn de_pso_tours_inspect_every_cage_without_touching_one() -> TestResult {
    for group in ["cages-a", "cages-b"] {
        let dir = tempfile::tempdir()?;
        let json = plan_and_check(
            group,
            dir.path(),
            &["--iterations", "80", "--particles", "30", "--seed", "3"],
        )?;
        assert_eq!(key(&json, "feasible").as_bool(), Some(true), "{group}");
        let t = &vehicle(&json, 0)["tour"];
        let order = t["order"].as_array().map(Vec::len).unwrap_or(0);
        assert_eq!(order, 10, "{group}: {t}");
        assert_eq!(t["cage_intersections"].as_u64(), Some(0));
        let growth = num(t, "growth_m");
        assert!(growth >= 0.0 && num(t, "growth_rate") < 0.5, "{group}: {t}");
        assert!((num(t, "tour_length_m") - num(t, "straight_tour_length_m") - growth).abs() < 1e-6);
        // The order swarm alone evaluates 100 × (2000 + 1) tours (Hu et al. 2023, Table 3).
        let evaluations = key(&json, "evaluations").as_u64().unwrap_or(0);
        assert!(evaluations >= 100 * 2001, "{group}: {evaluations}");
    }
    Ok(())
}

#[test]
fn a_fleet_shares_the_inspection_points_and_keeps_apart() -> TestResult {
    let dir = tempfile::tempdir()?;
    let json = plan_and_check("cages-fleet", dir.path(), &common::CAGES_FLEET_QUICK)?;
    assert_eq!(key(&json, "feasible").as_bool(), Some(true));
    let mut labels: Vec<String> = Vec::new();
    let mut lengths = Vec::new();
    for k in 0..2 {
        let t = &vehicle(&json, k)["tour"];
        lengths.push(num(t, "tour_length_m"));
        for l in t["order"].as_array().into_iter().flatten() {
            labels.push(l.as_str().unwrap_or("").to_string());
        }
    }
    labels.sort();
    let expected: Vec<String> = (1..=5)
        .flat_map(|c| [format!("A{c}.1"), format!("A{c}.2")])
        .collect();
    assert_eq!(labels, expected);
    // Balanced: neither tour is more than 1.5 times the other.
    assert!(
        lengths[0] < 1.5 * lengths[1] && lengths[1] < 1.5 * lengths[0],
        "{lengths:?}"
    );
    let fleet = key(&json, "fleet");
    assert!(fleet["min_separation_m"]
        .as_f64()
        .is_some_and(|d| d >= 20.0));
    assert!(fleet["arrival_spread_s"].as_f64().is_some_and(|s| s <= 1.0));
    Ok(())
}

#[test]
fn the_checker_catches_tampered_energy_and_tour_plans() -> TestResult {
    // An honest plan is clean; the same plan claiming a wider turn, or a tour whose named point
    // is not on its trajectory, is not.
    let dir = tempfile::tempdir()?;
    let json = plan_and_check("epa-pso", dir.path(), &["--iterations", "10"])?;
    let toml = std::fs::read_to_string(scenario("epa-pso"))?;
    let mut lied = json.clone();
    lied["vehicles"][0]["energy"]["min_turn_radius_m"] = Value::from(1000.0);
    let report = shoal_tests::check(&toml, &lied.to_string())?;
    assert!(
        report
            .mismatches
            .iter()
            .any(|m| m.contains("min_turn_radius_m")),
        "{:?}",
        report.mismatches
    );

    let dir = tempfile::tempdir()?;
    let json = plan_and_check(
        "cages-a",
        dir.path(),
        &["--iterations", "20", "--particles", "20"],
    )?;
    let toml = std::fs::read_to_string(scenario("cages-a"))?;
    let mut moved = json.clone();
    moved["vehicles"][0]["tour"]["points"][3] = serde_json::json!([1.0, 2.0, 3.0]);
    let report = shoal_tests::check(&toml, &moved.to_string())?;
    assert!(!report.is_clean());
    assert!(
        report
            .failures
            .iter()
            .chain(&report.mismatches)
            .any(|f| f.contains("does not pass inspection point")),
        "{report:?}"
    );
    Ok(())
}

/// The number before " %" in the notice that contains `marker`.
fn percent_in(json: &Value, marker: &str) -> f64 {
    let notices = key(json, "notices").as_array().cloned().unwrap_or_default();
    let text = notices
        .iter()
        .filter_map(Value::as_str)
        .find(|n| n.contains(marker))
        .unwrap_or_else(|| panic!("no notice with {marker:?} in {notices:?}"));
    let number = text
        .split(" %")
        .next()
        .and_then(|head| head.rsplit(' ').next())
        .and_then(|n| n.parse::<f64>().ok());
    number.unwrap_or_else(|| panic!("no percentage in {text:?}"))
}

/// The plan's curve ends at its fitness (the refinement adds the last point).
fn curve_ends_at_fitness(json: &Value) {
    let curve = key(json, "convergence")
        .as_array()
        .cloned()
        .unwrap_or_default();
    let last = curve.last().and_then(Value::as_f64).unwrap_or(f64::NAN);
    let fitness = num(json, "fitness");
    assert!(
        (last - fitness).abs() <= 1e-9 * fitness.abs().max(1.0),
        "{last} vs {fitness}"
    );
}

#[test]
fn energy_and_tour_plans_are_refined_and_state_their_gap_to_a_reference() -> TestResult {
    let short = ["--iterations", "40", "--seed", "2"];
    let dir = tempfile::tempdir()?;
    let refined = plan_and_check("epa-pso", dir.path(), &short)?;
    let dir = tempfile::tempdir()?;
    let alone = plan_and_check(
        "epa-pso",
        dir.path(),
        &[&short[..], &["--no-refine"]].concat(),
    )?;
    assert!(
        num(&refined, "fitness") < num(&alone, "fitness"),
        "the refinement lowers the cost"
    );
    curve_ends_at_fitness(&refined);
    let says = |j: &Value, what: &str| {
        let notices = key(j, "notices").as_array().cloned().unwrap_or_default();
        notices
            .iter()
            .filter_map(Value::as_str)
            .any(|n| n.starts_with(what))
    };
    assert!(says(&refined, "refinement:") && !says(&alone, "refinement:"));
    // The reference is the same for both; the refined plan is nearer to it.
    let (gap_refined, gap_alone) = (
        percent_in(&refined, "cheapest path"),
        percent_in(&alone, "cheapest path"),
    );
    assert!(gap_refined < gap_alone, "{gap_refined} vs {gap_alone}");
    for group in ["cages-a", "cages-b"] {
        let args = ["--iterations", "80", "--particles", "30", "--seed", "3"];
        let dir = tempfile::tempdir()?;
        let refined = plan_and_check(group, dir.path(), &args)?;
        let dir = tempfile::tempdir()?;
        let alone = plan_and_check(group, dir.path(), &[&args[..], &["--no-refine"]].concat())?;
        let length = |j: &Value| num(&vehicle(j, 0)["tour"], "tour_length_m");
        assert!(
            length(&refined) < length(&alone),
            "{group}: legs pulled tighter"
        );
        curve_ends_at_fitness(&refined);
        // The order is the swarm's either way, and never shorter than the exact optimum.
        let order_gap = percent_in(&refined, "shortest order");
        assert_eq!(order_gap, percent_in(&alone, "shortest order"), "{group}");
        assert!(order_gap >= 0.0, "{group}: {order_gap}");
    }
    Ok(())
}
