//! Planning a mission, in this process or over the agents, and writing `plan.json` and
//! `plan.svg`: what `plan` does, and the first half of `run`.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use anyhow::{bail, Context};
use shoal_common::scenario::Scenario;

use super::options::{load_scenario, MissionOptions};
use crate::distributed::{self, DistributedOptions};
use crate::planning::{coverage, coverage_fleet, planner};
use crate::report::out::{say, write_outputs, write_svg};
use crate::report::progress::Progress;
use crate::report::{crawler_gap, summary};

/// Plans the mission and writes its outputs into `options.out`; whether the plan is feasible.
/// `shutdown` ends the search early (the best plan so far is still written).
pub fn plan_mission(options: &MissionOptions, shutdown: Arc<AtomicBool>) -> anyhow::Result<bool> {
    let scenario = load_scenario(&options.scenario, &options.overrides)?;
    if scenario.coverage.is_some() {
        let planned = plan_coverage_mission(options, &scenario, &shutdown, || {
            Ok(options.network()?.distributed(&scenario, logs(options)))
        })?;
        return Ok(planned.feasible);
    }
    let algorithm = scenario.optimizer.algorithm;
    if algorithm.is_energy_planner() && !options.in_process {
        bail!(
            "{}: {} plans one AUV inside this process (Zhang et al. 2022 has no fleet to distribute): add --in-process",
            options.scenario.display(),
            algorithm.as_str()
        );
    }
    let distributed = if options.in_process {
        None
    } else {
        Some(options.network()?.distributed(&scenario, logs(options)))
    };
    std::fs::create_dir_all(&options.out)
        .with_context(|| format!("cannot create output directory {}", options.out.display()))?;
    tracing::info!(
        scenario = %scenario.name,
        algorithm = scenario.optimizer.algorithm.as_str(),
        seed = scenario.optimizer.seed,
        distributed = distributed.is_some(),
        "planning"
    );
    let mut progress = Progress::new(scenario.optimizer.iterations, options.quiet);
    let mut plan = match &distributed {
        None => planner::plan_in_process(&scenario, Some(Arc::clone(&shutdown)), &mut |r| {
            progress.update(r)
        }),
        Some(o) => distributed::plan_distributed(&scenario, o, &shutdown, &mut |s| {
            progress.update_distributed(s)
        })?,
    };
    progress.finish();
    if !shutdown.load(std::sync::atomic::Ordering::Relaxed) {
        plan.notices.extend(crawler_gap::notices(&scenario, &plan));
    }
    write_outputs(&options.out, &plan)?;
    write_svg(&options.out, &scenario, &plan)?;
    say(&summary::summary(&plan));
    say(&format!(
        "Wrote {} and {}\n",
        options.out.join("plan.json").display(),
        options.out.join("plan.svg").display()
    ));
    Ok(plan.feasible)
}

/// Where embedded agents write their logs while they plan: `<out>/logs`.
pub fn logs(options: &MissionOptions) -> std::path::PathBuf {
    options.out.join("logs")
}

/// Plans a `[coverage]` mission: one crawler in this process, a fleet over its agents (with
/// the options `distributed` gives) unless in-process; writes `plan.json` and `plan.svg` into
/// `out`.
pub fn plan_coverage_mission(
    options: &MissionOptions,
    scenario: &Scenario,
    shutdown: &Arc<AtomicBool>,
    distributed: impl FnOnce() -> anyhow::Result<DistributedOptions>,
) -> anyhow::Result<coverage::PlannedCoverage> {
    let Some(settings) = &scenario.coverage else {
        bail!("{}: no [coverage] table", options.scenario.display());
    };
    let fleet = scenario.vehicles.len() > 1;
    if !fleet && !options.in_process {
        bail!(
            "{}: a [coverage] mission with one crawler plans inside this process: add --in-process (several crawlers split the area among their agents)",
            options.scenario.display()
        );
    }
    if let Some(a) = options.overrides.algorithm {
        eprintln!(
            "note: --algorithm {} is not used: a [coverage] mission plans with CPP-DSMV's Boustrophedon",
            a.as_str()
        );
    }
    std::fs::create_dir_all(&options.out)
        .with_context(|| format!("cannot create output directory {}", options.out.display()))?;
    if fleet {
        let distributed = if options.in_process {
            None
        } else {
            Some(distributed()?)
        };
        coverage_fleet::plan_fleet_coverage(
            &options.scenario,
            scenario,
            &options.out,
            options.quiet,
            distributed.as_ref(),
            shutdown,
        )
    } else {
        coverage::plan_coverage_command(
            &options.scenario,
            scenario,
            settings,
            &options.out,
            options.quiet,
            shutdown,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::super::options::Overrides;
    use super::*;

    fn scenario() -> std::path::PathBuf {
        concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/amp-pso-1.toml").into()
    }

    /// An override that breaks a rule is named as the command line's, not blamed on the file;
    /// the file's own fields are checked as before.
    #[test]
    fn an_override_that_breaks_a_rule_is_told_as_the_command_lines() -> anyhow::Result<()> {
        let bad = Overrides {
            iterations: Some(0),
            seed: Some(4),
            ..Overrides::default()
        };
        let e = load_scenario(&scenario(), &bad)
            .err()
            .map(|e| format!("{e:#}"))
            .unwrap_or_default();
        assert!(
            e.starts_with(
                "with the command line's --seed 4 --iterations 0 over the scenario file: "
            ) && e.contains("`optimizer.iterations` = 0"),
            "{e}"
        );
        let seven = Overrides {
            iterations: Some(7),
            ..Overrides::default()
        };
        assert_eq!(load_scenario(&scenario(), &seven)?.optimizer.iterations, 7);
        Ok(())
    }

    #[test]
    fn plans_are_touched_up_unless_the_overrides_say_not() -> anyhow::Result<()> {
        assert!(
            load_scenario(&scenario(), &Overrides::default())?
                .optimizer
                .touch_up
        );
        let off = Overrides {
            no_touch_up: true,
            ..Overrides::default()
        };
        assert!(!load_scenario(&scenario(), &off)?.optimizer.touch_up);
        Ok(())
    }
}
