//! The MCAP mission log end to end: `shoal-coordinator run` writes `mission.mcap` beside
//! `mission.ndjson`, `replay` reads either to the same result, `export --format mcap` converts
//! the NDJSON log to the same file, and an independent reader (`tests/python/check_mcap.py`:
//! Foxglove's Python `mcap` 1.6.0 and `jsonschema` 4.26.0) finds in each the NDJSON log's
//! records, every channel's JSON Schema valid and every message valid against it, and every
//! report's position within 1 cm of the NDJSON log's.
//!
//! The interpreter comes from [`shoal_interop::python`] (a venv with the pinned packages).

mod common;

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use common::fleet::Fleet;
use common::process::{coordinator, root, run, Run};
use common::{scenario, without_shoal_env, TestResult};

const LIMIT: Duration = Duration::from_secs(240);
/// The first bytes of every MCAP file.
const MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// `shoal-coordinator export <input> <args...>`.
fn export(input: &Path, args: &[&str]) -> Run {
    let mut cmd = Command::new(coordinator());
    without_shoal_env(&mut cmd);
    cmd.current_dir(root()).arg("export").arg(input).args(args);
    run(cmd, Duration::from_secs(60))
}

/// `check_mcap.py NDJSON MCAP...`; its JSON summary.
fn check_mcap(
    ndjson: &Path,
    mcaps: &[&Path],
) -> Result<serde_json::Value, Box<dyn std::error::Error>> {
    let mut check = Command::new(common::interop_python()?);
    check
        .arg(root().join("tests/python/check_mcap.py"))
        .arg(ndjson)
        .args(mcaps);
    let r = run(check, Duration::from_secs(120));
    assert_eq!(r.code(), Some(0), "{r}");
    match serde_json::from_str(r.stdout.trim()) {
        Ok(v) => Ok(v),
        Err(e) => Err(format!("no JSON summary ({e}):\n{r}").into()),
    }
}

#[test]
fn a_run_writes_an_mcap_log_that_replays_exports_and_reads_independently() -> TestResult {
    let mut fleet = Fleet::new();
    let out = fleet.dir().join("out");
    // Scenario 2's three AUVs, planned briefly and run at 200× real time (about 10 s).
    let mut cmd = Command::new(coordinator());
    without_shoal_env(&mut cmd);
    cmd.current_dir(root())
        .arg("run")
        .arg(scenario("amp-pso-2"))
        .args(["--in-process", "-q", "--time-scale", "200"])
        .args(["--iterations", "40", "--out"])
        .arg(&out);
    let c = fleet.spawn("coordinator", cmd);
    let r = fleet.wait(c, Instant::now() + LIMIT);
    assert_eq!(r.code(), Some(0), "{}\n{}", r.stdout, r.stderr);
    let ndjson = out.join("mission.ndjson");
    let mcap = out.join("mission.mcap");
    let bytes = std::fs::read(&mcap)?;
    assert!(
        bytes.starts_with(MAGIC) && bytes.ends_with(MAGIC),
        "not a whole MCAP file"
    );

    // `replay` tells the formats apart by their content and finds the same of both.
    let from_ndjson = fleet.replay(&ndjson);
    let from_mcap = fleet.replay(&mcap);
    assert_eq!(from_ndjson.stdout, from_mcap.stdout);
    assert!(from_mcap.stdout.contains("  MET: "), "{}", from_mcap.stdout);

    // `export --format mcap` of the NDJSON log: the file `run` wrote, byte for byte.
    let exported = fleet.dir().join("exported");
    let e = export(
        &ndjson,
        &["--format", "mcap", "--out", &exported.to_string_lossy()],
    );
    assert_eq!(e.code(), Some(0), "{e}");
    assert!(e.stdout.contains("mission.mcap"), "{e}");
    let exported = exported.join("mission.mcap");
    assert!(
        std::fs::read(&exported)? == bytes,
        "the export differs from run's mission.mcap"
    );

    let summary = check_mcap(&ndjson, &[&mcap, &exported])?;
    let kinds = &summary["kinds"];
    for (kind, at_least) in [("start", 1), ("plan", 1), ("telemetry", 30), ("end", 1)] {
        assert!(
            kinds[kind].as_u64().is_some_and(|n| n >= at_least),
            "{summary}"
        );
    }
    let reports = &summary["reports"];
    for v in ["auv1", "auv2", "auv3"] {
        assert!(reports[v].as_u64().is_some_and(|n| n >= 10), "{summary}");
    }
    // start, plan, event, end and one telemetry channel per vehicle.
    assert!(
        summary["channels"].as_u64().is_some_and(|n| n >= 7),
        "{summary}"
    );

    // A plan is not a log, nor a log a plan.
    let plan = out.join("plan.json");
    assert!(plan.is_file(), "run wrote no plan.json");
    let e = export(
        &plan,
        &["--format", "mcap", "--out", &out.to_string_lossy()],
    );
    assert_eq!(e.code(), Some(1), "{e}");
    assert!(e.stderr.contains("not a mission log: it is a plan"), "{e}");
    for log in [&ndjson, &mcap] {
        let e = export(
            log,
            &["--format", "geojson", "--out", &out.to_string_lossy()],
        );
        assert_eq!(e.code(), Some(1), "{e}");
        assert!(e.stderr.contains("is a mission log, not a plan"), "{e}");
    }

    // What a run killed mid-write leaves: the records before the cut replay.
    // Cut inside the last report before two thirds of the file.
    let needle = b"\"received_unix_us\"";
    let Some(at) = bytes[..bytes.len() * 2 / 3]
        .windows(needle.len())
        .rposition(|w| w == needle)
    else {
        return Err("no report in the first two thirds of mission.mcap".into());
    };
    let cut = fleet.dir().join("cut.mcap");
    std::fs::write(&cut, &bytes[..at + 5])?;
    let mut cmd = Command::new(coordinator());
    without_shoal_env(&mut cmd);
    cmd.current_dir(root()).arg("replay").arg(&cut);
    let r = run(cmd, Duration::from_secs(60));
    assert!(matches!(r.code(), Some(0 | 3)), "{r}");
    assert!(
        r.stdout.contains("the log has no end record") && r.stdout.contains("is cut short"),
        "{r}"
    );
    fleet.passed();
    Ok(())
}
