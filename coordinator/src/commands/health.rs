//! `shoal-coordinator health`: a container healthcheck on a health file.

use std::path::PathBuf;

/// `shoal-coordinator health`.
#[derive(Debug, Clone, clap::Args)]
pub struct HealthArgs {
    /// The health file `plan --health-file` rewrites.
    #[arg(long, env = "SHOAL_HEALTH_FILE")]
    pub file: PathBuf,
}

/// Exit 0 if the health file was rewritten in the last 10 s.
pub fn command(args: &HealthArgs) -> anyhow::Result<i32> {
    shoal_common::health::check(&args.file, std::time::Duration::from_secs(10))
        .map_err(anyhow::Error::msg)?;
    Ok(super::exit::EXIT_FEASIBLE)
}
