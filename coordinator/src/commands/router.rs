//! `shoal-coordinator router`: only a Zenoh router (what `zenohd` does) until Ctrl-C.

use std::sync::atomic::AtomicBool;

use crate::distributed;

/// `shoal-coordinator router`.
#[derive(Debug, Clone, clap::Args)]
pub struct RouterArgs {
    /// Where the router listens.
    #[command(flatten)]
    pub listen: shoal_common::wire::flags::ZenohListen,
    /// How members authenticate (a router beyond loopback needs it, or --insecure).
    #[command(flatten)]
    pub zenoh: shoal_common::wire::flags::ZenohSecurityArgs,
}

/// Serves until `shutdown` is raised.
pub fn command(args: &RouterArgs, shutdown: &AtomicBool) -> anyhow::Result<i32> {
    distributed::network::serve_router(&args.listen.listen, &args.zenoh.security()?, shutdown)?;
    Ok(super::exit::EXIT_FEASIBLE)
}
