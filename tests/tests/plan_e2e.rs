//! End-to-end tests of `shoal-coordinator plan --in-process`: run the real binary on a real
//! scenario, then check `plan.json` with the independent checker of this crate.
//!
//! CLI contract under test:
//! `shoal-coordinator plan <SCENARIO.toml> --in-process --out <DIR> [--seed N]
//!  [--algorithm amp-pso|pso|mp-pso|a-pso] [--iterations N] [--populations N] [--particles N]`
//! writes `<DIR>/plan.json` and `<DIR>/plan.svg`; exit 0 = feasible plan, 3 = plan with
//! violations, 1 = error (message on stderr naming the file, field and value).

use std::error::Error;
use std::fmt;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::sync::OnceLock;
use std::thread;
use std::time::{Duration, Instant};

use serde_json::Value;
use shoal_tests::{check, geometry, parse_plan};

type TestResult = Result<(), Box<dyn Error>>;

/// Time limit for one planner run.
const RUN_TIMEOUT: Duration = Duration::from_secs(120);
/// Time limit for building the binary.
const BUILD_TIMEOUT: Duration = Duration::from_secs(1200);

/// A finished child process.
struct Run {
    what: String,
    status: ExitStatus,
    stdout: String,
    stderr: String,
}

impl Run {
    fn code(&self) -> Option<i32> {
        self.status.code()
    }
}

impl fmt::Display for Run {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}\nexit status: {}\n--- stdout ---\n{}\n--- stderr ---\n{}",
            self.what, self.status, self.stdout, self.stderr
        )
    }
}

/// Runs `cmd` to completion, killing it (and failing the test) after `timeout`.
fn run(mut cmd: Command, timeout: Duration) -> Run {
    let what = format!("{cmd:?}");
    cmd.stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let mut child = match cmd.spawn() {
        Ok(c) => c,
        Err(e) => panic!("cannot start {what}: {e}"),
    };
    let drain = |pipe: Option<Box<dyn Read + Send>>| {
        thread::spawn(move || {
            let mut buf = Vec::new();
            if let Some(mut p) = pipe {
                let _ = p.read_to_end(&mut buf);
            }
            String::from_utf8_lossy(&buf).into_owned()
        })
    };
    let out = drain(
        child
            .stdout
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let err = drain(
        child
            .stderr
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let start = Instant::now();
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) if start.elapsed() < timeout => thread::sleep(Duration::from_millis(50)),
            Ok(None) => {
                let _ = child.kill();
                let _ = child.wait();
                // Grandchildren may still hold the pipes: give the readers a moment only.
                thread::sleep(Duration::from_millis(500));
                let stdout = if out.is_finished() {
                    out.join().unwrap_or_default()
                } else {
                    String::new()
                };
                let stderr = if err.is_finished() {
                    err.join().unwrap_or_default()
                } else {
                    String::new()
                };
                panic!("{what} did not finish within {timeout:?}; killed\n--- stdout ---\n{stdout}\n--- stderr ---\n{stderr}");
            }
            Err(e) => panic!("cannot wait for {what}: {e}"),
        }
    };
    Run {
        what,
        status,
        stdout: out
            .join()
            .unwrap_or_else(|_| "<stdout reader panicked>".into()),
        stderr: err
            .join()
            .unwrap_or_else(|_| "<stderr reader panicked>".into()),
    }
}

/// The workspace root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// `target/<profile>/shoal-coordinator`, built once per test process.
///
/// The directory is the parent of the `deps` directory this test executable lives in. The binary
/// is (re)built with `cargo build -p shoal-coordinator` in the same profile so that a stale binary
/// from an earlier build is never tested; this is a no-op when it is up to date.
fn coordinator() -> &'static Path {
    static BIN: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    match BIN.get_or_init(locate_and_build) {
        Ok(p) => p,
        Err(e) => panic!("{e}"),
    }
}

