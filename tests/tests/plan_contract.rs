//! End-to-end contract of a successful `shoal-coordinator plan --in-process` run: the fields and
//! shape of `plan.json` (checked independently by this crate's checker), and determinism across
//! runs with the same seed and across thread counts.

mod common;

use common::{key, nullable_number, number, plan_and_check, TestResult};
use serde_json::Value;

#[test]
fn amp_pso_plan_meets_the_contract() -> TestResult {
    let dir = tempfile::tempdir()?;
    let json = plan_and_check(
        "amp-pso-1",
        dir.path(),
        &[
            "--iterations",
            "30",
            "--populations",
            "4",
            "--particles",
            "20",
            "--seed",
            "3",
        ],
    )?;
    assert_eq!(key(&json, "scenario"), "amp-pso-1");
    assert_eq!(key(&json, "algorithm"), "amp-pso");
    assert_eq!(key(&json, "mode"), "in-process");
    assert_eq!(key(&json, "seed").as_u64(), Some(3));
    assert!(number(&json, "runtime_s") >= 0.0);
    assert!(number(&json, "fitness").is_finite());
    let Some(feasible) = key(&json, "feasible").as_bool() else {
        panic!("`feasible` is not a boolean");
    };
    let Some(violations) = key(&json, "violations").as_array() else {
        panic!("`violations` is not an array");
    };
    assert!(
        violations.iter().all(Value::is_string),
        "violations must be strings: {violations:?}"
    );
    assert_eq!(feasible, violations.is_empty());

    let Some(vehicles) = key(&json, "vehicles").as_array() else {
        panic!("`vehicles` is not an array");
    };
    let ids: Vec<&str> = vehicles
        .iter()
        .filter_map(|v| v.get("id")?.as_str())
        .collect();
    assert!(
        ids.contains(&"auv1") && ids.contains(&"auv2"),
        "vehicle ids {ids:?}"
    );
    for v in vehicles {
        let Some(t) = v.get("trajectory").and_then(Value::as_array) else {
            panic!("vehicle without a trajectory array: {v}");
        };
        assert!(t.len() >= 2, "trajectory too short: {v}");
        assert!(
            t.iter().all(|s| s.as_array().is_some_and(|s| s.len() == 4)),
            "samples must be [t, x, y, z]"
        );
    }

    nullable_number(&json, "fleet.min_separation_m");
    assert!(key(&json, "fleet.hard_collisions").is_u64());
    assert!(number(&json, "fleet.arrival_spread_s") >= 0.0);

    let Some(convergence) = key(&json, "convergence").as_array() else {
        panic!("`convergence` is not an array");
    };
    let c: Vec<f64> = convergence.iter().filter_map(Value::as_f64).collect();
    // One entry per iteration, and one more for the local steps after the swarm when they
    // changed the plan: the curve ends at the plan's fitness.
    assert!(
        c.len() == 30 || c.len() == 31,
        "one convergence entry per iteration (and the local steps'): {convergence:?}"
    );
    assert_eq!(c.last().copied(), key(&json, "fitness").as_f64());
    for (k, w) in c[..30].windows(2).enumerate() {
        assert!(
            w[1] <= w[0],
            "convergence rises from iteration {k} to {}: {} → {}",
            k + 1,
            w[0],
            w[1]
        );
    }
    Ok(())
}

#[test]
fn same_seed_gives_the_same_plan() -> TestResult {
    let args = [
        "--iterations",
        "10",
        "--populations",
        "3",
        "--particles",
        "12",
        "--seed",
        "11",
    ];
    let (d1, d2) = (tempfile::tempdir()?, tempfile::tempdir()?);
    let mut first = plan_and_check("amp-pso-1", d1.path(), &args)?;
    let mut second = plan_and_check("amp-pso-1", d2.path(), &args)?;
    assert_eq!(
        key(&first, "vehicles"),
        key(&second, "vehicles"),
        "trajectories differ"
    );
    assert_eq!(
        key(&first, "fitness"),
        key(&second, "fitness"),
        "fitness differs"
    );
    for j in [&mut first, &mut second] {
        if let Some(o) = j.as_object_mut() {
            o.remove("runtime_s");
        }
    }
    if let (Some(a), Some(b)) = (first.as_object(), second.as_object()) {
        for (k, va) in a {
            assert_eq!(
                Some(va),
                b.get(k),
                "`{k}` differs between two runs with the same seed"
            );
        }
        assert_eq!(a.len(), b.len());
    }
    Ok(())
}

#[test]
fn thread_count_does_not_change_the_plan() -> TestResult {
    let args = [
        "--iterations",
        "8",
        "--populations",
        "3",
        "--particles",
        "10",
        "--seed",
        "21",
    ];
    let (d1, d4) = (tempfile::tempdir()?, tempfile::tempdir()?);
    let one = plan_and_check(
        "amp-pso-1",
        d1.path(),
        &[&args[..], &["--threads", "1"]].concat(),
    )?;
    let four = plan_and_check(
        "amp-pso-1",
        d4.path(),
        &[&args[..], &["--threads", "4"]].concat(),
    )?;
    assert_eq!(
        key(&one, "vehicles"),
        key(&four, "vehicles"),
        "trajectories depend on --threads"
    );
    assert_eq!(
        key(&one, "fitness"),
        key(&four, "fitness"),
        "fitness depends on --threads"
    );
    Ok(())
}
