//! A finished mission log for the page (`replay LOG --view ADDR`): shaped once, sent whole to
//! every page, which plays it back with a time slider. The log holds no statuses, so they are
//! rebuilt by folding the records into the fleet picture as the live run did
//! ([`Statuses`]), one per wall second of the original run and one as it ended. A long log is
//! thinned so a page gets at most [`MAX_REPORTS_PER_VEHICLE`] reports per vehicle and
//! [`MAX_STATUSES`] statuses.

use std::collections::BTreeMap;
use std::path::Path;

use crate::execute::live::LiveMessage;
use crate::execute::log::Record;
use crate::execute::replayed::Statuses;

use super::message::{push_json, Shaper, ViewMessage};

/// Messages per frame: a long log goes in several frames.
const FRAME_MESSAGES: usize = 1000;
/// Reports per vehicle sent at most (every k-th past it, the last always).
pub const MAX_REPORTS_PER_VEHICLE: usize = 3000;
/// Statuses sent at most.
pub const MAX_STATUSES: usize = 3000;

/// A log, shaped into the frames every page is sent.
#[derive(Debug, Clone, PartialEq)]
pub struct ReplayLog {
    /// JSON arrays of page messages: `hello`, `reset`, the records and statuses, `caught_up`.
    pub frames: Vec<String>,
}

impl ReplayLog {
    /// Shapes `messages`, in order.
    pub fn new(messages: &[LiveMessage]) -> ReplayLog {
        let mut frames = Vec::new();
        let mut out = String::from("[");
        push_json(&mut out, &ViewMessage::Hello { mode: "replay" });
        push_json(&mut out, &ViewMessage::Reset);
        let mut shaper = Shaper::default();
        for chunk in messages.chunks(FRAME_MESSAGES) {
            for m in chunk {
                shaper.push(&mut out, m);
            }
            out.push(']');
            frames.push(std::mem::replace(&mut out, String::from("[")));
        }
        push_json(&mut out, &ViewMessage::CaughtUp);
        out.push(']');
        frames.push(out);
        ReplayLog { frames }
    }

    /// A log's records (`path` names it in errors), thinned, with statuses rebuilt between them
    /// ([`Statuses`]).
    pub fn from_records(records: &[Record], path: &Path) -> anyhow::Result<ReplayLog> {
        let strides = report_strides(records);
        let (first, last) = telemetry_span(records);
        let mut statuses = Statuses::new(records, path, (last - first) / MAX_STATUSES as f64)?;
        let mut seen: BTreeMap<&str, usize> = BTreeMap::new();
        let mut messages = Vec::new();
        for r in records {
            let status = statuses.apply(r);
            match r {
                Record::Telemetry { telemetry, .. } => {
                    let n = seen.entry(telemetry.vehicle.as_str()).or_default();
                    let (stride, total) = strides
                        .get(telemetry.vehicle.as_str())
                        .copied()
                        .unwrap_or((1, 0));
                    if n.is_multiple_of(stride) || *n + 1 == total {
                        messages.push(LiveMessage::Record(r.clone()));
                    }
                    *n += 1;
                }
                _ => messages.push(LiveMessage::Record(r.clone())),
            }
            messages.extend(status.map(LiveMessage::Status));
        }
        Ok(ReplayLog::new(&messages))
    }
}

/// Per vehicle: keep every how-many-th report, and how many it has.
fn report_strides(records: &[Record]) -> BTreeMap<&str, (usize, usize)> {
    let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
    for r in records {
        if let Record::Telemetry { telemetry, .. } = r {
            *counts.entry(telemetry.vehicle.as_str()).or_default() += 1;
        }
    }
    counts
        .into_iter()
        .map(|(v, n)| (v, (n.div_ceil(MAX_REPORTS_PER_VEHICLE).max(1), n)))
        .collect()
}

/// Mission times of the first and last report (0, 0 without any).
fn telemetry_span(records: &[Record]) -> (f64, f64) {
    let times = records.iter().filter_map(|r| match r {
        Record::Telemetry { telemetry, .. } => Some(telemetry.state.t_s),
        _ => None,
    });
    times
        .fold(None, |span: Option<(f64, f64)>, t| {
            Some(span.map_or((t, t), |(a, b)| (a.min(t), b.max(t))))
        })
        .unwrap_or((0.0, 0.0))
}
