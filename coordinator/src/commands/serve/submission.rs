//! What a client sends on `shoal/submit` and what it gets back, and the checks a submission
//! passes before it may wait in the queue. Anyone on the network can submit, so every number
//! is bounded ([`shoal_common::limits`]) before anything is allocated, files the scenario names
//! must lie under the operator's data directory, and no refusal quotes a file or says whether
//! a path exists.

use std::path::Path;

use serde::{Deserialize, Serialize};
use shoal_common::limits;
use shoal_common::scenario::{DataDir, Scenario};
use shoal_common::wire::{codec, topics};

use super::refusal::Refusal;
// Mission seconds per wall second when a submission sets none: `run`'s default.
use crate::mission::options::DEFAULT_TIME_SCALE;

/// A mission submitted on `shoal/submit`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Submission {
    /// 1.
    pub version: u16,
    /// The scenario file's text (TOML, as in `scenarios/`).
    pub scenario_toml: String,
    /// Mission id (default: from the scenario's name).
    #[serde(default)]
    pub mission: Option<String>,
    /// Mission seconds per wall second (default 1).
    #[serde(default)]
    pub time_scale: Option<f64>,
    /// Telemetry rate, Hz (default 2).
    #[serde(default)]
    pub telemetry_hz: Option<f64>,
    /// Optimizer iterations (default: the scenario's).
    #[serde(default)]
    pub iterations: Option<usize>,
    /// RNG seed (default: the scenario's).
    #[serde(default)]
    pub seed: Option<u64>,
    /// Plan inside the coordinator instead of with the agents (default false).
    #[serde(default)]
    pub in_process: bool,
}

/// The reply to a submission.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Receipt {
    /// 1.
    pub version: u16,
    /// Taken (it runs after the missions before it).
    pub accepted: bool,
    /// The mission id: its keys are `shoal/<mission>/…`.
    pub mission: Option<String>,
    /// Why it was refused.
    pub error: Option<String>,
}

/// What the operator allows a submission (the `serve` flags the checks depend on).
#[derive(Debug, Clone)]
pub struct Rules {
    /// The only directory whose files a submitted scenario may name; `None`: no file at all.
    pub data_dir: Option<DataDir>,
    /// Longest expected wall time of one mission (mission time / time scale), seconds: no
    /// submission may hold the queue longer.
    pub max_wall_s: f64,
}

/// A submission that passed every check that needs no queue state.
#[derive(Debug, Clone, PartialEq)]
pub struct Accepted {
    /// The mission id, a valid single path component and key chunk.
    pub mission: String,
    /// The submission, its `scenario_toml` rewritten with the checked, canonical file paths.
    pub submission: Submission,
}

/// Names the submitted scenario in errors: it has no file of its own.
const SUBMITTED: &str = "<submitted scenario>";

/// Checks a submission's bytes; the mission id and the checked submission, or why not.
pub fn accept(bytes: &[u8], rules: &Rules) -> Result<Accepted, Refusal> {
    check_size(bytes.len())?;
    let mut s: Submission =
        codec::decode_json(bytes).map_err(|e| Refusal::Malformed(e.to_string()))?;
    if s.version != 1 {
        return Err(Refusal::Version(s.version));
    }
    check_rates(&s)?;
    if let Some(n) = s.iterations {
        check_at_most("iterations", n as u128, limits::MAX_ITERATIONS as u128)?;
    }
    let (scenario, text) = Scenario::parse_submitted(
        &s.scenario_toml,
        Path::new(SUBMITTED),
        rules.data_dir.as_ref(),
    )
    .map_err(|e| Refusal::Scenario(e.to_string()))?;
    check_evaluations(&scenario, s.iterations)?;
    check_wall_time(&scenario, &s, rules.max_wall_s)?;
    let mission = match &s.mission {
        Some(m) => m.clone(),
        None => crate::distributed::default_mission_id(&scenario),
    };
    topics::check_id("mission", &mission).map_err(|e| Refusal::MissionId(e.to_string()))?;
    s.scenario_toml = text;
    Ok(Accepted {
        mission,
        submission: s,
    })
}

/// Refuses more than [`limits::MAX_SUBMISSION_BYTES`] before anything is decoded.
pub fn check_size(bytes: usize) -> Result<(), Refusal> {
    if bytes > limits::MAX_SUBMISSION_BYTES {
        return Err(Refusal::TooLarge(bytes));
    }
    Ok(())
}

