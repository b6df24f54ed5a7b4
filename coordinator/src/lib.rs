//! Shoal's coordinator as a library: the binary parses its command line and calls [`run()`]; tests
//! call [`run()`] (or the functions it uses) directly.
//!
//! # Layout
//!
//! - [`commands`]: one file per command, its clap arguments beside its handler; `commands/mod.rs`
//!   holds the [`Command`] enum and the dispatch ([`commands::run()`]). Each command turns its
//!   flags into typed options in one place. Commands never call each other and never build an
//!   argv: what two of them share goes down a layer (or, for a flag group, into `plan_args` or
//!   `shoal_common::wire::flags`).
//! - [`mission`]: the typed mission options ([`MissionOptions`], [`RunOptions`]) and the entry
//!   points [`plan_mission`] and [`run_mission`] that `plan`, `run`, `serve` and tests call.
//! - [`planning`]: the planners (fleet swarms, one-AUV energy, inspection tours, coverage),
//!   the seed-comparison runner's planners and the random scenario generator.
//! - [`report`]: what the commands print and write: `plan.json`/`plan.svg`, progress, summaries,
//!   the comparison tables, the SVG charts and the GeoJSON/QGroundControl exports.
//! - [`distributed`] (planning over agents on Zenoh) and [`execute`] (driving a plan, watching
//!   the fleet, replanning).
//! - [`view`]: the operator's live web view (`--view ADDR`): a page and a WebSocket fed from
//!   the execution's live feed, or a finished log.
//! - [`foxglove`]: a Foxglove WebSocket server fed from the execution's live feed (`--foxglove`).
//! - [`web_tls`]: how those two are reached beyond loopback (mutual TLS with the fleet's keys,
//!   `--insecure`, or refused), as the fleet's Zenoh router is.
//! - [`cpu`]: the process's CPU time, for the figures that report a step's cost.
//! - The rule: `commands` → `mission` → `planning`, `report`, `distributed`, `execute`, never
//!   back (`commands` may also call the lower layers directly); no cycle between files
//!   (`.ci/module-cycles` checks it).

pub mod acl;
pub mod commands;
pub mod cpu;
pub mod distributed;
pub mod execute;
pub mod foxglove;
pub mod mission;
pub mod planning;
pub mod report;
pub mod view;
pub mod web_tls;

pub use commands::plan_args::PlanArgs;
pub use commands::{
    default_log_filter, run, Cli, Command, EXIT_ERROR, EXIT_FEASIBLE, EXIT_VIOLATIONS,
};
pub use mission::{plan_mission, run_mission, MissionOptions, RunOptions};
