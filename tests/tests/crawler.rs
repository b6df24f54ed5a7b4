//! Crawlers on the seabed end to end (Lu et al. 2023 as a Shoal capability): the DSMV scenario of
//! §5.1 planned in process by every Lu et al. 2023 algorithm, and a mixed fleet of two crawlers and an
//! AUV planned in process and by one agent process per vehicle; every plan passes the
//! independent checker, which re-evaluates the seabed and the hazards itself, a measured
//! seabed (an ESRI ASCII grid file) included.

mod common;

use std::time::{Duration, Instant};

use common::fleet::Fleet;
use common::{
    check_plan_run, check_plan_run_at, key, number, plan, plan_and_check, scenario, TestResult,
};
use serde_json::Value;

/// The `crawler` block of vehicle `id`.
fn crawler<'a>(json: &'a Value, id: &str) -> &'a Value {
    let vehicles = key(json, "vehicles");
    match vehicles
        .as_array()
        .and_then(|l| l.iter().find(|v| v["id"] == id))
    {
        Some(v) => &v["crawler"],
        None => panic!("no vehicle {id} in {vehicles}"),
    }
}

#[test]
fn every_ipso_plans_the_dsmv_on_the_seabed() -> TestResult {
    for algorithm in ["ipso", "spso", "cbpso", "nspso", "aco-pso"] {
        let dir = tempfile::tempdir()?;
        let json = plan_and_check(
            "ipso-dsmv",
            dir.path(),
            &[
                "--algorithm",
                algorithm,
                "--iterations",
                "25",
                "--seed",
                "4",
            ],
        )?;
        assert_eq!(key(&json, "algorithm"), algorithm);
        assert_eq!(key(&json, "feasible").as_bool(), Some(true), "{algorithm}");
        let c = crawler(&json, "dsmv");
        assert_eq!(c["hazard_intrusions"].as_u64(), Some(0), "{algorithm}: {c}");
        assert!(c["off_seabed_m"].as_f64().is_some_and(|d| d < 1e-9), "{c}");
        // Longer than the 281.43 m straight line (which crosses hazard pa), not absurdly so.
        let length = c["length_m"].as_f64().unwrap_or(f64::NAN);
        assert!(length > 281.43 && length < 300.0, "{algorithm}: {length}");
        // The plan says how far that is from the grid-search reference (282.314 m on 1 m cells).
        let gap = 100.0 * (length / 282.3137 - 1.0);
        let told = format!("dsmv: path {length:.1} m, {gap:+.2} % against the shortest");
        let notices = key(&json, "notices").to_string();
        assert!(
            notices.contains(&told),
            "{algorithm}: {told} not in {notices}"
        );
        assert!(c["max_slope_deg"].as_f64() <= c["slope_limit_deg"].as_f64());
        // Energy by hand from the length: 1 m/s, 60 % mining: L/3600 · (1.5·90 + 50 + 2.5·5).
        let energy = length / 3600.0 * (1.5 * 90.0 + 50.0 + 2.5 * 5.0);
        assert!((c["energy_kwh"].as_f64().unwrap_or(0.0) - energy).abs() < 1e-9);
        let svg = std::fs::read_to_string(dir.path().join("plan.svg"))?;
        assert!(
            svg.contains("on the seabed (dark = high)"),
            "no seabed in the top view"
        );
        assert!(
            svg.contains(">\npa\n<") || svg.contains(">pa<"),
            "hazard pa not labelled"
        );
    }
    Ok(())
}

#[test]
fn the_checker_rejects_a_crawler_driven_through_a_hazard() -> TestResult {
    let dir = tempfile::tempdir()?;
    let json = plan_and_check("ipso-dsmv", dir.path(), &["--iterations", "10"])?;
    let mut tampered = json.clone();
    let Some(samples) = tampered["vehicles"][0]["trajectory"].as_array_mut() else {
        panic!("no trajectory");
    };
    // Put the middle sample on hazard pa's centre (keeping its z).
    let mid = samples.len() / 2;
    samples[mid][1] = serde_json::json!(148.62);
    samples[mid][2] = serde_json::json!(149.23);
    let text = std::fs::read_to_string(scenario("ipso-dsmv"))?;
    let report = shoal_tests::check(&text, &tampered.to_string())?;
    let all = format!("{report}");
    assert!(!report.is_clean(), "{all}");
    assert!(all.contains("enters hazard pa"), "{all}");
    assert!(all.contains("leaves the seabed"), "{all}");
    assert!(all.contains("dsmv.crawler.length_m"), "{all}");
    Ok(())
}

