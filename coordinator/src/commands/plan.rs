//! `shoal-coordinator plan <SCENARIO>`: plan a scenario (in this process or over the agents)
//! and write `plan.json` and `plan.svg` ([`crate::mission::plan_mission`]).

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use super::exit::{EXIT_FEASIBLE, EXIT_VIOLATIONS};
use super::plan_args::PlanArgs;
use crate::mission::plan_mission;

/// Plans, writes the outputs; exit 0 for a feasible plan, 3 for one with violations.
pub fn command(args: &PlanArgs, shutdown: Arc<AtomicBool>) -> anyhow::Result<i32> {
    Ok(if plan_mission(&args.options(false)?, shutdown)? {
        EXIT_FEASIBLE
    } else {
        EXIT_VIOLATIONS
    })
}
