//! The open interface: what Shoal publishes and accepts as JSON, so a Python
//! `eclipse-zenoh` client or a ground-station bridge needs no Rust. Keys are built in
//! [`super::topics`]; the JSON codec is [`super::codec::encode_json`] / [`super::codec::decode_json`].
//!
//! | key | direction | payload |
//! |---|---|---|
//! | `shoal/<mission>/telemetry/<vehicle>` | agent → anyone | [`Telemetry`] |
//! | `shoal/<mission>/status` | coordinator → anyone (put at 1 Hz, and a queryable) | [`FleetStatus`] |
//! | `shoal/<mission>/plan` | coordinator → anyone (on every plan and replan) | [`PlanNotice`] |
//! | `shoal/<mission>/events` | coordinator → anyone | [`MissionEvent`] |
//! | `shoal/<mission>/obstacles` | anyone → coordinator | a scenario obstacle (`id`, `kind`, `centre`, `radius_m`, `inflation_m`) |
//!
//! Every payload carries `"version": 1`; a reader ignores fields it does not know.

use serde::{Deserialize, Serialize};

use crate::execution::picture::{Conflict, Progress};
use crate::execution::{CommandReport, VehicleState};

/// Version of the JSON payloads.
pub const OPEN_VERSION: u16 = 1;

/// One telemetry report of a vehicle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct Telemetry {
    /// [`OPEN_VERSION`].
    pub version: u16,
    /// Mission id.
    pub mission: String,
    /// Vehicle id.
    pub vehicle: String,
    /// Report number, from 0.
    pub seq: u64,
    /// Revision of the plan the vehicle follows (0 = the first plan).
    pub revision: u32,
    /// Unix time the agent sent it, microseconds (end-to-end latency on one clock).
    pub sent_unix_us: u64,
    /// The state.
    pub state: VehicleState,
    /// The agent's latest hold, stop or upload and what the vehicle made of it (absent before
    /// the first, and from older agents).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub command: Option<CommandReport>,
}

/// One vehicle in the live fleet picture.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct VehicleStatusRow {
    /// Vehicle id.
    pub vehicle: String,
    /// Latest report (None before the first).
    pub state: Option<VehicleState>,
    /// Where it is on its plan.
    pub progress: Option<Progress>,
    /// Plan revision it follows.
    pub revision: u32,
    /// Seconds (wall) since its last report: infinite before the first, which JSON writes as
    /// `null` (so the schema allows it).
    #[schemars(with = "Option<f64>")]
    pub silent_s: f64,
    /// Its latest hold, stop or upload and what the vehicle made of it, as it reported.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub command: Option<CommandReport>,
    /// Lost: silent longer than the mission allows.
    pub lost: bool,
}

/// The live fleet picture.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct FleetStatus {
    /// [`OPEN_VERSION`].
    pub version: u16,
    /// Mission id.
    pub mission: String,
    /// Mission time of the picture, seconds.
    pub t_s: f64,
    /// Minimum separation the fleet keeps, metres.
    pub d_min_m: f64,
    /// Per vehicle.
    pub vehicles: Vec<VehicleStatusRow>,
    /// Closest pair now: `[a, b]` indices and distance, metres.
    pub current_min_separation_m: Option<f64>,
    /// The pair of `current_min_separation_m`.
    pub current_pair: Option<[String; 2]>,
    /// Predicted closest approach over the horizon.
    pub predicted: Option<Conflict>,
    /// Prediction horizon, seconds of mission time.
    pub horizon_s: f64,
}

/// A plan (or replan) as published.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct PlanNotice {
    /// [`OPEN_VERSION`].
    pub version: u16,
    /// Mission id.
    pub mission: String,
    /// Revision (0 = the first plan).
    pub revision: u32,
    /// The vehicles whose trajectories this revision changed (all, for revision 0).
    pub changed: Vec<String>,
    /// Every vehicle's current trajectory: `[t_s, x, y, z]` samples, mission time.
    pub trajectories: Vec<(String, Vec<[f64; 4]>)>,
}

/// A decision or an observation of the coordinator, as logged and published.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct MissionEvent {
    /// [`OPEN_VERSION`].
    pub version: u16,
    /// Mission id.
    pub mission: String,
    /// Mission time, seconds.
    pub t_s: f64,
    /// What kind: `conflict_predicted`, `deviation`, `vehicle_lost`, `obstacle`, `replanned`,
    /// `hold`, `hold_failed` / `stop_failed` / `upload_failed` (the vehicle refused or did not
    /// answer; the detail names the fallback), `hold_confirmed`, `arrived`, `mission_end`, `implausible_report` (a report refused: a jump, out of
    /// bounds, numbered far ahead, off the clock), `obstacle_dropped` (a published obstacle
    /// refused: out of scale, a known id, over the cap or the rate), …
    pub kind: String,
    /// Vehicles concerned.
    pub vehicles: Vec<String>,
    /// In plain words.
    pub detail: String,
}
