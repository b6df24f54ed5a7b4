//! Repairing the rest of an inspection tour while the fleet drives. A tour's path is
//! not "any way to the goal": it must still pass every remaining inspection point in order, so
//! the point-to-point replan of [`super::replan`] would be wrong for it. The same holds for an
//! energy plan (Zhang et al. 2022), whose path points were chosen for the seabed, the AUV's turning
//! radius and the current, none of which the replan models. A repair keeps the
//! rest of the tour and changes only what must change:
//!
//! - the vehicle goes from where it will be back onto its tour (directly: after a deviation it
//!   rejoins at the next point of the plan; after a hold, at the next point after where it
//!   stopped, so the points its plan passed while it waited are still visited);
//! - every run of legs that a hard obstacle now blocks is replaced by a way round it
//!   ([`super::detour`]) from the last point before the run to the first point after it;
//! - the result is re-timed to arrive when the plan did, each leg's speed scaled alike and kept
//!   within the vehicle's range (a longer way than the top speed can make up arrives late).
//!
//! The path is fixed, but not its timing: when the on-time repair comes within d_min plus the
//! separation buffer of another vehicle's predicted track, the legs up to that closest
//! approach are flown a little slower or faster ([`RETIMINGS`]), the later ones making up the
//! difference, and the first timing that keeps the buffer is taken, else the first that keeps
//! d_min (as [`super::replan`] prefers the buffer but never holds for it alone).
//! A coverage crawler (CPP-DSMV) is repaired the same way, but its way round a blocked run
//! must stay on passable seabed, which the detour's 3-D grid does not know: it is searched on
//! the seabed map instead ([`shoal_common::coverage::reroute`]: the coverage planner's safety
//! clearance and turning radius, the obstacle's keep-out sphere at the crawler's height). Its
//! rejoin is searched there too when the straight line back would cross ground it may not
//! drive. A vehicle standing still near its path is gone round like an obstacle, and an
//! obstacle's margin the crawler is already inside is eased to let it out
//! ([`super::keep_out`]). A crawler whose finish a keep-out covers ends its path before the
//! stretch that leads there (its finish is only where its last row ends), or, already on that
//! stretch, at the keep-out's edge ([`super::keep_out::drive_to_keep_out`]). A crawler with no
//! way (none within the search budget, or no map) holds, and the retries start from where it
//! stopped; the hold says why in words ([`Replanned::shortfall`]).
//!
//! A repair that still meets a hard obstacle, or comes within d_min of another vehicle's
//! predicted track at every timing, is not safe: the coordinator then holds the vehicle and
//! retries, so a tour vehicle gives way by waiting, and carries on when the way is clear.

use std::time::Instant;

use shoal_common::coverage::path::Pose2;
use shoal_common::coverage::reroute::WaysRound;
use shoal_common::geometry::{leg_lengths, polyline_length, segment_hits_sphere, Vec3};
use shoal_common::scenario::{Obstacle, ObstacleKind, Scenario};
use shoal_common::separation::{motion_separation, Motion};
use shoal_common::trajectory::Trajectory;

use super::keep_out::{
    crawler_scenario, drive_to_keep_out, keep_out_at, near_obstacle, MIN_DRIVE_M,
    WAY_ROUND_MARGIN_M,
};
use super::replan::{rebase, Replanned, Request};

/// Whether the leg `a`–`b` enters the inflated sphere of a hard obstacle of `obstacles`.
fn blocked(obstacles: &[Obstacle], a: &Vec3, b: &Vec3) -> bool {
    obstacles.iter().any(|o| {
        o.kind == ObstacleKind::Hard && segment_hits_sphere(a, b, &o.centre(), o.inflated_radius())
    })
}

/// A repaired path: its points, the plan's own speed on each leg, and what it gave up.
struct Repaired {
    points: Vec<Vec3>,
    speeds: Vec<f64>,
    /// Plain words, for the event (a crawler's finish given up).
    note: Option<String>,
}

