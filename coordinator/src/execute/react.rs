//! What the coordinator does with reports and with what it sees (issue 8, item 3): a predicted
//! loss of separation, a cross-track error beyond the tolerance, a vehicle silent too long or a
//! new obstacle on a vehicle's remaining path makes it replan that vehicle (see
//! [`super::replan`]); a replan that is not safe becomes a hold, retried until one is. Every
//! decision is an event, logged and published.
//!
//! Who gives way in a predicted conflict: a vehicle that can (not lost, holding or arrived);
//! between two that can, the later one in scenario order — a fixed priority, so two
//! coordinators' decisions never chase each other.

use std::time::{Duration, Instant};

use shoal_common::geometry::{segment_hits_sphere, Vec3};
use shoal_common::scenario::{Obstacle, ObstacleKind};
use shoal_common::wire::codec;
use shoal_common::wire::coordinator_to_agent::CoordinatorToAgent;
use shoal_common::wire::open::{FleetStatus, Telemetry, OPEN_VERSION};
use shoal_common::wire::WireTrajectory;

use super::lead::{
    conflict_horizon_s, course_conflict, course_enters_obstacle, hold_retry_after, update_lead_s,
};
use super::log::{Record, EVENT_FAULT, EVENT_HOLD, EVENT_LOST};
use super::repair;
use super::replan::{self, Request};
use super::Exec;

/// Shortest wall time between two reactions for one vehicle (a new obstacle does not wait; a
/// held vehicle's retries come sooner at high time scales, see [`hold_retry_after`]).
const COOL_DOWN: Duration = Duration::from_secs(2);

/// A report from the telemetry key.
pub(super) fn telemetry(x: &mut Exec, bytes: &[u8], received_us: u64) {
    let t: Telemetry = match codec::decode_json(bytes) {
        Ok(t) => t,
        Err(e) => return drop_message(x, &format!("telemetry: {e}")),
    };
    if t.version != OPEN_VERSION || t.mission != x.mission {
        return drop_message(
            x,
            &format!(
                "telemetry of version {} for mission {:?}",
                t.version, t.mission
            ),
        );
    }
    let Some(i) = x.fleet.index(&t.vehicle) else {
        return drop_message(x, &format!("telemetry of unknown vehicle {:?}", t.vehicle));
    };
    let finite = t
        .state
        .position
        .iter()
        .chain(&t.state.velocity)
        .all(|v| v.is_finite())
        && t.state.t_s.is_finite();
    if !finite {
        return drop_message(
            x,
            &format!("telemetry of {} with a non-finite state", t.vehicle),
        );
    }
    let was_arrived = x.fleet.vehicles[i].arrived_s.is_some();
    let was_lost = x.fleet.vehicles[i].lost;
    let was_faulted = x.fleet.vehicles[i].fault_s.is_some();
    let revision = t.revision;
    x.log.write(&Record::Telemetry {
        received_unix_us: received_us,
        telemetry: t.clone(),
    });
    if !x.fleet.report(t, received_us) {
        return;
    }
    if let Some((rev, at)) = x.pending[i] {
        if revision >= rev {
            x.deliveries_ms.push(at.elapsed().as_secs_f64() * 1000.0);
            x.pending[i] = None;
        }
    }
    let id = x.fleet.vehicles[i].id.clone();
    if was_lost {
        x.event(
            "vehicle_back",
            vec![id.clone()],
            format!("{id} reports again"),
        );
    }
    match (was_faulted, x.fleet.vehicles[i].fault_s) {
        (false, Some(t)) => x.event(
            EVENT_FAULT,
            vec![id.clone()],
            format!(
                "{id}'s link reports a fault at t = {t:.1} s: it is no longer re-planned or waited for, and the others keep clear of where it is"
            ),
        ),
        (true, None) => x.event(
            "fault_cleared",
            vec![id.clone()],
            format!("{id}'s link reports no fault any more"),
        ),
        _ => {}
    }
    if !was_arrived {
        if let Some(t) = x.fleet.vehicles[i].arrived_s {
            x.event(
                "arrived",
                vec![id.clone()],
                format!("{id} arrived at t = {t:.1} s"),
            );
        }
    }
}

fn drop_message(x: &mut Exec, detail: &str) {
    x.dropped += 1;
    if x.dropped == 1 {
        tracing::warn!(
            "dropped an open-interface message: {detail}; further ones are only counted"
        );
    }
}

