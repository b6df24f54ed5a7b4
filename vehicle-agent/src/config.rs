//! What an agent is told to do, typed and checked: built from the command line in one place
//! ([`crate::AgentArgs::config`]) or directly by tests and embedding programs.

use std::path::PathBuf;
use std::time::Duration;

use shoal_common::wire::security::Security;

use crate::link::LinkSettings;

/// Threads stepping the follower populations by default.
pub const DEFAULT_THREADS: usize = 1;
/// Seconds of a coordinator's silence after which a mission is abandoned by default.
pub const DEFAULT_IDLE_TIMEOUT_S: f64 = 30.0;
/// Position noise of simulated fixes by default, metres.
pub const DEFAULT_POSITION_NOISE_M: f64 = 1.0;

/// One agent's settings.
#[derive(Debug, Clone)]
pub struct AgentConfig {
    /// The vehicle this agent serves (a vehicle id of the scenarios it will be given).
    pub vehicle: String,
    /// The coordinator's Zenoh endpoints.
    pub connect: Vec<String>,
    /// How the agent authenticates to the coordinator (its vehicle's certificate).
    pub security: Security,
    /// Leave after the first mission ends (the coordinator's own agents do).
    pub once: bool,
    /// Threads stepping the follower populations.
    pub threads: usize,
    /// Abandon a mission whose coordinator has been silent this long.
    pub idle_timeout: Duration,
    /// Rewritten every 2 s while the agent serves, for container healthchecks.
    pub health_file: Option<PathBuf>,
    /// How the agent drives its vehicle when a plan is executed.
    pub link: LinkSettings,
    /// Leave when this process is no longer the agent's parent (a coordinator's own agents
    /// are given the coordinator's process id).
    pub parent: Option<u32>,
}

impl AgentConfig {
    /// An agent for `vehicle` connecting to `connect` without authentication, serving until
    /// stopped with one thread, a 30 s idle timeout and a simulated vehicle (1 m fix noise):
    /// the command line's defaults.
    pub fn new(vehicle: impl Into<String>, connect: Vec<String>) -> AgentConfig {
        AgentConfig {
            vehicle: vehicle.into(),
            connect,
            security: Security::default(),
            once: false,
            threads: DEFAULT_THREADS,
            idle_timeout: Duration::from_secs_f64(DEFAULT_IDLE_TIMEOUT_S),
            health_file: None,
            link: LinkSettings {
                kind: crate::link::LinkKind::Sim,
                position_noise_m: DEFAULT_POSITION_NOISE_M,
                mavlink: None,
            },
            parent: None,
        }
    }
}
