//! What every planning command writes: `plan.json`, `plan.svg`, and text on stdout.

use std::path::Path;

use anyhow::Context;
use shoal_common::plan::Plan;
use shoal_common::scenario::Scenario;

use crate::report::svg;

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
pub fn say(text: &str) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    let _ = out.write_all(text.as_bytes()).and_then(|()| out.flush());
}
