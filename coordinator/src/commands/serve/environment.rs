//! The `SHOAL_*` variables of `run`'s flags that reach the missions `serve` runs. A submission
//! says only what its [`super::Submission`] holds; every other setting of its mission is `run`'s
//! default, or what the operator put in serve's environment for `run` (a longer join timeout,
//! the agent binary, a healthcheck file…). Read here, once per mission, by the names `run`'s
//! flags read them; the settings serve decides itself (output, mission id, network, security,
//! quiet) are not among them.

use std::ffi::OsString;
use std::path::PathBuf;
use std::str::FromStr;

use anyhow::bail;

use crate::mission::options::seconds;
use crate::mission::RunOptions;

/// A variable's value, `None` when unset or empty (as clap's `env` takes it).
fn raw(name: &str) -> Option<OsString> {
    std::env::var_os(name).filter(|v| !v.is_empty())
}

/// A variable read as a `T`, or an error naming it and its value.
fn parsed<T: FromStr>(name: &str) -> anyhow::Result<Option<T>> {
    let Some(v) = raw(name) else {
        return Ok(None);
    };
    match v.to_str().map(str::parse) {
        Some(Ok(x)) => Ok(Some(x)),
        _ => bail!("{name} = {v:?}: not a valid value"),
    }
}

/// A path variable.
fn path(name: &str) -> Option<PathBuf> {
    raw(name).map(PathBuf::from)
}

/// Puts the environment's settings over `options` (which `run`'s defaults fill).
pub fn overlay(options: &mut RunOptions) -> anyhow::Result<()> {
    let m = &mut options.mission;
    let o = &mut m.overrides;
    o.seed = parsed("SHOAL_SEED")?;
    o.algorithm = parsed("SHOAL_ALGORITHM")?;
    o.iterations = parsed("SHOAL_ITERATIONS")?;
    o.populations = parsed("SHOAL_POPULATIONS")?;
    o.particles = parsed("SHOAL_PARTICLES")?;
    o.threads = parsed("SHOAL_THREADS")?;
    o.no_touch_up = parsed("SHOAL_NO_TOUCH_UP")?.unwrap_or(false);
    o.no_refine = parsed("SHOAL_NO_REFINE")?.unwrap_or(false);
    m.in_process = parsed("SHOAL_IN_PROCESS")?.unwrap_or(false);
    if let Some(n) = m.network.as_mut() {
        if let Some(s) = parsed("SHOAL_JOIN_TIMEOUT")? {
            n.join_timeout = seconds("--join-timeout (SHOAL_JOIN_TIMEOUT)", s)?;
        }
        if let Some(s) = parsed("SHOAL_ROUND_TIMEOUT")? {
            n.round_timeout = seconds("--round-timeout (SHOAL_ROUND_TIMEOUT)", s)?;
        }
        n.agent_bin = path("SHOAL_AGENT_BIN");
        n.health_file = path("SHOAL_HEALTH_FILE");
    }
    let e = &mut options.execution;
    let f64s: [(&str, &mut f64); 6] = [
        ("SHOAL_TIME_SCALE", &mut e.time_scale),
        ("SHOAL_TELEMETRY_HZ", &mut e.telemetry_hz),
        ("SHOAL_HORIZON", &mut e.horizon_s),
        ("SHOAL_LOST_AFTER", &mut e.lost_after_s),
        ("SHOAL_ARRIVAL_WINDOW", &mut e.arrival_window_s),
        ("SHOAL_POSITION_NOISE", &mut e.position_noise_m),
    ];
    for (name, field) in f64s {
        if let Some(v) = parsed(name)? {
            *field = v;
        }
    }
    e.deviation_m = parsed("SHOAL_DEVIATION")?;
    e.separation_buffer_m = parsed("SHOAL_SEPARATION_BUFFER")?;
    if let Some(ms) = parsed("SHOAL_REPLAN_BUDGET_MS")? {
        e.replan_budget_ms = ms;
    }
    e.log = path("SHOAL_LOG");
    Ok(())
}
