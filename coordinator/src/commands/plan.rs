//! `shoal-coordinator plan <SCENARIO>`: plan a scenario (in this process or over the agents)
//! and write `plan.json` and `plan.svg`.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use anyhow::{bail, Context};

use super::exit::{EXIT_FEASIBLE, EXIT_VIOLATIONS};
use super::plan_args::{distributed_options, load_scenario, plan_coverage_mission, PlanArgs};
use crate::distributed;
use crate::planning::planner;
use crate::report::out::{say, write_outputs, write_svg};
use crate::report::progress::Progress;
use crate::report::summary;

/// Plans, writes the outputs; exit 0 for a feasible plan, 3 for one with violations.
pub fn command(args: &PlanArgs, shutdown: Arc<AtomicBool>) -> anyhow::Result<i32> {
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

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    /// `plan`'s flags alone, parsed as the command line would be.
    #[derive(Parser)]
    struct Plan {
        #[command(flatten)]
        args: PlanArgs,
    }

    fn plan_args(extra: &[&str]) -> anyhow::Result<PlanArgs> {
        let scenario = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/amp-pso-1.toml");
        let mut line = vec!["plan", scenario, "--in-process"];
        line.extend_from_slice(extra);
        Ok(Plan::try_parse_from(line)?.args)
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
