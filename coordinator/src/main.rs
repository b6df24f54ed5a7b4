//! `shoal-coordinator`: parses the command line, sets up logging, and calls the library's `run`.

use std::process::ExitCode;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use clap::Parser;
use shoal_coordinator::cli::Cli;

fn main() -> ExitCode {
    let cli = Cli::parse();
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("warn")),
        )
        .with_writer(std::io::stderr)
        .init();
    let shutdown = Arc::new(AtomicBool::new(false));
    match shoal_coordinator::run(cli.command, shutdown) {
        Ok(code) => ExitCode::from(code as u8),
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(shoal_coordinator::EXIT_ERROR as u8)
        }
    }
}
