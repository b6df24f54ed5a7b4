//! `shoal-coordinator bench-telemetry`: the coordinator's cost of watching a large fleet. N
//! simulated AUVs (one embedded agent process each) drive straight parallel lanes 3.7 km long,
//! 3.6 km / N apart, so no conflict interferes; the mission is time-scaled to last about
//! `--seconds` of wall time. Reported: the coordinator process's CPU use over the execution
//! (user + system time / wall time, from `/proc/self/stat`: Linux), the end-to-end telemetry
//! latency (agent send → coordinator receipt, one clock) median and p99, and the reports
//! received against those expected.
//!
//! With `--view ADDR` it measures the web view's cost: the same execution twice, side by side,
//! the view served both times, first with no page connected, then with a headless Chromium
//! showing it (`--browser`; the browser's own CPU is not the coordinator's and is not counted).

use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::{Duration, Instant};

use shoal_common::scenario::Scenario;
use shoal_common::trajectory::Trajectory;

use crate::cpu::cpu_time;
use crate::execute::{self, ExecOptions};
use crate::mission::NetworkOptions;
use crate::planning::generated::{scenario_text, Layout};

/// `shoal-coordinator bench-telemetry`.
#[derive(Debug, Clone, clap::Args)]
pub struct BenchTelemetryArgs {
    /// Simulated vehicles.
    #[arg(long, default_value_t = 32, value_parser = clap::value_parser!(u32).range(2..=128))]
    pub vehicles: u32,
    /// Telemetry rate per vehicle, Hz.
    #[arg(long, default_value_t = 2.0)]
    pub hz: f64,
    /// About how long the execution runs, wall seconds.
    #[arg(long, default_value_t = 60.0)]
    pub seconds: f64,
    /// Where the mission log and agent logs go.
    #[arg(long, default_value = "bench-telemetry")]
    pub out: std::path::PathBuf,
    /// Also measure the web view's cost: serve it here (loopback) and run the execution twice,
    /// without and then with a headless browser showing it.
    #[arg(long, value_name = "ADDR")]
    pub view: Option<std::net::SocketAddr>,
    /// The browser `--view` connects (Debian's `chromium`), run headless.
    #[arg(long, default_value = "chromium", value_name = "PATH")]
    pub browser: std::path::PathBuf,
}

/// One execution's figures, as printed.
struct Measured {
    /// Wall time of the execution, seconds.
    wall: f64,
    /// The coordinator's CPU over it, seconds (`None` without `/proc/self/stat`).
    cpu: Option<f64>,
    /// The line printed.
    line: String,
}

/// Runs the benchmark and prints its figures.
pub fn command(args: &BenchTelemetryArgs, stop: &AtomicBool) -> anyhow::Result<i32> {
    if !(args.hz.is_finite() && args.hz > 0.0 && args.seconds.is_finite() && args.seconds > 5.0) {
        anyhow::bail!("--hz must be positive and --seconds over 5");
    }
    let text = scenario_text(args.vehicles, 0, 1, Layout::Crossing);
    let mut scenario = Scenario::parse(&text, std::path::Path::new("<bench-telemetry scenario>"))?;
    scenario.name = "bench-telemetry".into();
    let n = scenario.vehicles.len();
    let speed = 1.5;
    let mut plans = Vec::with_capacity(n);
    for v in &mut scenario.vehicles {
        v.goal = [v.goal[0], v.start[1], v.start[2]];
        let (a, b) = (v.start(), v.goal());
        let mid = (a + b) / 2.0;
        let length = (b - a).norm();
        plans.push(Trajectory {
            times: vec![0.0, length / 2.0 / speed, length / speed],
            points: vec![a, mid, b],
        });
    }
    let arrival = plans.iter().map(Trajectory::arrival).fold(0.0, f64::max);
    let time_scale = arrival / args.seconds;
    std::fs::create_dir_all(&args.out)?;
    let bench = Bench {
        scenario: &scenario,
        plans: &plans,
        arrival,
        time_scale,
    };
    eprintln!(
        "bench-telemetry: {n} vehicles at {} Hz for about {:.0} s ({time_scale:.1}× real time)",
        args.hz, args.seconds
    );
    let feed = crate::execute::live::LiveFeed::new();
    let Some(server) = crate::view::start_live(
        args.view,
        &shoal_common::wire::security::Security::default(),
        &feed,
    )?
    else {
        let m = bench.measure(args, ("", ""), None, stop)?;
        crate::report::out::say(&m.line);
        return Ok(crate::commands::exit::EXIT_FEASIBLE);
    };
    let without = bench.measure(
        args,
        ("no-page", "view served, no page"),
        Some(Arc::clone(&feed)),
        stop,
    )?;
    let browser =
        super::headless::Headless::open(&args.browser, &server.url(), &args.out.join("browser"))?;
    browser.wait_for_page(server.stats(), Duration::from_secs(60))?;
    let with = bench.measure(
        args,
        ("browser", "view served, headless browser connected"),
        Some(feed),
        stop,
    )?;
    let pages = server
        .stats()
        .clients
        .load(std::sync::atomic::Ordering::SeqCst);
    drop(browser);
    let share = |m: &Measured| m.cpu.map(|c| 100.0 * c / m.wall);
    let extra = share(&with)
        .zip(share(&without))
        .map_or("unknown".into(), |(a, b)| {
            format!(
                "{:+.1} % of one core ({:+.0} % of the coordinator's)",
                a - b,
                100.0 * (a - b) / b
            )
        });
    crate::report::out::say(&format!(
        "{}{}view cost: {extra}; pages connected at the end: {pages}\n",
        without.line, with.line
    ));
    Ok(crate::commands::exit::EXIT_FEASIBLE)
}

