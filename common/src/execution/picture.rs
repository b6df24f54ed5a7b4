//! The coordinator's live fleet picture: from each vehicle's latest state report and its timed
//! plan, where it is on its plan ([`progress`]), where it will be over the next minutes
//! ([`predict`]), and the closest approach now and ahead ([`current_min_separation`],
//! [`predicted_min_separation`], [`predicted_conflicts`]).
//!
//! This is the conflict check of a traffic schedule: the plans were deconflicted before the start,
//! but vehicles run late, early or off track, so the coordinator re-projects every vehicle from
//! its latest fix along its own plan and checks the projected trajectories against each other
//! with the same exact closest-approach routine the planner uses ([`crate::separation`]).
//! Predictions are piecewise linear in time and sampled at every breakpoint, so that check misses
//! nothing between samples.

use serde::{Deserialize, Serialize};

use crate::geometry::{closest_param, Vec3};
use crate::separation::all_pairs;
use crate::trajectory::Trajectory;

/// Where a vehicle is relative to its plan.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct Progress {
    /// Arc length along the plan of the point nearest the vehicle, metres.
    pub along_m: f64,
    /// along_m / plan length, in [0, 1] (1 for a zero-length plan).
    pub fraction: f64,
    /// Plan time at that nearest point, seconds (interpolated on the segment).
    pub plan_time_s: f64,
    /// Distance from the vehicle to that nearest point (cross-track error), metres.
    pub cross_track_m: f64,
    /// now − plan_time_s: how late the vehicle is on its schedule, seconds (negative = early).
    pub lag_s: f64,
    /// Predicted arrival (mission time): now + (plan arrival − plan_time_s), i.e. it drives the
    /// rest at planned pace.
    pub eta_s: f64,
}

/// A predicted closest approach of two vehicles.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct Conflict {
    /// Index of the first vehicle (the smaller one).
    pub a: usize,
    /// Index of the second vehicle.
    pub b: usize,
    /// Smallest predicted distance, metres.
    pub min_distance_m: f64,
    /// Mission time at which it occurs, seconds.
    pub at_s: f64,
}

/// The nearest point found on one plan segment.
#[derive(Debug, Clone, Copy)]
struct Nearest {
    along: f64,
    plan_time: f64,
    dist: f64,
}

/// Samples usable by index: a malformed plan with more times than points (or the reverse) is
/// read up to the shorter of the two.
fn samples(plan: &Trajectory) -> usize {
    plan.times.len().min(plan.points.len())
}

/// Nearest point to `p` on segment `k` of `plan`, whose start lies `along0` metres along it.
///
/// On a segment of zero length (the plan waits there) every time in its span is as near as any
/// other, so the plan time is `now` clamped to the span: a vehicle waiting where its plan waits
/// is on schedule.
fn on_segment(plan: &Trajectory, k: usize, p: &Vec3, now: f64, along0: f64) -> Nearest {
    let (a, b) = (plan.points[k], plan.points[k + 1]);
    let (t0, t1) = (plan.times[k], plan.times[k + 1]);
    let u = closest_param(&a, &b, p);
    let plan_time = if (b - a).norm_squared() <= f64::EPSILON {
        now.max(t0).min(t1)
    } else {
        t0 + u * (t1 - t0)
    };
    Nearest {
        along: along0 + u * (b - a).norm(),
        plan_time,
        dist: (a + (b - a) * u - p).norm(),
    }
}

/// Progress of a vehicle at `position` reported at mission time `now`. The nearest point is
/// searched among the segments whose time span overlaps [now − window_s, now + window_s]
/// (so a path that passes near itself does not make progress jump), falling back to all
/// segments if none overlaps. Ties: the one whose plan time is closest to `now`.
///
/// A plan of one sample is a point held from its time on; an empty plan is held at the origin,
/// as [`Trajectory::position_at`] reads it. A negative or NaN window counts as 0.
pub fn progress(plan: &Trajectory, position: Vec3, now: f64, window_s: f64) -> Progress {
    progress_near(plan, position, now, window_s, now, 0.0)
}