/// The rest of the tour from `p0` as points and the plan's own speed on each leg, planned in
/// `scenario` (`r.scenario`, or a crawler's [`crawler_scenario`]); `Err` in plain words for a
/// way round a blocked run that the grid cannot find (or, for a crawler, not within the
/// request's budget).
///
/// A coverage crawler's finish is only where its last row ends, so when a keep-out covers it
/// the crawler ends its path before the blocked stretch that leads there (the same widened
/// run a way round would replace), rather than hold where it is with the rest of its rows
/// undone; already on that stretch, it drives on to the keep-out's edge. A tour's or an energy
/// plan's goal is the mission's, and it holds.
fn repaired_path(r: &Request, scenario: &Scenario) -> Result<Repaired, String> {
    let started = Instant::now();
    let crawler = scenario.coverage.is_some();
    let over_budget = || {
        format!(
            "no way round within the {:.0} ms budget",
            r.budget.as_secs_f64() * 1000.0
        )
    };
    const NO_MAP: &str = "no seabed map to search a way round on";
    // A crawler's ways round, rasterised on first use (see `crawler_way_round`).
    let keep_out = |p: &Vec3| near_obstacle(scenario, p);
    let mut ways: Option<Option<WaysRound>> = None;
    let rest = rebase(r.current, r.resume_s.unwrap_or(r.t0));
    let mut pts = rest.points.clone();
    pts[0] = r.p0;
    let mut speeds: Vec<f64> = pts
        .windows(2)
        .zip(rest.times.windows(2))
        .map(|(p, t)| (p[1] - p[0]).norm() / (t[1] - t[0]).max(1e-9))
        .collect();
    if crawler {
        // The rejoin, from where the crawler will be to its plan's next point, is a straight
        // line where that line keeps to ground it may drive, else a way on the map, else none
        // (the crawler holds rather than drive over impassable ground).
        if let Some(g) = r
            .ground
            .filter(|g| pts.len() >= 2 && !g.drivable(&pts[0], &pts[1]))
        {
            let id = &scenario.vehicles[r.vehicle].id;
            let ways = ways.get_or_insert_with(|| Some(g.ways_round(&keep_out)));
            // Arriving on the plan's leg from its next point (the chord's direction at its end).
            let along = pts
                .get(2)
                .map(|p| p - pts[1])
                .filter(|d| d.x.hypot(d.y) > 1e-6)
                .unwrap_or(pts[1] - pts[0]);
            let ways = ways.as_ref().ok_or(NO_MAP)?;
            let Some(way) = crawler_way_round(r, ways, &pts, (0, 0), along) else {
                return Err("no way back to its path on ground it may drive".into());
            };
            let metres = polyline_length(&way);
            tracing::info!(
                "{id}: the straight way back to its path crosses ground it may not drive; \
                 rejoining by {metres:.0} m searched on the seabed map"
            );
            if started.elapsed() > r.budget {
                return Err(over_budget());
            }
            let rejoin_speed = speeds[0];
            pts.splice(0..2, way.iter().copied());
            speeds.splice(0..1, std::iter::repeat_n(rejoin_speed, way.len() - 1));
        }
        (pts, speeds) = split_legs(&pts, &speeds, CRAWLER_LEG_M);
    }
    let runs = blocked_runs(scenario, r, &pts);
    let mut out = vec![pts[0]];
    let mut out_speeds = Vec::new();
    let mut note = None;
    let mut k = 0;
    while k + 1 < pts.len() {
        let Some(&(_, j)) = runs.iter().find(|(a, _)| *a == k) else {
            out.push(pts[k + 1]);
            out_speeds.push(speeds[k]);
            k += 1;
            continue;
        };
        let (from, to) = (pts[k], pts[j + 1]);
        let stretch = || {
            format!(
                "no way round the blocked stretch from ({:.0}, {:.0}) to ({:.0}, {:.0})",
                from.x, from.y, to.x, to.y
            )
        };
        // The run k..=j, rejoined at its end point.
        let way = if crawler {
            let last = j + 2 == pts.len();
            if let Some(o) = last.then(|| keep_out_at(scenario, &to)).flatten() {
                if k == 0 {
                    // Already on that stretch: it drives on along it to the keep-out's edge,
                    // the full margins' (one eased to let the crawler out is not a way in).
                    let own = r.scenario.obstacles.len();
                    let edges: Vec<Obstacle> = r
                        .scenario
                        .obstacles
                        .iter()
                        .chain(&scenario.obstacles[own..])
                        .cloned()
                        .collect();
                    let (driven, short) = drive_to_keep_out(
                        &edges,
                        &pts[..=j + 1],
                        &speeds,
                        &mut out,
                        &mut out_speeds,
                    );
                    if driven < MIN_DRIVE_M {
                        return Err(format!(
                            "its finish ({:.0}, {:.0}) is inside {}'s keep-out, and it stands at the keep-out's edge on the last stretch before it",
                            to.x, to.y, o.id
                        ));
                    }
                    let end = out[out.len() - 1];
                    note = Some(format!(
                        "its finish ({:.0}, {:.0}) is inside {}'s keep-out: it is on the last stretch there, and its path now ends at ({:.0}, {:.0}), at the keep-out's edge, the last {short:.0} m undriven",
                        to.x, to.y, o.id, end.x, end.y
                    ));
                    break;
                }
                let short: f64 = (k..=j).map(|i| (pts[i + 1] - pts[i]).norm()).sum();
                note = Some(format!(
                    "its finish ({:.0}, {:.0}) is inside {}'s keep-out: its path now ends at ({:.0}, {:.0}), the last {short:.0} m undriven",
                    to.x, to.y, o.id, from.x, from.y
                ));
                break;
            }
            // A coverage crawler must stay on passable seabed, which the 3-D grid of the
            // detour does not know: its way round is searched on the seabed map. Without the
            // map (it could not be built) there is none, and the crawler holds.
            let ways = ways.get_or_insert_with(|| r.ground.map(|g| g.ways_round(&keep_out)));
            let ways = ways.as_ref().ok_or(NO_MAP)?;
            let way = crawler_way_round(r, ways, &pts, (k, j), pts[j + 1] - pts[j])
                .ok_or_else(|| format!("{} on ground it may drive", stretch()))?;
            // Past its budget the repair gives up: the crawler holds, and the retry has longer.
            if started.elapsed() > r.budget {
                return Err(over_budget());
            }
            way
        } else {
            super::detour::detour(
                scenario,
                from,
                to,
                scenario.vehicles[r.vehicle].max_pitch_deg,
                super::detour::keep_off(scenario, r.vehicle),
                r.stop.as_deref(),
            )
            .ok_or_else(stretch)?
        };
        let run_length: f64 = (k..=j).map(|i| (pts[i + 1] - pts[i]).norm()).sum();
        let run_time: f64 = (k..=j)
            .map(|i| (pts[i + 1] - pts[i]).norm() / speeds[i].max(1e-9))
            .sum();
        let speed = run_length / run_time.max(1e-9);
        for p in &way[1..] {
            out.push(*p);
            out_speeds.push(speed);
        }
        k = j + 1;
    }
    Ok(Repaired {
        points: out,
        speeds: out_speeds,
        note,
    })
}

