//! The agent's settings, as its command line and environment give them.

use std::time::Duration;

use crate::link;

/// Shoal vehicle agent: plans one vehicle's share of the fleet's missions (its follower
/// populations of distributed AMP-PSO) with the coordinator over Zenoh.
#[derive(Debug, Clone, clap::Parser)]
#[command(name = "shoal-agent", version, about)]
pub struct AgentArgs {
    /// The vehicle this agent serves (a vehicle id of the scenarios it will be given).
    #[arg(long, env = "SHOAL_VEHICLE")]
    pub vehicle: String,
    /// The coordinator's Zenoh endpoint(s), e.g. tcp/coordinator:7447 (comma-separated).
    #[arg(
        long,
        env = "SHOAL_CONNECT",
        value_delimiter = ',',
        default_value = "tcp/127.0.0.1:7447"
    )]
    pub connect: Vec<String>,
    /// How the agent authenticates to the coordinator (its vehicle's certificate).
    #[command(flatten)]
    pub zenoh: shoal_common::wire::flags::ZenohSecurityArgs,
    /// Leave after the first mission ends (the coordinator's own agents do).
    #[arg(long, env = "SHOAL_ONCE")]
    pub once: bool,
    /// Threads stepping the follower populations.
    #[arg(long, env = "SHOAL_THREADS", default_value_t = 1)]
    pub threads: usize,
    /// Abandon a mission whose coordinator has been silent this long, seconds.
    #[arg(long, env = "SHOAL_IDLE_TIMEOUT", default_value_t = 30.0)]
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
    #[arg(long, env = "SHOAL_LINK", value_enum, default_value_t = link::LinkKind::Sim)]
    pub link: link::LinkKind,
    /// `sim` link: position noise of the simulated fixes (standard deviation per axis), metres.
    #[arg(long, env = "SHOAL_POSITION_NOISE", default_value_t = 1.0)]
    pub position_noise: f64,
    /// `mavlink` link: the vehicle's address, `udpout:HOST:PORT` (we send first) or
    /// `udpin:ADDR:PORT` (we listen; the vehicle must send first).
    #[arg(long, env = "SHOAL_MAVLINK_ADDRESS", value_parser = link::check_mavlink_address)]
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
    pub mavlink_origin: Option<link::GeoOrigin>,
    /// `mavlink` link: the vehicle's MAVLink system and component ids (default 1,1).
    #[arg(
        long,
        env = "SHOAL_MAVLINK_TARGET",
        value_name = "SYS,COMP",
        value_parser = link::parse_mavlink_target
    )]
    pub mavlink_target: Option<(u8, u8)>,
    /// `mavlink` link: the vehicle's autopilot family, which decides the mission layout and
    /// how it is made to hold (`auto`: from its HEARTBEAT).
    #[arg(long, env = "SHOAL_MAVLINK_AUTOPILOT", value_enum, default_value_t = link::mavlink::AutopilotChoice::Auto)]
    pub mavlink_autopilot: link::mavlink::AutopilotChoice,
    /// `mavlink` link: do not upload the scenario's bounds and hard obstacles as a geofence.
    #[arg(long, env = "SHOAL_MAVLINK_NO_FENCE")]
    pub mavlink_no_fence: bool,
}

impl AgentArgs {
    /// The idle timeout as a duration (a bad value falls back to 30 s).
    pub fn idle(&self) -> Duration {
        Duration::try_from_secs_f64(self.idle_timeout).unwrap_or(Duration::from_secs(30))
    }
}

impl AgentArgs {
    /// The vehicle-link settings.
    pub fn link_settings(&self) -> link::LinkSettings {
        link::LinkSettings {
            kind: self.link,
            position_noise_m: self.position_noise,
            mavlink: self.mavlink_address.as_ref().map(|address| {
                let mut m = link::MavlinkSettings::new(address, self.mavlink_origin);
                if let Some((system, component)) = self.mavlink_target {
                    (m.target_system, m.target_component) = (system, component);
                }
                (m.autopilot, m.fence) = (self.mavlink_autopilot, !self.mavlink_no_fence);
                m
            }),
        }
    }
}