/// A new obstacle from the obstacles key.
pub(super) fn obstacle_bytes(x: &mut Exec, bytes: &[u8]) {
    let received = Instant::now();
    let o: Obstacle = match codec::decode_json(bytes) {
        Ok(o) => o,
        Err(e) => return drop_message(x, &format!("obstacle: {e}")),
    };
    let ok = o.centre.iter().all(|v| v.is_finite())
        && o.radius_m.is_finite()
        && o.radius_m > 0.0
        && o.inflation_m.is_finite()
        && o.inflation_m >= 0.0;
    if !ok {
        return drop_message(
            x,
            &format!(
                "obstacle {:?}: centre {:?}, radius_m {}, inflation_m {}: need finite numbers and a positive radius",
                o.id, o.centre, o.radius_m, o.inflation_m
            ),
        );
    }
    obstacle(x, o, received);
}

/// Adds `o` to the scenario and replans every vehicle whose remaining path it blocks.
fn obstacle(x: &mut Exec, o: Obstacle, received: Instant) {
    let now = x.clock();
    let blocked: Vec<usize> = (0..x.fleet.vehicles.len())
        .filter(|&i| {
            let v = &x.fleet.vehicles[i];
            !v.lost && v.arrived_s.is_none() && o.kind == ObstacleKind::Hard && {
                let from = v.progress.map_or(now, |p| p.plan_time_s);
                remaining_hits(&v.plan, from, v.position(), &o)
            }
        })
        .collect();
    let names: Vec<String> = blocked
        .iter()
        .map(|&i| x.fleet.vehicles[i].id.clone())
        .collect();
    x.event(
        "obstacle",
        names.clone(),
        format!(
            "{} obstacle {} at ({:.0}, {:.0}, {:.0}) m, radius {:.0} + {:.0} m: blocks {}",
            if o.kind == ObstacleKind::Hard {
                "hard"
            } else {
                "soft"
            },
            o.id,
            o.centre[0],
            o.centre[1],
            o.centre[2],
            o.radius_m,
            o.inflation_m,
            if names.is_empty() {
                "no vehicle's path".to_string()
            } else {
                names.join(", ")
            }
        ),
    );
    x.log.write(&Record::Obstacle(o.clone()));
    x.scenario.obstacles.push(o.clone());
    x.fleet.obstacle_published();
    for i in blocked {
        if replan_vehicle(x, i, "a new obstacle blocks its path") {
            x.decisions_ms
                .push(received.elapsed().as_secs_f64() * 1000.0);
        }
    }
}

/// Whether the rest of `plan` after mission time `from`, starting at `p`, enters `o`'s
/// inflated sphere.
fn remaining_hits(
    plan: &shoal_common::trajectory::Trajectory,
    from: f64,
    p: Vec3,
    o: &Obstacle,
) -> bool {
    super::standing::rest_of(plan, from, p)
        .windows(2)
        .any(|w| segment_hits_sphere(&w[0], &w[1], &o.centre(), o.inflated_radius()))
}

/// Marks vehicle `id` lost (once) and says why; the others then treat its last fix as an
/// obstacle in their predictions and replans.
pub(super) fn lose(x: &mut Exec, id: &str, why: &str) {
    let Some(i) = x.fleet.index(id) else {
        return;
    };
    let v = &x.fleet.vehicles[i];
    if v.lost || v.arrived_s.is_some() {
        return;
    }
    x.fleet.vehicles[i].lost = true;
    x.event(
        EVENT_LOST,
        vec![id.to_string()],
        format!("{id} is lost: {why}; the others treat its last position as an obstacle"),
    );
}

/// The periodic checks (see the module doc).
pub(super) fn check(x: &mut Exec, now: f64) {
    let o = x.options;
    for i in 0..x.fleet.vehicles.len() {
        let v = &x.fleet.vehicles[i];
        let silent = match v.heard {
            Some(h) => h.elapsed() > o.lost_after,
            // Never heard: lost once the mission has run for a while without it.
            None => {
                now > 0.0 && x.mission_clock.since_epoch() > o.lost_after + Duration::from_secs(5)
            }
        };
        if silent {
            let id = v.id.clone();
            let why = format!("no report for {:.1} s", o.lost_after.as_secs_f64());
            lose(x, &id, &why);
        }
    }
    for i in 0..x.fleet.vehicles.len() {
        let v = &x.fleet.vehicles[i];
        let active = !v.lost && v.arrived_s.is_none() && v.fault_s.is_none();
        let wait = if v.holding {
            hold_retry_after(o.time_scale, x.last_attempt[i], COOL_DOWN)
        } else {
            COOL_DOWN
        };
        let cooled = x.last_reaction[i].is_none_or(|t| t.elapsed() >= wait);
        if !(active && cooled) {
            continue;
        }
        if v.holding {
            replan_vehicle(x, i, "retrying after a hold");
            continue;
        }
        if let Some(p) = v.progress {
            if p.cross_track_m > o.deviation_m {
                let why = format!(
                    "cross-track error {:.1} m is over the {:.1} m tolerance",
                    p.cross_track_m, o.deviation_m
                );
                replan_vehicle(x, i, &why);
            }
        }
    }
    for c in x.fleet.conflicts_over(now, conflict_horizon_s(o)) {
        let can = |i: usize| {
            let v = &x.fleet.vehicles[i];
            !v.lost && !v.holding && v.arrived_s.is_none() && v.fault_s.is_none()
        };
        let who = if can(c.b) {
            c.b
        } else if can(c.a) {
            c.a
        } else {
            continue;
        };
        if x.last_reaction[who].is_some_and(|t| t.elapsed() < COOL_DOWN) {
            continue;
        }
        let why = format!(
            "predicted separation {:.1} m from {} at t = {:.0} s is under d_min {:.0} m",
            c.min_distance_m,
            x.fleet.vehicles[if who == c.a { c.b } else { c.a }].id,
            c.at_s,
            x.fleet.d_min
        );
        x.event(
            "conflict_predicted",
            vec![
                x.fleet.vehicles[c.a].id.clone(),
                x.fleet.vehicles[c.b].id.clone(),
            ],
            why.clone(),
        );
        replan_vehicle(x, who, &why);
    }
}

