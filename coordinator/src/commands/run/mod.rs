//! `shoal-coordinator run <SCENARIO>`: plan (as `plan` does), then execute the plan with one
//! agent per vehicle driving it through its vehicle link, and report the execution's figures
//! (`<out>/execution.json`, the mission log `<out>/mission.ndjson`).

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

use anyhow::{bail, Context as _};
use shoal_common::scenario::{Obstacle, ObstacleKind, Scenario};
use shoal_common::trajectory::Trajectory;

use super::exit::{EXIT_FEASIBLE, EXIT_VIOLATIONS};
use super::plan_args::{distributed_options, load_scenario, PlanArgs};
use crate::distributed;
use crate::execute::{self, verdict, ExecOptions, ExecutionReport};
use crate::planning::planner;
use crate::report::out::{say, write_outputs, write_svg};
use crate::report::progress::Progress;
use crate::report::summary;

pub mod coverage;
pub mod executable;

pub use executable::{executable, Executable};

/// `shoal-coordinator run`.
#[derive(Debug, Clone, clap::Args)]
pub struct RunArgs {
    /// Planning settings, as for `plan`.
    #[command(flatten)]
    pub plan: PlanArgs,
    /// Mission seconds per wall second (50 runs a 2700 s mission in 54 s).
    #[arg(long, env = "SHOAL_TIME_SCALE", default_value_t = 1.0)]
    pub time_scale: f64,
    /// Telemetry reports per wall second and vehicle.
    #[arg(long, env = "SHOAL_TELEMETRY_HZ", default_value_t = 2.0)]
    pub telemetry_hz: f64,
    /// Prediction horizon of the separation check, mission seconds, counted from when a
    /// replan's update could take effect (the replan budget plus 250 ms of wall time ahead).
    #[arg(long, env = "SHOAL_HORIZON", default_value_t = 180.0)]
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
    #[arg(long, env = "SHOAL_LOST_AFTER", default_value_t = 3.0)]
    pub lost_after: f64,
    /// Wall-time budget of one replan, milliseconds.
    #[arg(long, env = "SHOAL_REPLAN_BUDGET_MS", default_value_t = 300)]
    pub replan_budget_ms: u64,
    /// Half-width of the arrival window around the common arrival time, mission seconds.
    #[arg(long, env = "SHOAL_ARRIVAL_WINDOW", default_value_t = 30.0)]
    pub arrival_window: f64,
    /// Simulated vehicles: position noise of their fixes (standard deviation per axis), metres.
    #[arg(long, env = "SHOAL_POSITION_NOISE", default_value_t = 1.0)]
    pub position_noise: f64,
    /// Publish a hard obstacle at mission time T, as a client would: `T:X,Y,Z,R` (seconds,
    /// metres; inflation d_min, at least the --deviation tolerance), or `T:VEHICLE,R` to put it on that vehicle's planned path
    /// 150 s of mission time after T. Repeatable.
    #[arg(long = "inject-obstacle", value_parser = parse_injection)]
    pub inject: Vec<(f64, Place, f64)>,
    /// The mission log (default: `<out>/mission.ndjson`).
    #[arg(long, env = "SHOAL_LOG")]
    pub log: Option<PathBuf>,
}

/// Where an injected obstacle goes.
#[derive(Debug, Clone, PartialEq)]
pub enum Place {
    /// At a point, metres.
    At([f64; 3]),
    /// On a vehicle's planned path, [`AHEAD_S`] after the injection time.
    OnPath(String),
}

/// How far ahead on a vehicle's planned path `T:VEHICLE,R` puts the obstacle, mission seconds.
pub const AHEAD_S: f64 = 150.0;

/// Reads `T:X,Y,Z,R` or `T:VEHICLE,R`: (time, place, radius).
fn parse_injection(s: &str) -> Result<(f64, Place, f64), String> {
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
    Ok((num(t)?, place, r))
}

/// Cross-track tolerance for a lone vehicle (d_min = 0, nothing to keep apart), metres: the
/// simulated AUV tracks to within 2–9 m in seed 001's current, so 10 m means it is really off.
pub const LONE_DEVIATION_M: f64 = 10.0;

/// `--deviation`'s default: half of d_min, so that two vehicles each off by less cannot close
/// the gap between them, or [`LONE_DEVIATION_M`] when the mission keeps no separation.
fn default_deviation(d_min: f64) -> f64 {
    if d_min > 0.0 {
        d_min / 2.0
    } else {
        LONE_DEVIATION_M
    }
}