#[test]
fn a_mixed_fleet_keeps_crawlers_apart_in_process_and_distributed() -> TestResult {
    let dir = tempfile::tempdir()?;
    let json = plan_and_check("seabed-fleet", dir.path(), &["--seed", "2"])?;
    for id in ["crawler1", "crawler2"] {
        let c = crawler(&json, id);
        assert_eq!(c["hazard_intrusions"].as_u64(), Some(0), "{id}: {c}");
        assert!(c["off_seabed_m"].as_f64().is_some_and(|d| d < 1e-9), "{c}");
    }
    assert!(
        crawler(&json, "auv1").is_null(),
        "a swimmer has no crawler block"
    );
    assert!(number(&json, "fleet.min_separation_m") >= 10.0);

    // One agent process per vehicle plans the same scenario over Zenoh.
    let mut fleet = Fleet::new();
    let out = fleet.dir().join("distributed");
    let c = fleet.coordinator("coordinator", "seabed-fleet", &out, &[]);
    let run = fleet.wait(c, Instant::now() + Duration::from_secs(120));
    let json = check_plan_run("seabed-fleet", &out, &run)?;
    assert_eq!(key(&json, "mode"), "distributed");
    for id in ["crawler1", "crawler2"] {
        let c = crawler(&json, id);
        assert_eq!(c["hazard_intrusions"].as_u64(), Some(0), "{id}: {c}");
    }
    fleet.passed();
    Ok(())
}

/// The seabed of scenario `name` sampled every metre over its bounds into an ESRI ASCII grid
/// (north row first), written as `seabed.asc` beside a copy of the scenario that names it
/// instead of its relief and mountains; `flip` writes the rows south first, a grid the checker
/// must read as a different seabed. Returns the copy's path.
fn on_a_grid(
    name: &str,
    dir: &std::path::Path,
    flip: bool,
) -> Result<std::path::PathBuf, Box<dyn std::error::Error>> {
    let text = std::fs::read_to_string(scenario(name))?;
    let analytic = shoal_tests::parse_scenario(&text)?;
    let Some(floor) = shoal_tests::crawler::Floor::of(&analytic) else {
        panic!("{name} has no analytic seabed");
    };
    let (lo, hi) = (analytic.bounds.min, analytic.bounds.max);
    // Whole metres from the lower corner, covering the bounds.
    let (nx, ny) = (
        (hi[0] - lo[0]).ceil() as usize,
        (hi[1] - lo[1]).ceil() as usize,
    );
    let mut rows: Vec<String> = (0..=ny)
        .rev()
        .map(|j| {
            let row: Vec<String> = (0..=nx)
                .map(|i| format!("{:.4}", floor.z(lo[0] + i as f64, lo[1] + j as f64)))
                .collect();
            row.join(" ")
        })
        .collect();
    if flip {
        rows.reverse();
    }
    let asc = format!(
        "ncols {}\nnrows {}\nxllcenter {}\nyllcenter {}\ncellsize 1\nNODATA_value -9999\n{}\n",
        nx + 1,
        ny + 1,
        lo[0],
        lo[1],
        rows.join("\n")
    );
    std::fs::write(dir.join("seabed.asc"), asc)?;
    let mut doc: toml::Table = toml::from_str(&text)?;
    let Some(seabed) = doc.get_mut("seabed").and_then(toml::Value::as_table_mut) else {
        panic!("{name} has no [seabed]");
    };
    seabed.remove("relief");
    seabed.remove("mountains");
    let mut grid = toml::Table::new();
    grid.insert("file".into(), toml::Value::String("seabed.asc".into()));
    seabed.insert("grid".into(), toml::Value::Table(grid));
    let path = dir.join(format!("{name}-grid.toml"));
    std::fs::write(&path, toml::to_string(&doc)?)?;
    Ok(path)
}

