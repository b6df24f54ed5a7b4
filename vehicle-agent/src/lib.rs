//! Shoal's vehicle agent as a library: the binary parses its command line and calls [`run`];
//! tests call [`run`] directly.
//!
//! An agent serves one vehicle. It connects to the coordinator's router as a Zenoh client
//! (waiting for it if it is not up yet), declares a liveliness token so the coordinator sees it,
//! and serves every mission that assigns its vehicle — several at once if they come — until it
//! is stopped. The layers stay apart so a vehicle link can be added without touching the swarm:
//! - [`network`]: the Zenoh session, subscriptions, decoding and counting of bad messages;
//! - [`assignment`]: what a mission hands an agent and what it hands back, below both ways of
//!   planning;
//! - [`mission`]: one mission's planning loop, fed messages through a channel and sending
//!   through a closure, with no knowledge of Zenoh;
//! - [`execute`]: one execution: the vehicle drives its plan through its [`link::VehicleLink`]
//!   and the agent reports telemetry;
//! - [`link`]: the vehicle-link seam (a simulator now; real vehicles plug in there).

mod args;
pub mod assignment;
pub mod execute;
pub mod link;
pub mod mission;
pub mod network;
mod one_shot;

pub use args::AgentArgs;

use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

/// Oldest a health file may be for `--health-check` to pass.
pub const HEALTH_MAX_AGE: Duration = Duration::from_secs(10);

/// Runs the agent until `shutdown` is raised (or, with `--once`, until its first mission ends).
pub fn run(args: AgentArgs, shutdown: Arc<AtomicBool>) -> anyhow::Result<()> {
    if args.health_check {
        let Some(file) = &args.health_file else {
            anyhow::bail!("--health-check needs --health-file (SHOAL_HEALTH_FILE)");
        };
        return shoal_common::health::check(file, HEALTH_MAX_AGE).map_err(anyhow::Error::msg);
    }
    shoal_common::wire::topics::check_id("vehicle", &args.vehicle)?;
    if !(args.idle_timeout.is_finite() && args.idle_timeout > 0.0) {
        anyhow::bail!(
            "--idle-timeout (SHOAL_IDLE_TIMEOUT) = {}: must be a positive number of seconds",
            args.idle_timeout
        );
    }
    if !(args.position_noise.is_finite() && args.position_noise >= 0.0) {
        anyhow::bail!(
            "--position-noise (SHOAL_POSITION_NOISE) = {}: must be a non-negative number of metres",
            args.position_noise
        );
    }
    if args.link == link::LinkKind::Mavlink && args.mavlink_address.is_none() {
        anyhow::bail!("--link mavlink needs --mavlink-address (SHOAL_MAVLINK_ADDRESS)");
    }
    network::serve(&args, &shutdown)
}
