//! `shoal-agent`: parses the command line, sets up logging, and calls the library's `run` with
//! the configuration the command line gives (or its healthcheck).

use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use clap::Parser;
use shoal_agent::AgentArgs;

fn main() -> ExitCode {
    let args = match AgentArgs::try_parse() {
        Ok(args) => args,
        Err(e) => {
            let _ = e.print();
            // As the coordinator: a bad command line exits 1 like any other error.
            return if e.use_stderr() {
                ExitCode::FAILURE
            } else {
                ExitCode::SUCCESS
            };
        }
    };
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info")),
        )
        .with_writer(std::io::stderr)
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .init();
    let shutdown = Arc::new(AtomicBool::new(false));
    // First Ctrl-C / SIGTERM: leave after telling the coordinator; second: at once.
    let flag = Arc::clone(&shutdown);
    if let Err(e) = ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
    }) {
        tracing::warn!("cannot install the Ctrl-C handler: {e}");
    }
    let result = if args.health_check {
        shoal_agent::health_check(args.health_file.as_deref())
    } else {
        args.config()
            .and_then(|config| shoal_agent::run(config, shutdown))
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
