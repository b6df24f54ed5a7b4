//! What the page receives: each WebSocket text frame is a JSON array of messages, each an
//! object with a `kind`. A connection starts with `hello` and `reset`, then the catch-up (or the
//! whole log), then `caught_up`, then what happens as it happens:
//!
//! | kind | what |
//! |---|---|
//! | `hello` | `mode`: `live` or `replay` |
//! | `reset` | forget everything: a catch-up follows |
//! | `scene` | a mission starts: bounds, obstacles, seabed, vehicles, clock settings |
//! | `plan` | `plan`: a plan or replan ([`PlanNotice`]) |
//! | `telemetry` | `telemetry`: a report ([`Telemetry`]) |
//! | `event` | `event`: a decision or an observation ([`MissionEvent`]) |
//! | `obstacle` | `obstacle`: an obstacle published during the execution |
//! | `status` | `status`: the fleet status (the open `status` key's); `predicted`: where its closest approach will happen |
//! | `end` | `figures`: the execution's figures |
//!
//! Records go in a field of their own, not flattened: an event and an obstacle have a `kind`
//! of their own.
//! | `caught_up` | the catch-up is complete |
//!
//! The page draws; the server does the geometry that needs the scenario or the plans: the
//! seabed sampled on a grid ([`seabed_view`]) and the places of the predicted closest approach
//! ([`predicted_view`]).

use std::collections::BTreeMap;
use std::path::Path;

use serde::Serialize;
use shoal_common::execution::picture::Conflict;
use shoal_common::execution::VehicleStatus;
use shoal_common::scenario::{Bounds, Obstacle, Scenario};
use shoal_common::terrain::{Hazard, Terrain};
use shoal_common::trajectory::Trajectory;
use shoal_common::wire::open::{
    FleetStatus, MissionEvent, PlanNotice, Telemetry, VehicleStatusRow,
};

use crate::execute::fleet::ExecutionFigures;
use crate::execute::live::LiveMessage;
use crate::execute::log::{Record, Start};

/// Seabed samples per axis sent to the page.
pub const SEABED_SAMPLES: usize = 48;

/// One message to the page.
#[derive(Debug, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ViewMessage<'a> {
    /// First message of a connection.
    Hello {
        /// `live` or `replay`.
        mode: &'static str,
    },
    /// Forget everything; a catch-up follows.
    Reset,
    /// A mission starts.
    Scene(Box<Scene>),
    /// A plan or replan.
    Plan {
        /// As published on the `plan` key.
        plan: &'a PlanNotice,
    },
    /// A report.
    Telemetry {
        /// As the agent sent it.
        telemetry: &'a Telemetry,
    },
    /// A decision or an observation.
    Event {
        /// As published on the `events` key.
        event: &'a MissionEvent,
    },
    /// An obstacle published during the execution.
    Obstacle {
        /// As published.
        obstacle: &'a Obstacle,
    },
    /// The fleet status.
    Status {
        /// As published on the `status` key.
        status: &'a FleetStatus,
        /// Where its predicted closest approach happens.
        predicted: Option<PredictedView>,
    },
    /// The execution's figures.
    End {
        /// As in `execution.json`.
        figures: &'a ExecutionFigures,
    },
    /// The catch-up is complete.
    CaughtUp,
}

/// What the page draws a mission in.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Scene {
    /// Mission id.
    pub mission: String,
    /// The scenario's name (`None` when its TOML could not be read back).
    pub name: Option<String>,
    /// Mission seconds per wall second.
    pub time_scale: f64,
    /// Prediction horizon, mission seconds.
    pub horizon_s: f64,
    /// The fleet's arrival time, mission seconds.
    pub common_arrival_s: f64,
    /// Unix time of mission time 0, milliseconds.
    pub epoch_unix_ms: u64,
    /// The box the vehicles stay in.
    pub bounds: Option<Bounds>,
    /// Minimum separation, metres.
    pub d_min_m: Option<f64>,
    /// Obstacles as planned (published ones come as `obstacle` messages).
    pub obstacles: Vec<Obstacle>,
    /// Soft-substrate zones crawlers keep out of.
    pub hazards: Vec<Hazard>,
    /// Vehicle ids, in the scenario's order (the status's conflict indices count in it).
    pub vehicles: Vec<String>,
    /// The seabed, where there is one.
    pub seabed: Option<SeabedView>,
}

/// The seabed sampled for drawing.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SeabedView {
    /// Sample x coordinates, metres, west to east.
    pub xs: Vec<f64>,
    /// Sample y coordinates, metres, south to north.
    pub ys: Vec<f64>,
    /// Elevation at `(xs[i], ys[j])`: `z[j][i]`, metres.
    pub z: Vec<Vec<f64>>,
    /// Side view: the highest seabed over y at each x (its silhouette seen from the south).
    pub profile: Vec<f64>,
}

/// Where a predicted closest approach happens.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PredictedView {
    /// The two vehicles.
    pub vehicles: [String; 2],
    /// Their predicted places at that time, metres.
    pub places: [[f64; 3]; 2],
    /// Smallest predicted distance, metres.
    pub min_distance_m: f64,
    /// Mission time of it, seconds.
    pub at_s: f64,
    /// Closer than d_min: a conflict.
    pub conflict: bool,
}

/// `n` evenly spaced values from `a` to `b` (both included; `a` alone for `n` = 1).
fn spaced(a: f64, b: f64, n: usize) -> Vec<f64> {
    let steps = n.saturating_sub(1).max(1) as f64;
    (0..n).map(|i| a + (b - a) * i as f64 / steps).collect()
}