/// [`progress`] for a vehicle whose plan time is expected near `expected_s` (where its previous
/// fix put it, carried on by the time since): where the plan passes the vehicle more than
/// once within `slack_m` of the nearest pass (out round an obstacle and back by the same way,
/// a loop), the pass whose nearest point's plan time is closest to `expected_s` is taken, not
/// the one a metre nearer. Tracking error decides between such passes by chance: a crawler
/// 3 m off track on its way back can be nearer its way out, and a fix matched there jumps
/// hundreds of seconds back along the plan. A pass is a run of consecutive segments within the
/// slack, and within a pass the nearest point is taken, so along-track progress is as exact as
/// [`progress`]'s. A slack of 0 (or negative, or NaN) is [`progress`] with ties broken by
/// `expected_s`.
pub fn progress_near(
    plan: &Trajectory,
    position: Vec3,
    now: f64,
    window_s: f64,
    expected_s: f64,
    slack_m: f64,
) -> Progress {
    let n = samples(plan);
    let arrival = if n > 0 { plan.times[n - 1] } else { 0.0 };
    let mut starts = Vec::with_capacity(n);
    let mut total = 0.0;
    for k in 0..n.saturating_sub(1) {
        starts.push(total);
        total += (plan.points[k + 1] - plan.points[k]).norm();
    }
    let w = if window_s > 0.0 { window_s } else { 0.0 };
    let overlaps = |k: &usize| plan.times[*k] <= now + w && plan.times[*k + 1] >= now - w;
    let mut segs: Vec<usize> = (0..starts.len()).filter(overlaps).collect();
    if segs.is_empty() {
        segs = (0..starts.len()).collect();
    }
    let found: Vec<(usize, Nearest)> = segs
        .into_iter()
        .map(|k| (k, on_segment(plan, k, &position, now, starts[k])))
        .collect();
    let nearest_dist = found.iter().map(|c| c.1.dist).fold(f64::INFINITY, f64::min);
    let slack = if slack_m > 0.0 { slack_m } else { 0.0 };
    let reach = nearest_dist + slack + 1e-9 * (1.0 + nearest_dist);
    // The nearest point of each pass (a run of consecutive segments within reach; a NaN
    // distance, from a NaN fix, is let through so that a fix is always placed somewhere).
    let mut passes: Vec<Nearest> = Vec::new();
    let mut previous: Option<usize> = None;
    for (k, c) in found
        .into_iter()
        .filter(|c| c.1.dist <= reach || c.1.dist.is_nan())
    {
        let same_pass = previous.is_some_and(|p| p + 1 == k);
        previous = Some(k);
        match passes.last_mut() {
            Some(b) if same_pass => {
                let tol = 1e-9 * (1.0 + b.dist);
                let nearer = c.dist < b.dist - tol;
                let tie = (c.dist - b.dist).abs() <= tol
                    && (c.plan_time - expected_s).abs() < (b.plan_time - expected_s).abs();
                if nearer || tie {
                    *b = c;
                }
            }
            _ => passes.push(c),
        }
    }
    let best = passes.into_iter().reduce(|b, c| {
        if (c.plan_time - expected_s).abs() < (b.plan_time - expected_s).abs() {
            c
        } else {
            b
        }
    });
    let nearest = best.unwrap_or_else(|| {
        // No segment: the plan is a single held point (or nothing, read as the origin).
        let point = plan.points.first().copied().unwrap_or_else(Vec3::zeros);
        Nearest {
            along: 0.0,
            plan_time: plan.times.first().copied().unwrap_or(0.0),
            dist: (position - point).norm(),
        }
    });
    Progress {
        along_m: nearest.along,
        fraction: if total > 0.0 {
            (nearest.along / total).clamp(0.0, 1.0)
        } else {
            1.0
        },
        plan_time_s: nearest.plan_time,
        cross_track_m: nearest.dist,
        lag_s: now - nearest.plan_time,
        eta_s: now + (arrival - nearest.plan_time).max(0.0),
    }
}

