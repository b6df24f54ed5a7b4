//! Missions as the library starts them: typed options ([`MissionOptions`], [`RunOptions`])
//! and one entry point per way of running one ([`plan_mission`], [`run_mission`]). The commands
//! turn their flags (or, for `serve`, a submission) into these options in one place each and
//! call an entry point; tests build the options directly.
//!
//! - [`options`]: the settings, their defaults, and the scenario with its overrides applied;
//! - [`plan`]: plan a mission and write `plan.json` and `plan.svg`;
//! - [`run`]: plan, then execute with the agents and write the execution's figures;
//! - [`coverage`] and [`executable`]: what `run` executes, a coverage mission's included.

pub mod coverage;
pub mod executable;
pub mod options;
pub mod plan;
pub mod run;

pub use options::{
    ExecutionSettings, Injection, MissionOptions, NetworkOptions, Overrides, Place, RunOptions,
};
pub use plan::plan_mission;
pub use run::run_mission;
