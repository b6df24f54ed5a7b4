//! The coordinator's live fleet picture during an execution: per vehicle its plan, its latest
//! report and where that puts it on the plan (progress, cross-track error, ETA); for the fleet
//! the closest pair now and the closest approach predicted over the next minutes (see
//! [`shoal_common::execution::picture`]). It also keeps what the figures need: each vehicle's
//! executed track, its cross-track errors, its arrival, and the telemetry latencies.

use std::time::Instant;

use serde::{Deserialize, Serialize};
use shoal_common::execution::picture::{self, Conflict, Progress};
use shoal_common::execution::VehicleStatus;
use shoal_common::geometry::Vec3;
use shoal_common::scenario::Obstacle;
use shoal_common::separation;
use shoal_common::stats::quantile;
use shoal_common::trajectory::Trajectory;
use shoal_common::wire::open::{FleetStatus, Telemetry, VehicleStatusRow, OPEN_VERSION};

use super::track::{along_plan, obstacle_clearance};

/// How far either side of the mission time a report's nearest plan point is searched,
/// mission seconds (a path that passes near itself must not make progress jump).
const PROGRESS_WINDOW_S: f64 = 300.0;
/// Seconds over which a prediction closes the vehicle's cross-track offset.
const CONVERGE_S: f64 = 60.0;

/// One vehicle as the coordinator sees it.
#[derive(Debug, Clone)]
pub struct Tracked {
    /// Vehicle id.
    pub id: String,
    /// The trajectory it follows (mission-timed).
    pub plan: Trajectory,
    /// Revision of `plan`.
    pub revision: u32,
    /// Its latest report.
    pub last: Option<Telemetry>,
    /// When that report came (wall).
    pub heard: Option<Instant>,
    /// Where the latest report puts it on its plan.
    pub progress: Option<Progress>,
    /// Executed track: every reported fix and, between two fixes on the same plan, that
    /// plan's corners shifted by the fixes' offsets from it ([`Fleet::report`]).
    pub track: Trajectory,
    /// Fixes in `track`.
    pub fixes: usize,
    /// The last fix in `track`: its plan time, its offset from the plan there, the plan's
    /// revision.
    anchor: Option<(f64, Vec3, u32)>,
    /// Cross-track error of every report, metres.
    pub cross_track: Vec<f64>,
    /// Mission time of its first `arrived` report.
    pub arrived_s: Option<f64>,
    /// Declared lost (silent too long).
    pub lost: bool,
    /// Commanded to hold.
    pub holding: bool,
}

