//! `shoal-coordinator status`: asks the running missions for their live fleet picture (a Zenoh
//! query on `shoal/<mission>/status`, or on every mission's) and prints it as a table.

use std::time::Duration;

use shoal_common::execution::CommandState;
use shoal_common::wire::open::FleetStatus;
use shoal_common::wire::topics::{self, OpenKey};
use shoal_common::wire::{codec, session};
use zenoh::Wait;

use crate::report::summary::opt;

/// `shoal-coordinator status`.
#[derive(Debug, Clone, clap::Args)]
pub struct StatusArgs {
    /// The coordinator's router.
    #[command(flatten)]
    pub connect: shoal_common::wire::flags::ZenohConnect,
    /// How to authenticate to the fleet's network.
    #[command(flatten)]
    pub zenoh: shoal_common::wire::flags::ZenohSecurityArgs,
    /// Only this mission (default: every running one).
    #[arg(long, env = "SHOAL_MISSION")]
    pub mission: Option<String>,
    /// Seconds to wait for answers.
    #[arg(long, default_value_t = 3.0)]
    pub timeout: f64,
    /// Print the JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// The log filter when `RUST_LOG` is not set: Zenoh's connection warnings only repeat the
/// error `status` prints itself (with the paths of Zenoh's source files), so they are left out.
pub const DEFAULT_LOG_FILTER: &str = "warn,zenoh=error";

/// Queries and prints; exit 1 when no mission answered.
pub fn command(args: &StatusArgs) -> anyhow::Result<i32> {
    let key = match &args.mission {
        Some(m) => topics::open_key(m, OpenKey::Status)?,
        None => topics::ALL_STATUS.to_string(),
    };
    let timeout = Duration::try_from_secs_f64(args.timeout)
        .ok()
        .filter(|d| !d.is_zero())
        .ok_or_else(|| {
            anyhow::anyhow!(
                "--timeout = {}: must be a positive number of seconds",
                args.timeout
            )
        })?;
    let statuses = query(
        &args.connect.connect,
        &args.zenoh.security()?,
        &key,
        timeout,
    )?;
    if statuses.is_empty() {
        eprintln!(
            "no running mission answered on {key} within {:.1} s",
            args.timeout
        );
        return Ok(crate::commands::exit::EXIT_ERROR);
    }
    let mut out = String::new();
    for s in &statuses {
        if args.json {
            out.push_str(&serde_json::to_string_pretty(s)?);
            out.push('\n');
        } else {
            out.push_str(&table(s));
        }
    }
    crate::report::out::say(&out);
    Ok(crate::commands::exit::EXIT_FEASIBLE)
}

/// The fleet pictures the missions matching `key` answer with (bad answers are skipped, with a
/// warning).
pub fn query(
    connect: &[String],
    security: &shoal_common::wire::security::Security,
    key: &str,
    timeout: Duration,
) -> anyhow::Result<Vec<FleetStatus>> {
    let config = session::client_config(connect, false, security)?;
    let s = zenoh::open(config).wait().map_err(|e| {
        // Zenoh's own text names its source files; it goes to the debug log, not to the user.
        tracing::debug!("zenoh: {e}");
        anyhow::anyhow!(
            "cannot reach {}: no Zenoh router accepted the connection (is a coordinator running \
             `run` or `serve` and listening there? set --connect or SHOAL_CONNECT)",
            connect.join(", ")
        )
    })?;
    let replies = s
        .get(key)
        .timeout(timeout)
        .wait()
        .map_err(|e| anyhow::anyhow!("cannot query {key}: {e}"))?;
    let mut out = Vec::new();
    while let Ok(reply) = replies.recv() {
        match reply.result() {
            Ok(sample) => match codec::decode_json::<FleetStatus>(&sample.payload().to_bytes()) {
                Ok(st) => out.push(st),
                Err(e) => tracing::warn!("{}: not a fleet status: {e}", sample.key_expr()),
            },
            Err(e) => tracing::warn!("an error reply: {:?}", e.payload().to_bytes()),
        }
    }
    let _ = s.close().wait();
    Ok(out)
}

/// One mission's picture as a table.
pub fn table(s: &FleetStatus) -> String {
    let mut t = format!(
        "mission {} at t = {:.0} s (d_min {:.0} m)\n{:<10} {:>8} {:>8} {:>8} {:>6} {:>9} {:>9} {:>8} {:>4}\n",
        s.mission, s.t_s, s.d_min_m, "vehicle", "x m", "y m", "z m", "done", "xtrack m", "ETA s", "status", "rev"
    );
    for v in &s.vehicles {
        // A vehicle that has not reported yet has no position, progress or state: "–".
        let (p, status) = match &v.state {
            Some(st) => (
                st.position.map(Some),
                format!("{:?}", st.status).to_lowercase(),
            ),
            None => ([None; 3], "–".into()),
        };
        let status = if v.lost { "LOST".to_string() } else { status };
        // A command the vehicle did not take: its status says what it does instead.
        let failed = v
            .command
            .as_ref()
            .filter(|c| matches!(c.state, CommandState::Failed | CommandState::GaveUp));
        let status = match failed {
            Some(c) => format!("{status} ({} failed)", c.command.name()),
            None => status,
        };
        let done = v
            .progress
            .map_or("–".into(), |p| format!("{:.0}%", 100.0 * p.fraction));
        t.push_str(&format!(
            "{:<10} {:>8} {:>8} {:>8} {:>6} {:>9} {:>9} {:>8} {:>4}\n",
            v.vehicle,
            opt(p[0], 0),
            opt(p[1], 0),
            opt(p[2], 0),
            done,
            opt(v.progress.map(|p| p.cross_track_m), 1),
            opt(v.progress.map(|p| p.eta_s), 0),
            status,
            v.revision
        ));
    }
    t.push_str(&format!(
        "separation now {}; predicted over {:.0} s: {}\n",
        s.current_min_separation_m
            .map_or("–".into(), |d| format!("{d:.1} m")),
        s.horizon_s,
        s.predicted.map_or("–".into(), |c| format!(
            "{:.1} m at t = {:.0} s ({} – {})",
            c.min_distance_m,
            c.at_s,
            s.vehicles.get(c.a).map_or("?", |v| v.vehicle.as_str()),
            s.vehicles.get(c.b).map_or("?", |v| v.vehicle.as_str())
        ))
    ));
    t
}

#[cfg(test)]
mod tests {
    use super::*;
    use shoal_common::execution::picture::Progress;
    use shoal_common::wire::open::{VehicleStatusRow, OPEN_VERSION};

