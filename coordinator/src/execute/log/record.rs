//! What a mission log holds, whatever its file format: the records in the order they happened,
//! and what a reader left out of a file cut short.

use std::fmt;

use serde::{Deserialize, Serialize};
use shoal_common::scenario::Obstacle;
use shoal_common::wire::open::{MissionEvent, PlanNotice, Telemetry};

use crate::execute::fleet::ExecutionFigures;

/// What starts a log.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct Start {
    /// Mission id.
    pub mission: String,
    /// The scenario as TOML (obstacles as planned; new ones come as events).
    pub scenario_toml: String,
    /// The fleet's arrival time, mission seconds.
    pub common_arrival_s: f64,
    /// Half-width of the arrival window, mission seconds.
    pub arrival_window_s: f64,
    /// Prediction horizon, mission seconds.
    pub horizon_s: f64,
    /// Mission seconds per wall second.
    pub time_scale: f64,
    /// Unix time of mission time 0, milliseconds.
    pub epoch_unix_ms: u64,
}

/// One record: a line of the NDJSON log, a message of the MCAP one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "record", rename_all = "snake_case")]
pub enum Record {
    /// First line.
    Start(Start),
    /// A plan or a replan.
    Plan(PlanNotice),
    /// A report, with when it came.
    Telemetry {
        /// Unix time of receipt, microseconds.
        received_unix_us: u64,
        /// The report.
        telemetry: Telemetry,
    },
    /// A decision or an observation.
    Event(MissionEvent),
    /// An obstacle published during the execution.
    Obstacle(Obstacle),
    /// Last line.
    End(ExecutionFigures),
}

/// Where a file cut short ends: a run stopped while writing its last record.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CutShort {
    /// NDJSON: the number of the last line, without its newline and not a whole record.
    Line(usize),
    /// MCAP: the file ends inside the record after this many messages.
    AfterMessage(usize),
}

impl fmt::Display for CutShort {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CutShort::Line(n) => write!(f, "line {n}"),
            CutShort::AfterMessage(n) => write!(f, "the record after message {n}"),
        }
    }
}

/// A log read back.
#[derive(Debug, Clone, PartialEq)]
pub struct Log {
    /// Its records, in order.
    pub records: Vec<Record>,
    /// A last record cut short, left out: the run was stopped while writing it.
    pub cut_short: Option<CutShort>,
}