/// The legs of `pts` a way round replaces, as runs `(first, last)` of leg indices in order:
/// each run of consecutive blocked legs; for a crawler, widened on both sides over the legs
/// that come within two turning radii of the keep-out, so the way round leaves and rejoins
/// the path where the crawler has room to turn (a rejoin on the edge of the keep-out, on the
/// path's heading, may not be reachable at all).
fn blocked_runs(scenario: &Scenario, r: &Request, pts: &[Vec3]) -> Vec<(usize, usize)> {
    let hit: Vec<bool> = pts
        .windows(2)
        .map(|w| blocked(&scenario.obstacles, &w[0], &w[1]))
        .collect();
    let room = match (scenario.coverage.is_some(), r.ground) {
        (true, Some(g)) => WAY_ROUND_MARGIN_M + 2.0 * g.min_turn_radius_m,
        _ => 0.0,
    };
    let near: Vec<bool> = if room > 0.0 {
        pts.windows(2)
            .map(|w| {
                scenario.hard_obstacles().any(|o| {
                    segment_hits_sphere(&w[0], &w[1], &o.centre(), o.inflated_radius() + room)
                })
            })
            .collect()
    } else {
        hit.clone()
    };
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut i = 0;
    while i < hit.len() {
        if !hit[i] {
            i += 1;
            continue;
        }
        let after_last = runs.last().map_or(0, |&(_, j)| j + 1);
        let mut k = i;
        while k > after_last && near[k - 1] {
            k -= 1;
        }
        let mut j = i;
        while j + 1 < hit.len() && (near[j + 1] || hit[j + 1]) {
            j += 1;
        }
        runs.push((k, j));
        i = j + 1;
    }
    runs
}