/// Where the vehicle is predicted to be from `now` over `horizon_s`: it starts at `position`
/// and continues along its plan at planned pace from `progress.plan_time_s`, closing its
/// cross-track offset linearly over `converge_s` seconds. Returns a Trajectory whose times are
/// mission times starting at `now` (first sample: `position` at `now`), sampled at the plan's own
/// sample times in that window plus the converge point and the horizon end.
///
/// Model: the vehicle keeps its current lag (it does not hurry to catch up, the usual
/// behaviour of a trajectory follower that re-times from its fix), so at `now + τ` it is at
/// `plan(plan_time_s + τ) + (1 − τ / converge_s)⁺ · e`, where `e = position − plan(plan_time_s)`
/// is its offset from the plan now. Both terms are linear between the samples, so the returned
/// trajectory is exact, not a sampling of it.
///
/// Degenerate input: a non-positive (or NaN) `converge_s` means the offset is kept over the whole
/// horizon (a vehicle cannot jump onto its plan); a zero or NaN horizon gives the single sample
/// `position` at `now`; an infinite horizon runs until the vehicle is settled at its goal. An
/// empty (or malformed: times and points differ in number) plan gives nothing to follow: the
/// vehicle is predicted to hold where it is.
pub fn predict(
    plan: &Trajectory,
    position: Vec3,
    progress: &Progress,
    now: f64,
    horizon_s: f64,
    converge_s: f64,
) -> Trajectory {
    let n = samples(plan);
    let pt = progress.plan_time_s;
    let converge = Some(converge_s)
        .filter(|c| *c > 0.0)
        .unwrap_or(f64::INFINITY);
    let horizon = if horizon_s.is_finite() {
        horizon_s.max(0.0)
    } else if horizon_s > 0.0 {
        let settle = if converge.is_finite() { converge } else { 0.0 };
        (plan.arrival() - pt).max(0.0) + settle
    } else {
        0.0
    };
    if n == 0 || n != plan.points.len() || n != plan.times.len() || horizon <= 0.0 {
        let mut times = vec![now];
        if horizon > 0.0 {
            times.push(now + horizon);
        }
        let points = vec![position; times.len()];
        return Trajectory { times, points };
    }
    let ghost = |tau: f64| plan.position_at(pt + tau);
    let offset = position - ghost(0.0);
    // τ is finite here, so an infinite converge time keeps the whole offset.
    let factor = |tau: f64| (1.0 - tau / converge).max(0.0);
    let mut taus: Vec<(f64, Vec3)> = vec![(0.0, ghost(0.0))];
    for k in 0..n {
        let tau = plan.times[k] - pt;
        if tau > 0.0 && tau < horizon {
            taus.push((tau, plan.points[k]));
        }
    }
    if converge < horizon {
        taus.push((converge, ghost(converge)));
    }
    taus.push((horizon, ghost(horizon)));
    // Stable: samples of a plan jump (two samples at one time) keep their order.
    taus.sort_by(|x, y| x.0.total_cmp(&y.0));
    taus.dedup_by(|later, earlier| later.0 == earlier.0 && later.1 == earlier.1);
    Trajectory {
        times: taus.iter().map(|(tau, _)| now + tau).collect(),
        points: taus
            .iter()
            .map(|(tau, g)| g + offset * factor(*tau))
            .collect(),
    }
}

/// The closest pair now: smallest pairwise distance among the given latest positions
/// (None for fewer than two): (i, j, distance). Ties go to the first pair in row order; pairs
/// whose distance is not a number (a bad fix) are skipped.
pub fn current_min_separation(positions: &[Vec3]) -> Option<(usize, usize, f64)> {
    let mut best: Option<(usize, usize, f64)> = None;
    for i in 0..positions.len() {
        for j in i + 1..positions.len() {
            let d = (positions[j] - positions[i]).norm();
            if !d.is_nan() && best.is_none_or(|b| d < b.2) {
                best = Some((i, j, d));
            }
        }
    }
    best
}

/// `p` on a clock shifted by `t_ref` (so the common start is 0, which
/// [`crate::separation::pair_separation`] assumes), held at its first point from 0 if it starts
/// later.
fn shifted(p: &Trajectory, t_ref: f64) -> Trajectory {
    let n = samples(p);
    let mut out = Trajectory {
        times: Vec::with_capacity(n + 1),
        points: Vec::with_capacity(n + 1),
    };
    if n > 0 && p.times[0] > t_ref {
        out.times.push(0.0);
        out.points.push(p.points[0]);
    }
    for k in 0..n {
        out.times.push(p.times[k] - t_ref);
        out.points.push(p.points[k]);
    }
    out
}

/// Exact closest approach of every pair of predictions, in row order; pairs with an empty
/// prediction are left out.
fn pairwise(predictions: &[Trajectory]) -> Vec<Conflict> {
    let t_ref = predictions
        .iter()
        .filter_map(|p| p.times.first().copied())
        .fold(f64::INFINITY, f64::min);
    if !t_ref.is_finite() {
        return Vec::new();
    }
    let clocks: Vec<Trajectory> = predictions.iter().map(|p| shifted(p, t_ref)).collect();
    all_pairs(&clocks, 0.0)
        .into_iter()
        .filter(|(_, s)| s.min_distance.is_finite())
        .map(|((a, b), s)| Conflict {
            a,
            b,
            min_distance_m: s.min_distance,
            at_s: s.min_time + t_ref,
        })
        .collect()
}

