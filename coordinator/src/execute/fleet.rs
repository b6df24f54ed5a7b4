//! The coordinator's live fleet picture during an execution: per vehicle its plan, its latest
//! report and where that puts it on the plan (progress, cross-track error, ETA); for the fleet
//! the closest pair now and the closest approach predicted over the next minutes (see
//! [`shoal_common::execution::picture`]). It also keeps what the figures need: each vehicle's
//! executed track, its cross-track errors, its arrival, and the telemetry latencies.

use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};
use shoal_common::execution::picture::{self, Conflict};
use shoal_common::execution::VehicleStatus;
use shoal_common::geometry::Vec3;
use shoal_common::scenario::{Obstacle, Scenario, VehicleKind};
use shoal_common::separation;
use shoal_common::stats::quantile;
use shoal_common::trajectory::Trajectory;
use shoal_common::wire::open::{FleetStatus, Telemetry, VehicleStatusRow, OPEN_VERSION};

use super::track::{
    along_plan, first_near, hazard_clearance, obstacle_clearance, seabed_clearance,
};
pub use super::tracked::Tracked;
use super::tracked::{CONVERGE_S, MATCH_SLACK_M, PROGRESS_WINDOW_S};

/// The fleet.
#[derive(Debug, Clone)]
pub struct Fleet {
    /// Per vehicle, scenario order.
    pub vehicles: Vec<Tracked>,
    /// Minimum separation, metres.
    pub d_min: f64,
    /// Prediction horizon, mission seconds.
    pub horizon_s: f64,
    /// End-to-end telemetry latencies (agent send → coordinator receipt), milliseconds.
    pub latencies_ms: Vec<f64>,
    /// Reports received.
    pub reports: u64,
    /// Closest pair over the executed tracks so far is computed at the end; this is the
    /// smallest pairwise distance between simultaneous latest fixes seen live, metres.
    pub live_min_separation: f64,
    /// Per obstacle published during the run, in order: each vehicle's number of track points
    /// when it came (see [`Fleet::obstacle_published`]).
    pub published: Vec<Vec<usize>>,
}

impl Fleet {
    /// Every vehicle at the start of its plan, nothing heard yet.
    pub fn new(ids: &[String], plans: &[Trajectory], d_min: f64, horizon_s: f64) -> Fleet {
        Fleet {
            vehicles: ids
                .iter()
                .zip(plans)
                .map(|(id, plan)| Tracked {
                    id: id.clone(),
                    plan: plan.clone(),
                    revision: 0,
                    last: None,
                    heard: None,
                    progress: None,
                    progress_revision: 0,
                    track: Trajectory {
                        times: Vec::new(),
                        points: Vec::new(),
                    },
                    fixes: 0,
                    anchor: None,
                    cross_track: Vec::new(),
                    arrived_s: None,
                    planned_arrival_s: plan.arrival(),
                    lost: false,
                    holding: false,
                    held_since_s: None,
                    held_at: None,
                    fault_s: None,
                })
                .collect(),
            d_min,
            horizon_s,
            latencies_ms: Vec::new(),
            reports: 0,
            live_min_separation: f64::INFINITY,
            published: Vec::new(),
        }
    }

    /// Notes that an obstacle was published now: a vehicle's clearance from it is measured on
    /// its track from its last fix before (the leg it was on then) onwards, not on the track it
    /// drove before the obstacle existed. The live run and `replay` call it at the same point
    /// of the record stream, so both measure the same.
    pub fn obstacle_published(&mut self) {
        let marks = self.vehicles.iter().map(|v| v.track.points.len()).collect();
        self.published.push(marks);
    }

    /// Index of vehicle `id`.
    pub fn index(&self, id: &str) -> Option<usize> {
        self.vehicles.iter().position(|v| v.id == id)
    }

