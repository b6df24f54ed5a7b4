//! Shoal's coordinator as a library: the binary parses its command line and calls [`run`]; tests
//! call [`run`] (or the functions it uses) directly.

pub mod acl;
pub mod bench_cages;
pub mod bench_energy;
pub mod bench_functions;
pub mod bench_pool;
pub mod bench_telemetry;
pub mod cli;
pub mod compare;
pub mod coverage_cmd;
pub mod coverage_fleet;
pub mod coverage_run;
pub mod crawler_table;
pub mod distributed;
pub mod energy_planner;
pub mod execute;
pub mod export;
pub mod generate;
pub mod geo_export;
pub mod keys;
pub mod planner;
pub mod replay;
pub mod run_cmd;
pub mod serve;
pub mod significance;
pub mod status_cmd;
pub mod summary;
pub mod svg;
pub mod svg_coverage;
pub mod svg_current;
pub mod svg_terrain;
pub mod svg_tour;
pub mod tour_planner;

use std::io::IsTerminal;
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use anyhow::{bail, Context};
use shoal_common::plan::Plan;
use shoal_common::scenario::Scenario;
use shoal_common::swarm::IterationReport;

pub use cli::{Command, PlanArgs};

/// Exit status of a plan with no violations.
pub const EXIT_FEASIBLE: i32 = 0;
/// Exit status of an error (bad input, I/O).
pub const EXIT_ERROR: i32 = 1;
/// Exit status of a plan produced with constraint violations.
pub const EXIT_VIOLATIONS: i32 = 3;

/// The log filter a command uses when `RUST_LOG` is not set.
pub fn default_log_filter(command: &Command) -> &'static str {
    match command {
        Command::Status(_) => status_cmd::DEFAULT_LOG_FILTER,
        _ => "warn",
    }
}

/// Runs one command to completion. `shutdown` ends long work early (the best result so far is
/// still written). Returns the process exit status.
pub fn run(command: Command, shutdown: Arc<AtomicBool>) -> anyhow::Result<i32> {
    match command {
        Command::Plan(args) => plan_command(&args, shutdown),
        Command::Export(args) => export::command(&args),
        Command::Compare(args) => compare_command(&args, &shutdown),
        Command::BenchFunctions(args) => bench_functions::command(&args, &shutdown),
        Command::BenchEnergy(args) => bench_energy::command(&args, &shutdown),
        Command::BenchCages(args) => bench_cages::command(&args, &shutdown),
        Command::BenchCoverage(args) => coverage_cmd::bench_coverage(&args, &shutdown),
        Command::Run(args) => run_cmd::run_command(&args, shutdown),
        Command::Replay(args) => replay::command(&args),
        Command::Serve(args) => serve::command(&args, shutdown),
        Command::BenchTelemetry(args) => bench_telemetry::command(&args, &shutdown),
        Command::Status(args) => status_cmd::command(&args),
        Command::Health(args) => {
            shoal_common::health::check(&args.file, std::time::Duration::from_secs(10))
                .map_err(anyhow::Error::msg)?;
            Ok(EXIT_FEASIBLE)
        }
        Command::Router(args) => {
            distributed::network::serve_router(&args.listen, &args.zenoh.security()?, &shutdown)?;
            Ok(EXIT_FEASIBLE)
        }
        Command::Keys(args) => keys::command(&args),
        Command::Generate(args) => {
            generate::generate(&args)?;
            say(&format!("Wrote {}\n", args.out.display()));
            Ok(EXIT_FEASIBLE)
        }
    }
}

