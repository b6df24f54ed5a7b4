//! Replans off the loop. A replan thinks for up to its wall-time budget (a held vehicle's retry
//! up to 8 × that: 2.4 s at the default 0.3 s); run on the loop, it left the coordinator blind
//! for that long — no report read, no conflict looked for, no status published — which is 1200
//! mission seconds at 500×. So the loop only decides: a replan is queued, run on its own thread
//! one at a time, and its result applied on the loop when it comes ([`poll`]).
//!
//! One at a time, as before: each replan plans against the others' plans as they are when it
//! starts, so two replans at once could each plan into the other's old path. A vehicle under
//! way goes first: its replan is queued before every held vehicle's retry, and a retry under
//! way yields to it (its swarm stops at the next iteration with its best so far; cut short and
//! not safe, it is not counted as a failed retry). A held vehicle is safe where it is, once its
//! report confirms the hold: until then it is replanned, queued and given a budget as one under
//! way, from its course (see [`ReplanStart`]). What the loop
//! learns while one thinks is checked when its result comes: a vehicle lost, arrived or told
//! to hold meanwhile drops it; a result that enters an obstacle published meanwhile is planned
//! again at once. And a vehicle that must wait its turn is held at once when its course until
//! an update could reach it is not safe (the same test a replan starts with, see
//! [`super::lead`]).

use std::sync::atomic::AtomicBool;
use std::sync::mpsc::{self, TryRecvError};
use std::sync::Arc;
use std::time::{Duration, Instant};

use shoal_common::geometry::Vec3;
use shoal_common::scenario::Scenario;
use shoal_common::trajectory::Trajectory;

use super::lead::{course_conflict, course_enters_obstacle, enters_any, update_lead_s};
use super::log::EVENT_HOLD;
use super::queue::{Job, UnderWay, Waiting};
use super::replan::Replanned;
use super::state::Exec;
use super::tracked::Tracked;

/// The budget of vehicle `i`'s next replan: a vehicle standing on a hold it confirmed is safe
/// where it is, so each retry may think longer: the budget doubles per failed retry, up to 8 ×.
fn budget(x: &Exec, i: usize) -> Duration {
    if x.fleet.vehicles[i].hold_confirmed() {
        x.options.replan_budget * (1u32 << x.hold_retries[i].min(3))
    } else {
        x.options.replan_budget
    }
}

/// Why vehicle `i`'s predicted course from now until mission time `until` is not safe (it
/// enters a hard obstacle or comes within d_min of another vehicle), or `None`.
fn course_blocked(x: &Exec, i: usize, until: f64) -> Option<String> {
    let now = x.clock();
    let course: Vec<Trajectory> = x
        .fleet
        .predictions_over(now, (until - now).max(0.0))
        .iter()
        .map(|p| p.until(until))
        .collect();
    if course_enters_obstacle(&course[i], &x.scenario) {
        return Some("its course enters a hard obstacle".to_string());
    }
    course_conflict(&course, i, x.fleet.d_min).map(|c| {
        let other = if c.a == i { c.b } else { c.a };
        format!(
            "its course comes {:.1} m from {} at t = {:.0} s",
            c.min_distance_m, x.fleet.vehicles[other].id, c.at_s
        )
    })
}