    /// Takes a report received at unix time `received_us`. Reports older than the latest one
    /// (by sequence number) are ignored; returns false for those.
    pub fn report(&mut self, t: Telemetry, received_us: u64) -> bool {
        let Some(i) = self.index(&t.vehicle) else {
            return false;
        };
        let v = &mut self.vehicles[i];
        if v.last.as_ref().is_some_and(|l| l.seq >= t.seq) {
            return false;
        }
        self.latencies_ms
            .push(received_us.saturating_sub(t.sent_unix_us) as f64 / 1000.0);
        self.reports += 1;
        let p = Vec3::from(t.state.position);
        let now = t.state.t_s;
        let was_underway = v
            .last
            .as_ref()
            .is_some_and(|l| l.state.status != VehicleStatus::Holding);
        // The last fix in the track, on the current plan: when the vehicle was replanned since,
        // that fix is placed on the new plan (which keeps the old one up to the replan, so near
        // the plan time it had). Fixes are 250 m apart for a crawler at 1000×.
        let anchored = match (v.anchor, v.track.times.last(), v.track.points.last()) {
            (Some((tau0, offset0, revision)), Some(&t0), Some(&q0)) => {
                Some(if revision == v.revision {
                    (t0, tau0, offset0)
                } else {
                    let tau = picture::progress_near(
                        &v.plan,
                        q0,
                        t0,
                        PROGRESS_WINDOW_S,
                        tau0,
                        MATCH_SLACK_M,
                    )
                    .plan_time_s;
                    (t0, tau, q0 - v.plan.position_at(tau))
                })
            }
            _ => None,
        };
        // This fix is expected where the last one, carried on at planned pace (or standing, for
        // a vehicle already holding then), has it: of two passes of a path by the same point,
        // that picks the one it is on.
        let (expected, slack) = match anchored {
            Some((t0, tau0, _)) if now >= t0 => {
                let driven = if was_underway { now - t0 } else { 0.0 };
                (tau0 + driven, MATCH_SLACK_M)
            }
            _ => (now, 0.0),
        };
        let progress = picture::progress_near(&v.plan, p, now, PROGRESS_WINDOW_S, expected, slack);
        // A vehicle told to hold is off its plan by command: its distance from it is no
        // tracking error.
        if !v.holding {
            v.cross_track.push(progress.cross_track_m);
        }
        v.progress = Some(progress);
        v.progress_revision = v.revision;
        if v.track.times.last().is_none_or(|&last| now >= last) {
            let tau = progress.plan_time_s;
            let offset = p - v.plan.position_at(tau);
            // A vehicle told to hold stays where it is: its fixes are joined directly, not
            // along the plan it has left (which would draw it driving on, past whatever it
            // was holding for), but for the drive from its last fix under way to the stop.
            let held = v.holding || t.state.status == VehicleStatus::Holding;
            // Replanned since the last fix, the track between follows the plan the vehicle was
            // switching to rather than a chord across whatever lies between.
            if let Some((t0, tau0, offset0)) = anchored {
                let corners = if !held {
                    along_plan(&v.plan, (t0, tau0, offset0), (now, tau, offset))
                } else if was_underway && now > t0 {
                    // Told to hold since the last fix: it drove on along its plan until the
                    // hold came (up to a report interval, 250 m for a crawler at 1000×), then
                    // stood. The stop is matched on the plan between the two fixes' times.
                    let stop = first_near(&v.plan, p, tau0, tau0 + (now - t0));
                    let at = t0 + (stop - tau0);
                    let offset_stop = p - v.plan.position_at(stop);
                    let mut c = along_plan(&v.plan, (t0, tau0, offset0), (at, stop, offset_stop));
                    c.push((at, p));
                    c
                } else {
                    Vec::new()
                };
                for (t, q) in corners {
                    v.track.times.push(t);
                    v.track.points.push(q);
                }
            }
            v.track.times.push(now);
            v.track.points.push(p);
            v.fixes += 1;
            v.anchor = Some((tau, offset, v.revision));
        }
        v.fault_s = match t.state.status {
            VehicleStatus::Fault => v.fault_s.or(Some(now)),
            _ => None,
        };
        if t.state.status == VehicleStatus::Arrived && v.arrived_s.is_none() {
            v.arrived_s = Some(t.state.arrived_s.unwrap_or(now));
        }
        v.heard = Some(Instant::now());
        v.lost = false;
        v.last = Some(t);
        let positions: Vec<Vec3> = self
            .vehicles
            .iter()
            .filter(|v| v.last.is_some())
            .map(Tracked::position)
            .collect();
        if let Some((_, _, d)) = picture::current_min_separation(&positions) {
            self.live_min_separation = self.live_min_separation.min(d);
        }
        true
    }

    /// Each vehicle's predicted trajectory from `now` over the horizon.
    pub fn predictions(&self, now: f64) -> Vec<Trajectory> {
        self.predictions_over(now, self.horizon_s)
    }