    #[test]
    fn a_vehicle_that_has_not_reported_shows_dashes_not_nan() {
        let row = |vehicle: &str, state, progress| VehicleStatusRow {
            vehicle: vehicle.into(),
            state,
            progress,
            revision: 0,
            silent_s: 0.0,
            lost: false,
            command: None,
        };
        let state =
            crate::execute::live::test_telemetry("auv1", 0, 10.0, [100.4, 200.6, -30.0]).state;
        let progress = Progress {
            along_m: 50.0,
            fraction: 0.25,
            plan_time_s: 10.0,
            cross_track_m: 1.3,
            lag_s: 0.0,
            eta_s: 400.4,
        };
        let status = FleetStatus {
            version: OPEN_VERSION,
            mission: "m".into(),
            t_s: 10.0,
            d_min_m: 50.0,
            vehicles: vec![
                row("auv1", Some(state), Some(progress)),
                row("auv2", None, None),
            ],
            current_min_separation_m: None,
            current_pair: None,
            predicted: None,
            horizon_s: 60.0,
        };
        let text = table(&status);
        assert!(!text.contains("NaN"), "{text}");
        let lines: Vec<&str> = text.lines().collect();
        let cells = |k: usize| lines[k].split_whitespace().collect::<Vec<_>>();
        assert_eq!(
            cells(2),
            ["auv1", "100", "201", "-30", "25%", "1.3", "400", "underway", "0"]
        );
        assert_eq!(cells(3), ["auv2", "–", "–", "–", "–", "–", "–", "–", "0"]);
        // A hold the vehicle refused shows beside what it does.
        let mut refused = status.clone();
        refused.vehicles[0].command = Some(shoal_common::execution::CommandReport {
            command: shoal_common::execution::VehicleCommand::Hold,
            state: CommandState::Failed,
            detail: "DENIED".into(),
            given_s: 9.0,
        });
        let text = table(&refused);
        let line = text.lines().nth(2).unwrap_or_default();
        assert!(line.contains("underway (hold failed)"), "{text}");
    }
}
