//! What the coordinator does with reports and with what it sees: a predicted
//! loss of separation, a cross-track error beyond the tolerance, a vehicle silent too long or a
//! new obstacle on a vehicle's remaining path makes it replan that vehicle (see
//! [`super::replan`]; the replan runs off the loop, [`super::replan_queue`]); a replan that is
//! not safe becomes a hold, retried until one is. Every decision is an event, logged and
//! published.
//!
//! Who gives way in a predicted conflict: see [`super::fleet::Fleet::gives_way`].

use std::time::{Duration, Instant};

use shoal_common::execution::CommandReport;
use shoal_common::geometry::{segment_hits_sphere, Vec3};
use shoal_common::limits;
use shoal_common::scenario::{Obstacle, ObstacleKind};
use shoal_common::wire::codec;
use shoal_common::wire::open::{FleetStatus, Telemetry, OPEN_VERSION};
use shoal_common::wire::topics;

use super::confirmations;
use super::lead::{conflict_horizon_s, hold_answer_patience, hold_retry_after};
use super::log::{Record, EVENT_FAULT, EVENT_IMPLAUSIBLE, EVENT_LOST, EVENT_OBSTACLE_DROPPED};
use super::plausible::{self, FixLimits, LastFix, Reason};
use super::replan_queue;
use super::state::Exec;

/// Shortest wall time between two reactions for one vehicle (a new obstacle does not wait; a
/// held vehicle's retries come sooner at high time scales, see [`hold_retry_after`]).
const COOL_DOWN: Duration = Duration::from_secs(2);

