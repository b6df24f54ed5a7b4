//! `shoal-coordinator serve`: a router that takes missions from anyone on the network. A client
//! (the Python `eclipse-zenoh` package, a ground station) sends a query on `shoal/submit` whose
//! payload is a JSON [`Submission`]; the reply is a JSON [`Receipt`] with the mission id (or
//! why it was refused). Accepted missions run one after another exactly as `run` runs them —
//! plan, then execute with one embedded agent per vehicle — on a router linked to this one, so
//! their plan, telemetry, status and events appear on the open JSON keys
//! (`shoal/<mission>/…`, see [`shoal_common::wire::open`]).

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::sync::Arc;
use std::time::Duration;

use clap::Parser;
use serde::{Deserialize, Serialize};
use shoal_common::scenario::Scenario;
use shoal_common::wire::{codec, session, topics};
use zenoh::Wait;

use crate::run_cmd::{run_command, RunArgs};

/// `shoal-coordinator serve`.
#[derive(Debug, Clone, clap::Args)]
pub struct ServeArgs {
    /// Endpoint(s) to listen on (comma-separated).
    #[arg(
        long,
        env = "SHOAL_LISTEN",
        value_delimiter = ',',
        default_value = "tcp/0.0.0.0:7447"
    )]
    pub listen: Vec<String>,
    /// Where each mission's files go (`<out>/<mission>/`).
    #[arg(long, env = "SHOAL_OUT", default_value = "missions")]
    pub out: PathBuf,
    /// Serve this many missions, then exit (default: until Ctrl-C).
    #[arg(long)]
    pub missions: Option<usize>,
}

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

/// Checks a submission's bytes; the mission id and the checked submission, or why not.
fn accept(bytes: &[u8]) -> Result<(String, Submission), String> {
    let s: Submission = codec::decode_json(bytes).map_err(|e| format!("not a submission: {e}"))?;
    if s.version != 1 {
        return Err(format!(
            "submission version {} (this coordinator reads 1)",
            s.version
        ));
    }
    let scenario = Scenario::parse(
        &s.scenario_toml,
        std::path::Path::new("<submitted scenario>"),
    )
    .map_err(|e| e.to_string())?;
    let mission = match &s.mission {
        Some(m) => m.clone(),
        None => crate::distributed::default_mission_id(&scenario),
    };
    topics::check_id("mission", &mission).map_err(|e| e.to_string())?;
    for (field, v) in [
        ("time_scale", s.time_scale),
        ("telemetry_hz", s.telemetry_hz),
    ] {
        if let Some(v) = v {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("{field} = {v}: must be a positive number"));
            }
        }
    }
    Ok((mission, s))
}

#[derive(Parser)]
struct Wrapper {
    #[command(flatten)]
    run: RunArgs,
}