impl Tracked {
    /// Latest position fix, or the plan's start before any.
    pub fn position(&self) -> Vec3 {
        match &self.last {
            Some(t) => Vec3::from(t.state.position),
            None => self
                .plan
                .points
                .first()
                .copied()
                .unwrap_or_else(Vec3::zeros),
        }
    }
}

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
                    track: Trajectory {
                        times: Vec::new(),
                        points: Vec::new(),
                    },
                    fixes: 0,
                    anchor: None,
                    cross_track: Vec::new(),
                    arrived_s: None,
                    lost: false,
                    holding: false,
                })
                .collect(),
            d_min,
            horizon_s,
            latencies_ms: Vec::new(),
            reports: 0,
            live_min_separation: f64::INFINITY,
        }
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
        let progress = picture::progress(&v.plan, p, now, PROGRESS_WINDOW_S);
        // A vehicle told to hold is off its plan by command: its distance from it is no
        // tracking error.
        if !v.holding {
            v.cross_track.push(progress.cross_track_m);
        }
        v.progress = Some(progress);
        if v.track.times.last().is_none_or(|&last| now >= last) {
            let tau = progress.plan_time_s;
            let offset = p - v.plan.position_at(tau);
            if let (Some((tau0, offset0, revision)), Some(&t0)) = (v.anchor, v.track.times.last()) {
                if revision == v.revision {
                    let corners = along_plan(&v.plan, (t0, tau0, offset0), (now, tau, offset));
                    for (t, q) in corners {
                        v.track.times.push(t);
                        v.track.points.push(q);
                    }
                }
            }
            v.track.times.push(now);
            v.track.points.push(p);
            v.fixes += 1;
            v.anchor = Some((tau, offset, v.revision));
        }
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
    /// lost or holding vehicle stays where it was last seen.
    pub fn predictions_over(&self, now: f64, horizon_s: f64) -> Vec<Trajectory> {
        self.vehicles
            .iter()
            .map(|v| {
                if v.lost || v.holding {
                    let p = v.position();
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
                let pr = picture::progress(&v.plan, p, at, PROGRESS_WINDOW_S);
                picture::predict(&v.plan, p, &pr, at, horizon_s + (now - at), CONVERGE_S).since(now)
            })
            .collect()
    }

    /// Pairs predicted to come closer than d_min over the horizon, closest first.
    pub fn conflicts(&self, now: f64) -> Vec<Conflict> {
        picture::predicted_conflicts(&self.predictions(now), self.d_min)
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

    /// The figures of the execution so far.
    /// `obstacles`: every obstacle known at the end (the scenario's and the published ones).
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
        let vehicles: Vec<VehicleFigures> = self
            .vehicles
            .iter()
            .map(|v| VehicleFigures {
                vehicle: v.id.clone(),
                reports: v.fixes,
                arrived_s: v.arrived_s,
                in_window: v
                    .arrived_s
                    .is_some_and(|t| (t - common_arrival_s).abs() <= window_s),
                max_cross_track_m: v.cross_track.iter().copied().fold(0.0, f64::max),
                min_obstacle_clearance_m: obstacle_clearance(&v.track, obstacles),
                median_cross_track_m: quantile(&v.cross_track, 0.5),
                p95_cross_track_m: quantile(&v.cross_track, 0.95),
                revision: v.revision,
                lost: v.lost,
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
            latency_median_ms: quantile(&self.latencies_ms, 0.5),
            latency_p99_ms: quantile(&self.latencies_ms, 0.99),
        }
    }
}

/// One vehicle's execution figures.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VehicleFigures {
    /// Vehicle id.
    pub vehicle: String,
    /// Reports received.
    pub reports: usize,
    /// Mission time of its first `arrived` report (resolution: the report interval).
    pub arrived_s: Option<f64>,
    /// Arrived within the window around the common arrival.
    pub in_window: bool,
    /// Largest cross-track error reported, metres.
    pub max_cross_track_m: f64,
    /// Closest the executed track ([`Tracked::track`]) came to a hard obstacle's physical
    /// surface, metres (negative: a collision; below its inflation margin: inside the keep-out
    /// sphere); `None` without hard obstacles or fixes.
    pub min_obstacle_clearance_m: Option<f64>,
    /// Median cross-track error, metres.
    pub median_cross_track_m: f64,
    /// 95th percentile, metres.
    pub p95_cross_track_m: f64,
    /// Plan revision it ended on.
    pub revision: u32,
    /// Lost at the end.
    pub lost: bool,
}