/// `time_scale` and `telemetry_hz` within their ranges.
fn check_rates(s: &Submission) -> Result<(), Refusal> {
    for (field, v, range) in [
        ("time_scale", s.time_scale, limits::TIME_SCALE),
        ("telemetry_hz", s.telemetry_hz, limits::TELEMETRY_HZ),
    ] {
        if let Some(v) = v {
            if !range.contains(&v) {
                return Err(Refusal::OutOfRange {
                    field,
                    value: v,
                    min: *range.start(),
                    max: *range.end(),
                });
            }
        }
    }
    Ok(())
}

/// `value` of submission `field` at most `max`.
fn check_at_most(field: &'static str, value: u128, max: u128) -> Result<(), Refusal> {
    if value > max {
        return Err(Refusal::OverLimit { field, value, max });
    }
    Ok(())
}

/// Particles × populations × iterations × vehicles within [`limits::MAX_EVALUATIONS`], with
/// the submission's iterations in place of the scenario's when it sets them.
fn check_evaluations(scenario: &Scenario, iterations: Option<usize>) -> Result<(), Refusal> {
    let o = &scenario.optimizer;
    let iterations = iterations.unwrap_or(o.iterations);
    let product = [
        o.particles,
        o.populations.max(1),
        iterations,
        scenario.vehicles.len(),
    ]
    .iter()
    .fold(1u128, |p, &n| p.saturating_mul(n as u128));
    if product > limits::MAX_EVALUATIONS {
        return Err(Refusal::Evaluations {
            particles: o.particles,
            populations: o.populations.max(1),
            iterations,
            vehicles: scenario.vehicles.len(),
            product,
        });
    }
    Ok(())
}

/// Mission time / time scale within `max_wall_s`: a slow replay of a long mission would hold
/// the queue for everyone behind it.
fn check_wall_time(scenario: &Scenario, s: &Submission, max_wall_s: f64) -> Result<(), Refusal> {
    let scale = s.time_scale.unwrap_or(DEFAULT_TIME_SCALE);
    let wall = scenario.fleet.mission_time_s / scale;
    if wall.is_nan() || wall > max_wall_s {
        return Err(Refusal::WallTime {
            mission_s: scenario.fleet.mission_time_s,
            scale,
            wall_s: wall,
            max_wall_s,
        });
    }
    Ok(())
}

/// The receipt of an accepted mission.
pub fn accepted(mission: &str) -> Receipt {
    Receipt {
        version: 1,
        accepted: true,
        mission: Some(mission.to_string()),
        error: None,
    }
}

