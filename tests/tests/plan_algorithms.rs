//! End-to-end runs of every optimizer (`amp-pso`, `pso`, `mp-pso`, `a-pso`): a quick consistent
//! plan from each, and an ignored slow sweep over every scenario, algorithm and a few seeds.

mod common;

use std::path::PathBuf;

use common::{key, plan_and_check, problems_of, root, TestResult};

/// Every scenario × algorithm × a few seeds at a moderate budget, checked independently.
/// Slow: `cargo test -p shoal-tests --test plan_algorithms -- --ignored`.
#[test]
#[ignore = "slow sweep; run with --ignored"]
fn sweep_every_scenario_algorithm_and_seed() -> TestResult {
    let mut scenarios: Vec<PathBuf> = std::fs::read_dir(root().join("scenarios"))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    scenarios.sort();
    let mut all = Vec::new();
    let mut runs = 0;
    for s in &scenarios {
        for algorithm in ["amp-pso", "pso", "mp-pso", "a-pso"] {
            for seed in ["1", "2", "3"] {
                let dir = tempfile::tempdir()?;
                let extra = [
                    "--algorithm",
                    algorithm,
                    "--seed",
                    seed,
                    "--iterations",
                    "40",
                    "--populations",
                    "4",
                    "--particles",
                    "20",
                ];
                runs += 1;
                for p in problems_of(s, dir.path(), &extra)? {
                    all.push(format!("{} {algorithm} seed {seed}: {p}", s.display()));
                }
            }
        }
    }
    assert!(runs > 0, "no scenarios found");
    assert!(
        all.is_empty(),
        "{} problems in {runs} runs:\n{}",
        all.len(),
        all.join("\n")
    );
    Ok(())
}

fn tiny_run(algorithm: &str) -> TestResult {
    let dir = tempfile::tempdir()?;
    let json = plan_and_check(
        "amp-pso-1",
        dir.path(),
        &[
            "--algorithm",
            algorithm,
            "--iterations",
            "5",
            "--populations",
            "2",
            "--particles",
            "10",
            "--seed",
            "5",
        ],
    )?;
    assert_eq!(key(&json, "algorithm"), algorithm);
    assert_eq!(key(&json, "seed").as_u64(), Some(5));
    // Five iterations, and the local steps' point when they changed the plan.
    let curve = key(&json, "convergence")
        .as_array()
        .cloned()
        .unwrap_or_default();
    assert!(curve.len() == 5 || curve.len() == 6, "{curve:?}");
    assert_eq!(
        curve.last().and_then(|c| c.as_f64()),
        key(&json, "fitness").as_f64()
    );
    Ok(())
}

#[test]
fn pso_plan_is_consistent() -> TestResult {
    tiny_run("pso")
}

#[test]
fn mp_pso_plan_is_consistent() -> TestResult {
    tiny_run("mp-pso")
}

#[test]
fn a_pso_plan_is_consistent() -> TestResult {
    tiny_run("a-pso")
}

/// A fleet plan that breaks limits (one iteration of a tiny swarm, no touch-up): exit 3, every
/// violation printed, and the independent checker agrees with what `plan.json` says of it.
#[test]
fn an_infeasible_fleet_plan_exits_3_and_lists_its_violations() -> TestResult {
    let dir = tempfile::tempdir()?;
    let json = plan_and_check(
        "amp-pso-2",
        dir.path(),
        &[
            "--iterations",
            "1",
            "--populations",
            "2",
            "--particles",
            "4",
            "--no-touch-up",
            "--no-refine",
            "--seed",
            "1",
        ],
    )?;
    assert_eq!(key(&json, "feasible").as_bool(), Some(false));
    let listed = key(&json, "violations").as_array().map_or(0, Vec::len);
    assert!(listed >= 1, "{json}");
    assert!(key(&json, "penalty").as_f64().is_some_and(|p| p > 0.0));
    Ok(())
}