/// Replans vehicle `i` and sends the update, or commands a hold; true when an update went out.
pub(super) fn replan_vehicle(x: &mut Exec, i: usize, why: &str) -> bool {
    let o = x.options;
    let now = x.clock();
    // A holding vehicle is safe where it is, so each retry may think longer: the budget
    // doubles per failed retry, up to 8 ×.
    let budget = if x.fleet.vehicles[i].holding {
        o.replan_budget * (1u32 << x.hold_retries[i].min(3))
    } else {
        o.replan_budget
    };
    let t0 = now + update_lead_s(budget, o.time_scale);
    let remaining = (x.common_arrival_s + o.arrival_window_s - now).max(o.horizon_s);
    // Long enough to cover the lead (near the end of a fast run it can be the longer).
    let predictions = x.fleet.predictions_over(now, remaining.max(t0 - now));
    // Until t0 the vehicle drives its predicted course: if that enters a hard obstacle or
    // comes within d_min of another vehicle, no update can take effect in time. A hold is
    // obeyed at once; the retries start from there.
    if !x.fleet.vehicles[i].holding {
        let course: Vec<_> = predictions.iter().map(|p| p.until(t0)).collect();
        let detail = if course_enters_obstacle(&course[i], &x.scenario) {
            Some("its course enters a hard obstacle".to_string())
        } else {
            course_conflict(&course, i, x.fleet.d_min).map(|c| {
                let other = if c.a == i { c.b } else { c.a };
                format!(
                    "its course comes {:.1} m from {} at t = {:.0} s",
                    c.min_distance_m, x.fleet.vehicles[other].id, c.at_s
                )
            })
        };
        if let Some(detail) = detail {
            x.last_reaction[i] = Some(Instant::now());
            let when = format!("before an update could take effect at t = {t0:.0} s");
            hold(x, i, why, format!("{detail} {when}"));
            return false;
        }
    }
    let p0 = predictions[i].position_at(t0);
    // The course there: where the prediction was heading over the last few seconds before.
    let heading = Some(p0 - predictions[i].position_at((t0 - 5.0).max(now)))
        .filter(|d| d.x.hypot(d.y) > 1e-3 && !x.fleet.vehicles[i].holding);
    // A retry must not repeat the swarm that just failed.
    let seed =
        o.seed ^ (u64::from(x.revision) << 8) ^ (u64::from(x.hold_retries[i]) << 32) ^ i as u64;
    let request = Request {
        scenario: &x.scenario,
        vehicle: i,
        t0,
        p0,
        heading,
        current: &x.fleet.vehicles[i].plan,
        resume_s: x.fleet.vehicles[i].resume_s(),
        others: &predictions,
        arrival_s: x.fleet.vehicles[i].planned_arrival_s,
        budget,
        separation_buffer_m: o.separation_buffer_m,
        seed,
        ground: x.ground.as_ref(),
    };
    // A tour must still pass its remaining inspection points, an energy plan (seed 001)
    // keeps the path its cost chose over the seabed, its turning radius and the current, and
    // a coverage crawler (seed 002) must still drive its remaining rows, none of which seed
    // 004's replan models: all three are repaired, not replanned.
    let algorithm = x.scenario.optimizer.algorithm;
    let result = if algorithm.is_tour_planner()
        || algorithm.is_energy_planner()
        || x.scenario.coverage.is_some()
    {
        repair::repair(&request)
    } else {
        replan::replan(&request)
    };
    x.last_reaction[i] = Some(Instant::now());
    x.last_attempt[i] = result.elapsed;
    let id = x.fleet.vehicles[i].id.clone();
    if result.safe {
        x.hold_retries[i] = 0;
        x.revision += 1;
        let v = &mut x.fleet.vehicles[i];
        // Under way, the vehicle goes on as predicted (its old course, its lag included) until
        // the new one starts at the predicted point; holding, it waits where it is for it. The
        // plan before now stays, for the record.
        let plan = if v.holding {
            result.trajectory.clone()
        } else {
            v.plan
                .followed_by(&predictions[i].followed_by(&result.trajectory))
        };
        v.plan = plan.clone();
        v.revision = x.revision;
        v.holding = false;
        v.held_since_s = None;
        x.send(
            &id,
            CoordinatorToAgent::Update {
                mission: x.mission.clone(),
                vehicle: id.clone(),
                revision: x.revision,
                trajectory: WireTrajectory::new(&id, &plan),
            },
        );
        x.pending[i] = Some((x.revision, Instant::now()));
        x.replans += 1;
        x.publish_plan(vec![id.clone()]);
        x.event(
            "replanned",
            vec![id.clone()],
            format!(
                "{id} replanned ({why}) in {:.0} ms: revision {}, from t = {t0:.0} s, arrival {:.0} s, closest vehicle {:.1} m{}",
                result.elapsed.as_secs_f64() * 1000.0,
                x.revision,
                result.trajectory.arrival(),
                result.min_separation_m,
                result.note.as_ref().map_or(String::new(), |n| format!("; {n}"))
            ),
        );
        true
    } else {
        if x.fleet.vehicles[i].holding {
            x.hold_retries[i] += 1;
            let n = x.hold_retries[i];
            if told_retry(n) {
                x.event(
                    "still_holding",
                    vec![id.clone()],
                    format!(
                        "{id} keeps holding: retry {n} found no safe replan in {:.0} ms ({}); the next event on it comes at retry {}",
                        result.elapsed.as_secs_f64() * 1000.0,
                        result.shortfall(),
                        2 * n
                    ),
                );
            }
        } else {
            hold(
                x,
                i,
                why,
                format!(
                    "no safe replan in {:.0} ms ({})",
                    result.elapsed.as_secs_f64() * 1000.0,
                    result.shortfall()
                ),
            );
        }
        false
    }
}

