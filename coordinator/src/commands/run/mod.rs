//! `shoal-coordinator run <SCENARIO>`: plan (as `plan` does), then execute the plan with one
//! agent per vehicle driving it through its vehicle link, and report the execution's figures
//! (`<out>/execution.json`, the mission log `<out>/mission.ndjson` and `<out>/mission.mcap`); see
//! [`crate::mission::run_mission`].

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use super::exit::{EXIT_FEASIBLE, EXIT_VIOLATIONS};
use super::plan_args::PlanArgs;
use crate::execute::live::LiveFeed;
use crate::foxglove::{self, FoxgloveArgs};
use crate::mission::{run_mission, ExecutionSettings, Injection, Place, RunOptions};

/// `shoal-coordinator run`.
#[derive(Debug, Clone, clap::Args)]
pub struct RunArgs {
    /// Planning settings, as for `plan`.
    #[command(flatten)]
    pub plan: PlanArgs,
    /// Mission seconds per wall second (50 runs a 2700 s mission in 54 s).
    #[arg(long, env = "SHOAL_TIME_SCALE", default_value_t = ExecutionSettings::DEFAULT.time_scale)]
    pub time_scale: f64,
    /// Telemetry reports per wall second and vehicle.
    #[arg(long, env = "SHOAL_TELEMETRY_HZ", default_value_t = ExecutionSettings::DEFAULT.telemetry_hz)]
    pub telemetry_hz: f64,
    /// Prediction horizon of the separation check, mission seconds, counted from when a
    /// replan's update could take effect (the replan budget plus 250 ms of wall time ahead).
    #[arg(long, env = "SHOAL_HORIZON", default_value_t = ExecutionSettings::DEFAULT.horizon_s)]
    pub horizon: f64,
    /// Cross-track error that triggers a replan, metres (default: d_min / 2; 10 m for a lone
    /// vehicle, d_min = 0).
    #[arg(long, env = "SHOAL_DEVIATION")]
    pub deviation: Option<f64>,
    /// Metres over d_min a replan keeps from the other vehicles, for their tracking error and
    /// fix noise (default: d_min / 5).
    #[arg(long, env = "SHOAL_SEPARATION_BUFFER")]
    pub separation_buffer: Option<f64>,
    /// Wall seconds without telemetry after which a vehicle is lost.
    #[arg(long, env = "SHOAL_LOST_AFTER", default_value_t = ExecutionSettings::DEFAULT.lost_after_s)]
    pub lost_after: f64,
    /// Wall-time budget of one replan, milliseconds.
    #[arg(long, env = "SHOAL_REPLAN_BUDGET_MS", default_value_t = ExecutionSettings::DEFAULT.replan_budget_ms)]
    pub replan_budget_ms: u64,
    /// Half-width of the arrival window around the common arrival time, mission seconds.
    #[arg(long, env = "SHOAL_ARRIVAL_WINDOW", default_value_t = ExecutionSettings::DEFAULT.arrival_window_s)]
    pub arrival_window: f64,
    /// Simulated vehicles: position noise of their fixes (standard deviation per axis), metres.
    #[arg(long, env = "SHOAL_POSITION_NOISE", default_value_t = ExecutionSettings::DEFAULT.position_noise_m)]
    pub position_noise: f64,
    /// Publish a hard obstacle at mission time T, as a client would: `T:X,Y,Z,R` (seconds,
    /// metres; inflation d_min, at least the --deviation tolerance), or `T:VEHICLE,R` to put it on that vehicle's planned path
    /// 150 s of mission time after T. Repeatable.
    #[arg(long = "inject-obstacle", value_parser = parse_injection)]
    pub inject: Vec<Injection>,
    /// The mission log (default: `<out>/mission.ndjson`); its MCAP copy goes beside it, with
    /// the extension `.mcap`.
    #[arg(long, env = "SHOAL_LOG")]
    pub log: Option<PathBuf>,
    /// Serve the live web view of the mission here (e.g. 127.0.0.1:8080; beyond loopback,
    /// HTTPS with the fleet's keys, or plain with --insecure).
    #[arg(long, env = "SHOAL_VIEW", value_name = "ADDR")]
    pub view: Option<std::net::SocketAddr>,
    /// Live view in Foxglove.
    #[command(flatten)]
    pub foxglove: FoxgloveArgs,
}