    /// Each vehicle's predicted trajectory from `now` over `horizon_s`: along its plan from its
    /// latest fix, from the fix's time (from where its plan has it, before its first report); a
    /// lost or faulted vehicle stays where it was last seen, one that confirmed a hold where it
    /// stopped ([`Tracked::standing`]).
    pub fn predictions_over(&self, now: f64, horizon_s: f64) -> Vec<Trajectory> {
        self.vehicles
            .iter()
            .map(|v| {
                if v.lost || v.hold_confirmed() || v.fault_s.is_some() {
                    let p = v.standing();
                    return Trajectory {
                        times: vec![now, now + horizon_s],
                        points: vec![p, p],
                    };
                }
                // From the latest fix at its own time (up to a report interval ago, 25 mission
                // seconds at 2 Hz and 50×), carried forward to now: starting the prediction at
                // the fix's position now would put it behind the vehicle.
                let (p, at) = match &v.last {
                    Some(t) => (v.position(), t.state.t_s.min(now)),
                    None => (v.plan.position_at(now), now),
                };
                let pr = match v.fix_progress() {
                    Some(pr) if v.last.as_ref().is_some_and(|t| t.state.t_s <= now) => pr,
                    _ => picture::progress(&v.plan, p, at, PROGRESS_WINDOW_S),
                };
                picture::predict(&v.plan, p, &pr, at, horizon_s + (now - at), CONVERGE_S).since(now)
            })
            .collect()
    }

    /// Pairs predicted to come closer than d_min over the horizon, closest first.
    pub fn conflicts(&self, now: f64) -> Vec<Conflict> {
        self.conflicts_over(now, self.horizon_s)
    }

    /// Pairs predicted to come closer than d_min over the next `horizon_s`, closest first.
    pub fn conflicts_over(&self, now: f64, horizon_s: f64) -> Vec<Conflict> {
        picture::predicted_conflicts(&self.predictions_over(now, horizon_s), self.d_min)
    }

    /// Which vehicle of conflict `c` gives way: one that can (it has reported, and is not
    /// lost, holding, arrived or faulted); of two that can, the later in scenario order, a
    /// fixed priority so two coordinators' decisions never chase each other. `None` when
    /// neither can, or while the answer of one of them is awaited:
    /// - while `starting`, one has not reported yet: its agent may not have its order, and a
    ///   command sent now is lost (a hold sent before the agents joined was, and the two met
    ///   1.8 m apart);
    /// - it was told to hold less than `patience` ago and has neither confirmed nor given it
    ///   up: its hold settles the conflict, and the other would be told to leave a course the
    ///   held one is already leaving (both held, when the answer came late).
    pub fn gives_way(&self, c: &Conflict, patience: Duration, starting: bool) -> Option<usize> {
        let awaited = |i: usize| {
            let v = &self.vehicles[i];
            (starting && v.last.is_none() && !v.lost) || v.awaiting_hold_answer(patience)
        };
        if awaited(c.a) || awaited(c.b) {
            return None;
        }
        let can = |i: usize| {
            let v = &self.vehicles[i];
            v.last.is_some() && v.driven() && !v.holding
        };
        [c.b, c.a].into_iter().find(|&i| can(i))
    }

    /// The live picture at mission time `now`.
    pub fn status(&self, mission: &str, now: f64) -> FleetStatus {
        let heard: Vec<usize> = (0..self.vehicles.len())
            .filter(|&i| self.vehicles[i].last.is_some())
            .collect();
        let positions: Vec<Vec3> = heard.iter().map(|&i| self.vehicles[i].position()).collect();
        let current = picture::current_min_separation(&positions);
        FleetStatus {
            version: OPEN_VERSION,
            mission: mission.to_string(),
            t_s: now,
            d_min_m: self.d_min,
            vehicles: self
                .vehicles
                .iter()
                .map(|v| VehicleStatusRow {
                    vehicle: v.id.clone(),
                    state: v.last.as_ref().map(|t| t.state.clone()),
                    progress: v.progress,
                    revision: v.revision,
                    silent_s: v.heard.map_or(f64::INFINITY, |h| h.elapsed().as_secs_f64()),
                    lost: v.lost,
                    command: v.last.as_ref().and_then(|t| t.command.clone()),
                })
                .collect(),
            current_min_separation_m: current.map(|c| c.2),
            current_pair: current.map(|(a, b, _)| {
                [
                    self.vehicles[heard[a]].id.clone(),
                    self.vehicles[heard[b]].id.clone(),
                ]
            }),
            predicted: picture::predicted_min_separation(&self.predictions(now)),
            horizon_s: self.horizon_s,
        }
    }