fn locate_and_build() -> Result<PathBuf, String> {
    let exe =
        std::env::current_exe().map_err(|e| format!("cannot find the test executable: {e}"))?;
    let deps = exe
        .parent()
        .ok_or_else(|| format!("{} has no parent directory", exe.display()))?;
    let profile_dir = if deps.file_name().is_some_and(|n| n == "deps") {
        deps.parent()
            .ok_or_else(|| format!("{} has no parent directory", deps.display()))?
    } else {
        deps
    };
    let bin = profile_dir.join(format!("shoal-coordinator{}", std::env::consts::EXE_SUFFIX));
    let mut cmd = Command::new(env!("CARGO"));
    cmd.current_dir(root()).args([
        "build",
        "-p",
        "shoal-coordinator",
        "--bin",
        "shoal-coordinator",
    ]);
    match profile_dir.file_name().and_then(|n| n.to_str()) {
        Some("debug") | None => {}
        Some("release") => {
            cmd.arg("--release");
        }
        Some(other) => {
            cmd.args(["--profile", other]);
        }
    }
    let build = run(cmd, BUILD_TIMEOUT);
    if !build.status.success() {
        return Err(format!("building shoal-coordinator failed:\n{build}"));
    }
    if !bin.is_file() {
        return Err(format!(
            "cargo build succeeded but {} does not exist (is CARGO_TARGET_DIR or --target different from this test's?)\n{build}",
            bin.display()
        ));
    }
    Ok(bin)
}

/// `scenarios/<name>.toml`.
fn scenario(name: &str) -> PathBuf {
    let p = root().join("scenarios").join(format!("{name}.toml"));
    assert!(p.is_file(), "scenario file {} is missing", p.display());
    p
}

/// `shoal-coordinator plan <scenario> --in-process --out <out> <extra...>`.
fn plan(scenario: &Path, out: &Path, extra: &[&str]) -> Run {
    let mut cmd = Command::new(coordinator());
    // Every flag has a SHOAL_* environment fallback: keep the caller's environment out.
    for (k, _) in std::env::vars_os() {
        if k.to_string_lossy().starts_with("SHOAL_") {
            cmd.env_remove(k);
        }
    }
    cmd.current_dir(root())
        .arg("plan")
        .arg(scenario)
        .arg("--in-process")
        .arg("--out")
        .arg(out)
        .args(extra);
    run(cmd, RUN_TIMEOUT)
}

/// Runs a plan that must succeed (exit 0 or 3) and checks it end to end; returns the plan JSON.
fn plan_and_check(name: &str, out: &Path, extra: &[&str]) -> Result<Value, Box<dyn Error>> {
    let scenario_path = scenario(name);
    let r = plan(&scenario_path, out, extra);
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

    let scenario_text = std::fs::read_to_string(&scenario_path)?;
    let report = match check(&scenario_text, &text) {
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
fn problems_of(
    scenario_path: &Path,
    out: &Path,
    extra: &[&str],
) -> Result<Vec<String>, Box<dyn Error>> {
    let r = plan(scenario_path, out, extra);
    if !matches!(r.code(), Some(0) | Some(3)) {
        return Ok(vec![format!("unexpected exit status:\n{r}")]);
    }
    let text = std::fs::read_to_string(out.join("plan.json"))?;
    let report = check(&std::fs::read_to_string(scenario_path)?, &text)?;
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

fn key<'a>(json: &'a Value, path: &str) -> &'a Value {
    let mut v = json;
    for k in path.split('.') {
        match v.get(k) {
            Some(x) => v = x,
            None => panic!("plan.json has no `{path}`"),
        }
    }
    v
}

fn number(json: &Value, path: &str) -> f64 {
    match key(json, path).as_f64() {
        Some(x) => x,
        None => panic!("plan.json `{path}` is not a number: {}", key(json, path)),
    }
}

fn nullable_number(json: &Value, path: &str) {
    let v = key(json, path);
    assert!(
        v.is_null() || v.is_f64() || v.is_i64() || v.is_u64(),
        "`{path}` must be null or a number: {v}"
    );
}

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
    assert_eq!(
        c.len(),
        30,
        "one convergence entry per iteration: {convergence:?}"
    );
    for (k, w) in c.windows(2).enumerate() {
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
    assert!(
        r.code().is_some_and(|c| c != 0),
        "expected a non-zero exit:\n{r}"
    );
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

/// Every scenario × algorithm × a few seeds at a moderate budget, checked independently.
/// Slow: `cargo test -p shoal-tests --test plan_e2e -- --ignored`.
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
    assert_eq!(key(&json, "convergence").as_array().map(Vec::len), Some(5));
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