/// The margin of an injected obstacle: d_min, as the scenario's own obstacles keep, but never
/// less than the cross-track error a vehicle may have before it is replanned (a lone vehicle's
/// d_min is 0, and a way round the bare sphere let its track graze 1.3 m into it).
fn injected_inflation(d_min: f64, deviation: f64) -> f64 {
    d_min.max(deviation)
}

/// A positive number of seconds, or an error naming the flag.
fn positive(flag: &str, v: f64) -> anyhow::Result<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        bail!("{flag} = {v}: must be a positive number")
    }
}

/// `--separation-buffer`, or d_min / 5: the simulated AUV tracks its trajectory to within
/// 2–5 m (p95 about 2.5 m, fix noise included), and two of them may err towards each other.
fn separation_buffer(flag: Option<f64>, d_min: f64) -> anyhow::Result<f64> {
    let buffer = flag.unwrap_or(d_min / 5.0);
    if !(buffer.is_finite() && buffer >= 0.0) {
        bail!("--separation-buffer (SHOAL_SEPARATION_BUFFER) = {buffer}: must be ≥ 0");
    }
    Ok(buffer)
}

/// Plans a fleet, energy or tour mission as `plan` does and writes its outputs; `None` (after
/// saying why) when the plan is not to be executed: infeasible, or Ctrl-C while planning.
fn plan_trajectories(
    p: &PlanArgs,
    scenario: &Scenario,
    options: &distributed::DistributedOptions,
    shutdown: &Arc<AtomicBool>,
) -> anyhow::Result<Option<Executable>> {
    let mut progress = Progress::new(scenario.optimizer.iterations, p.quiet);
    let plan = if p.in_process {
        planner::plan_in_process(scenario, Some(Arc::clone(shutdown)), &mut |r| {
            progress.update(r)
        })
    } else {
        distributed::plan_distributed(scenario, options, shutdown, &mut |s| {
            progress.update_distributed(s)
        })?
    };
    progress.finish();
    write_outputs(&p.out, &plan)?;
    write_svg(&p.out, scenario, &plan)?;
    say(&summary::summary(&plan));
    if !executable(plan.feasible, shutdown) {
        return Ok(None);
    }
    Ok(Some(Executable {
        scenario: scenario.clone(),
        trajectories: plan
            .vehicles
            .iter()
            .map(|v| Trajectory::from_samples(&v.trajectory))
            .collect(),
        common_arrival_s: plan.common_arrival_s,
    }))
}