/// Whether a held vehicle's failed retry `n` (from 1) gets an event: 1, 2, 4, 8, …. A vehicle
/// held for good is retried every 30 mission seconds or so ([`hold_retry_after`]): an event for
/// each put 166 in one 10,000 s mission log at 500×.
fn told_retry(n: u32) -> bool {
    n.is_power_of_two()
}

/// Commands vehicle `i` to hold where it is (obeyed at once) and says why.
fn hold(x: &mut Exec, i: usize, why: &str, detail: String) {
    let id = x.fleet.vehicles[i].id.clone();
    x.send(
        &id,
        CoordinatorToAgent::Hold {
            mission: x.mission.clone(),
            vehicle: id.clone(),
            reason: why.to_string(),
        },
    );
    let now = x.clock();
    x.fleet.vehicles[i].holding = true;
    x.fleet.vehicles[i].held_since_s = Some(now);
    x.holds += 1;
    x.event(
        EVENT_HOLD,
        vec![id.clone()],
        format!("{id} told to hold ({why}): {detail}"),
    );
}

/// The progress line on stderr.
pub(super) fn progress_line(s: &FleetStatus, reports: u64) -> String {
    let fmt = |v: Option<f64>| v.map_or("–".to_string(), |d| format!("{d:.0} m"));
    let vehicles: Vec<String> = s
        .vehicles
        .iter()
        .map(|v| match (&v.progress, v.lost) {
            (_, true) => format!("{} LOST", v.vehicle),
            (Some(p), _) => format!(
                "{} {:.0}% cte {:.1} m",
                v.vehicle,
                100.0 * p.fraction,
                p.cross_track_m
            ),
            (None, _) => format!("{} –", v.vehicle),
        })
        .collect();
    format!(
        "t {:>6.0} s | {reports} reports | separation now {}, predicted {} | {}",
        s.t_s,
        fmt(s.current_min_separation_m),
        fmt(s.predicted.map(|c| c.min_distance_m)),
        vehicles.join(" | ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failed_retries_1_2_4_8_and_so_on_are_told() {
        let told: Vec<u32> = (1..=20).filter(|&n| told_retry(n)).collect();
        assert_eq!(told, vec![1, 2, 4, 8, 16]);
        // The 166 retries of a crawler held for good at 500× make 8 events.
        assert_eq!((1..=166).filter(|&n| told_retry(n)).count(), 8);
    }
}