/// Asks for a replan of vehicle `i`: started at once when none is under way, else queued. A
/// vehicle under way whose course until its update could take effect is not safe is told to
/// hold instead (obeyed at once; its retries start from there).
pub(super) fn request(x: &mut Exec, i: usize, why: &str, obstacle_received: Option<Instant>) {
    let o = x.options;
    let standing = x.fleet.vehicles[i].hold_confirmed();
    if !standing && !x.queue.busy(i) {
        x.queue.yield_retry();
    }
    let waiting_at = x.queue.waiting.iter().position(|w| w.vehicle == i);
    let fleet = &x.fleet;
    let slot = x.queue.slot(|j| fleet.vehicles[j].hold_confirmed());
    // When its update could take effect at the earliest (when it starts at once, `start`
    // looks).
    let effect = match &x.queue.under_way {
        None => None,
        Some(u) if u.asked.vehicle == i => Some(u.t0),
        Some(_) => {
            // Its place in the queue (already waiting, or where it would go) and its budget.
            let (ahead, own) = match waiting_at {
                Some(k) => (k, x.queue.waiting[k].budget),
                None => (slot, budget(x, i)),
            };
            Some(
                x.clock()
                    + x.queue.wait_for(ahead).as_secs_f64() * o.time_scale
                    + update_lead_s(own, o.time_scale),
            )
        }
    };
    if let Some(effect) = effect.filter(|_| !standing) {
        if let Some(detail) = course_blocked(x, i, effect) {
            x.queue.waiting.retain(|w| w.vehicle != i);
            x.last_reaction[i] = Some(Instant::now());
            let when = format!("before an update could take effect at t = {effect:.0} s");
            hold(x, i, why, format!("{detail} {when}"));
            return;
        }
    }
    if x.queue.busy(i) {
        // Its replan plans with the obstacle (waiting) or is checked against it (under way):
        // the update it sends is the decision on it.
        if let Some(u) = x.queue.under_way.as_mut().filter(|u| u.asked.vehicle == i) {
            u.asked.obstacle_received = u.asked.obstacle_received.or(obstacle_received);
        }
        if let Some(w) = x.queue.waiting.iter_mut().find(|w| w.vehicle == i) {
            w.obstacle_received = w.obstacle_received.or(obstacle_received);
        }
        return;
    }
    x.last_reaction[i] = Some(Instant::now());
    let w = Waiting {
        vehicle: i,
        why: why.to_string(),
        obstacle_received,
        budget: budget(x, i),
    };
    if standing {
        x.queue.waiting.push_back(w);
    } else {
        x.queue.waiting.insert(slot, w);
    }
    poll(x);
}

/// Applies the result of the replan under way when it has come, and starts the next one.
pub(super) fn poll(x: &mut Exec) {
    if let Some(u) = &x.queue.under_way {
        let result = match u.result.try_recv() {
            Ok(r) => r,
            Err(TryRecvError::Empty) => return,
            Err(TryRecvError::Disconnected) => {
                let id = &x.fleet.vehicles[u.asked.vehicle].id;
                tracing::error!("the replan thread of {id} ended without a result");
                Replanned::not_found(
                    no_path(),
                    u.started,
                    "the replan failed (see the log)".into(),
                )
            }
        };
        if let Some(u) = x.queue.under_way.take() {
            apply(x, u, result);
        }
    }
    while x.queue.under_way.is_none() {
        let Some(w) = x.queue.waiting.pop_front() else {
            break;
        };
        start(x, w);
    }
}

/// The trajectory of a replan that never ran.
fn no_path() -> Trajectory {
    Trajectory {
        times: Vec::new(),
        points: Vec::new(),
    }
}

