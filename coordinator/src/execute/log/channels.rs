//! How a record becomes an MCAP message and back. One channel per record kind, on the topics
//! `/shoal/start`, `/shoal/plan`, `/shoal/event`, `/shoal/obstacle` and `/shoal/end`, and one
//! per vehicle for its reports, `/shoal/telemetry/<vehicle>`: robotics tools plot and filter by
//! topic, and a report is logged only for a vehicle of the fleet, so there are at most
//! `limits::MAX_VEHICLES` of them. A message is its record's JSON without the `record` tag
//! (the channel says which kind it is); every channel has a JSON Schema of it, derived from
//! the serde type it is read with, so the schema cannot drift from the messages.

use serde::{Deserialize, Serialize};
use shoal_common::scenario::Obstacle;
use shoal_common::wire::open::{MissionEvent, PlanNotice, Telemetry};

use super::record::{Record, Start};
use crate::execute::fleet::ExecutionFigures;

/// Every channel's message encoding.
pub const MESSAGE_ENCODING: &str = "json";
/// Every schema's encoding.
pub const SCHEMA_ENCODING: &str = "jsonschema";
/// Start of the per-vehicle telemetry topics.
const TELEMETRY_TOPIC: &str = "/shoal/telemetry/";

/// A kind of record: which channel its messages go on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Kind {
    /// [`Record::Start`].
    Start,
    /// [`Record::Plan`].
    Plan,
    /// [`Record::Telemetry`].
    Telemetry,
    /// [`Record::Event`].
    Event,
    /// [`Record::Obstacle`].
    Obstacle,
    /// [`Record::End`].
    End,
}

/// The message of a telemetry record, as read back.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
struct TelemetryMessage {
    /// Unix time of receipt, microseconds.
    received_unix_us: u64,
    /// The report.
    telemetry: Telemetry,
}

/// The message of a telemetry record, as written (without a copy of the report).
#[derive(Serialize)]
struct TelemetryMessageRef<'a> {
    received_unix_us: u64,
    telemetry: &'a Telemetry,
}

impl Kind {
    /// The kind of `r`.
    pub fn of(r: &Record) -> Kind {
        match r {
            Record::Start(_) => Kind::Start,
            Record::Plan(_) => Kind::Plan,
            Record::Telemetry { .. } => Kind::Telemetry,
            Record::Event(_) => Kind::Event,
            Record::Obstacle(_) => Kind::Obstacle,
            Record::End(_) => Kind::End,
        }
    }

    /// The record's tag in the NDJSON log, and the last part of its schema's name.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Start => "start",
            Kind::Plan => "plan",
            Kind::Telemetry => "telemetry",
            Kind::Event => "event",
            Kind::Obstacle => "obstacle",
            Kind::End => "end",
        }
    }

    /// The kind of the messages on `topic`; `None` for a topic that is not one of ours.
    pub fn of_topic(topic: &str) -> Option<Kind> {
        if topic
            .strip_prefix(TELEMETRY_TOPIC)
            .is_some_and(|v| !v.is_empty())
        {
            return Some(Kind::Telemetry);
        }
        [
            Kind::Start,
            Kind::Plan,
            Kind::Event,
            Kind::Obstacle,
            Kind::End,
        ]
        .into_iter()
        .find(|k| topic.strip_prefix("/shoal/") == Some(k.name()))
    }

    /// The name of the channel's schema (`shoal.telemetry`).
    pub fn schema_name(self) -> String {
        format!("shoal.{}", self.name())
    }

    /// The JSON Schema (draft 2020-12) of this kind's messages.
    pub fn schema(self) -> schemars::Schema {
        match self {
            Kind::Start => schemars::schema_for!(Start),
            Kind::Plan => schemars::schema_for!(PlanNotice),
            Kind::Telemetry => schemars::schema_for!(TelemetryMessage),
            Kind::Event => schemars::schema_for!(MissionEvent),
            Kind::Obstacle => schemars::schema_for!(Obstacle),
            Kind::End => schemars::schema_for!(ExecutionFigures),
        }
    }
}

/// The topic of `r`'s channel.
pub fn topic(r: &Record) -> String {
    match r {
        Record::Telemetry { telemetry, .. } => format!("{TELEMETRY_TOPIC}{}", telemetry.vehicle),
        _ => format!("/shoal/{}", Kind::of(r).name()),
    }
}

/// The message of `r`: its JSON without the `record` tag.
pub fn message(r: &Record) -> serde_json::Result<Vec<u8>> {
    match r {
        Record::Start(s) => serde_json::to_vec(s),
        Record::Plan(p) => serde_json::to_vec(p),
        Record::Telemetry {
            received_unix_us,
            telemetry,
        } => serde_json::to_vec(&TelemetryMessageRef {
            received_unix_us: *received_unix_us,
            telemetry,
        }),
        Record::Event(e) => serde_json::to_vec(e),
        Record::Obstacle(o) => serde_json::to_vec(o),
        Record::End(f) => serde_json::to_vec(f),
    }
}

/// The record of a message of `kind` on `topic`. A report on another vehicle's topic is an
/// error: the file was not written by a mission.
pub fn record(kind: Kind, topic: &str, data: &[u8]) -> anyhow::Result<Record> {
    Ok(match kind {
        Kind::Start => Record::Start(serde_json::from_slice(data)?),
        Kind::Plan => Record::Plan(serde_json::from_slice(data)?),
        Kind::Telemetry => {
            let m: TelemetryMessage = serde_json::from_slice(data)?;
            let on = topic.strip_prefix(TELEMETRY_TOPIC).unwrap_or(topic);
            if on != m.telemetry.vehicle {
                anyhow::bail!("a report of {:?} on {topic}", m.telemetry.vehicle);
            }
            Record::Telemetry {
                received_unix_us: m.received_unix_us,
                telemetry: m.telemetry,
            }
        }
        Kind::Event => Record::Event(serde_json::from_slice(data)?),
        Kind::Obstacle => Record::Obstacle(serde_json::from_slice(data)?),
        Kind::End => Record::End(serde_json::from_slice(data)?),
    })
}

/// Mission time in nanoseconds, the MCAP log time: `t_s` mission seconds (0 before the start).
pub fn mission_ns(t_s: f64) -> u64 {
    // A float to integer cast saturates (and takes NaN to 0).
    (t_s * 1e9).round().max(0.0) as u64
}

/// The mission time, seconds, of Unix time `unix_us`, on the clock of `start`.
pub fn mission_s(start: &Start, unix_us: u64) -> f64 {
    (unix_us as f64 - start.epoch_unix_ms as f64 * 1000.0) / 1e6 * start.time_scale
}