/// Legs of a crawler's path are cut to at most this long before its blocked runs are found, so
/// a way round replaces only the stretch near the obstacle, not a whole row.
const CRAWLER_LEG_M: f64 = 10.0;

/// `pts` with every leg longer than `max_m` cut into equal pieces at most that long, each
/// piece keeping its leg's speed (the path and its timing are unchanged).
fn split_legs(pts: &[Vec3], speeds: &[f64], max_m: f64) -> (Vec<Vec3>, Vec<f64>) {
    let mut out = vec![pts[0]];
    let mut out_speeds = Vec::new();
    for (w, s) in pts.windows(2).zip(speeds) {
        let n = ((w[1] - w[0]).norm() / max_m).ceil().max(1.0) as usize;
        for m in 1..=n {
            out.push(w[0] + (w[1] - w[0]) * (m as f64 / n as f64));
            out_speeds.push(*s);
        }
    }
    (out, out_speeds)
}

/// A crawler's way round the legs `k..=j` of `pts` ([`WaysRound::between`]), from `pts[k]` on
/// the heading it arrives there with to `pts[j + 1]`, arriving along `arrive_along` (for a
/// blocked run its last leg; for a rejoin the plan's leg from there), ending exactly there.
/// `None` without a way.
fn crawler_way_round(
    r: &Request,
    ways: &WaysRound,
    pts: &[Vec3],
    (k, j): (usize, usize),
    arrive_along: Vec3,
) -> Option<Vec<Vec3>> {
    let heading = |d: Vec3| (d.x.hypot(d.y) > 1e-6).then(|| d.y.atan2(d.x));
    // Arriving at pts[k]: the leg before it, or (at the vehicle) its course, else the
    // blocked leg's own direction.
    let before = if k > 0 {
        Some(pts[k] - pts[k - 1])
    } else {
        r.heading
    };
    let start = before
        .and_then(heading)
        .or_else(|| heading(pts[k + 1] - pts[k]))?;
    let end = heading(arrive_along)?;
    let mut way = ways.between(
        Pose2::new(pts[k].x, pts[k].y, start),
        Pose2::new(pts[j + 1].x, pts[j + 1].y, end),
    )?;
    // The search may end within a metre of the goal: end on the path's own point.
    if let Some(last) = way.last_mut() {
        *last = pts[j + 1];
    }
    way[0] = pts[k];
    Some(way)
}

/// `points` flown at `speeds` scaled alike to take `duration` from `t0`, each leg kept within
/// `[v_min, v_max]`.
fn timed(points: Vec<Vec3>, speeds: &[f64], t0: f64, duration: f64, v: (f64, f64)) -> Trajectory {
    let lengths: Vec<f64> = leg_lengths(&points).collect();
    let natural: f64 = lengths
        .iter()
        .zip(speeds)
        .map(|(l, s)| l / s.max(1e-9))
        .sum();
    let scale = if duration > 0.0 {
        natural / duration
    } else {
        1.0
    };
    let mut times = vec![t0];
    for (l, s) in lengths.iter().zip(speeds) {
        let speed = (s * scale).clamp(v.0, v.1);
        times.push(times[times.len() - 1] + l / speed);
    }
    Trajectory { times, points }
}

/// Factors tried on the time the repaired tour takes to reach its closest approach to another
/// vehicle: as planned first, then a little slower or faster. The legs after it take up the
/// difference, so the arrival stays as planned where the speed range allows.
pub const RETIMINGS: [f64; 7] = [1.0, 1.05, 0.95, 1.1, 0.9, 1.2, 0.8];