/// The execution measured, the same each time.
struct Bench<'a> {
    /// The lanes' scenario.
    scenario: &'a Scenario,
    /// One straight plan per vehicle.
    plans: &'a [Trajectory],
    /// Arrival time, mission seconds.
    arrival: f64,
    /// Mission seconds per wall second.
    time_scale: f64,
}

impl Bench<'_> {
    /// Runs the execution once and measures it; `(name, label)` name its directory under
    /// `--out` and its line (empty: `--out` itself, no label).
    fn measure(
        &self,
        args: &BenchTelemetryArgs,
        (name, tag): (&str, &str),
        live: Option<Arc<crate::execute::live::LiveFeed>>,
        stop: &AtomicBool,
    ) -> anyhow::Result<Measured> {
        let (scenario, plans, arrival, time_scale) =
            (self.scenario, self.plans, self.arrival, self.time_scale);
        let n = plans.len();
        let dir = args.out.join(name);
        std::fs::create_dir_all(&dir)?;
        // Embedded agents on a free loopback port; a minute to join, for 128 of them.
        let mut distributed = NetworkOptions {
            join_timeout: Duration::from_secs(60),
            ..NetworkOptions::default()
        }
        .for_mission(
            format!("bench-telemetry-{}{name}", std::process::id()),
            dir.join("logs"),
        );
        distributed.agent_args = vec!["--position-noise".into(), "1".into()];
        let options = ExecOptions {
            time_scale,
            telemetry_hz: args.hz,
            horizon_s: 180.0,
            deviation_m: 25.0,
            separation_buffer_m: 10.0,
            lost_after: Duration::from_secs(5),
            replan_budget: Duration::from_millis(300),
            arrival_window_s: 60.0,
            log: dir.join("mission.ndjson"),
            inject: Vec::new(),
            quiet: true,
            seed: 1,
            live,
        };
        let cpu0 = cpu_time();
        let wall0 = Instant::now();
        let report =
            execute::execute_trajectories(scenario, plans, arrival, &distributed, &options, stop)?;
        let wall = wall0.elapsed().as_secs_f64();
        let cpu = cpu_time().zip(cpu0).map(|(a, b)| (a - b).as_secs_f64());
        let f = &report.figures;
        let expected = (n as f64 * args.hz * (arrival / time_scale)).round();
        let line = format!(
            "{}{n} vehicles, {} Hz, {wall:.1} s wall: {} reports ({expected:.0} expected over the mission), coordinator CPU {} , latency median {} ms, p99 {} ms; min separation {}; {}\n",
            if tag.is_empty() { String::new() } else { format!("{tag}: ") },
            args.hz,
            f.reports,
            cpu.map_or("unknown (no /proc/self/stat)".to_string(), |c| format!("{c:.2} s = {:.1} % of one core", 100.0 * c / wall)),
            crate::report::summary::opt(f.latency_median_ms, 2),
            crate::report::summary::opt(f.latency_p99_ms, 2),
            f.min_separation_m.map_or("–".into(), |d| format!("{d:.1} m")),
            report.ended
        );
        Ok(Measured { wall, cpu, line })
    }
}