/// Serves until `shutdown` (or `--missions` missions).
pub fn command(args: &ServeArgs, shutdown: Arc<AtomicBool>) -> anyhow::Result<i32> {
    let listen: Vec<String> = args
        .listen
        .iter()
        .map(|e| crate::distributed::network::resolve_port_zero(e))
        .collect::<anyhow::Result<_>>()?;
    let config = session::router_config(&listen, &[])?;
    let router = zenoh::open(config)
        .wait()
        .map_err(|e| anyhow::anyhow!("cannot open a Zenoh router on {}: {e}", listen.join(", ")))?;
    let (tx, rx) = mpsc::channel::<(String, Submission)>();
    let refused = Arc::new(std::sync::atomic::AtomicU64::new(0));
    let count = Arc::clone(&refused);
    let _submit = router
        .declare_queryable(topics::SUBMIT)
        .callback(move |q| {
            let bytes = q
                .payload()
                .map(|p| p.to_bytes().into_owned())
                .unwrap_or_default();
            let receipt = match accept(&bytes) {
                Ok((mission, s)) => {
                    let _ = tx.send((mission.clone(), s));
                    Receipt {
                        version: 1,
                        accepted: true,
                        mission: Some(mission),
                        error: None,
                    }
                }
                Err(why) => {
                    count.fetch_add(1, Ordering::Relaxed);
                    tracing::warn!("refused a submission: {why}");
                    Receipt {
                        version: 1,
                        accepted: false,
                        mission: None,
                        error: Some(why),
                    }
                }
            };
            if let Ok(b) = codec::encode_json(&receipt) {
                let _ = q.reply(topics::SUBMIT, b).wait();
            }
        })
        .wait()
        .map_err(|e| anyhow::anyhow!("cannot declare the queryable {}: {e}", topics::SUBMIT))?;
    let link = listen
        .first()
        .map(|e| e.replace("/0.0.0.0:", "/127.0.0.1:"))
        .unwrap_or_default();
    eprintln!(
        "serving missions on {} (submit on {}); Ctrl-C to stop",
        listen.join(", "),
        topics::SUBMIT
    );
    let mut served = 0usize;
    while !shutdown.load(Ordering::Relaxed) && args.missions.is_none_or(|n| served < n) {
        let (mission, s) = match rx.recv_timeout(Duration::from_millis(200)) {
            Ok(m) => m,
            Err(mpsc::RecvTimeoutError::Timeout) => continue,
            Err(mpsc::RecvTimeoutError::Disconnected) => break,
        };
        let dir = args.out.join(&mission);
        std::fs::create_dir_all(&dir)
            .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", dir.display()))?;
        let file = dir.join("scenario.toml");
        std::fs::write(&file, &s.scenario_toml)
            .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", file.display()))?;
        let mut argv: Vec<String> = vec!["run".into(), file.display().to_string()];
        argv.extend([
            "--out".into(),
            dir.display().to_string(),
            "--mission".into(),
            mission.clone(),
        ]);
        argv.extend(["--router".into(), link.clone(), "--quiet".into()]);
        if s.in_process {
            argv.push("--in-process".into());
        }
        for (flag, v) in [
            ("--time-scale", s.time_scale.map(|v| v.to_string())),
            ("--telemetry-hz", s.telemetry_hz.map(|v| v.to_string())),
            ("--iterations", s.iterations.map(|v| v.to_string())),
            ("--seed", s.seed.map(|v| v.to_string())),
        ] {
            if let Some(v) = v {
                argv.extend([flag.to_string(), v]);
            }
        }
        served += 1;
        let run = match Wrapper::try_parse_from(&argv) {
            Ok(w) => w.run,
            Err(e) => {
                tracing::error!("mission {mission}: {e}");
                continue;
            }
        };
        eprintln!(
            "mission {mission}: planning and executing (files in {})",
            dir.display()
        );
        match run_command(&run, Arc::clone(&shutdown)) {
            Ok(code) => eprintln!("mission {mission}: ended with status {code}"),
            Err(e) => eprintln!("mission {mission}: failed: {e:#}"),
        }
    }
    if let Err(e) = router.close().wait() {
        tracing::warn!("closing the router: {e}");
    }
    eprintln!(
        "served {served} mission(s); refused {} submission(s)",
        refused.load(Ordering::Relaxed)
    );
    Ok(crate::EXIT_FEASIBLE)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn submissions_are_checked_and_refusals_say_why() {
        let scenario = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../scenarios/amp-pso-2.toml"
        ))
        .unwrap_or_default();
        let ok = serde_json::json!({"version": 1, "scenario_toml": scenario, "mission": "m-1", "time_scale": 50.0});
        let (m, s) = match accept(ok.to_string().as_bytes()) {
            Ok(x) => x,
            Err(e) => panic!("{e}"),
        };
        assert_eq!(m, "m-1");
        assert_eq!(s.time_scale, Some(50.0));
        let bad = |v: serde_json::Value| accept(v.to_string().as_bytes()).err().unwrap_or_default();
        assert!(bad(serde_json::json!({"version": 2, "scenario_toml": ""})).contains("version 2"));
        assert!(accept(b"not json")
            .err()
            .unwrap_or_default()
            .contains("not a submission"));
        let e = bad(serde_json::json!({"version": 1, "scenario_toml": "name = 3"}));
        assert!(e.contains("<submitted scenario>"), "{e}");
        let e = bad(serde_json::json!({"version": 1, "scenario_toml": scenario, "mission": "a/b"}));
        assert!(e.contains("\"a/b\""), "{e}");
        let e =
            bad(serde_json::json!({"version": 1, "scenario_toml": scenario, "time_scale": -1.0}));
        assert!(e.contains("time_scale = -1"), "{e}");
    }
}
