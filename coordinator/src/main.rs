//! `shoal-coordinator`: parses the command line, sets up logging, and calls the library's `run`.

use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use clap::Parser;
use shoal_coordinator::Cli;

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let _ = e.print();
            // `--help` and `--version` are not errors; a bad command line is, and every error
            // exits 1 (README), not clap's own 2.
            return if e.use_stderr() {
                ExitCode::from(shoal_coordinator::EXIT_ERROR as u8)
            } else {
                ExitCode::SUCCESS
            };
        }
    };
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| {
                tracing_subscriber::EnvFilter::new(shoal_coordinator::default_log_filter(
                    &cli.command,
                ))
            }),
        )
        .with_writer(std::io::stderr)
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .init();
    let shutdown = Arc::new(AtomicBool::new(false));
    // First Ctrl-C: stop after the current iteration and write the best plan so far.
    // Second Ctrl-C: leave at once.
    let flag = Arc::clone(&shutdown);
    if let Err(e) = ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
        eprintln!("interrupted: finishing the work in hand and writing what is done so far (Ctrl-C again to quit now)");
    }) {
        tracing::warn!("cannot install the Ctrl-C handler: {e}");
    }
    match shoal_coordinator::run(cli.command, shutdown) {
        Ok(code) => ExitCode::from(code as u8),
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(shoal_coordinator::EXIT_ERROR as u8)
        }
    }
}