/// The receipt of a refused submission.
pub fn refused(why: String) -> Receipt {
    Receipt {
        version: 1,
        accepted: false,
        mission: None,
        error: Some(why),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::{json, Value};

    const BASE: &str = include_str!("../../../../scenarios/amp-pso-2.toml");

    fn rules() -> Rules {
        Rules {
            data_dir: None,
            max_wall_s: 6.0 * 3600.0,
        }
    }

    /// The refusal of `v` under `rules`.
    fn refusal_with(v: Value, rules: &Rules) -> String {
        match accept(v.to_string().as_bytes(), rules) {
            Ok(a) => panic!("accepted {}", a.mission),
            Err(e) => e.to_string(),
        }
    }

    fn refusal(v: Value) -> String {
        refusal_with(v, &rules())
    }

    #[test]
    fn a_valid_submission_is_accepted_with_its_scenario_unchanged() -> Result<(), Refusal> {
        let ok = json!({"version": 1, "scenario_toml": BASE, "mission": "m-1", "time_scale": 50.0, "iterations": 5});
        let a = accept(ok.to_string().as_bytes(), &rules())?;
        assert_eq!(a.mission, "m-1");
        assert_eq!(a.submission.time_scale, Some(50.0));
        assert_eq!(a.submission.scenario_toml, BASE);
        Ok(())
    }

    #[test]
    fn an_oversized_submission_is_refused_before_it_is_decoded() {
        let big = vec![b'x'; limits::MAX_SUBMISSION_BYTES + 1];
        assert_eq!(
            accept(&big, &rules()).err().map(|e| e.to_string()),
            Some("submission: 1048577 bytes is over the limit 1048576".into())
        );
    }

    #[test]
    fn malformed_and_other_version_submissions_say_why() {
        assert!(accept(b"not json", &rules())
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
            .contains("not a submission"));
        assert!(refusal(json!({"version": 2, "scenario_toml": ""})).contains("version 2"));
        let e = refusal(json!({"version": 1, "scenario_toml": "name = 3"}));
        assert!(e.contains("<submitted scenario>"), "{e}");
    }

    #[test]
    fn iterations_over_the_limit_are_refused_before_the_scenario_is_read() {
        let e =
            refusal(json!({"version": 1, "scenario_toml": "", "iterations": 1_000_000_000_000u64}));
        assert_eq!(
            e,
            "submission: iterations = 1000000000000 is over the limit 1000000"
        );
    }

    #[test]
    fn iterations_within_their_limit_are_still_bounded_by_the_evaluations() {
        // 500 particles × 20 populations × 10^6 iterations × 3 vehicles = 3·10^10 > 10^10.
        let text = BASE.replace("\nparticles = 50", "\nparticles = 500");
        let e = refusal(json!({"version": 1, "scenario_toml": text, "iterations": 1_000_000}));
        assert_eq!(
            e,
            "submission: particles × populations × iterations × vehicles = 500 × 20 × 1000000 × 3 = 30000000000 is over the limit 10000000000"
        );
        // The scenario's own 200 iterations: 6·10^6, accepted.
        assert!(accept(
            json!({"version": 1, "scenario_toml": text})
                .to_string()
                .as_bytes(),
            &rules()
        )
        .is_ok());
    }

    #[test]
    fn a_billion_particles_are_refused_without_allocating_them() {
        let text = BASE.replace("\nparticles = 50", "\nparticles = 1000000000");
        let e = refusal(json!({"version": 1, "scenario_toml": text}));
        assert!(e.contains("particles") && e.contains("1000000000"), "{e}");
    }

    #[test]
    fn time_scale_and_telemetry_rate_outside_their_ranges_are_refused() {
        let e = refusal(json!({"version": 1, "scenario_toml": BASE, "time_scale": 1e-6}));
        assert_eq!(
            e,
            "submission: time_scale = 0.000001 is outside 0.1 to 10000"
        );
        let e = refusal(json!({"version": 1, "scenario_toml": BASE, "time_scale": -1.0}));
        assert_eq!(e, "submission: time_scale = -1 is outside 0.1 to 10000");
        let e = refusal(json!({"version": 1, "scenario_toml": BASE, "telemetry_hz": 1000.0}));
        assert_eq!(e, "submission: telemetry_hz = 1000 is outside 0.1 to 50");
    }

    #[test]
    fn a_mission_longer_than_the_servers_wall_time_limit_is_refused() {
        // 2300 s of mission at 0.1× is 23,000 s, over 6 h = 21,600 s; at 1× (2300 s) it is not.
        let e = refusal(json!({"version": 1, "scenario_toml": BASE, "time_scale": 0.1}));
        assert_eq!(
            e,
            "submission: fleet.mission_time_s / time_scale = 2300 s / 0.1 = 23000 s of wall time is over this server's limit 21600 s (--max-mission-hours)"
        );
        let short = Rules {
            max_wall_s: 2000.0,
            ..rules()
        };
        let e = refusal_with(json!({"version": 1, "scenario_toml": BASE}), &short);
        assert!(e.contains("2300 s / 1 = 2300 s"), "{e}");
    }

    #[test]
    fn mission_ids_that_are_not_one_path_component_are_refused() {
        for bad in [
            "..",
            ".",
            "",
            "a/b",
            "a\\b",
            ".hidden",
            "../../etc",
            &"x".repeat(65),
        ] {
            let e = refusal(json!({"version": 1, "scenario_toml": BASE, "mission": bad}));
            assert!(
                e.starts_with(&format!("submission: mission id {bad:?}")),
                "{e}"
            );
        }
    }

    #[test]
    fn a_scenario_naming_etc_passwd_is_refused_without_quoting_it() -> std::io::Result<()> {
        let text = format!("{BASE}\n[currents]\nmodel = \"grid\"\nfile = \"/etc/passwd\"\n");
        let e = refusal(json!({"version": 1, "scenario_toml": text}));
        assert!(
            e.contains("start it with --data-dir") && !e.contains("root:"),
            "{e}"
        );
        let data = tempfile::tempdir()?;
        let with_dir = Rules {
            data_dir: Some(DataDir::open(data.path())?),
            ..rules()
        };
        let e = refusal_with(json!({"version": 1, "scenario_toml": text}), &with_dir);
        assert_eq!(
            e,
            "<submitted scenario>: field `currents.file` = \"/etc/passwd\": names a file outside the data directory"
        );
        Ok(())
    }
}
