//! The agent's command line, and the one place it becomes an [`AgentConfig`] (ripgrep's
//! low-level arguments becoming its `HiArgs`).

use std::time::Duration;

use shoal_common::wire::flags::{ZenohConnect, ZenohSecurityArgs};
use shoal_common::wire::topics;

use crate::config::{
    AgentConfig, DEFAULT_IDLE_TIMEOUT_S, DEFAULT_POSITION_NOISE_M, DEFAULT_THREADS,
};
use crate::link::mavlink::AutopilotChoice;
use crate::link::{
    check_mavlink_address, parse_mavlink_target, GeoOrigin, LinkKind, LinkSettings, MavlinkSettings,
};

/// Shoal vehicle agent: plans one vehicle's share of the fleet's missions (its follower
/// populations of distributed AMP-PSO) with the coordinator over Zenoh.
#[derive(Debug, Clone, clap::Parser)]
#[command(name = "shoal-agent", version, about)]
pub struct AgentArgs {
    /// The vehicle this agent serves (a vehicle id of the scenarios it will be given).
    #[arg(long, env = "SHOAL_VEHICLE")]
    pub vehicle: String,
    /// Where the coordinator's router is.
    #[command(flatten)]
    pub connect: ZenohConnect,
    /// How the agent authenticates to the coordinator (its vehicle's certificate).
    #[command(flatten)]
    pub zenoh: ZenohSecurityArgs,
    /// Leave after the first mission ends (the coordinator's own agents do).
    #[arg(long, env = "SHOAL_ONCE")]
    pub once: bool,
    /// Leave when process PID is no longer this agent's parent: the coordinator passes its own
    /// process id to the agents it starts, so they do not outlive it even when it is killed.
    #[arg(long, value_name = "PID")]
    pub parent_pid: Option<u32>,
    /// Threads stepping the follower populations.
    #[arg(long, env = "SHOAL_THREADS", default_value_t = DEFAULT_THREADS)]
    pub threads: usize,
    /// Abandon a mission whose coordinator has been silent this long, seconds.
    #[arg(long, env = "SHOAL_IDLE_TIMEOUT", default_value_t = DEFAULT_IDLE_TIMEOUT_S)]
    pub idle_timeout: f64,
    /// Rewrite this file every 2 s while the agent serves (connected or waiting for a
    /// coordinator), for container healthchecks.
    #[arg(long, env = "SHOAL_HEALTH_FILE")]
    pub health_file: Option<std::path::PathBuf>,
    /// Do not run: exit 0 if the health file was rewritten in the last 10 s, else 1 (the
    /// container healthcheck).
    #[arg(long)]
    pub health_check: bool,
    /// How the agent drives its vehicle when a plan is executed.
    #[arg(long, env = "SHOAL_LINK", value_enum, default_value_t = LinkKind::Sim)]
    pub link: LinkKind,
    /// `sim` link: position noise of the simulated fixes (standard deviation per axis), metres.
    #[arg(long, env = "SHOAL_POSITION_NOISE", default_value_t = DEFAULT_POSITION_NOISE_M)]
    pub position_noise: f64,
    /// `mavlink` link: the vehicle's address, `udpout:HOST:PORT` (we send first) or
    /// `udpin:ADDR:PORT` (we listen; the vehicle must send first).
    #[arg(long, env = "SHOAL_MAVLINK_ADDRESS", value_parser = check_mavlink_address)]
    pub mavlink_address: Option<String>,
    /// `mavlink` link: geodetic origin of the scenario frame, `LAT,LON,ALT` (degrees, degrees,
    /// metres above mean sea level of scenario point (0, 0, 0)). Optional when the scenario
    /// has an `[origin]`; when both are given, a mission whose origin differs is refused.
    #[arg(
        long,
        env = "SHOAL_MAVLINK_ORIGIN",
        value_name = "LAT,LON,ALT",
        allow_hyphen_values = true
    )]
    pub mavlink_origin: Option<GeoOrigin>,
    /// `mavlink` link: the vehicle's MAVLink system and component ids (default 1,1).
    #[arg(
        long,
        env = "SHOAL_MAVLINK_TARGET",
        value_name = "SYS,COMP",
        value_parser = parse_mavlink_target
    )]
    pub mavlink_target: Option<(u8, u8)>,
    /// `mavlink` link: the vehicle's autopilot family, which decides the mission layout and
    /// how it is made to hold (`auto`: from its HEARTBEAT).
    #[arg(long, env = "SHOAL_MAVLINK_AUTOPILOT", value_enum, default_value_t = AutopilotChoice::Auto)]
    pub mavlink_autopilot: AutopilotChoice,
    /// `mavlink` link: do not upload the scenario's bounds and hard obstacles as a geofence.
    #[arg(long, env = "SHOAL_MAVLINK_NO_FENCE")]
    pub mavlink_no_fence: bool,
}

impl AgentArgs {
    /// The agent these flags ask for: the one place they become an [`AgentConfig`], every
    /// value checked (the password file read).
    pub fn config(&self) -> anyhow::Result<AgentConfig> {
        topics::check_id("vehicle", &self.vehicle)?;
        if !(self.idle_timeout.is_finite() && self.idle_timeout > 0.0) {
            anyhow::bail!(
                "--idle-timeout (SHOAL_IDLE_TIMEOUT) = {}: must be a positive number of seconds",
                self.idle_timeout
            );
        }
        if !(self.position_noise.is_finite() && self.position_noise >= 0.0) {
            anyhow::bail!(
                "--position-noise (SHOAL_POSITION_NOISE) = {}: must be a non-negative number of metres",
                self.position_noise
            );
        }
        if let Some(pid) = self.parent_pid {
            match crate::parent_watch::parent_id() {
                Some(parent) if parent != pid => anyhow::bail!(
                    "--parent-pid {pid}: this agent's parent is process {parent} (gone already?)"
                ),
                Some(_) => {}
                None => anyhow::bail!("--parent-pid: not supported on this platform"),
            }
        }
        if self.link == LinkKind::Mavlink && self.mavlink_address.is_none() {
            anyhow::bail!("--link mavlink needs --mavlink-address (SHOAL_MAVLINK_ADDRESS)");
        }
        Ok(AgentConfig {
            vehicle: self.vehicle.clone(),
            connect: self.connect.connect.clone(),
            security: self.zenoh.security()?,
            once: self.once,
            threads: self.threads,
            // Finite and positive, so only an absurdly long one falls back.
            idle_timeout: Duration::try_from_secs_f64(self.idle_timeout)
                .unwrap_or(Duration::from_secs_f64(DEFAULT_IDLE_TIMEOUT_S)),
            health_file: self.health_file.clone(),
            link: self.link_settings(),
            parent: self.parent_pid,
        })
    }

    /// The vehicle-link settings.
    pub fn link_settings(&self) -> LinkSettings {
        LinkSettings {
            kind: self.link,
            position_noise_m: self.position_noise,
            mavlink: self.mavlink_address.as_ref().map(|address| {
                let mut m = MavlinkSettings::new(address, self.mavlink_origin);
                if let Some((system, component)) = self.mavlink_target {
                    (m.target_system, m.target_component) = (system, component);
                }
                (m.autopilot, m.fence) = (self.mavlink_autopilot, !self.mavlink_no_fence);
                m
            }),
        }
    }
}