/// `base` with the legs that start before mission time `at` flown in `factor` times their
/// planned time and the later legs re-timed to keep `base`'s arrival; every leg's speed stays
/// within `[v_min, v_max]`, so the arrival moves only when the range cannot make up the
/// difference.
fn retimed(base: &Trajectory, at: f64, factor: f64, v: (f64, f64)) -> Trajectory {
    let legs: Vec<(f64, f64)> = base
        .points
        .windows(2)
        .zip(base.times.windows(2))
        .map(|(p, t)| ((p[1] - p[0]).norm(), t[1] - t[0]))
        .collect();
    let fly = |length: f64, time: f64| time.clamp(length / v.1, length / v.0.max(1e-9));
    // At least the first leg, at most every leg.
    let prefix = base.times[..base.times.len() - 1]
        .iter()
        .filter(|t| **t < at)
        .count()
        .clamp(1, legs.len().max(1));
    let mut durations: Vec<f64> = legs[..prefix.min(legs.len())]
        .iter()
        .map(|(l, t)| fly(*l, t * factor))
        .collect();
    let used: f64 = durations.iter().sum();
    let rest: f64 = legs[durations.len()..].iter().map(|(_, t)| t).sum();
    let left = base.arrival() - base.times[0] - used;
    let scale = if rest > 0.0 && left > 0.0 {
        left / rest
    } else {
        0.0
    };
    durations.extend(
        legs[durations.len()..]
            .iter()
            .map(|(l, t)| fly(*l, t * scale)),
    );
    let mut times = vec![base.times[0]];
    for d in durations {
        times.push(times[times.len() - 1] + d);
    }
    Trajectory {
        times,
        points: base.points.clone(),
    }
}

/// Repairs the vehicle's tour (see the module doc).
pub fn repair(r: &Request) -> Replanned {
    let started = Instant::now();
    let v = &r.scenario.vehicles[r.vehicle];
    let d_min = r.scenario.fleet.d_min_m;
    let shaped = crawler_scenario(r);
    let scenario = shaped.as_ref().unwrap_or(r.scenario);
    let Repaired {
        points,
        speeds,
        note,
    } = match repaired_path(r, scenario) {
        Ok(p) => p,
        Err(why) => return Replanned::not_found(r.current.clone(), started, why),
    };
    // The path, hence its obstacle intrusions, is the same at every timing. They are counted
    // on the scenario's own obstacles (a margin the crawler was inside eased as it planned);
    // the standing vehicles are the separation check's.
    let own = &scenario.obstacles[..r.scenario.obstacles.len()];
    let hard_hits = points
        .windows(2)
        .filter(|w| blocked(own, &w[0], &w[1]))
        .count();
    let range = (v.speed_min_mps, v.speed_max_mps);
    let on_time = timed(points, &speeds, r.t0, r.current.arrival() - r.t0, range);
    let buffered = d_min + r.separation_buffer_m.max(0.0);
    let (separation, closest_at) = closest_vehicle(r, &on_time, d_min);
    let retimings: Vec<(Trajectory, f64)> = if separation < buffered {
        RETIMINGS[1..]
            .iter()
            .map(|f| {
                let t = retimed(&on_time, closest_at, *f, range);
                let (s, _) = closest_vehicle(r, &t, d_min);
                (t, s)
            })
            .collect()
    } else {
        Vec::new()
    };
    let mut candidates = vec![(on_time, separation)];
    candidates.extend(retimings);
    let pick = [buffered, d_min]
        .iter()
        .find_map(|d| candidates.iter().position(|(_, s)| *s >= *d))
        .unwrap_or(0);
    let (trajectory, min_separation_m) = candidates.swap_remove(pick);
    Replanned {
        trajectory,
        safe: hard_hits == 0 && min_separation_m >= d_min,
        hard_hits,
        min_separation_m,
        elapsed: started.elapsed(),
        no_way: None,
        note,
    }
}

/// The smallest predicted distance from `trajectory` to any other vehicle, metres, and the
/// mission time it comes at (`t0` when there is no other vehicle).
fn closest_vehicle(r: &Request, trajectory: &Trajectory, d_min: f64) -> (f64, f64) {
    let mine = rebase(trajectory, r.t0);
    r.others
        .iter()
        .enumerate()
        .filter(|(j, _)| *j != r.vehicle)
        .map(|(_, o)| {
            let o = rebase(o, r.t0);
            let pair = motion_separation(&Motion::new(&mine), &Motion::new(&o), d_min, false);
            (pair.min_distance, r.t0 + pair.min_time)
        })
        .fold((f64::INFINITY, r.t0), |a, b| if b.0 < a.0 { b } else { a })
}

#[cfg(test)]
mod tests;