/// A report from the telemetry key.
///
/// The key's vehicle must be the report's: access control lets a vehicle publish only on its
/// own key, so a report there naming another vehicle is a forgery, dropped and counted.
pub(super) fn telemetry(x: &mut Exec, key: &str, bytes: &[u8], received_us: u64) {
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
    if topics::vehicle_of_telemetry(key) != Some(t.vehicle.as_str()) {
        return drop_message(
            x,
            &format!("telemetry on {key} names vehicle {:?}", t.vehicle),
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
    // Refused before it is logged: `replay` rebuilds the picture from the logged reports.
    if let Err((reason, why)) = plausible_fix(x, i, &t, received_us) {
        let detail = format!("{}'s report {}: {why}", t.vehicle, t.seq);
        return refuse(x, EVENT_IMPLAUSIBLE, &t.vehicle, reason, detail);
    }
    let was_arrived = x.fleet.vehicles[i].arrived_s.is_some();
    let was_lost = x.fleet.vehicles[i].lost;
    let was_faulted = x.fleet.vehicles[i].fault_s.is_some();
    let revision = t.revision;
    let command_before = x.fleet.vehicles[i]
        .last
        .as_ref()
        .and_then(|l| l.command.clone());
    let command_now = t.command.clone();
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
    command_event(x, &id, command_before.as_ref(), command_now.as_ref());
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

/// What the vehicle made of its latest command, as an event when that changed (see
/// [`confirmations::change`]).
fn command_event(
    x: &mut Exec,
    id: &str,
    before: Option<&CommandReport>,
    now: Option<&CommandReport>,
) {
    if let Some((kind, detail)) = confirmations::change(id, before, now) {
        x.event(&kind, vec![id.to_string()], detail);
    }
}

/// Whether report `t` of vehicle `i`, received at unix time `received_us`, can be true (see
/// [`plausible::check_fix`]).
fn plausible_fix(
    x: &Exec,
    i: usize,
    t: &Telemetry,
    received_us: u64,
) -> Result<(), (Reason, String)> {
    let o = x.options;
    let limits = FixLimits::of(&x.scenario, i, o.telemetry_hz, o.time_scale, o.deviation_m);
    let v = &x.fleet.vehicles[i];
    let last = v.last.as_ref().map(|l| LastFix {
        position: l.state.position,
        t_s: l.state.t_s,
        seq: l.seq,
        wall_since_s: v.heard.map_or(0.0, |h| h.elapsed().as_secs_f64()),
    });
    // The mission clock when the report came (not when the loop got to it), as
    // `MissionClock::now` counts it: from 0 at the epoch.
    let epoch_us = x.mission_clock.epoch_unix_ms.saturating_mul(1000);
    let now_s = ((received_us as f64 - epoch_us as f64) / 1e6 * o.time_scale).max(0.0);
    plausible::check_fix(
        t,
        last,
        &limits,
        &x.scenario.bounds,
        now_s,
        x.guard.started.elapsed().as_secs_f64(),
    )
}

/// Counts a refusal of `reason` for `who` and, at most once per [`plausible::EVENT_EVERY`]
/// for `who` and `reason`, says so in an event of `kind`.
fn refuse(x: &mut Exec, kind: &str, who: &str, reason: Reason, detail: String) {
    if x.guard.refuse(who, reason, Instant::now()) {
        let every = plausible::EVENT_EVERY.as_secs();
        x.event(
            kind,
            if kind == EVENT_IMPLAUSIBLE {
                vec![who.to_string()]
            } else {
                Vec::new()
            },
            format!(
                "{detail}: dropped ({}); further ones within {every} s are only counted",
                reason.name()
            ),
        );
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

/// A new obstacle from the obstacles key, come at `arrived`.
pub(super) fn obstacle_bytes(x: &mut Exec, bytes: &[u8], arrived: Instant) {
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
    if let Err(why) = plausible::check_obstacle_scale(&o, &x.scenario.bounds) {
        return refuse(
            x,
            EVENT_OBSTACLE_DROPPED,
            "obstacles",
            Reason::ObstacleOutOfScale,
            why.to_string(),
        );
    }
    // A known id is dropped rather than replacing the obstacle: a client resending for
    // reliability changes nothing, and the replans and the clearance figures (measured from the
    // publication on, as `replay` recomputes them) stay those of the obstacle first published.
    // A moved obstacle is published under a new id.
    if x.scenario.obstacles.iter().any(|k| k.id == o.id) {
        let why = format!("obstacle {:?}: the id is already known", o.id);
        return refuse(
            x,
            EVENT_OBSTACLE_DROPPED,
            "obstacles",
            Reason::ObstacleDuplicate,
            why,
        );
    }
    if x.guard.published >= limits::MAX_PUBLISHED_OBSTACLES {
        let why = format!(
            "obstacle {:?}: {} obstacles were published already, the limit is {}",
            o.id,
            x.guard.published,
            limits::MAX_PUBLISHED_OBSTACLES
        );
        return refuse(
            x,
            EVENT_OBSTACLE_DROPPED,
            "obstacles",
            Reason::ObstacleCap,
            why,
        );
    }
    if !x.guard.obstacles.take(arrived) {
        let why = format!(
            "obstacle {:?}: over the limit of {} obstacles a second",
            o.id,
            limits::MAX_OBSTACLES_PER_S
        );
        return refuse(
            x,
            EVENT_OBSTACLE_DROPPED,
            "obstacles",
            Reason::ObstacleRate,
            why,
        );
    }
    x.guard.published += 1;
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
        replan_queue::request(x, i, "a new obstacle blocks its path", Some(received));
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
    let patience = hold_answer_patience(o.telemetry_hz);
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
        let active = v.driven();
        let wait = if v.holding {
            hold_retry_after(o.time_scale, x.last_attempt[i], COOL_DOWN)
        } else {
            COOL_DOWN
        };
        let cooled = x.last_reaction[i].is_none_or(|t| t.elapsed() >= wait);
        if !(active && cooled) || x.queue.busy(i) {
            continue;
        }
        if v.holding {
            // Retried from where it stands once it says it holds (or failed to answer).
            if !v.awaiting_hold_answer(patience) {
                replan_queue::request(x, i, "retrying after a hold", None);
            }
            continue;
        }
        if let Some(p) = v.progress {
            if p.cross_track_m > o.deviation_m {
                let why = format!(
                    "cross-track error {:.1} m is over the {:.1} m tolerance",
                    p.cross_track_m, o.deviation_m
                );
                replan_queue::request(x, i, &why, None);
            }
        }
    }
    let starting = x.mission_clock.since_epoch() < o.lost_after;
    for c in x.fleet.conflicts_over(now, conflict_horizon_s(o)) {
        let Some(who) = x.fleet.gives_way(&c, patience, starting) else {
            continue;
        };
        if x.queue.busy(who) || x.last_reaction[who].is_some_and(|t| t.elapsed() < COOL_DOWN) {
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
        replan_queue::request(x, who, &why, None);
    }
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