/// Reads `T:X,Y,Z,R` or `T:VEHICLE,R`: (time, place, radius).
fn parse_injection(s: &str) -> Result<Injection, String> {
    let (t, rest) = s
        .split_once(':')
        .ok_or_else(|| format!("{s:?}: expected T:X,Y,Z,R or T:VEHICLE,R"))?;
    let num = |v: &str| {
        v.trim()
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("{s:?}: {v:?} is not a number"))
    };
    let parts: Vec<&str> = rest.split(',').collect();
    let (place, r) = match parts.as_slice() {
        [x, y, z, r] => (Place::At([num(x)?, num(y)?, num(z)?]), num(r)?),
        [v, r] => (Place::OnPath(v.trim().to_string()), num(r)?),
        _ => return Err(format!("{s:?}: expected T:X,Y,Z,R or T:VEHICLE,R")),
    };
    if r <= 0.0 {
        return Err(format!("{s:?}: radius {r} must be positive"));
    }
    Ok(Injection {
        at_s: num(t)?,
        place,
        radius_m: r,
    })
}

impl RunArgs {
    /// The mission these flags ask for: the one place `run`'s flags become options.
    pub fn options(&self) -> anyhow::Result<RunOptions> {
        Ok(RunOptions {
            mission: self.plan.options(true)?,
            execution: ExecutionSettings {
                time_scale: self.time_scale,
                telemetry_hz: self.telemetry_hz,
                horizon_s: self.horizon,
                deviation_m: self.deviation,
                separation_buffer_m: self.separation_buffer,
                lost_after_s: self.lost_after,
                replan_budget_ms: self.replan_budget_ms,
                arrival_window_s: self.arrival_window,
                position_noise_m: self.position_noise,
                inject: self.inject.clone(),
                log: self.log.clone(),
                live: None,
            },
        })
    }
}

/// Plans, then executes; exit 0 when the execution kept d_min, stayed out of every hard
/// obstacle and every vehicle arrived in the window, 3 otherwise.
pub fn command(args: &RunArgs, shutdown: Arc<AtomicBool>) -> anyhow::Result<i32> {
    let mut options = args.options()?;
    let feed = LiveFeed::new();
    let security = args.plan.zenoh.security()?;
    let view = crate::view::start_live(args.view, &security, &feed)?;
    let foxglove = foxglove::start(&args.foxglove, &security, &feed)?;
    options.execution.live = (view.is_some() || foxglove.is_some()).then(|| Arc::clone(&feed));
    let kept = run_mission(&options, shutdown)?;
    // The clients get the end of the mission before their connections close.
    drop(foxglove);
    drop(view);
    Ok(if kept { EXIT_FEASIBLE } else { EXIT_VIOLATIONS })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn injections_are_read_and_bad_ones_named() {
        assert_eq!(
            parse_injection("1200:800,1000,900,60"),
            Ok(Injection {
                at_s: 1200.0,
                place: Place::At([800.0, 1000.0, 900.0]),
                radius_m: 60.0
            })
        );
        assert_eq!(
            parse_injection("1150:auv2,40"),
            Ok(Injection {
                at_s: 1150.0,
                place: Place::OnPath("auv2".into()),
                radius_m: 40.0
            })
        );
        let e = parse_injection("1200:800,1000,60")
            .err()
            .unwrap_or_default();
        assert!(e.contains("expected T:X,Y,Z,R or T:VEHICLE,R"), "{e}");
        let e = parse_injection("x:1,2,3,4").err().unwrap_or_default();
        assert!(e.contains("\"x\" is not a number"), "{e}");
        let e = parse_injection("5:1,2,3,-4").err().unwrap_or_default();
        assert!(e.contains("must be positive"), "{e}");
    }
}