/// Starts the replan `w` on its own thread, or holds the vehicle when its course until the
/// update could take effect is not safe; nothing for a vehicle that no longer drives.
fn start(x: &mut Exec, w: Waiting) {
    let i = w.vehicle;
    let o = x.options;
    let v = &x.fleet.vehicles[i];
    if !v.driven() {
        return;
    }
    let holding = v.holding;
    let now = x.clock();
    let budget = budget(x, i);
    let t0 = now + update_lead_s(budget, o.time_scale);
    if !v.hold_confirmed() {
        if let Some(detail) = course_blocked(x, i, t0) {
            x.last_reaction[i] = Some(Instant::now());
            // Told to hold and not holding (the hold was lost, given up, or not yet
            // answered): a retry would follow its course through the conflict to t0, so it is
            // told again, and the other vehicle meanwhile gives way (`Fleet::gives_way`).
            let when = format!("before an update could take effect at t = {t0:.0} s");
            let again = if holding {
                "its hold is not confirmed and "
            } else {
                ""
            };
            hold(x, i, &w.why, format!("{again}{detail} {when}"));
            return;
        }
    }
    let remaining = (x.common_arrival_s + o.arrival_window_s - now).max(o.horizon_s);
    // Long enough to cover the lead (near the end of a fast run it can be the longer).
    let predictions = x.fleet.predictions_over(now, remaining.max(t0 - now));
    let from = ReplanStart::of(&x.fleet.vehicles[i], &predictions[i], now, t0);
    // A retry must not repeat the swarm that just failed.
    let seed =
        o.seed ^ (u64::from(x.revision) << 8) ^ (u64::from(x.hold_retries[i]) << 32) ^ i as u64;
    let course = predictions[i].clone();
    let stop = Arc::new(AtomicBool::new(false));
    let job = Job {
        scenario: x.scenario.clone(),
        vehicle: i,
        t0,
        p0: from.p0,
        heading: from.heading,
        current: x.fleet.vehicles[i].plan.clone(),
        resume_s: from.resume_s,
        arrival_s: x.fleet.vehicles[i].planned_arrival_s,
        budget,
        separation_buffer_m: o.separation_buffer_m,
        seed,
        ground: x.ground.clone(),
        others: predictions,
        stop: Arc::clone(&stop),
    };
    let (tx, rx) = mpsc::channel();
    let u = UnderWay {
        asked: Waiting { budget, ..w },
        t0,
        course,
        was_holding: holding,
        was_standing: from.standing,
        obstacles: x.scenario.obstacles.len(),
        started: Instant::now(),
        result: rx,
        stop,
    };
    let name = format!("replan-{}", x.fleet.vehicles[i].id);
    let spawned = std::thread::Builder::new().name(name).spawn(move || {
        // The loop may have ended and dropped the receiver: nothing to tell then.
        let _ = tx.send(job.run());
    });
    match spawned {
        Ok(_) => x.queue.under_way = Some(u),
        Err(e) => {
            let result = Replanned::not_found(
                no_path(),
                u.started,
                format!("cannot start a replan thread: {e}"),
            );
            apply(x, u, result);
        }
    }
}

/// Where and how a vehicle's replan starts.
#[derive(Debug, Clone, PartialEq)]
struct ReplanStart {
    /// Where it will be when the update takes effect.
    p0: Vec3,
    /// The course it will be on there, for the new path's first turn; none for a vehicle
    /// standing still.
    heading: Option<Vec3>,
    /// For a vehicle standing still, the plan time where it stopped (see
    /// [`Tracked::resume_s`]).
    resume_s: Option<f64>,
    /// Whether it stands still on a hold it confirmed.
    standing: bool,
}

impl ReplanStart {
    /// Vehicle `v`'s replan at mission time `now` taking effect at `t0`, when `course` is its
    /// prediction. A vehicle told to hold is taken as standing only once its report confirms
    /// it: one whose hold is not confirmed (in flight, refused, lost) drives on, and a path
    /// that starts as from a stop would ask it for a turn it cannot make.
    fn of(v: &Tracked, course: &Trajectory, now: f64, t0: f64) -> ReplanStart {
        let standing = v.hold_confirmed();
        let p0 = course.position_at(t0);
        // The course there: where the prediction was heading over the last few seconds before.
        let heading = Some(p0 - course.position_at((t0 - 5.0).max(now)))
            .filter(|d| d.x.hypot(d.y) > 1e-3 && !standing);
        ReplanStart {
            p0,
            heading,
            resume_s: if standing { v.resume_s() } else { None },
            standing,
        }
    }
}

/// Whether `t` enters the inflated sphere of a hard obstacle of `scenario` from the
/// `from`-th on.
fn enters_new_obstacle(t: &Trajectory, scenario: &Scenario, from: usize) -> bool {
    enters_any(t, scenario.obstacles.get(from..).unwrap_or(&[]))
}