fn compare_command(args: &compare::CompareArgs, stop: &Arc<AtomicBool>) -> anyhow::Result<i32> {
    let seeds = args.seed_range()?;
    let scenarios = args
        .scenarios
        .iter()
        .map(|p| {
            let mut s = Scenario::load(p)?;
            if let Some(i) = args.iterations {
                s.optimizer.iterations = i;
            }
            s.validate(p)?;
            // Every algorithm must fit every scenario, checked before the first run.
            for &a in &args.algorithms {
                let mut with = s.clone();
                with.optimizer.algorithm = a;
                with.validate(p)?;
            }
            Ok(s)
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let multi = args
        .algorithms
        .iter()
        .filter(|a| a.is_multi_population())
        .count();
    let per_scenario = args.algorithms.len() + if args.distributed { multi } else { 0 };
    let total = scenarios.len() * per_scenario * args.seeds as usize;
    let mut done = 0;
    let distributed = args.distributed.then(|| distributed::DistributedOptions {
        mission: String::new(),
        agents: distributed::AgentsMode::Embedded,
        listen: vec!["tcp/127.0.0.1:0".into()],
        routers: Vec::new(),
        security: Default::default(),
        join_timeout: std::time::Duration::from_secs(30),
        round_timeout: std::time::Duration::from_secs(10),
        agent_bin: None,
        log_dir: std::env::temp_dir().join("shoal-compare-logs"),
        health_file: None,
        agent_args: Vec::new(),
    });
    let cells = compare::compare(
        &scenarios,
        &args.algorithms,
        seeds.clone(),
        distributed.as_ref(),
        stop,
        &mut |p| {
            done += 1;
            eprintln!(
                "[{done}/{total}] {} {} {} seed {}: fitness {:.4}, {} in {:.2} s",
                p.scenario,
                p.algorithm,
                p.mode,
                p.seed,
                p.fitness,
                if p.feasible { "feasible" } else { "infeasible" },
                p.runtime_s
            );
        },
    )?;
    if stop.load(std::sync::atomic::Ordering::Relaxed) {
        eprintln!("interrupted: the table has only the cells completed before Ctrl-C");
    }
    let mut table = compare::seeds_line(&seeds);
    table.push_str(&compare::markdown(&cells));
    table.push_str(&significance::markdown(&significance::significance(&cells)));
    if cells.iter().any(|c| c.crawler.is_some()) {
        eprintln!(
            "computing the reference crawler paths (grid {} m)…",
            args.reference_cell
        );
        let references = crawler_table::references(&scenarios, args.reference_cell);
        table.push_str(&crawler_table::markdown(&cells, &references));
    }
    say(&table);
    if let Some(out) = &args.out {
        std::fs::write(out, &table).with_context(|| format!("cannot write {}", out.display()))?;
    }
    Ok(EXIT_FEASIBLE)
}

/// Loads a scenario and applies the command-line overrides.
pub fn load_scenario(args: &PlanArgs) -> anyhow::Result<Scenario> {
    let mut s = Scenario::load(&args.scenario)?;
    let o = &mut s.optimizer;
    // The flags given, as typed, for an error that would otherwise blame the file.
    let mut given = Vec::new();
    if let Some(v) = args.seed {
        o.seed = v;
        given.push(format!("--seed {v}"));
    }
    if let Some(v) = args.algorithm {
        o.algorithm = v;
        given.push(format!("--algorithm {}", v.as_str()));
    }
    if let Some(v) = args.iterations {
        o.iterations = v;
        given.push(format!("--iterations {v}"));
    }
    if let Some(v) = args.populations {
        o.populations = v;
        given.push(format!("--populations {v}"));
    }
    if let Some(v) = args.particles {
        o.particles = v;
        given.push(format!("--particles {v}"));
    }
    if let Some(v) = args.threads {
        o.threads = v;
        given.push(format!("--threads {v}"));
    }
    if args.no_touch_up {
        o.touch_up = false;
    }
    // Overrides are user input too: check them with the same rules, naming the field, and
    // saying that the command line set it.
    match s.validate(&args.scenario) {
        Ok(()) => Ok(s),
        Err(e) if given.is_empty() => Err(e.into()),
        Err(e) => Err(anyhow::Error::new(e).context(format!(
            "with the command line's {} over the scenario file",
            given.join(" ")
        ))),
    }
}

/// A duration from a number of seconds given by the user, or an error naming the flag.
fn seconds(flag: &str, value: f64) -> anyhow::Result<std::time::Duration> {
    match std::time::Duration::try_from_secs_f64(value) {
        Ok(d) if value > 0.0 => Ok(d),
        _ => bail!("{flag} = {value}: must be a positive number of seconds"),
    }
}

/// The distributed-mode settings the command line gives.
pub fn distributed_options(
    args: &PlanArgs,
    scenario: &Scenario,
) -> anyhow::Result<distributed::DistributedOptions> {
    let listen = if args.listen.is_empty() {
        vec![match args.agents {
            distributed::AgentsMode::Embedded => "tcp/127.0.0.1:0".to_string(),
            distributed::AgentsMode::External => "tcp/127.0.0.1:7447".to_string(),
        }]
    } else {
        args.listen.clone()
    };
    Ok(distributed::DistributedOptions {
        mission: args
            .mission
            .clone()
            .unwrap_or_else(|| distributed::default_mission_id(scenario)),
        agents: args.agents,
        listen,
        routers: args.router.clone(),
        security: match &args.link_security {
            Some(s) => s.clone(),
            None => args.zenoh.security()?,
        },
        join_timeout: seconds("--join-timeout (SHOAL_JOIN_TIMEOUT)", args.join_timeout)?,
        round_timeout: seconds("--round-timeout (SHOAL_ROUND_TIMEOUT)", args.round_timeout)?,
        agent_bin: args.agent_bin.clone(),
        log_dir: args.out.join("logs"),
        health_file: args.health_file.clone(),
        agent_args: Vec::new(),
    })
}

/// Plans a `[coverage]` mission as `plan` does (`run` too): one crawler in this process, a
/// fleet over its agents (with the options `distributed` gives) unless `--in-process`; writes
/// `plan.json` and `plan.svg` into `--out`.
pub fn plan_coverage_mission(
    args: &PlanArgs,
    scenario: &Scenario,
    shutdown: &Arc<AtomicBool>,
    distributed: impl FnOnce() -> anyhow::Result<distributed::DistributedOptions>,
) -> anyhow::Result<coverage_cmd::PlannedCoverage> {
    let Some(settings) = &scenario.coverage else {
        bail!("{}: no [coverage] table", args.scenario.display());
    };
    let fleet = scenario.vehicles.len() > 1;
    if !fleet && !args.in_process {
        bail!(
            "{}: a [coverage] mission with one crawler plans inside this process: add --in-process (several crawlers split the area among their agents)",
            args.scenario.display()
        );
    }
    if let Some(a) = args.algorithm {
        eprintln!(
            "note: --algorithm {} is not used: a [coverage] mission plans with seed 002's Boustrophedon",
            a.as_str()
        );
    }
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create output directory {}", args.out.display()))?;
    if fleet {
        let options = if args.in_process {
            None
        } else {
            Some(distributed()?)
        };
        coverage_fleet::plan_fleet_coverage(
            &args.scenario,
            scenario,
            &args.out,
            args.quiet,
            options.as_ref(),
            shutdown,
        )
    } else {
        coverage_cmd::plan_coverage_command(
            &args.scenario,
            scenario,
            settings,
            &args.out,
            args.quiet,
            shutdown,
        )
    }
}

fn plan_command(args: &PlanArgs, shutdown: Arc<AtomicBool>) -> anyhow::Result<i32> {
    let scenario = load_scenario(args)?;
    if scenario.coverage.is_some() {
        let planned = plan_coverage_mission(args, &scenario, &shutdown, || {
            distributed_options(args, &scenario)
        })?;
        return Ok(if planned.feasible {
            EXIT_FEASIBLE
        } else {
            EXIT_VIOLATIONS
        });
    }
    let algorithm = scenario.optimizer.algorithm;
    if algorithm.is_energy_planner() && !args.in_process {
        bail!(
            "{}: {} plans one AUV inside this process (seed 001 has no fleet to distribute): add --in-process",
            args.scenario.display(),
            algorithm.as_str()
        );
    }
    let options = if args.in_process {
        None
    } else {
        Some(distributed_options(args, &scenario)?)
    };
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create output directory {}", args.out.display()))?;
    tracing::info!(
        scenario = %scenario.name,
        algorithm = scenario.optimizer.algorithm.as_str(),
        seed = scenario.optimizer.seed,
        distributed = options.is_some(),
        "planning"
    );
    let mut progress = Progress::new(scenario.optimizer.iterations, args.quiet);
    let plan = match &options {
        None => planner::plan_in_process(&scenario, Some(shutdown), &mut |r| progress.update(r)),
        Some(o) => distributed::plan_distributed(&scenario, o, &shutdown, &mut |s| {
            progress.update_distributed(s)
        })?,
    };
    progress.finish();
    write_outputs(&args.out, &plan)?;
    write_svg(&args.out, &scenario, &plan)?;
    say(&summary::summary(&plan));
    say(&format!(
        "Wrote {} and {}\n",
        args.out.join("plan.json").display(),
        args.out.join("plan.svg").display()
    ));
    Ok(if plan.feasible {
        EXIT_FEASIBLE
    } else {
        EXIT_VIOLATIONS
    })
}

/// Writes `plan.json` (and `plan.svg`) into `dir`.
pub fn write_outputs(dir: &Path, plan: &Plan) -> anyhow::Result<()> {
    let json = serde_json::to_string_pretty(plan).context("cannot serialise the plan")?;
    let path = dir.join("plan.json");
    std::fs::write(&path, json).with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}

/// Writes `plan.svg` into `dir`.
pub fn write_svg(dir: &Path, scenario: &Scenario, plan: &Plan) -> anyhow::Result<()> {
    let svg = svg::render_plan(scenario, plan)?;
    let path = dir.join("plan.svg");
    std::fs::write(&path, svg).with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}

/// Prints to stdout; a closed pipe (`| head`) is not an error worth a panic.
pub(crate) fn say(text: &str) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    let _ = out.write_all(text.as_bytes()).and_then(|()| out.flush());
}

/// Progress on stderr: a bar on a terminal; otherwise a line after the first iteration, every
/// tenth of the run, and at least every [`PROGRESS_EVERY`].
struct Progress {
    bar: Option<indicatif::ProgressBar>,
    every: usize,
    quiet: bool,
    last: Option<std::time::Instant>,
}

/// Longest silence on a non-terminal stderr during a run.
const PROGRESS_EVERY: std::time::Duration = std::time::Duration::from_secs(2);

impl Progress {
    fn new(iterations: usize, quiet: bool) -> Progress {
        let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
            let b = indicatif::ProgressBar::new(iterations as u64);
            let style = indicatif::ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} iterations  {msg}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
            b.set_style(style);
            b
        });
        Progress {
            bar,
            every: (iterations / 10).max(1),
            quiet,
            last: None,
        }
    }

    fn update(&mut self, r: &IterationReport) {
        let msg = format!(
            "best fitness {:.4}, {} evaluations",
            r.best_cost, r.evaluations
        );
        self.show(r.iteration, r.max_iterations, msg);
    }

    fn update_distributed(&mut self, s: &distributed::mission::Status) {
        let msg = format!(
            "best fitness {:.4}, agents alive {}/{}",
            s.best_cost, s.alive, s.vehicles
        );
        self.show(s.iteration, s.max_iterations, msg);
    }

    fn show(&mut self, iteration: usize, max_iterations: usize, msg: String) {
        if let Some(b) = &self.bar {
            b.set_position(iteration as u64);
            b.set_message(msg);
        } else if !self.quiet {
            let due = self.last.is_none_or(|t| t.elapsed() >= PROGRESS_EVERY)
                || iteration.is_multiple_of(self.every)
                || iteration == max_iterations;
            if due {
                eprintln!("iteration {iteration}/{max_iterations}: {msg}");
                self.last = Some(std::time::Instant::now());
            }
        }
    }

    fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    fn plan_args(extra: &[&str]) -> anyhow::Result<PlanArgs> {
        let scenario = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/amp-pso-1.toml");
        let mut line = vec!["shoal-coordinator", "plan", scenario, "--in-process"];
        line.extend_from_slice(extra);
        match cli::Cli::try_parse_from(line)?.command {
            cli::Command::Plan(a) => Ok(a),
            _ => anyhow::bail!("not a plan command"),
        }
    }

    /// A flag that breaks a rule is named as the command line's, not blamed on the file; the
    /// file's own fields are checked as before.
    #[test]
    fn an_override_that_breaks_a_rule_is_told_as_the_command_lines() -> anyhow::Result<()> {
        let e = load_scenario(&plan_args(&["--iterations", "0", "--seed", "4"])?)
            .err()
            .map(|e| format!("{e:#}"))
            .unwrap_or_default();
        assert!(
            e.starts_with(
                "with the command line's --seed 4 --iterations 0 over the scenario file: "
            ) && e.contains("`optimizer.iterations` = 0"),
            "{e}"
        );
        let s = load_scenario(&plan_args(&["--iterations", "7"])?)?;
        assert_eq!(s.optimizer.iterations, 7);
        Ok(())
    }

    #[test]
    fn plans_are_touched_up_unless_the_command_line_says_not() -> anyhow::Result<()> {
        assert!(load_scenario(&plan_args(&[])?)?.optimizer.touch_up);
        assert!(
            !load_scenario(&plan_args(&["--no-touch-up"])?)?
                .optimizer
                .touch_up
        );
        Ok(())
    }
}
