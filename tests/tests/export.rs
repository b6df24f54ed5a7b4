//! End-to-end `shoal-coordinator export`: scenario 3 planned by the real binary, exported to
//! GeoJSON and QGroundControl `.plan` files, and read back by independent Python readers
//! (`tests/python/check_export.py`: geojson 3.3.0 and shapely 2.2.0 for the GeoJSON, plain JSON for
//! the `.plan` files, PROJ through pyproj 3.7.2 for every position, converted from the scenario's
//! own metres and `[origin]`).
//!
//! The interpreter comes from [`shoal_interop::python`] (a venv with the pinned packages). The
//! command-line contract (origin from the plan, the scenario or `--origin`, errors when there is
//! none or two disagree) needs no Python.

mod common;

use std::path::Path;
use std::process::Command;
use std::time::Duration;

use common::process::{coordinator, root, run, Run};
use common::{plan, read_json, scenario, without_shoal_env, TestResult};

/// `shoal-coordinator export <plan> <args...>`.
fn export(plan: &Path, args: &[&str]) -> Run {
    let mut cmd = Command::new(coordinator());
    without_shoal_env(&mut cmd);
    cmd.current_dir(root()).arg("export").arg(plan).args(args);
    run(cmd, Duration::from_secs(60))
}

/// Scenario 3 at seed 1 planned into `dir/plan`.
fn planned(dir: &Path) -> Result<std::path::PathBuf, Box<dyn std::error::Error>> {
    let out = dir.join("plan");
    let r = plan(&scenario("amp-pso-3"), &out, &["--seed", "1"]);
    assert!(matches!(r.code(), Some(0 | 3)), "{r}");
    let json = read_json(&out.join("plan.json"))?;
    assert_eq!(
        json["origin"],
        serde_json::json!({"lat_deg": 31.5, "lon_deg": -22.0, "alt_m": -2000.0}),
        "plan.json carries the scenario's origin"
    );
    Ok(out)
}

#[test]
fn scenario_3_exports_to_geojson_and_qgc_files_that_independent_readers_accept() -> TestResult {
    let dir = tempfile::tempdir()?;
    let out = planned(dir.path())?;
    let maps = dir.path().join("maps");
    let s3 = scenario("amp-pso-3");
    let s3 = s3.to_string_lossy();
    let maps_s = maps.to_string_lossy();
    for format in ["geojson", "qgc"] {
        let r = export(
            &out,
            &["--format", format, "--scenario", &s3, "--out", &maps_s],
        );
        assert_eq!(r.code(), Some(0), "{r}");
        assert!(r.stdout.contains("Wrote "), "{r}");
    }
    let names = ["plan.geojson", "auv1.plan", "auv5.plan"];
    for name in names {
        assert!(maps.join(name).is_file(), "{name} is missing");
    }
    let py = common::interop_python()?;
    let mut check = Command::new(py);
    check
        .arg(root().join("tests/python/check_export.py"))
        .arg(scenario("amp-pso-3"))
        .arg(out.join("plan.json"))
        .arg(maps.join("plan.geojson"))
        .arg(&maps);
    let r = run(check, Duration::from_secs(120));
    assert_eq!(r.code(), Some(0), "{r}");
    let Ok(summary) = serde_json::from_str::<serde_json::Value>(r.stdout.trim()) else {
        panic!("no JSON summary:\n{r}");
    };
    // Origin, bounds, 12 obstacles, then per AUV a path and its waypoints.
    assert!(
        summary["features"].as_u64().is_some_and(|n| n > 14 + 5),
        "{r}"
    );
    Ok(())
}

#[test]
fn the_origin_comes_from_the_plan_the_scenario_or_the_command_line_and_must_agree() -> TestResult {
    let dir = tempfile::tempdir()?;
    let out = planned(dir.path())?;
    let maps = dir.path().join("maps");
    let maps_s = maps.to_string_lossy();

    // The plan's own origin, no scenario: paths only, and a line on stderr saying so.
    let r = export(&out, &["--format", "geojson", "--out", &maps_s]);
    assert_eq!(r.code(), Some(0), "{r}");
    assert!(
        r.stderr
            .contains("no --scenario: exporting the vehicles' paths only"),
        "{r}"
    );
    let fc = read_json(&maps.join("plan.geojson"))?;
    let features = fc["features"].as_array().cloned().unwrap_or_default();
    assert!(
        features.iter().all(|f| {
            let what = f["properties"]["feature"].as_str().unwrap_or("");
            matches!(what, "origin" | "path" | "waypoint")
        }),
        "only paths without a scenario"
    );

    // A different --origin than the plan's is refused, naming both.
    let r = export(
        &out,
        &[
            "--format",
            "qgc",
            "--origin",
            "31.5,-22,0",
            "--out",
            &maps_s,
        ],
    );
    assert_eq!(r.code(), Some(1), "{r}");
    assert!(
        r.stderr
            .contains("plan.json's origin 31.5,-22,-2000 and --origin 31.5,-22,0 differ"),
        "{r}"
    );

    // A plan without an origin needs one: none is an error, --origin supplies it.
    let bare = dir.path().join("bare.json");
    let mut json = read_json(&out.join("plan.json"))?;
    if let Some(o) = json.as_object_mut() {
        o.remove("origin");
    }
    std::fs::write(&bare, serde_json::to_string(&json)?)?;
    let r = export(&bare, &["--format", "qgc", "--out", &maps_s]);
    assert_eq!(r.code(), Some(1), "{r}");
    assert!(r.stderr.contains("error: no origin"), "{r}");
    let r = export(
        &bare,
        &[
            "--format",
            "qgc",
            "--origin",
            "-45,179.99,0",
            "--out",
            &maps_s,
        ],
    );
    assert_eq!(r.code(), Some(0), "{r}");
    let auv1 = read_json(&maps.join("auv1.plan"))?;
    let home = &auv1["mission"]["plannedHomePosition"];
    // auv1 starts 100 m east and 300 m north of the origin, just east of the date line.
    assert!(
        home[0]
            .as_f64()
            .is_some_and(|lat| (lat + 44.9973).abs() < 1e-3),
        "{home}"
    );
    assert!(
        home[1]
            .as_f64()
            .is_some_and(|lon| (lon - 179.9913).abs() < 1e-3),
        "{home}"
    );
    Ok(())
}