/// Applies the result of `u`: sends the update, or commands a hold (or, for a vehicle held
/// already, counts a failed retry). Dropped when the loop learnt meanwhile that the vehicle no
/// longer drives or was told to hold; planned again at once when it enters an obstacle
/// published meanwhile.
fn apply(x: &mut Exec, u: UnderWay, result: Replanned) {
    let i = u.asked.vehicle;
    x.last_reaction[i] = Some(Instant::now());
    x.last_attempt[i] = result.elapsed;
    let v = &x.fleet.vehicles[i];
    let id = v.id.clone();
    if !v.driven() || v.holding != u.was_holding || v.hold_confirmed() != u.was_standing {
        tracing::info!(
            "{id}'s replan ({}) is dropped: the vehicle's state changed while it ran",
            u.asked.why
        );
        return;
    }
    if result.safe && enters_new_obstacle(&result.trajectory, &x.scenario, u.obstacles) {
        x.queue.waiting.push_front(Waiting {
            vehicle: i,
            why: "a new obstacle blocks its path".to_string(),
            obstacle_received: u.asked.obstacle_received,
            budget: budget(x, i),
        });
        return;
    }
    if u.yielded() && !result.safe {
        // Cut short for a vehicle under way: not a failed retry (its budget does not double).
        let ms = result.elapsed.as_secs_f64() * 1000.0;
        tracing::info!("{id}'s retry yielded to a vehicle under way after {ms:.0} ms");
        return;
    }
    let why = u.asked.why;
    let t0 = u.t0;
    if result.safe {
        x.hold_retries[i] = 0;
        x.revision += 1;
        let v = &mut x.fleet.vehicles[i];
        // Under way, the vehicle goes on as predicted (its old course, its lag included) until
        // the new one starts at the predicted point; standing on a hold it confirmed, it waits
        // where it is for it. The plan before now stays, for the record.
        let plan = if u.was_standing {
            result.trajectory.clone()
        } else {
            v.plan
                .followed_by(&u.course.followed_by(&result.trajectory))
        };
        v.plan = plan;
        v.revision = x.revision;
        v.holding = false;
        v.held_since_s = None;
        v.held_at = None;
        x.send(&id, x.update_of(i));
        x.pending[i] = Some((x.revision, Instant::now()));
        x.replans += 1;
        if let Some(received) = u.asked.obstacle_received {
            x.decisions_ms
                .push(received.elapsed().as_secs_f64() * 1000.0);
        }
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
    } else if x.fleet.vehicles[i].holding {
        x.hold_retries[i] += 1;
        let n = x.hold_retries[i];
        if told_retry(n) {
            let holds = holding_words(&x.fleet.vehicles[i]);
            x.event(
                "still_holding",
                vec![id.clone()],
                format!(
                    "{id} {holds}: retry {n} found no safe replan in {:.0} ms ({}); the next event on it comes at retry {}",
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
            &why,
            format!(
                "no safe replan in {:.0} ms ({})",
                result.elapsed.as_secs_f64() * 1000.0,
                result.shortfall()
            ),
        );
    }
}

/// How a held vehicle's failed retry describes it: by what the vehicle confirmed, not by what
/// it was told.
fn holding_words(v: &Tracked) -> &'static str {
    if v.hold_confirmed() {
        "keeps holding"
    } else {
        "is still told to hold (the vehicle has not confirmed it)"
    }
}

/// Whether a held vehicle's failed retry `n` (from 1) gets an event: 1, 2, 4, 8, …. A vehicle
/// held for good is retried every 30 mission seconds or so ([`super::lead::hold_retry_after`]):
/// an event for each put 166 in one 10,000 s mission log at 500×.
fn told_retry(n: u32) -> bool {
    n.is_power_of_two()
}

/// Commands vehicle `i` to hold where it is (obeyed at once) and says why.
fn hold(x: &mut Exec, i: usize, why: &str, detail: String) {
    let id = x.fleet.vehicles[i].id.clone();
    x.send(&id, x.hold_of(i, why));
    let now = x.clock();
    x.fleet.vehicles[i].holding = true;
    x.fleet.vehicles[i].held_since_s = Some(now);
    x.fleet.vehicles[i].held_at = Some(Instant::now());
    x.holds += 1;
    x.event(
        EVENT_HOLD,
        vec![id.clone()],
        format!("{id} told to hold ({why}): {detail}"),
    );
}

#[cfg(test)]
mod tests;