/// Plans, then executes; exit 0 when the execution kept d_min, stayed out of every hard
/// obstacle and every vehicle arrived in the window, 3 otherwise.
pub fn command(args: &RunArgs, shutdown: Arc<AtomicBool>) -> anyhow::Result<i32> {
    let p = &args.plan;
    let scenario = load_scenario(p)?;
    positive("--time-scale (SHOAL_TIME_SCALE)", args.time_scale)?;
    positive("--telemetry-hz (SHOAL_TELEMETRY_HZ)", args.telemetry_hz)?;
    positive("--horizon (SHOAL_HORIZON)", args.horizon)?;
    positive("--lost-after (SHOAL_LOST_AFTER)", args.lost_after)?;
    positive(
        "--arrival-window (SHOAL_ARRIVAL_WINDOW)",
        args.arrival_window,
    )?;
    if !(args.position_noise.is_finite() && args.position_noise >= 0.0) {
        bail!(
            "--position-noise (SHOAL_POSITION_NOISE) = {}: must be ≥ 0",
            args.position_noise
        );
    }
    let d_min = scenario.fleet.d_min_m;
    let deviation = positive(
        "--deviation (SHOAL_DEVIATION)",
        args.deviation.unwrap_or(default_deviation(d_min)),
    )?;
    let buffer = separation_buffer(args.separation_buffer, d_min)?;
    std::fs::create_dir_all(&p.out)
        .with_context(|| format!("cannot create output directory {}", p.out.display()))?;
    // The log's directory too, as for --out, and before planning: a bad --log is told at once,
    // not after the plan.
    let log = args
        .log
        .clone()
        .unwrap_or_else(|| p.out.join("mission.ndjson"));
    if let Some(dir) = log.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| {
            format!(
                "--log (SHOAL_LOG) {}: cannot create its directory {}",
                log.display(),
                dir.display()
            )
        })?;
    }
    let mut options = distributed_options(p, &scenario)?;
    // The execution is the mission (its keys are shoal/<mission>/…); planning is its own.
    let mission = options.mission.clone();
    options.mission = format!("{mission}-plan");
    let executable = if scenario.coverage.is_some() {
        coverage::plan(p, &scenario, &options, buffer, &shutdown)?
    } else {
        plan_trajectories(p, &scenario, &options, &shutdown)?
    };
    let Some(Executable {
        scenario,
        trajectories,
        common_arrival_s,
    }) = executable
    else {
        return Ok(EXIT_VIOLATIONS);
    };
    options.mission = mission;
    options.agent_args = vec!["--position-noise".into(), args.position_noise.to_string()];
    options.log_dir = p.out.join("logs-exec");
    let exec = ExecOptions {
        time_scale: args.time_scale,
        telemetry_hz: args.telemetry_hz,
        horizon_s: args.horizon,
        deviation_m: deviation,
        separation_buffer_m: buffer,
        lost_after: Duration::from_secs_f64(args.lost_after),
        replan_budget: Duration::from_millis(args.replan_budget_ms),
        arrival_window_s: args.arrival_window,
        log: log.clone(),
        inject: args
            .inject
            .iter()
            .enumerate()
            .map(|(k, (t, place, r))| {
                let centre = match place {
                    Place::At(c) => *c,
                    Place::OnPath(v) => {
                        let i = scenario
                            .vehicles
                            .iter()
                            .position(|x| &x.id == v)
                            .ok_or_else(|| {
                                anyhow::anyhow!(
                                    "--inject-obstacle: the scenario has no vehicle {v:?}"
                                )
                            })?;
                        let c = trajectories[i].position_at(t + AHEAD_S);
                        [c.x, c.y, c.z]
                    }
                };
                Ok((
                    *t,
                    Obstacle {
                        id: format!("injected#{}", k + 1),
                        kind: ObstacleKind::Hard,
                        centre,
                        radius_m: *r,
                        inflation_m: injected_inflation(d_min, deviation),
                    },
                ))
            })
            .collect::<anyhow::Result<_>>()?,
        quiet: p.quiet,
        seed: scenario.optimizer.seed,
    };
    eprintln!(
        "executing mission {} at {}× real time ({} vehicles, telemetry {} Hz)",
        options.mission,
        args.time_scale,
        scenario.vehicles.len(),
        args.telemetry_hz
    );
    let report = execute::execute_trajectories(
        &scenario,
        &trajectories,
        common_arrival_s,
        &options,
        &exec,
        &shutdown,
    )?;
    let path = p.out.join("execution.json");
    let json = serde_json::to_string_pretty(&report).context("cannot serialise the execution")?;
    std::fs::write(&path, json).with_context(|| format!("cannot write {}", path.display()))?;
    say(&execution_summary(&report));
    say(&format!("Wrote {} and {}\n", path.display(), log.display()));
    Ok(if execution_ok(&report) {
        EXIT_FEASIBLE
    } else {
        EXIT_VIOLATIONS
    })
}

/// Whether the execution met everything [`verdict::failures`] checks.
pub fn execution_ok(r: &ExecutionReport) -> bool {
    verdict::failures(&r.figures).is_empty()
}

/// The human summary of an execution.
pub fn execution_summary(r: &ExecutionReport) -> String {
    let f = &r.figures;
    let mut s = format!("Execution: {}\n", r.ended);
    for v in &f.vehicles {
        s.push_str(&verdict::vehicle_line(v));
    }
    s.push_str(&format!(
        "  fleet: min separation {} (d_min {:.0} m){}, arrival window {:.0} ± {:.0} s, {} replans, {} holds\n",
        f.min_separation_m.map_or("–".to_string(), |d| format!("{d:.1} m")),
        f.d_min_m,
        f.min_separation_pair
            .as_ref()
            .map_or(String::new(), |p| format!(" between {} and {}", p[0], p[1])),
        f.common_arrival_s,
        f.arrival_window_s,
        r.replans,
        r.holds
    ));
    s.push_str(&verdict::coverage_line(f));
    s.push_str(&format!(
        "  telemetry: {} reports, latency median {} ms, p99 {} ms; the loop's longest pause {:.0} ms\n",
        f.reports,
        crate::report::summary::opt(f.latency_median_ms, 2),
        crate::report::summary::opt(f.latency_p99_ms, 2),
        r.loop_longest_pause_ms
    ));
    if !r.obstacle_decision_ms.is_empty() || !r.update_delivery_ms.is_empty() {
        s.push_str(&format!(
            "  replans: obstacle → update sent {}; update → first report on it {}\n",
            ms_list(&r.obstacle_decision_ms),
            ms_list(&r.update_delivery_ms)
        ));
    }
    s.push_str(&verdict::verdict_line(f));
    s
}