/// `terrain` over `bounds`' horizontal extent, `n` × `n` samples.
pub fn seabed_view(terrain: &Terrain, bounds: &Bounds, n: usize) -> SeabedView {
    let xs = spaced(bounds.min[0], bounds.max[0], n);
    let ys = spaced(bounds.min[1], bounds.max[1], n);
    let z: Vec<Vec<f64>> = ys
        .iter()
        .map(|&y| xs.iter().map(|&x| terrain.elevation(x, y)).collect())
        .collect();
    let profile = (0..xs.len())
        .map(|i| z.iter().map(|row| row[i]).fold(f64::NEG_INFINITY, f64::max))
        .collect();
    SeabedView { xs, ys, z, profile }
}

/// The scene of a start record; a scenario that cannot be read back gives a scene without
/// bounds or obstacles (the page then frames what it is sent).
pub fn scene(start: &Start) -> Scene {
    let parsed = Scenario::parse(&start.scenario_toml, Path::new("<start record>"));
    if let Err(e) = &parsed {
        tracing::warn!("web view: the start record's scenario: {e}");
    }
    let s = parsed.ok();
    Scene {
        mission: start.mission.clone(),
        name: s.as_ref().map(|s| s.name.clone()),
        time_scale: start.time_scale,
        horizon_s: start.horizon_s,
        common_arrival_s: start.common_arrival_s,
        epoch_unix_ms: start.epoch_unix_ms,
        bounds: s.as_ref().map(|s| s.bounds.clone()),
        d_min_m: s.as_ref().map(|s| s.fleet.d_min_m),
        obstacles: s.as_ref().map(|s| s.obstacles.clone()).unwrap_or_default(),
        hazards: s.as_ref().map(|s| s.hazards.clone()).unwrap_or_default(),
        vehicles: s
            .as_ref()
            .map(|s| s.vehicles.iter().map(|v| v.id.clone()).collect())
            .unwrap_or_default(),
        seabed: s.as_ref().and_then(|s| {
            s.terrain()
                .map(|t| seabed_view(t, &s.bounds, SEABED_SAMPLES))
        }),
    }
}

/// Where vehicle `row` will be at `at_s`, as the coordinator predicts it: where it was last
/// seen if it stands (lost, holding, faulted, arrived, stopped); else along its plan at its
/// current lag (a vehicle 20 s late is where its plan is 20 s earlier); along its plan on time
/// before its first report, or at its plan's start when it is lost before any.
pub fn predicted_place(
    row: &VehicleStatusRow,
    plan: Option<&Trajectory>,
    at_s: f64,
) -> Option<[f64; 3]> {
    let standing = |s: VehicleStatus| {
        matches!(
            s,
            VehicleStatus::Holding
                | VehicleStatus::Fault
                | VehicleStatus::Arrived
                | VehicleStatus::Stopped
        )
    };
    match (&row.state, plan) {
        (Some(s), _) if row.lost || standing(s.status) => Some(s.position),
        (Some(s), None) => Some(s.position),
        (None, Some(plan)) if row.lost => plan.points.first().map(|p| [p.x, p.y, p.z]),
        (_, Some(plan)) => {
            let lag = row.progress.map_or(0.0, |p| p.lag_s);
            let p = plan.position_at(at_s - lag);
            Some([p.x, p.y, p.z])
        }
        (None, None) => None,
    }
}

/// Where `status`'s predicted closest approach happens, given each vehicle's current plan.
pub fn predicted_view(
    status: &FleetStatus,
    plans: &BTreeMap<String, Trajectory>,
) -> Option<PredictedView> {
    let Conflict {
        a,
        b,
        min_distance_m,
        at_s,
    } = status.predicted?;
    let (ra, rb) = (status.vehicles.get(a)?, status.vehicles.get(b)?);
    let place = |r: &VehicleStatusRow| predicted_place(r, plans.get(&r.vehicle), at_s);
    Some(PredictedView {
        vehicles: [ra.vehicle.clone(), rb.vehicle.clone()],
        places: [place(ra)?, place(rb)?],
        min_distance_m,
        at_s,
        conflict: min_distance_m < status.d_min_m,
    })
}

/// Turns feed messages into page messages for one connection: it keeps the current plans,
/// which the predicted closest approach's places need.
#[derive(Default)]
pub struct Shaper {
    /// Each vehicle's current plan.
    plans: BTreeMap<String, Trajectory>,
}

impl Shaper {
    /// Appends `m`, shaped, to the JSON array being written in `out` (a comma first unless
    /// `out` is just the opening bracket).
    pub fn push(&mut self, out: &mut String, m: &LiveMessage) {
        let shaped = match m {
            LiveMessage::Status(status) => ViewMessage::Status {
                status,
                predicted: predicted_view(status, &self.plans),
            },
            LiveMessage::Record(r) => match r {
                Record::Start(s) => {
                    self.plans.clear();
                    ViewMessage::Scene(Box::new(scene(s)))
                }
                Record::Plan(p) => {
                    for (id, samples) in &p.trajectories {
                        self.plans
                            .insert(id.clone(), Trajectory::from_samples(samples));
                    }
                    ViewMessage::Plan { plan: p }
                }
                Record::Telemetry { telemetry, .. } => ViewMessage::Telemetry { telemetry },
                Record::Event(event) => ViewMessage::Event { event },
                Record::Obstacle(obstacle) => ViewMessage::Obstacle { obstacle },
                Record::End(figures) => ViewMessage::End { figures },
            },
        };
        push_json(out, &shaped);
    }
}

/// Appends `m` as JSON to the array being written in `out`.
pub fn push_json(out: &mut String, m: &ViewMessage<'_>) {
    match serde_json::to_string(m) {
        Ok(json) => {
            if !out.ends_with('[') {
                out.push(',');
            }
            out.push_str(&json);
        }
        Err(e) => tracing::warn!("web view: cannot write a message: {e}"),
    }
}

#[cfg(test)]
mod tests;
