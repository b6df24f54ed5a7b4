//! A vehicle standing still near another coverage crawler's remaining path.
//!
//! A held, lost or faulted vehicle stands where it is for as long as it does: where a crawler's
//! remaining path passes it is known at once, over the whole path, not only when the predicted
//! conflict comes within the prediction horizon. Waiting for that was too late at high time
//! scales (an update is started one replan budget ahead: 275 mission seconds at 500×, longer
//! than the horizon), and a path passing just over d_min from the standing vehicle was never
//! seen as a conflict at all, though the tracking error of the passing crawler takes it under.
//! So a crawler whose remaining path comes within d_min plus the separation buffer of a
//! standing vehicle is repaired, once per stand: the repair goes round it ([`super::repair`]:
//! a standing vehicle is an obstacle to a coverage crawler's way round), at d_min plus the
//! buffer where there is room. It is repaired when that stretch of its path comes within the
//! conflict horizon ([`conflict_horizon_s`]: `--horizon` past the update lead, so the update
//! always takes effect in time), not as soon as the other stands: a held vehicle is retried
//! every 30 mission seconds and usually goes on long before a pass hours ahead, and a way round
//! is never undone, so rounding it at once left that ground uncovered for nothing.
//!
//! Only coverage missions: a tour's repair waits rather than skip inspection points (it would
//! be held long before it needs to), and Zhi & Zuo's replan is not a way round.

use shoal_common::geometry::{segment_point_distance, Vec3};
use shoal_common::trajectory::Trajectory;

use super::fleet::Tracked;
use super::lead::conflict_horizon_s;
use super::replan_queue;
use super::state::Exec;

/// Whether `v` stands still for the others: held, lost or faulted (not arrived: the plans
/// were made with its finish in them).
fn stands(v: &Tracked) -> bool {
    v.arrived_s.is_none() && (v.holding || v.lost || v.fault_s.is_some())
}

/// The path from `p` along the rest of `plan` after plan time `from`: its points.
pub(super) fn rest_of(plan: &Trajectory, from: f64, p: Vec3) -> Vec<Vec3> {
    let mut pts = vec![p];
    pts.extend(
        plan.times
            .iter()
            .zip(&plan.points)
            .filter(|(t, _)| **t > from)
            .map(|(_, x)| *x),
    );
    pts
}

/// Closest approach to `q` of the path from `p` along the rest of `plan` after plan time
/// `from` up to plan time `from + window_s`, metres.
fn closest_within(plan: &Trajectory, from: f64, p: Vec3, q: Vec3, window_s: f64) -> f64 {
    closest_remaining(&plan.until(from + window_s), from, p, q)
}

/// Closest approach to `q` of the path from `p` along the rest of `plan` after plan time
/// `from` ([`rest_of`]), metres.
pub(super) fn closest_remaining(plan: &Trajectory, from: f64, p: Vec3, q: Vec3) -> f64 {
    let pts = rest_of(plan, from, p);
    if pts.len() == 1 {
        return (p - q).norm();
    }
    pts.windows(2)
        .map(|w| segment_point_distance(&w[0], &w[1], &q))
        .fold(f64::INFINITY, f64::min)
}

