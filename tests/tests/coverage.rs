//! Area coverage by a mining crawler (CPP-DSMV) end to end: the real binary plans a shrunken copy
//! of `scenarios/cpp-seabed.toml` and `plan.json` is checked against the paper's figures; the
//! Hybrid A* baseline runs under the same macro-routing; bad input is refused with the file, the
//! field and the value.

mod common;

use std::path::Path;

use common::{key, plan, read_json, scenario, TestResult};
use serde_json::Value;

fn num(v: &Value, field: &str) -> f64 {
    match v[field].as_f64() {
        Some(x) => x,
        None => panic!("{field} is not a number in {v}"),
    }
}

/// `cpp-seabed.toml` on a 300 m × 300 m area with a seamount in the middle, edited by `edit`.
fn small_scenario(
    dir: &Path,
    edit: &dyn Fn(String) -> String,
) -> Result<std::path::PathBuf, Box<dyn std::error::Error>> {
    let text = std::fs::read_to_string(scenario("cpp-seabed"))?;
    let text = text
        .replace("max = [1000.0, 1000.0, 0.0]", "max = [300.0, 300.0, 0.0]")
        .replace("goal = [995.0, 995.0, -6000.0]", "goal = [295.0, 295.0, -6000.0]")
        .replace("size_m = [1000.0, 1000.0]", "size_m = [300.0, 300.0]")
        .replace("count = 8 ", "count = 0 ")
        .replace("count = 4 ", "count = 0 ")
        .replace(
            "[coverage.terrain.undulation]",
            "peaks = [{ centre = [150.0, 140.0], height_m = 40.0, sigma_m = 20.0 }]\n[coverage.terrain.undulation]",
        );
    let path = dir.join("cpp-small.toml");
    std::fs::write(&path, edit(text))?;
    Ok(path)
}

#[test]
fn a_crawler_covers_a_small_seabed_safely_and_tracks_its_path() -> TestResult {
    let dir = tempfile::tempdir()?;
    let file = small_scenario(dir.path(), &|t| t)?;
    let out = dir.path().join("out");
    let r = plan(&file, &out, &[]);
    assert_eq!(r.code(), Some(0), "{}\n{}", r.stdout, r.stderr);
    let json = read_json(&out.join("plan.json"))?;
    assert_eq!(key(&json, "kind").as_str(), Some("coverage"));
    assert_eq!(key(&json, "feasible").as_bool(), Some(true));
    let c = key(&json, "coverage");
    assert_eq!(c["method"].as_str(), Some("arcs"));
    // The seamount's flanks are impassable: the plan has to go round them.
    assert!(num(c, "impassable_fraction") > 0.005, "{c}");
    assert!(
        c["event_counts"][0].as_u64().unwrap_or(0) >= 1,
        "no detour: {}",
        c["event_counts"]
    );
    // Zero samples under the 8 m clearance, and the exact minimum is at least that.
    assert_eq!(c["samples_below_clearance"].as_u64(), Some(0));
    assert!(num(&c["clearance"], "min") >= 8.0 - 1e-6);
    assert!(num(c, "max_curvature") <= 1.0 / 5.0 + 1e-9);
    assert!(num(&c["coverage"], "ratio") > 0.6, "{}", c["coverage"]);
    assert!(num(c, "planning_time_s") < 5.0);
    let t = &c["tracking"];
    assert_eq!(t["reached_end"].as_bool(), Some(true));
    assert!(num(t, "max_abs_cte_m") < 4.0, "{t}");
    assert!(num(t, "median_abs_cte_m") < 0.5, "{t}");
    let svg = std::fs::read_to_string(out.join("plan.svg"))?;
    for needle in [
        "no-go boxes",
        "tracked",
        "cross-track",
        "slope under the path",
    ] {
        assert!(svg.contains(needle), "plan.svg lacks {needle:?}");
    }
    assert!(r.stdout.contains("coverage"), "{}", r.stdout);
    Ok(())
}

#[test]
fn the_hybrid_a_star_baseline_runs_under_the_same_macro_routing() -> TestResult {
    let dir = tempfile::tempdir()?;
    let file = small_scenario(dir.path(), &|t| {
        t.replace("detour = \"arcs\"", "detour = \"hybrid-a-star\"")
            .replace("track = true", "track = false")
    })?;
    let out = dir.path().join("out");
    // An --algorithm a coverage mission does not use is named as such, not silently dropped.
    let r = plan(&file, &out, &["--algorithm", "mp-pso"]);
    assert!(
        matches!(r.code(), Some(0) | Some(3)),
        "{}\n{}",
        r.stdout,
        r.stderr
    );
    assert!(
        r.stderr
            .contains("note: --algorithm mp-pso is not used: a [coverage] mission plans"),
        "{}",
        r.stderr
    );
    let json = read_json(&out.join("plan.json"))?;
    let c = key(&json, "coverage");
    assert_eq!(c["method"].as_str(), Some("hybrid-a-star"));
    assert!(c["tracking"].is_null());
    // The baseline honours only the dilated map: half the 8 m width.
    assert!(
        num(&c["clearance"], "min") >= 4.0 - 1e-6,
        "{}",
        c["clearance"]
    );
    assert!(num(c, "max_curvature") <= 1.0 / 5.0 + 1e-9);
    assert!(num(&c["coverage"], "ratio") > 0.6, "{}", c["coverage"]);
    Ok(())
}

#[test]
fn bad_coverage_settings_name_the_file_the_field_and_the_value() -> TestResult {
    let dir = tempfile::tempdir()?;
    let file = small_scenario(dir.path(), &|t| {
        t.replace("min_turn_radius_m = 5.0", "min_turn_radius_m = -5.0")
    })?;
    let r = plan(&file, &dir.path().join("out"), &[]);
    assert_eq!(r.code(), Some(1), "{}", r.stderr);
    for needle in ["cpp-small.toml", "coverage.planner.min_turn_radius_m", "-5"] {
        assert!(
            r.stderr.contains(needle),
            "stderr lacks {needle:?}: {}",
            r.stderr
        );
    }
    // A coverage mission is planned in process only, and says so.
    let ok = small_scenario(dir.path(), &|t| t)?;
    let mut cmd = std::process::Command::new(common::coordinator());
    common::without_shoal_env(&mut cmd);
    let out = cmd
        .arg("plan")
        .arg(&ok)
        .arg("--out")
        .arg(dir.path().join("out2"))
        .output()?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("--in-process"), "{stderr}");
    Ok(())
}