/// The figures of an execution (also what `replay` reports).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExecutionFigures {
    /// Minimum separation, metres.
    pub d_min_m: f64,
    /// Closest approach of two executed tracks ([`Tracked::track`]), metres.
    pub min_separation_m: Option<f64>,
    /// When, mission seconds.
    pub min_separation_at_s: Option<f64>,
    /// Which pair.
    pub min_separation_pair: Option<[String; 2]>,
    /// The arrival every vehicle was timed for, mission seconds.
    pub common_arrival_s: f64,
    /// Half-width of the arrival window, mission seconds.
    pub arrival_window_s: f64,
    /// Every vehicle arrived within the window.
    pub all_arrived_in_window: bool,
    /// Per vehicle.
    pub vehicles: Vec<VehicleFigures>,
    /// Reports received.
    pub reports: u64,
    /// Telemetry latency, median, milliseconds.
    pub latency_median_ms: f64,
    /// Telemetry latency, 99th percentile, milliseconds.
    pub latency_p99_ms: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use shoal_common::execution::VehicleState;
    use shoal_common::scenario::ObstacleKind;

    fn straight(y: f64) -> Trajectory {
        Trajectory {
            times: vec![0.0, 100.0],
            points: vec![Vec3::new(0.0, y, 0.0), Vec3::new(100.0, y, 0.0)],
        }
    }

    fn report(vehicle: &str, seq: u64, t: f64, p: [f64; 3], status: VehicleStatus) -> Telemetry {
        Telemetry {
            version: OPEN_VERSION,
            mission: "m".into(),
            vehicle: vehicle.into(),
            seq,
            revision: 0,
            sent_unix_us: 1_000_000,
            state: VehicleState {
                t_s: t,
                position: p,
                velocity: [1.0, 0.0, 0.0],
                heading_deg: 0.0,
                depth_m: None,
                altitude_m: None,
                battery: 1.0,
                status,
                arrived_s: (status == VehicleStatus::Arrived).then_some(100.0),
            },
        }
    }

    #[test]
    fn between_two_fixes_the_track_follows_the_plan_round_its_corners() {
        // East 100 m then north 100 m at 1 m/s; an obstacle of 10 m inside the corner.
        let p = |x: f64, y: f64| Vec3::new(x, y, 0.0);
        let plan = Trajectory {
            times: vec![0.0, 100.0, 200.0],
            points: vec![p(0.0, 0.0), p(100.0, 0.0), p(100.0, 100.0)],
        };
        let ids = vec!["a".to_string()];
        let mut f = Fleet::new(&ids, std::slice::from_ref(&plan), 50.0, 60.0);
        // Fixes 2 m left of the plan at t = 50 and 2 m short of it at t = 150.
        f.report(
            report("a", 0, 50.0, [50.0, 2.0, 0.0], VehicleStatus::Underway),
            1,
        );
        f.report(
            report("a", 1, 150.0, [98.0, 50.0, 0.0], VehicleStatus::Underway),
            2,
        );
        // The corner (100, 0) at plan time 100, halfway: offset (0, 2) + ½ ((−2, 0) − (0, 2)).
        let track = &f.vehicles[0].track;
        assert_eq!(track.times, vec![50.0, 100.0, 150.0]);
        assert!((track.points[1] - p(99.0, 1.0)).norm() < 1e-9, "{track:?}");
        assert_eq!(f.vehicles[0].fixes, 2);
        let cage = Obstacle {
            id: "o".into(),
            kind: ObstacleKind::Hard,
            centre: [75.0, 25.0, 0.0],
            radius_m: 10.0,
            inflation_m: 1.0,
        };
        // Both legs pass the centre at |49·23 + 25| / √2402 = 23.5053 m: 13.5053 m clear. The
        // chord (50, 2)–(98, 50) would pass 1.414 m from the centre, 8.6 m inside.
        let fig = f.figures(200.0, 10.0, std::slice::from_ref(&cage));
        let clearance = fig.vehicles[0].min_obstacle_clearance_m.unwrap_or(f64::NAN);
        assert!((clearance - 13.505_309_691).abs() < 1e-6, "{clearance}");
        assert_eq!(fig.vehicles[0].reports, 2);
        // A fix 10 s later that matches the plan 110 s further on (past the corner) is joined
        // directly: plan time ran more than twice as fast as mission time.
        let mut f = Fleet::new(&ids, std::slice::from_ref(&plan), 50.0, 60.0);
        f.report(
            report("a", 0, 50.0, [50.0, 2.0, 0.0], VehicleStatus::Underway),
            1,
        );
        f.report(
            report("a", 1, 60.0, [100.0, 60.0, 0.0], VehicleStatus::Underway),
            2,
        );
        assert_eq!(f.vehicles[0].track.times, vec![50.0, 60.0]);
        // Nor is one on a new revision of the plan.
        let mut f = Fleet::new(&ids, std::slice::from_ref(&plan), 50.0, 60.0);
        f.report(
            report("a", 0, 50.0, [50.0, 2.0, 0.0], VehicleStatus::Underway),
            1,
        );
        f.vehicles[0].revision = 1;
        f.report(
            report("a", 1, 150.0, [98.0, 50.0, 0.0], VehicleStatus::Underway),
            2,
        );
        assert_eq!(f.vehicles[0].track.times, vec![50.0, 150.0]);
    }

    #[test]
    fn reports_give_progress_separation_and_figures() {
        let ids = vec!["a".to_string(), "b".to_string()];
        let mut f = Fleet::new(&ids, &[straight(0.0), straight(60.0)], 50.0, 60.0);
        // a is 3 m off its line at x = 50 when the plan has it at x = 50: cross-track 3.
        assert!(f.report(
            report("a", 0, 50.0, [50.0, 3.0, 0.0], VehicleStatus::Underway),
            1_002_000
        ));
        assert!(f.report(
            report("b", 0, 50.0, [50.0, 60.0, 0.0], VehicleStatus::Underway),
            1_001_000
        ));
        // An older report is ignored.
        assert!(!f.report(
            report("a", 0, 40.0, [40.0, 0.0, 0.0], VehicleStatus::Underway),
            1_001_000
        ));
        let p = f.vehicles[0]
            .progress
            .unwrap_or_else(|| panic!("no progress"));
        assert!((p.cross_track_m - 3.0).abs() < 1e-9 && (p.fraction - 0.5).abs() < 1e-9);
        // 57 m apart now (60 − 3).
        assert!((f.live_min_separation - 57.0).abs() < 1e-9);
        let s = f.status("m", 50.0);
        assert!((s.current_min_separation_m.unwrap_or(0.0) - 57.0).abs() < 1e-9);
        assert_eq!(s.current_pair, Some(["a".to_string(), "b".to_string()]));
        f.report(
            report("a", 1, 100.0, [100.0, 0.0, 0.0], VehicleStatus::Arrived),
            1_004_000,
        );
        f.report(
            report("b", 1, 100.0, [100.0, 60.0, 0.0], VehicleStatus::Arrived),
            1_003_000,
        );
        let wall = Obstacle {
            id: "o".into(),
            kind: ObstacleKind::Hard,
            centre: [50.0, 30.0, 0.0],
            radius_m: 10.0,
            inflation_m: 5.0,
        };
        let fig = f.figures(100.0, 10.0, &[wall]);
        // Tracks: a from (50,3) to (100,0), b along y = 60: closest 57 m at t = 50.
        assert!(
            (fig.min_separation_m.unwrap_or(0.0) - 57.0).abs() < 1e-9,
            "{fig:?}"
        );
        assert!(fig.all_arrived_in_window);
        assert_eq!(fig.vehicles[0].arrived_s, Some(100.0));
        // a's track passes (50, 3): 27 m from the centre, 17 m from the surface.
        assert!((fig.vehicles[0].min_obstacle_clearance_m.unwrap_or(0.0) - 17.0).abs() < 1e-9);
        assert!((fig.vehicles[1].min_obstacle_clearance_m.unwrap_or(0.0) - 20.0).abs() < 1e-9);
        // Latencies 2, 1, 4, 3 ms: median 2.5.
        assert!((fig.latency_median_ms - 2.5).abs() < 1e-9, "{fig:?}");
        assert_eq!(fig.reports, 4);
    }

    #[test]
    fn a_vehicle_predicted_into_a_lost_one_is_a_conflict() {
        let ids = vec!["a".to_string(), "b".to_string()];
        let b_plan = Trajectory {
            times: vec![0.0, 100.0],
            points: vec![Vec3::new(100.0, 0.0, 0.0), Vec3::new(100.0, 100.0, 0.0)],
        };
        let mut f = Fleet::new(&ids, &[straight(0.0), b_plan], 50.0, 120.0);
        f.report(
            report("a", 0, 10.0, [10.0, 0.0, 0.0], VehicleStatus::Underway),
            1_000_000,
        );
        f.report(
            report("b", 0, 10.0, [100.0, 10.0, 0.0], VehicleStatus::Underway),
            1_000_000,
        );
        // Both on plan: a reaches (100, 0) at t = 100, b is at (100, 100) by then.
        assert!(f.conflicts(10.0).is_empty());
        // b is lost where it was last seen: a drives into it.
        f.vehicles[1].lost = true;
        let c = f.conflicts(10.0);
        assert_eq!(c.len(), 1);
        assert!((c[0].min_distance_m - 10.0).abs() < 1e-6, "{c:?}");
    }

    #[test]
    fn a_prediction_starts_from_the_fix_carried_forward_to_now() {
        let ids = vec!["a".to_string()];
        let mut f = Fleet::new(&ids, &[straight(0.0)], 50.0, 60.0);
        // On its plan at x = 40 at t = 40; at t = 65 it is predicted at x = 65, not left at 40.
        f.report(
            report("a", 0, 40.0, [40.0, 0.0, 0.0], VehicleStatus::Underway),
            1_000_000,
        );
        let p = &f.predictions_over(65.0, 20.0)[0];
        assert_eq!(p.times.first(), Some(&65.0));
        assert!(
            (p.position_at(65.0) - Vec3::new(65.0, 0.0, 0.0)).norm() < 1e-9,
            "{p:?}"
        );
        assert!(
            (p.position_at(85.0) - Vec3::new(85.0, 0.0, 0.0)).norm() < 1e-9,
            "{p:?}"
        );
    }
}