/// Repairs every coverage crawler under way whose path within the conflict horizon passes
/// within d_min plus the separation buffer of a vehicle that stands still, once per stand (see
/// the module doc). A crawler already that close is left to the conflict check, which lets it
/// move away.
pub(super) fn check(x: &mut Exec, now: f64) {
    if x.scenario.coverage.is_none() {
        return;
    }
    let d = x.fleet.d_min + x.options.separation_buffer_m.max(0.0);
    let horizon = conflict_horizon_s(x.options);
    let n = x.fleet.vehicles.len();
    // A stand is over once the vehicle moves again: the next one is a new stand.
    let fleet = &x.fleet;
    x.rounded.retain(|&(_, j)| stands(&fleet.vehicles[j]));
    for j in 0..n {
        if !stands(&x.fleet.vehicles[j]) {
            continue;
        }
        let at = x.fleet.vehicles[j].standing();
        for i in 0..n {
            let v = &x.fleet.vehicles[i];
            let under_way = v.driven() && !v.holding;
            // One under replan now is looked at again once its update is in.
            let busy = x.queue.busy(i);
            if i == j || !under_way || busy || x.rounded.contains(&(i, j)) {
                continue;
            }
            let p = v.position();
            if (p - at).norm() < d {
                continue;
            }
            let from = v.progress.map_or(now, |pr| pr.plan_time_s);
            let closest = closest_within(&v.plan, from, p, at, horizon);
            if closest >= d {
                continue;
            }
            x.rounded.push((i, j));
            let why = format!(
                "{} stands {closest:.1} m from its remaining path, under d_min plus the buffer ({d:.0} m)",
                x.fleet.vehicles[j].id
            );
            replan_queue::request(x, i, &why, None);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Hand values: an L-shaped rest of a plan, from a position before its corner.
    #[test]
    fn the_closest_approach_is_measured_along_the_rest_of_the_plan_only() {
        let plan = Trajectory {
            times: vec![0.0, 100.0, 200.0],
            points: vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(100.0, 0.0, 0.0),
                Vec3::new(100.0, 100.0, 0.0),
            ],
        };
        // From (50, 0) at plan time 50: the rest is (50,0)→(100,0)→(100,100).
        let p = Vec3::new(50.0, 0.0, 0.0);
        // (130, 60): 30 m from the second leg.
        let d = closest_remaining(&plan, 50.0, p, Vec3::new(130.0, 60.0, 0.0));
        assert!((d - 30.0).abs() < 1e-9, "{d}");
        // (0, 40): the plan's start passed by, 40 m away, does not count; the closest of the
        // rest is the current position, √(50² + 40²).
        let d = closest_remaining(&plan, 50.0, p, Vec3::new(0.0, 40.0, 0.0));
        assert!((d - 50.0f64.hypot(40.0)).abs() < 1e-9, "{d}");
        // Past the end: only the position.
        let d = closest_remaining(&plan, 250.0, p, Vec3::new(50.0, 3.0, 4.0));
        assert!((d - 5.0).abs() < 1e-9, "{d}");
        // Within a window of plan time: 30 s ahead the path ends at (80, 0), 78.1 m from
        // (130, 60); 100 s ahead at (100, 50), √(30² + 10²); 200 s ahead, the whole rest.
        let q = Vec3::new(130.0, 60.0, 0.0);
        let d = closest_within(&plan, 50.0, p, q, 30.0);
        assert!((d - 50.0f64.hypot(60.0)).abs() < 1e-9, "{d}");
        let d = closest_within(&plan, 50.0, p, q, 100.0);
        assert!((d - 30.0f64.hypot(10.0)).abs() < 1e-9, "{d}");
        let d = closest_within(&plan, 50.0, p, q, 200.0);
        assert!((d - 30.0).abs() < 1e-9, "{d}");
    }

    #[test]
    fn held_lost_and_faulted_vehicles_stand_an_arrived_one_does_not() {
        let ids = vec!["a".to_string()];
        let plan = Trajectory {
            times: vec![0.0, 1.0],
            points: vec![Vec3::zeros(), Vec3::new(1.0, 0.0, 0.0)],
        };
        let f = super::super::fleet::Fleet::new(&ids, &[plan], 50.0, 60.0);
        let mut v = f.vehicles[0].clone();
        assert!(!stands(&v));
        v.holding = true;
        assert!(stands(&v));
        v.holding = false;
        v.lost = true;
        assert!(stands(&v));
        v.lost = false;
        v.fault_s = Some(3.0);
        assert!(stands(&v));
        v.arrived_s = Some(4.0);
        assert!(!stands(&v));
    }
}