/// Durations as `12, 336 ms`, or "–" for none (e.g. every vehicle an obstacle blocked was held
/// first, so no update went out at once).
fn ms_list(ms: &[f64]) -> String {
    if ms.is_empty() {
        return "–".to_string();
    }
    let each: Vec<String> = ms.iter().map(|v| format!("{v:.0}")).collect();
    format!("{} ms", each.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_deviation_defaults_to_half_of_d_min_or_ten_metres_alone() {
        assert!((default_deviation(50.0) - 25.0).abs() < 1e-12);
        assert!((default_deviation(20.0) - 10.0).abs() < 1e-12);
        // seed 001's lone AUV (d_min 0) gets a tolerance, not an error about a flag.
        assert!((default_deviation(0.0) - LONE_DEVIATION_M).abs() < 1e-12);
        assert!(positive("--deviation", default_deviation(0.0)).is_ok());
    }

    #[test]
    fn an_injected_obstacle_keeps_d_min_or_the_deviation_tolerance() {
        assert!((injected_inflation(50.0, 25.0) - 50.0).abs() < 1e-12);
        assert!((injected_inflation(0.0, LONE_DEVIATION_M) - 10.0).abs() < 1e-12);
        assert!((injected_inflation(20.0, 30.0) - 30.0).abs() < 1e-12);
    }

    #[test]
    fn durations_read_as_a_list_of_milliseconds() {
        assert_eq!(ms_list(&[]), "–");
        assert_eq!(ms_list(&[336.0]), "336 ms");
        assert_eq!(ms_list(&[12.4, 336.6]), "12, 337 ms");
    }

    #[test]
    fn the_separation_buffer_defaults_to_a_fifth_of_d_min_and_bad_ones_are_named() {
        assert!((separation_buffer(None, 50.0).unwrap_or(f64::NAN) - 10.0).abs() < 1e-12);
        assert_eq!(separation_buffer(Some(0.0), 50.0).ok(), Some(0.0));
        assert_eq!(separation_buffer(Some(7.5), 50.0).ok(), Some(7.5));
        for bad in [-1.0, f64::NAN, f64::INFINITY] {
            let e = separation_buffer(Some(bad), 50.0)
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default();
            assert!(
                e.contains("--separation-buffer") && e.contains(&bad.to_string()),
                "{bad}: {e:?}"
            );
        }
    }

    /// A --log whose directory cannot be made (a file stands there) is an error naming the
    /// flag, told before any planning (it used to come after the plan, from the execution).
    #[test]
    fn a_bad_log_path_is_told_before_planning() -> anyhow::Result<()> {
        use clap::Parser;
        let dir = std::env::temp_dir().join(format!("shoal-run-log-{}", std::process::id()));
        std::fs::create_dir_all(&dir)?;
        let file = dir.join("a-file");
        std::fs::write(&file, "")?;
        let scenario = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/amp-pso-1.toml");
        let log = file.join("m.ndjson");
        let out = dir.join("out");
        #[derive(clap::Parser)]
        struct Run {
            #[command(flatten)]
            args: RunArgs,
        }
        let cli = Run::try_parse_from([
            "run".as_ref(),
            scenario.as_ref(),
            "--in-process".as_ref(),
            "--iterations".as_ref(),
            "3".as_ref(),
            "--log".as_ref(),
            log.as_os_str(),
            "--out".as_ref(),
            out.as_os_str(),
        ] as [&std::ffi::OsStr; 9])?;
        let args = cli.args;
        let e = command(&args, Arc::new(AtomicBool::new(false)))
            .err()
            .map(|e| format!("{e:#}"))
            .unwrap_or_default();
        std::fs::remove_dir_all(&dir)?;
        assert!(
            e.contains("--log (SHOAL_LOG)") && e.contains("a-file"),
            "{e}"
        );
        Ok(())
    }

    #[test]
    fn injections_are_read_and_bad_ones_named() {
        assert_eq!(
            parse_injection("1200:800,1000,900,60"),
            Ok((1200.0, Place::At([800.0, 1000.0, 900.0]), 60.0))
        );
        assert_eq!(
            parse_injection("1150:auv2,40"),
            Ok((1150.0, Place::OnPath("auv2".into()), 40.0))
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
