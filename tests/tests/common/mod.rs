//! Helpers shared by the end-to-end tests of `shoal-coordinator plan`: run the real binary on a
//! real scenario (in process here, distributed with real agents through [`fleet`]), then check
//! `plan.json` with the independent checker of this crate.
//!
//! CLI contract under test:
//! `shoal-coordinator plan <SCENARIO.toml> --in-process --out <DIR> [--seed N]
//!  [--algorithm amp-pso|pso|mp-pso|a-pso] [--iterations N] [--populations N] [--particles N]`
//! writes `<DIR>/plan.json` and `<DIR>/plan.svg`; exit 0 = feasible plan, 3 = plan with
//! violations, 1 = error (message on stderr naming the file, field and value).
//!
//! Every test file compiles its own copy of this module and uses only part of it.
#![allow(dead_code)]

pub mod coverage;
pub mod fleet;
pub mod process;

use std::error::Error;
use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;
use shoal_tests::{check_file, geometry, parse_plan};

pub use process::{agent, coordinator, root, Run};
use process::{run, RUN_TIMEOUT};

pub type TestResult = Result<(), Box<dyn Error>>;

/// A small budget that plans `cages-fleet`'s two tours quickly and safely (LDIW-PSO legs).
pub const CAGES_FLEET_QUICK: [&str; 6] = [
    "--iterations",
    "60",
    "--particles",
    "30",
    "--algorithm",
    "ldiw-pso",
];

/// The Python interpreter of the interop tests ([`shoal_interop::python`]: `$SHOAL_INTEROP_PYTHON`,
/// else a venv with the pinned packages made on first use); an error fails the test.
pub fn interop_python() -> Result<String, String> {
    shoal_interop::python()
}

/// The JSON file at `path` (a `plan.json`, `execution.json`, …); an error names the file.
pub fn read_json(path: &Path) -> Result<Value, Box<dyn Error>> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?)
}

/// `scenarios/<name>.toml`.
pub fn scenario(name: &str) -> PathBuf {
    let p = root().join("scenarios").join(format!("{name}.toml"));
    assert!(p.is_file(), "scenario file {} is missing", p.display());
    p
}

/// `shoal-coordinator plan <scenario> --in-process --out <out> <extra...>`.
pub fn plan(scenario: &Path, out: &Path, extra: &[&str]) -> Run {
    let mut cmd = Command::new(coordinator());
    without_shoal_env(&mut cmd);
    cmd.current_dir(root())
        .arg("plan")
        .arg(scenario)
        .arg("--in-process")
        .arg("--out")
        .arg(out)
        .args(extra);
    run(cmd, RUN_TIMEOUT)
}

/// Every flag has a SHOAL_* environment fallback: keeps the caller's environment out of `cmd`.
pub fn without_shoal_env(cmd: &mut Command) {
    for (k, _) in std::env::vars_os() {
        if k.to_string_lossy().starts_with("SHOAL_") {
            cmd.env_remove(k);
        }
    }
}

/// Runs an in-process plan that must succeed (exit 0 or 3) and checks it end to end (see
/// [`check_plan_run`]); returns the plan JSON.
pub fn plan_and_check(name: &str, out: &Path, extra: &[&str]) -> Result<Value, Box<dyn Error>> {
    let r = plan(&scenario(name), out, extra);
    check_plan_run(name, out, &r)
}

/// Checks a finished plan run `r` of scenario `name` that wrote into `out`, however it was
/// planned: exit 0 or 3, and exactly 0 when the plan is feasible; every violation printed; a
/// summary on stdout; the independent checker agrees with `plan.json`; exact and sampled
/// separations agree; `plan.svg` is an SVG. Returns the plan JSON.
pub fn check_plan_run(name: &str, out: &Path, r: &Run) -> Result<Value, Box<dyn Error>> {
    check_plan_run_at(&scenario(name), out, r)
}

