//! Shoal's vehicle agent as a library: the binary parses its command line ([`AgentArgs`]),
//! turns it into an [`AgentConfig`] and calls [`run`]; tests build the config and call [`run`]
//! directly.
//!
//! An agent serves one vehicle. It connects to the coordinator's router as a Zenoh client
//! (waiting for it if it is not up yet), declares a liveliness token so the coordinator sees it,
//! and serves every mission that assigns its vehicle — several at once if they come — until it
//! is stopped. The layers stay apart so a vehicle link can be added without touching the swarm:
//! - [`args`] and [`config`]: the command line, and the typed configuration it becomes in one
//!   place ([`AgentArgs::config`]);
//! - [`network`]: the Zenoh session, subscriptions, decoding and counting of bad messages;
//! - [`assignment`]: what a mission hands an agent and what it hands back, below both ways of
//!   planning;
//! - [`mission`]: one mission's planning loop, fed messages through a channel and sending
//!   through a closure, with no knowledge of Zenoh;
//! - [`execute`]: one execution: the vehicle drives its plan through its [`link::VehicleLink`]
//!   and the agent reports telemetry;
//! - [`link`]: the vehicle-link seam (a simulator now; real vehicles plug in there);
//! - [`parent_watch`]: an embedded agent leaves when the coordinator that started it is gone.

pub mod args;
pub mod assignment;
pub mod config;
pub mod execute;
pub mod link;
pub mod mission;
pub mod network;
mod one_shot;
pub mod parent_watch;

use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

pub use args::AgentArgs;
pub use config::AgentConfig;

/// Oldest a health file may be for `--health-check` to pass.
pub const HEALTH_MAX_AGE: Duration = Duration::from_secs(10);

/// The container healthcheck (`--health-check`): fine if `file` was rewritten in the last
/// [`HEALTH_MAX_AGE`].
pub fn health_check(file: Option<&Path>) -> anyhow::Result<()> {
    let Some(file) = file else {
        anyhow::bail!("--health-check needs --health-file (SHOAL_HEALTH_FILE)");
    };
    shoal_common::health::check(file, HEALTH_MAX_AGE).map_err(anyhow::Error::msg)
}

/// Runs the agent until `shutdown` is raised (or, with `once`, until its first mission ends).
/// With a `parent`, it also stops when that process is no longer its parent ([`parent_watch`]).
pub fn run(config: AgentConfig, shutdown: Arc<AtomicBool>) -> anyhow::Result<()> {
    if let Some(parent) = config.parent {
        parent_watch::start(parent, &config.vehicle, Arc::clone(&shutdown));
    }
    network::serve(&config, &shutdown)
}