#[test]
fn a_crawler_planned_on_a_measured_seabed_is_checked_on_that_grid() -> TestResult {
    let dir = tempfile::tempdir()?;
    let path = on_a_grid("ipso-dsmv", dir.path(), false)?;
    let out = dir.path().join("out");
    let r = plan(&path, &out, &["--iterations", "10", "--seed", "4"]);
    let json = check_plan_run_at(&path, &out, &r)?;
    assert_eq!(key(&json, "feasible").as_bool(), Some(true), "{r}");
    let c = crawler(&json, "dsmv");
    assert_eq!(c["hazard_intrusions"].as_u64(), Some(0), "{c}");
    assert!(c["off_seabed_m"].as_f64().is_some_and(|d| d < 1e-9), "{c}");

    // The checker judges the path on the grid it reads itself: the same plan over the grid
    // written south row first, or with one sample lifted 30 cm, leaves the seabed.
    let plan_text = std::fs::read_to_string(out.join("plan.json"))?;
    let flipped_dir = dir.path().join("flipped");
    std::fs::create_dir(&flipped_dir)?;
    let flipped = on_a_grid("ipso-dsmv", &flipped_dir, true)?;
    let report = shoal_tests::check_file(&flipped, &plan_text)?;
    assert!(
        format!("{report}").contains("leaves the seabed"),
        "{report}"
    );
    let mut lifted = json.clone();
    let Some(samples) = lifted["vehicles"][0]["trajectory"].as_array_mut() else {
        panic!("no trajectory");
    };
    let mid = samples.len() / 2;
    let z = samples[mid][3].as_f64().unwrap_or(f64::NAN);
    samples[mid][3] = serde_json::json!(z + 0.3);
    let report = shoal_tests::check_file(&path, &lifted.to_string())?;
    let all = format!("{report}");
    assert!(all.contains("leaves the seabed by 0.3000 m"), "{all}");
    Ok(())
}

#[test]
fn a_mixed_fleet_planned_over_a_measured_seabed_is_checked_on_that_grid() -> TestResult {
    let dir = tempfile::tempdir()?;
    let path = on_a_grid("seabed-fleet", dir.path(), false)?;
    let out = dir.path().join("out");
    let r = plan(&path, &out, &["--seed", "2"]);
    let json = check_plan_run_at(&path, &out, &r)?;
    for id in ["crawler1", "crawler2"] {
        let c = crawler(&json, id);
        assert_eq!(c["hazard_intrusions"].as_u64(), Some(0), "{id}: {c}");
        assert!(c["off_seabed_m"].as_f64().is_some_and(|d| d < 1e-9), "{c}");
    }
    // The AUV's lowest height over the grid is reported, and the checker agreed with it.
    let vehicles = key(&json, "vehicles");
    let auv = vehicles
        .as_array()
        .and_then(|l| l.iter().find(|v| v["id"] == "auv1"));
    assert!(
        auv.is_some_and(|v| v["min_seabed_clearance_m"].as_f64().is_some()),
        "{vehicles}"
    );
    // Over the grid flipped north to south, the crawlers leave the seabed and the AUV's
    // seabed clearance is not what was reported.
    let flipped_dir = dir.path().join("flipped");
    std::fs::create_dir(&flipped_dir)?;
    let flipped = on_a_grid("seabed-fleet", &flipped_dir, true)?;
    let report =
        shoal_tests::check_file(&flipped, &std::fs::read_to_string(out.join("plan.json"))?)?;
    let all = format!("{report}");
    assert!(
        all.contains("crawler1 is a crawler but leaves the seabed"),
        "{all}"
    );
    assert!(all.contains("auv1.min_seabed_clearance_m"), "{all}");
    Ok(())
}
