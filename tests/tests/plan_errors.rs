//! End-to-end error handling of `shoal-coordinator plan --in-process`: bad scenario values,
//! missing files and unknown options exit non-zero with a message naming the culprit, and write
//! no plan.

mod common;

use common::{plan, scenario, TestResult};

#[test]
fn bad_value_is_reported_with_file_field_and_value() -> TestResult {
    let dir = tempfile::tempdir()?;
    let text = std::fs::read_to_string(scenario("amp-pso-1"))?;
    let mut doc: toml::Table = toml::from_str(&text)?;
    let Some(v0) = doc
        .get_mut("vehicles")
        .and_then(|v| v.as_array_mut())
        .and_then(|a| a.first_mut())
        .and_then(|v| v.as_table_mut())
    else {
        panic!("amp-pso-1.toml has no [[vehicles]]");
    };
    v0.insert("speed_max_mps".into(), toml::Value::Float(-1.0));
    let bad = dir.path().join("bad-speed.toml");
    std::fs::write(&bad, toml::to_string(&doc)?)?;
    let out = dir.path().join("out");
    let r = plan(
        &bad,
        &out,
        &[
            "--iterations",
            "2",
            "--populations",
            "1",
            "--particles",
            "4",
        ],
    );
    assert_eq!(r.code(), Some(1), "{r}");
    for needle in ["bad-speed.toml", "vehicles[0].speed_max_mps", "-1"] {
        assert!(
            r.stderr.contains(needle),
            "stderr does not mention `{needle}`:\n{r}"
        );
    }
    assert!(
        !out.join("plan.json").exists(),
        "a plan was written for a bad scenario:\n{r}"
    );
    Ok(())
}

#[test]
fn missing_scenario_file_is_reported() -> TestResult {
    let dir = tempfile::tempdir()?;
    let missing = dir.path().join("does-not-exist.toml");
    let r = plan(&missing, &dir.path().join("out"), &[]);
    assert_eq!(r.code(), Some(1), "{r}");
    assert!(
        r.stderr.contains(&missing.display().to_string()),
        "stderr does not name {}:\n{r}",
        missing.display()
    );
    Ok(())
}

#[test]
fn unknown_algorithm_is_refused() -> TestResult {
    let dir = tempfile::tempdir()?;
    let r = plan(&scenario("amp-pso-1"), dir.path(), &["--algorithm", "nope"]);
    // A bad command line is an error like any other: exit 1 (clap's own would be 2).
    assert_eq!(r.code(), Some(1), "{r}");
    assert!(
        r.stderr.contains("nope"),
        "stderr does not name the bad value:\n{r}"
    );
    assert!(
        !dir.path().join("plan.json").exists(),
        "a plan was written:\n{r}"
    );
    Ok(())
}

#[test]
fn an_inspection_scenario_refuses_a_path_planner() -> TestResult {
    // Its AUV returns to its base: a start-to-goal planner would plan it a path of zero length
    // and call the plan feasible.
    let dir = tempfile::tempdir()?;
    let out = dir.path().join("out");
    let r = plan(&scenario("cages-a"), &out, &["--algorithm", "amp-pso"]);
    assert_eq!(r.code(), Some(1), "{r}");
    for needle in [
        "cages-a.toml",
        "optimizer.algorithm",
        "amp-pso",
        "[inspection]",
    ] {
        assert!(
            r.stderr.contains(needle),
            "stderr does not mention `{needle}`:\n{r}"
        );
    }
    assert!(!out.join("plan.json").exists(), "a plan was written:\n{r}");
    Ok(())
}

#[test]
fn compare_refuses_an_algorithm_that_does_not_fit_a_scenario_before_running_any() -> TestResult {
    let mut cmd = std::process::Command::new(common::coordinator());
    common::without_shoal_env(&mut cmd);
    cmd.current_dir(common::root())
        .arg("compare")
        .arg(scenario("amp-pso-1"))
        .args([
            "--seeds",
            "1",
            "--iterations",
            "2",
            "--algorithms",
            "pso,de-pso",
        ]);
    let out = cmd.output()?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    for needle in ["amp-pso-1.toml", "optimizer.algorithm", "de-pso"] {
        assert!(
            stderr.contains(needle),
            "stderr does not mention `{needle}`:\n{stderr}"
        );
    }
    // Refused up front: no run was made, no table printed.
    assert!(!stderr.contains("seed 1: fitness"), "{stderr}");
    assert!(
        out.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    Ok(())
}

#[test]
fn status_with_no_coordinator_says_so_in_one_line() -> TestResult {
    let endpoint = common::fleet::endpoint(common::fleet::free_port());
    let mut cmd = std::process::Command::new(common::coordinator());
    common::without_shoal_env(&mut cmd);
    cmd.env_remove("RUST_LOG")
        .args(["status", "--connect", &endpoint, "--timeout", "1"]);
    let out = cmd.output()?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains(&format!(
            "error: cannot reach {endpoint}: no Zenoh router accepted the connection"
        )),
        "{stderr}"
    );
    // Neither Zenoh's own warnings nor the paths of its source files.
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(!stderr.contains(".rs:"), "{stderr}");
    Ok(())
}

#[test]
fn a_bad_command_line_exits_1_and_help_exits_0() -> TestResult {
    for (program, args, code) in [
        (
            common::coordinator(),
            vec!["plan", "x.toml", "--seed", "-1"],
            1,
        ),
        (common::coordinator(), vec!["no-such-command"], 1),
        (common::coordinator(), vec!["plan", "--help"], 0),
        (common::agent(), vec!["--no-such-flag"], 1),
        (common::agent(), vec!["--version"], 0),
    ] {
        let mut cmd = std::process::Command::new(program);
        common::without_shoal_env(&mut cmd);
        let out = cmd.args(&args).output()?;
        let text = String::from_utf8_lossy(if code == 0 { &out.stdout } else { &out.stderr });
        assert_eq!(out.status.code(), Some(code), "{args:?}: {text}");
        assert!(!text.is_empty(), "{args:?} printed nothing");
    }
    Ok(())
}