/// [`check_plan_run`] of the scenario file at `scenario_path`.
pub fn check_plan_run_at(
    scenario_path: &Path,
    out: &Path,
    r: &Run,
) -> Result<Value, Box<dyn Error>> {
    let code = r.code();
    assert!(
        code == Some(0) || code == Some(3),
        "expected exit 0 (feasible) or 3 (violations):\n{r}"
    );
    let plan_path = out.join("plan.json");
    let Ok(text) = std::fs::read_to_string(&plan_path) else {
        panic!("cannot read {}:\n{r}", plan_path.display());
    };
    let json: Value = match serde_json::from_str(&text) {
        Ok(v) => v,
        Err(e) => panic!("plan.json is not JSON: {e}\n{r}"),
    };
    let parsed = match parse_plan(&text) {
        Ok(p) => p,
        Err(e) => panic!("{e}\n{r}"),
    };
    assert_eq!(
        code == Some(0),
        parsed.feasible,
        "exit status must be 0 exactly when the plan is feasible (violations: {:?})\n{r}",
        parsed.violations
    );
    if !parsed.feasible {
        let printed = format!("{}\n{}", r.stdout, r.stderr);
        for v in &parsed.violations {
            assert!(
                printed.contains(v.as_str()),
                "violation {v:?} is not printed:\n{r}"
            );
        }
    }
    assert!(!r.stdout.trim().is_empty(), "no summary on stdout:\n{r}");

    let report = match check_file(scenario_path, &text) {
        Ok(rep) => rep,
        Err(e) => panic!("checker cannot read the files: {e}\n{r}"),
    };
    assert!(
        report.is_clean(),
        "independent checker disagrees with {}:\n{report}\n{r}",
        plan_path.display()
    );

    // Cross-check the exact separation with sampling every second: sampling can only find a larger
    // distance, and not much larger (relative speed ≤ the sum of the two top speeds, ~2·3 m/s).
    for (i, a) in parsed.vehicles.iter().enumerate() {
        for b in &parsed.vehicles[i + 1..] {
            let exact = geometry::min_separation(&a.trajectory, &b.trajectory);
            let dense = geometry::sampled_min_separation(&a.trajectory, &b.trajectory, 1.0);
            assert!(
                exact.distance <= dense.distance + 1e-9,
                "{} {}: {exact:?} vs {dense:?}",
                a.id,
                b.id
            );
            let relative_speed = a.max_speed_mps + b.max_speed_mps;
            assert!(
                dense.distance - exact.distance <= relative_speed * 0.5 + 1e-6,
                "{} {}: exact {exact:?} far below sampled {dense:?}",
                a.id,
                b.id
            );
        }
    }

    let svg_path = out.join("plan.svg");
    let Ok(svg) = std::fs::read_to_string(&svg_path) else {
        panic!("cannot read {}:\n{r}", svg_path.display());
    };
    assert!(svg.contains("<svg"), "{} is not an SVG", svg_path.display());
    Ok(json)
}

/// Runs a plan and returns what the independent checker finds wrong with it (empty = clean).
pub fn problems_of(
    scenario_path: &Path,
    out: &Path,
    extra: &[&str],
) -> Result<Vec<String>, Box<dyn Error>> {
    let r = plan(scenario_path, out, extra);
    if !matches!(r.code(), Some(0) | Some(3)) {
        return Ok(vec![format!("unexpected exit status:\n{r}")]);
    }
    let text = std::fs::read_to_string(out.join("plan.json"))?;
    let report = check_file(scenario_path, &text)?;
    let mut problems = report.problems();
    let parsed = parse_plan(&text)?;
    if (r.code() == Some(0)) != parsed.feasible {
        problems.push(format!(
            "exit status {:?} but feasible = {}",
            r.code(),
            parsed.feasible
        ));
    }
    Ok(problems)
}

/// The value at the dotted `path` of a plan's JSON; panics when it is missing.
pub fn key<'a>(json: &'a Value, path: &str) -> &'a Value {
    let mut v = json;
    for k in path.split('.') {
        match v.get(k) {
            Some(x) => v = x,
            None => panic!("plan.json has no `{path}`"),
        }
    }
    v
}

/// The number at the dotted `path`; panics when it is missing or not a number.
pub fn number(json: &Value, path: &str) -> f64 {
    match key(json, path).as_f64() {
        Some(x) => x,
        None => panic!("plan.json `{path}` is not a number: {}", key(json, path)),
    }
}

/// Asserts that the dotted `path` holds null or a number.
pub fn nullable_number(json: &Value, path: &str) {
    let v = key(json, path);
    assert!(
        v.is_null() || v.is_f64() || v.is_i64() || v.is_u64(),
        "`{path}` must be null or a number: {v}"
    );
}
