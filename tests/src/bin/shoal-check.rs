//! `shoal-check SCENARIO PLAN [--degraded IDS]`: the independent checker as a command, for the
//! container fleet test. Recomputes every figure of `plan.json` from its trajectories (see the
//! crate docs) and requires a collision-free plan with separation ≥ d_min and a synchronised
//! arrival. `--degraded auv2` also requires exactly those vehicles (comma-separated; empty for
//! none) to be named as planned in degraded mode. Exit 0 when every check passes, 1 otherwise.

use std::path::Path;
use std::process::ExitCode;

use shoal_tests::{check_file, parse_plan, parse_scenario_file, MAX_ARRIVAL_SPREAD_S};

fn main() -> ExitCode {
    match run() {
        Ok(summary) => {
            println!("ok: {summary}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("shoal-check: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<String, String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (scenario_path, plan_path) = match (args.first(), args.get(1)) {
        (Some(s), Some(p)) => (s, p),
        _ => return Err("usage: shoal-check SCENARIO PLAN [--degraded IDS]".into()),
    };
    let expected: Option<Vec<String>> = match (args.get(2).map(String::as_str), args.get(3)) {
        (Some("--degraded"), Some(ids)) => Some(
            ids.split(',')
                .filter(|s| !s.is_empty())
                .map(str::to_string)
                .collect(),
        ),
        (Some("--degraded"), None) => Some(Vec::new()),
        (None, _) => None,
        (Some(other), _) => return Err(format!("unknown argument {other:?}")),
    };
    let plan_text =
        std::fs::read_to_string(plan_path).map_err(|e| format!("cannot read {plan_path}: {e}"))?;
    let report = check_file(Path::new(scenario_path), &plan_text)
        .map_err(|e| format!("{plan_path}: {e}"))?;
    if !report.is_clean() {
        return Err(format!(
            "{plan_path} disagrees with its trajectories:\n{report}"
        ));
    }
    let scenario = parse_scenario_file(Path::new(scenario_path))?;
    let plan = parse_plan(&plan_text).map_err(|e| e.to_string())?;
    // The checker found the reported fleet figures equal to its own recomputation.
    let fleet = &plan.fleet;
    let mut problems = Vec::new();
    if fleet.hard_collisions > 0 {
        problems.push(format!(
            "{} hard-obstacle collisions",
            fleet.hard_collisions
        ));
    }
    let sep = fleet.min_separation_m.unwrap_or(f64::INFINITY);
    if sep < scenario.fleet.d_min_m - 1e-6 {
        problems.push(format!(
            "minimum separation {sep:.2} m below d_min {} m",
            scenario.fleet.d_min_m
        ));
    }
    if fleet.arrival_spread_s > MAX_ARRIVAL_SPREAD_S {
        problems.push(format!(
            "arrival spread {:.2} s: not synchronised",
            fleet.arrival_spread_s
        ));
    }
    let json: serde_json::Value = serde_json::from_str(&plan_text).map_err(|e| e.to_string())?;
    let mut degraded: Vec<String> = json["distributed"]["degraded"]
        .as_array()
        .map(|a| {
            a.iter()
                .filter_map(|d| d["vehicle"].as_str().map(str::to_string))
                .collect()
        })
        .unwrap_or_default();
    degraded.sort();
    if let Some(mut want) = expected {
        want.sort();
        if want != degraded {
            problems.push(format!("degraded vehicles {degraded:?}, expected {want:?}"));
        }
    }
    if !problems.is_empty() {
        return Err(format!("{plan_path}: {}", problems.join("; ")));
    }
    Ok(format!(
        "{plan_path}: {} vehicles, no hard collision, min separation {sep:.1} m, arrival spread {:.3} s, fitness {}, runtime_s {}, degraded {degraded:?}",
        plan.vehicles.len(),
        fleet.arrival_spread_s,
        json["fitness"],
        json["runtime_s"]
    ))
}
