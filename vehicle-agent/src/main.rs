//! `shoal-agent`: one process per vehicle. Distributed planning (follower populations over
//! Zenoh) arrives with issue 3; until then the binary only reports its version and says so.

use clap::Parser;

/// Shoal vehicle agent (distributed planning is not built yet: plan with
/// `shoal-coordinator plan SCENARIO --in-process`).
#[derive(Debug, Parser)]
#[command(name = "shoal-agent", version, about)]
struct Cli {}

fn main() {
    let _ = Cli::parse();
    println!(
        "shoal-agent {} (shoal-common {}): distributed planning is not available yet; \
         use `shoal-coordinator plan <SCENARIO> --in-process`",
        env!("CARGO_PKG_VERSION"),
        shoal_common::VERSION
    );
}
