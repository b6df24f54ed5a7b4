//! The hostile scenario corpus (`tests/hostile/scenarios/`, written by
//! `tests/hostile/make_scenarios.py`): shipped scenarios with one field made huge, zero,
//! negative, NaN, of the wrong type, missing, or naming a device or a system file. Each must
//! give what `manifest.tsv` says: an error naming the field, or a plan within a small budget —
//! and never a panic, an abort or a hang.

mod common;

use std::path::{Path, PathBuf};

use common::{plan, root, TestResult};
use shoal_common::scenario::Scenario;

/// What a corpus file must give.
#[derive(Debug, Clone, PartialEq)]
enum Expect {
    /// Loading it fails with a message naming the file and this text (the field).
    Error(String),
    /// It loads, and `plan` plans it.
    Plan,
    /// It loads, and `plan` exits 1 with a message naming this text.
    PlanError(String),
}

/// One line of the manifest.
struct Case {
    path: PathBuf,
    expect: Expect,
}

fn corpus() -> PathBuf {
    root().join("tests").join("hostile").join("scenarios")
}

/// The manifest's cases; every `.toml` of the corpus is listed, and only those.
fn manifest() -> Result<Vec<Case>, Box<dyn std::error::Error>> {
    let dir = corpus();
    let text = std::fs::read_to_string(dir.join("manifest.tsv"))?;
    let mut cases = Vec::new();
    for line in text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
    {
        let fields: Vec<&str> = line.split('\t').collect();
        let [file, expect, names] = fields[..] else {
            return Err(format!("manifest.tsv: bad line {line:?}").into());
        };
        let expect = match expect {
            "error" => Expect::Error(names.to_string()),
            "plan" => Expect::Plan,
            "plan-error" => Expect::PlanError(names.to_string()),
            other => return Err(format!("manifest.tsv: unknown expectation {other:?}").into()),
        };
        cases.push(Case {
            path: dir.join(file),
            expect,
        });
    }
    let mut listed: Vec<PathBuf> = cases.iter().map(|c| c.path.clone()).collect();
    let mut present: Vec<PathBuf> = std::fs::read_dir(&dir)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    listed.sort();
    present.sort();
    assert_eq!(listed, present, "manifest.tsv and the corpus disagree");
    Ok(cases)
}

/// The file name, for messages.
fn name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

#[test]
fn every_hostile_scenario_is_refused_naming_its_field_or_loads_as_the_manifest_says() -> TestResult
{
    let cases = manifest()?;
    assert!(cases.len() >= 60, "only {} files", cases.len());
    let (mut errors, mut loads, mut panics) = (0, 0, Vec::new());
    let mut wrong = Vec::new();
    for case in &cases {
        // `plan` loads a scenario with `Scenario::load`, which validates it; the command-line
        // overrides are validated again with the same checks.
        let loaded = std::panic::catch_unwind(|| Scenario::load(&case.path));
        let Ok(loaded) = loaded else {
            panics.push(name(&case.path));
            continue;
        };
        match (&case.expect, loaded) {
            (Expect::Error(field), Err(e)) => {
                errors += 1;
                let message = e.to_string();
                if !(message.contains(&name(&case.path)) && message.contains(field.as_str())) {
                    wrong.push(format!(
                        "{}: does not name `{field}`: {message}",
                        name(&case.path)
                    ));
                }
            }
            (Expect::Error(field), Ok(_)) => {
                wrong.push(format!(
                    "{}: loaded; expected an error naming `{field}`",
                    name(&case.path)
                ));
            }
            (_, Ok(_)) => loads += 1,
            (_, Err(e)) => wrong.push(format!("{}: expected to load: {e}", name(&case.path))),
        }
    }
    eprintln!(
        "hostile corpus: {} files, {errors} refused naming their field, {loads} loaded, {} panics",
        cases.len(),
        panics.len()
    );
    assert!(panics.is_empty(), "panicked: {panics:?}");
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    Ok(())
}

/// A budget that plans any of the corpus's plannable files in about a second of a debug build.
const QUICK: [&str; 7] = [
    "--iterations",
    "3",
    "--populations",
    "2",
    "--particles",
    "6",
    "--no-touch-up",
];

#[test]
fn the_plannable_hostile_scenarios_plan_with_a_small_budget_and_the_rest_exit_1() -> TestResult {
    let dir = tempfile::tempdir()?;
    let mut planned = 0;
    for (k, case) in manifest()?.iter().enumerate() {
        if matches!(case.expect, Expect::Error(_)) {
            continue;
        }
        let out = dir.path().join(format!("out{k}"));
        let r = plan(&case.path, &out, &QUICK);
        let file = name(&case.path);
        match &case.expect {
            Expect::PlanError(text) => {
                assert_eq!(r.code(), Some(1), "{file}:\n{r}");
                assert!(
                    r.stderr.contains(text.as_str()),
                    "{file}: no `{text}`:\n{r}"
                );
            }
            _ => {
                assert!(matches!(r.code(), Some(0 | 3)), "{file}:\n{r}");
                assert!(
                    out.join("plan.json").is_file(),
                    "{file}: no plan.json:\n{r}"
                );
                planned += 1;
            }
        }
    }
    eprintln!("hostile corpus: {planned} plannable files planned");
    assert!(planned >= 10, "{planned}");
    Ok(())
}

#[test]
fn plan_refuses_a_billion_particles_with_exit_1_naming_the_field_and_the_limit() -> TestResult {
    let dir = tempfile::tempdir()?;
    let file = corpus().join("particles-1e9.toml");
    let r = plan(&file, &dir.path().join("out"), &[]);
    // 1, an error: not 134, the abort of a failed allocation.
    assert_eq!(r.code(), Some(1), "{r}");
    for needle in [
        "particles-1e9.toml",
        "optimizer.particles",
        "1000000000",
        "over the limit 10000",
    ] {
        assert!(r.stderr.contains(needle), "no `{needle}`:\n{r}");
    }
    Ok(())
}

#[test]
fn plan_refuses_a_billion_particles_given_on_the_command_line_naming_the_flag() -> TestResult {
    let dir = tempfile::tempdir()?;
    let file = root().join("scenarios").join("amp-pso-1.toml");
    let r = plan(
        &file,
        &dir.path().join("out"),
        &["--particles", "1000000000"],
    );
    assert_eq!(r.code(), Some(1), "{r}");
    for needle in [
        "--particles 1000000000",
        "optimizer.particles",
        "over the limit 10000",
    ] {
        assert!(r.stderr.contains(needle), "no `{needle}`:\n{r}");
    }
    Ok(())
}