    /// [`Fleet::figures`] against `scenario` (its obstacles, the published ones included, its
    /// seabed and its hazards): what the live run and `replay` both report. The vehicles are the
    /// scenario's, in its order.
    pub fn figures_for(
        &self,
        scenario: &Scenario,
        common_arrival_s: f64,
        window_s: f64,
    ) -> ExecutionFigures {
        let mut f = self.figures(common_arrival_s, window_s, &scenario.obstacles);
        let seabed = scenario.terrain();
        for ((fig, v), s) in f
            .vehicles
            .iter_mut()
            .zip(&self.vehicles)
            .zip(&scenario.vehicles)
        {
            match s.kind {
                // An AUV must keep off the seabed ...
                VehicleKind::Auv => {
                    fig.min_seabed_clearance_m = seabed.and_then(|t| seabed_clearance(&v.track, t));
                }
                // ... a crawler drives on it, and must keep out of the soft-substrate hazards.
                VehicleKind::Crawler => {
                    fig.min_hazard_clearance_m = hazard_clearance(&v.track, &scenario.hazards);
                }
            }
        }
        // A coverage crawler must keep off the ground its map calls impassable.
        if scenario.coverage.is_some() {
            let tracks: Vec<Trajectory> = self.vehicles.iter().map(|v| v.track.clone()).collect();
            if let Some(g) = super::ground::ground(scenario, &tracks) {
                for (fig, t) in f.vehicles.iter_mut().zip(g.tracks) {
                    fig.min_ground_clearance_m = t.map(|t| t.min_clearance_m);
                    fig.impassable_m = t.map(|t| t.impassable_m);
                }
                f.coverage = Some(g.coverage);
            }
        }
        f
    }

    /// The figures of the execution so far.
    /// `obstacles`: every obstacle known at the end (the scenario's, then the published ones
    /// in the order [`Fleet::obstacle_published`] noted them).
    pub fn figures(
        &self,
        common_arrival_s: f64,
        window_s: f64,
        obstacles: &[Obstacle],
    ) -> ExecutionFigures {
        let tracks: Vec<Trajectory> = self.vehicles.iter().map(|v| v.track.clone()).collect();
        let mut closest: Option<(f64, f64, [String; 2])> = None;
        for ((a, b), s) in separation::all_pairs(&tracks, self.d_min) {
            if tracks[a].times.is_empty() || tracks[b].times.is_empty() {
                continue;
            }
            if closest.as_ref().is_none_or(|c| s.min_distance < c.0) {
                closest = Some((
                    s.min_distance,
                    s.min_time,
                    [self.vehicles[a].id.clone(), self.vehicles[b].id.clone()],
                ));
            }
        }
        // Per vehicle, the first track point that counts for each obstacle: 0 for the
        // scenario's own, the last fix before publication for a published one.
        let own = obstacles.len().saturating_sub(self.published.len());
        let since = |i: usize| -> Vec<usize> {
            (0..obstacles.len())
                .map(|o| {
                    o.checked_sub(own)
                        .and_then(|p| self.published.get(p))
                        .and_then(|marks| marks.get(i))
                        .map_or(0, |n| n.saturating_sub(1))
                })
                .collect()
        };
        let vehicles: Vec<VehicleFigures> = self
            .vehicles
            .iter()
            .enumerate()
            .map(|(i, v)| VehicleFigures {
                vehicle: v.id.clone(),
                reports: v.fixes,
                arrived_s: v.arrived_s,
                planned_arrival_s: Some(v.planned_arrival_s),
                in_window: v
                    .arrived_s
                    .is_some_and(|t| (t - v.planned_arrival_s).abs() <= window_s),
                max_cross_track_m: v.cross_track.iter().copied().fold(0.0, f64::max),
                min_obstacle_clearance_m: obstacle_clearance(&v.track, obstacles, &since(i)),
                min_seabed_clearance_m: None,
                min_hazard_clearance_m: None,
                min_ground_clearance_m: None,
                impassable_m: None,
                median_cross_track_m: quantile_of(&v.cross_track, 0.5),
                p95_cross_track_m: quantile_of(&v.cross_track, 0.95),
                revision: v.revision,
                lost: v.lost,
                fault_s: v.fault_s,
            })
            .collect();
        ExecutionFigures {
            d_min_m: self.d_min,
            min_separation_m: closest.as_ref().map(|c| c.0),
            min_separation_at_s: closest.as_ref().map(|c| c.1),
            min_separation_pair: closest.map(|c| c.2),
            common_arrival_s,
            arrival_window_s: window_s,
            all_arrived_in_window: vehicles.iter().all(|v| v.in_window),
            vehicles,
            reports: self.reports,
            latency_median_ms: quantile_of(&self.latencies_ms, 0.5),
            latency_p99_ms: quantile_of(&self.latencies_ms, 0.99),
            coverage: None,
        }
    }
}