/// Predicted closest approach over the predictions (all starting at the same `now`):
/// (i, j, min distance, mission time of it), None for fewer than two.
///
/// Every prediction holds its last point after its horizon, so with different horizons the
/// check runs to the longest one. Ties go to the first pair in row order.
pub fn predicted_min_separation(predictions: &[Trajectory]) -> Option<Conflict> {
    pairwise(predictions)
        .into_iter()
        .min_by(|x, y| x.min_distance_m.total_cmp(&y.min_distance_m))
}

/// Every pair predicted to come closer than d_min, closest first.
pub fn predicted_conflicts(predictions: &[Trajectory], d_min: f64) -> Vec<Conflict> {
    let mut out: Vec<Conflict> = pairwise(predictions)
        .into_iter()
        .filter(|c| c.min_distance_m < d_min)
        .collect();
    out.sort_by(|x, y| x.min_distance_m.total_cmp(&y.min_distance_m));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    fn traj(samples: &[(f64, [f64; 3])]) -> Trajectory {
        Trajectory {
            times: samples.iter().map(|s| s.0).collect(),
            points: samples.iter().map(|s| Vec3::from(s.1)).collect(),
        }
    }

    fn straight() -> Trajectory {
        traj(&[(0.0, [0., 0., 0.]), (100.0, [100., 0., 0.])])
    }

    #[test]
    fn progress_on_straight_and_l_shaped_plans_by_hand() {
        let p = progress(&straight(), Vec3::new(30., 4., 0.), 35.0, 30.0);
        assert_abs_diff_eq!(p.along_m, 30.0, epsilon = 1e-9);
        assert_abs_diff_eq!(p.fraction, 0.3, epsilon = 1e-12);
        assert_abs_diff_eq!(p.plan_time_s, 30.0, epsilon = 1e-9);
        assert_abs_diff_eq!(p.cross_track_m, 4.0, epsilon = 1e-9);
        assert_abs_diff_eq!(p.lag_s, 5.0, epsilon = 1e-9);
        // 70 s of plan left at planned pace from 35.
        assert_abs_diff_eq!(p.eta_s, 105.0, epsilon = 1e-9);

        let plan = traj(&[
            (0.0, [0., 0., 0.]),
            (100.0, [100., 0., 0.]),
            (200.0, [100., 100., 0.]),
        ]);
        // 50 m from the first leg, 2 m from the second at (100, 50): 100 + 50 along.
        let p = progress(&plan, Vec3::new(98., 50., 0.), 150.0, 60.0);
        assert_abs_diff_eq!(p.along_m, 150.0, epsilon = 1e-9);
        assert_abs_diff_eq!(p.cross_track_m, 2.0, epsilon = 1e-9);
        assert_abs_diff_eq!(p.plan_time_s, 150.0, epsilon = 1e-9);
        assert_abs_diff_eq!(p.fraction, 0.75, epsilon = 1e-12);
    }

    #[test]
    fn a_path_passing_near_itself_maps_by_time() {
        // Out along y = 0 over 0..100, an instant side-step to y = 5, back along y = 5 over 100..200.
        let plan = traj(&[
            (0.0, [0., 0., 0.]),
            (100.0, [100., 0., 0.]),
            (100.0, [100., 5., 0.]),
            (200.0, [0., 5., 0.]),
        ]);
        let pos = Vec3::new(50., 2., 0.);
        let out = progress(&plan, pos, 40.0, 30.0);
        assert_abs_diff_eq!(out.plan_time_s, 50.0, epsilon = 1e-9);
        assert_abs_diff_eq!(out.cross_track_m, 2.0, epsilon = 1e-9);
        // Nearer the outgoing leg (2 m vs 3 m), but at 160 only the return leg is in the window.
        let back = progress(&plan, pos, 160.0, 30.0);
        assert_abs_diff_eq!(back.plan_time_s, 150.0, epsilon = 1e-9);
        assert_abs_diff_eq!(back.cross_track_m, 3.0, epsilon = 1e-9);
        assert_abs_diff_eq!(back.along_m, 155.0, epsilon = 1e-9);
        // Without a window in reach the nearest leg of all wins.
        let far = progress(&plan, pos, 1000.0, 30.0);
        assert_abs_diff_eq!(far.plan_time_s, 50.0, epsilon = 1e-9);
    }

    #[test]
    fn a_pass_by_the_same_point_is_chosen_by_the_expected_time() {
        // Out along y = 0 over 0..100, round a corner 5 m wide, back along y = 3 over 110..210:
        // (50, 1) is 1 m from the way out (plan time 50) and 2 m from the way back (160).
        let plan = traj(&[
            (0.0, [0., 0., 0.]),
            (100.0, [100., 0., 0.]),
            (105.0, [100., 3., 0.]),
            (110.0, [100., 3., 0.]),
            (210.0, [0., 3., 0.]),
        ]);
        let pos = Vec3::new(50., 1., 0.);
        // Both passes in the window: the nearest wins without a slack.
        let nearest = progress(&plan, pos, 120.0, 300.0);
        assert_abs_diff_eq!(nearest.plan_time_s, 50.0, epsilon = 1e-9);
        // Expected at 158 (the previous fix carried on): the way back, 1 m farther.
        let back = progress_near(&plan, pos, 120.0, 300.0, 158.0, 5.0);
        assert_abs_diff_eq!(back.plan_time_s, 160.0, epsilon = 1e-9);
        assert_abs_diff_eq!(back.cross_track_m, 2.0, epsilon = 1e-9);
        assert_abs_diff_eq!(back.along_m, 100.0 + 3.0 + 50.0, epsilon = 1e-9);
        assert_abs_diff_eq!(back.lag_s, -40.0, epsilon = 1e-9);
        // Expected on the way out: the way out.
        let out = progress_near(&plan, pos, 120.0, 300.0, 45.0, 5.0);
        assert_abs_diff_eq!(out.plan_time_s, 50.0, epsilon = 1e-9);
        // A slack under the 1 m between the passes keeps the nearest.
        let tight = progress_near(&plan, pos, 120.0, 300.0, 158.0, 0.5);
        assert_abs_diff_eq!(tight.plan_time_s, 50.0, epsilon = 1e-9);
        // Within one pass the nearest point is kept, however far the expected time: no pull
        // along the track towards it.
        // (48, 2) is 2 m from the first segment at 48 and 2.83 m from the second at its start.
        let line = traj(&[
            (0.0, [0., 0., 0.]),
            (50.0, [50., 0., 0.]),
            (100.0, [100., 0., 0.]),
        ]);
        let on_line = progress_near(&line, Vec3::new(48., 2., 0.), 48.0, 300.0, 90.0, 5.0);
        assert_abs_diff_eq!(on_line.plan_time_s, 48.0, epsilon = 1e-9);
    }

    #[test]
    fn prediction_follows_the_plan_at_planned_pace() {
        let plan = straight();
        let pos = Vec3::new(20., 0., 0.);
        let p = progress(&plan, pos, 20.0, 30.0);
        let pred = predict(&plan, pos, &p, 20.0, 60.0, 10.0);
        assert_abs_diff_eq!(pred.times[0], 20.0);
        assert_abs_diff_eq!((pred.points[0] - pos).norm(), 0.0);
        let at = pred.position_at(50.0);
        assert_abs_diff_eq!((at - plan.position_at(50.0)).norm(), 0.0, epsilon = 1e-9);

        // 5 s late at x = 30: keeps the lag, so x = 60 (not 65) 30 s later.
        let pos = Vec3::new(30., 0., 0.);
        let p = progress(&plan, pos, 35.0, 30.0);
        let pred = predict(&plan, pos, &p, 35.0, 80.0, 10.0);
        let at = pred.position_at(65.0);
        assert_abs_diff_eq!((at - Vec3::new(60., 0., 0.)).norm(), 0.0, epsilon = 1e-9);
        // Samples: now, the converge point, the plan's arrival (late, at 105), the horizon end.
        assert_eq!(pred.times, vec![35.0, 45.0, 105.0, 115.0]);
        assert_abs_diff_eq!(pred.position_at(115.0).x, 100.0, epsilon = 1e-9);

        // 4 m off track: the offset closes linearly over the 10 s convergence.
        let pos = Vec3::new(30., 4., 0.);
        let p = progress(&plan, pos, 35.0, 30.0);
        let pred = predict(&plan, pos, &p, 35.0, 60.0, 10.0);
        // Half way: x 35, y 2; on the plan from then on.
        let half = pred.position_at(40.0);
        assert_abs_diff_eq!((half - Vec3::new(35., 2., 0.)).norm(), 0.0, epsilon = 1e-9);
        let done = pred.position_at(45.0);
        assert_abs_diff_eq!((done - Vec3::new(40., 0., 0.)).norm(), 0.0, epsilon = 1e-9);
        // Samples: now, the converge point, the horizon end (the plan's arrival, 105, is past it).
        assert_eq!(pred.times, vec![35.0, 45.0, 95.0]);
    }

    #[test]
    fn degenerate_plans_and_horizons_do_not_panic_or_nan() {
        let pos = Vec3::new(3., 4., 0.);
        let plans = [
            traj(&[]),
            traj(&[(5.0, [0., 0., 0.])]),
            traj(&[
                (0.0, [0., 0., 0.]),
                (10.0, [0., 0., 0.]),
                (10.0, [0., 0., 0.]),
            ]),
        ];
        for plan in &plans {
            for (h, c) in [
                (0.0, 10.0),
                (30.0, 0.0),
                (f64::INFINITY, f64::NAN),
                (f64::NAN, 5.0),
            ] {
                let p = progress(plan, pos, 7.0, f64::NAN);
                let pred = predict(plan, pos, &p, 7.0, h, c);
                let f = [p.along_m, p.fraction, p.plan_time_s, p.lag_s, p.eta_s];
                assert!(f.iter().all(|v| v.is_finite()), "{p:?}");
                assert_abs_diff_eq!(p.cross_track_m, 5.0, epsilon = 1e-12);
                assert!(pred.times.iter().all(|t| t.is_finite()));
                assert!(pred.points.iter().all(|q| q.iter().all(|v| v.is_finite())));
                assert!(pred.times.windows(2).all(|w| w[0] <= w[1]));
                assert_eq!(pred.points[0], pos);
            }
        }
        // Waiting where the plan waits is on schedule.
        let p = progress(&plans[2], Vec3::zeros(), 7.0, 5.0);
        assert_abs_diff_eq!(p.lag_s, 0.0);
        assert_abs_diff_eq!(p.fraction, 1.0);
    }

    #[test]
    fn current_min_separation_by_hand() {
        // 5 m (3-4-5), 10 m and sqrt(65) ≈ 8.06 m.
        let pts = [[0., 0., 0.], [3., 4., 0.], [10., 0., 0.]].map(Vec3::from);
        let (i, j, d) = current_min_separation(&pts).unwrap_or((9, 9, -1.0));
        assert_eq!((i, j), (0, 1));
        assert_abs_diff_eq!(d, 5.0, epsilon = 1e-12);
        assert_eq!(current_min_separation(&pts[..1]), None);
        assert_eq!(current_min_separation(&[]), None);
    }

    #[test]
    fn head_on_predictions_by_hand() {
        let a = traj(&[(1000.0, [0., 0., 0.]), (1100.0, [100., 0., 0.])]);
        let b = traj(&[(1000.0, [100., 0., 0.]), (1100.0, [0., 0., 0.])]);
        let c = predicted_min_separation(&[a.clone(), b]);
        assert!(c.is_some_and(|c| (c.a, c.b) == (0, 1)
            && c.min_distance_m.abs() < 1e-9
            && (c.at_s - 1050.0).abs() < 1e-9));

        let b30 = traj(&[(1000.0, [100., 30., 0.]), (1100.0, [0., 30., 0.])]);
        let preds = [a.clone(), b30];
        let c = predicted_min_separation(&preds);
        assert!(c.is_some_and(
            |c| (c.min_distance_m - 30.0).abs() < 1e-9 && (c.at_s - 1050.0).abs() < 1e-9
        ));
        let within = predicted_conflicts(&preds, 50.0);
        assert_eq!(within.len(), 1);
        assert_eq!((within[0].a, within[0].b), (0, 1));
        assert!(predicted_conflicts(&preds, 20.0).is_empty());
        assert_eq!(predicted_min_separation(&preds[..1]), None);
        // An empty prediction pairs with nothing.
        assert_eq!(predicted_min_separation(&[a, traj(&[])]), None);
    }
}