/// The `q` quantile of `x`, or `None` for no values: a vehicle that never reported has no
/// median (a NaN would be written to the log as `null` and not read back).
fn quantile_of(x: &[f64], q: f64) -> Option<f64> {
    (!x.is_empty()).then(|| quantile(x, q))
}

/// One vehicle's execution figures.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct VehicleFigures {
    /// Vehicle id.
    pub vehicle: String,
    /// Reports received.
    pub reports: usize,
    /// Mission time of its first `arrived` report (resolution: the report interval).
    pub arrived_s: Option<f64>,
    /// When its plan had it arrive, mission seconds (absent in logs written before it was
    /// kept: their vehicles were all timed for the common arrival).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub planned_arrival_s: Option<f64>,
    /// Arrived within the window around its planned arrival.
    pub in_window: bool,
    /// Largest cross-track error reported, metres.
    pub max_cross_track_m: f64,
    /// Closest the executed track ([`Tracked::track`]) came to a hard obstacle's physical
    /// surface, metres (negative: a collision; below its inflation margin: inside the keep-out
    /// sphere); `None` without hard obstacles or fixes.
    pub min_obstacle_clearance_m: Option<f64>,
    /// Lowest height of an AUV's executed track above the scenario's seabed, metres (negative:
    /// through it); absent for a crawler, or without a seabed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_seabed_clearance_m: Option<f64>,
    /// Closest a crawler's executed track came to a soft-substrate hazard (Lu et al. 2023, eq. (4)),
    /// horizontally, metres (negative: inside it); absent for an AUV, or without hazards.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_hazard_clearance_m: Option<f64>,
    /// A coverage crawler (CPP-DSMV): the closest its executed track came to impassable ground
    /// of its seabed map (a cell centre), metres; absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_ground_clearance_m: Option<f64>,
    /// A coverage crawler: metres of its executed track on impassable ground; absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub impassable_m: Option<f64>,
    /// Median cross-track error, metres; `None` without a report on a plan.
    pub median_cross_track_m: Option<f64>,
    /// 95th percentile, metres; `None` likewise.
    pub p95_cross_track_m: Option<f64>,
    /// Plan revision it ended on.
    pub revision: u32,
    /// Lost at the end.
    pub lost: bool,
    /// Its link reported a fault from this mission time to the end; absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fault_s: Option<f64>,
}

/// The figures of an execution (also what `replay` reports).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct ExecutionFigures {
    /// Minimum separation, metres.
    pub d_min_m: f64,
    /// Closest approach of two executed tracks ([`Tracked::track`]), metres.
    pub min_separation_m: Option<f64>,
    /// When, mission seconds.
    pub min_separation_at_s: Option<f64>,
    /// Which pair.
    pub min_separation_pair: Option<[String; 2]>,
    /// The arrival every vehicle was timed for, mission seconds (a coverage fleet's crawlers
    /// each have their own, [`VehicleFigures::planned_arrival_s`]: this is the last of them).
    pub common_arrival_s: f64,
    /// Half-width of the arrival window, mission seconds.
    pub arrival_window_s: f64,
    /// Every vehicle arrived within the window.
    pub all_arrived_in_window: bool,
    /// Per vehicle.
    pub vehicles: Vec<VehicleFigures>,
    /// Reports received.
    pub reports: u64,
    /// Telemetry latency, median, milliseconds; `None` without reports.
    pub latency_median_ms: Option<f64>,
    /// Telemetry latency, 99th percentile, milliseconds; `None` without reports.
    pub latency_p99_ms: Option<f64>,
    /// A coverage mission: the area the executed tracks' swaths covered (the plan's swath
    /// width); absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coverage: Option<shoal_common::coverage::metrics::CoverageCount>,
}

#[cfg(test)]
mod hold_tests;
#[cfg(test)]
mod tests;
