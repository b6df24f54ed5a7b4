//! A coverage crawler's keep-outs: the scenario its repair plans in (the vehicles standing near
//! its path as obstacles, a margin it is inside eased to let it out) and where a path meets
//! them. Split from `repair`, which uses them.

use shoal_common::geometry::{polyline_length, Vec3};
use shoal_common::scenario::{Obstacle, ObstacleKind, Scenario};

use super::replan::Request;

/// Least a crawler on the last stretch to a finish inside a keep-out must have ahead of it to
/// end its path there rather than hold, metres (its path would be a point).
pub(super) const MIN_DRIVE_M: f64 = 0.5;

/// The path `pts` (its legs flown at `speeds`) driven from its first point up to where it
/// first comes within [`WAY_ROUND_MARGIN_M`] of the inflated sphere of a hard obstacle of
/// `obstacles`: the points after the first are pushed on `out` and their speeds on
/// `out_speeds`. Metres driven, and metres of `pts` left undriven.
pub(super) fn drive_to_keep_out(
    obstacles: &[Obstacle],
    pts: &[Vec3],
    speeds: &[f64],
    out: &mut Vec<Vec3>,
    out_speeds: &mut Vec<f64>,
) -> (f64, f64) {
    let total = polyline_length(pts);
    let mut driven = 0.0;
    for (i, w) in pts.windows(2).enumerate() {
        let (a, b) = (w[0], w[1]);
        match entry_along(obstacles, &a, &b) {
            Some(s) => {
                let q = a + (b - a) * s;
                if (q - a).norm() > 1e-9 {
                    out.push(q);
                    out_speeds.push(speeds[i]);
                    driven += (q - a).norm();
                }
                break;
            }
            None => {
                out.push(b);
                out_speeds.push(speeds[i]);
                driven += (b - a).norm();
            }
        }
    }
    (driven, (total - driven).max(0.0))
}

/// Where along the leg `a`–`b` (0 at `a`, 1 at `b`) it first comes within
/// [`WAY_ROUND_MARGIN_M`] of the inflated sphere of a hard obstacle of `obstacles` (0 when `a`
/// is already that close); `None` when it never does.
pub(super) fn entry_along(obstacles: &[Obstacle], a: &Vec3, b: &Vec3) -> Option<f64> {
    let d = b - a;
    let dd = d.dot(&d);
    obstacles
        .iter()
        .filter(|o| o.kind == ObstacleKind::Hard)
        .filter_map(|o| {
            let r = o.inflated_radius() + WAY_ROUND_MARGIN_M;
            let f = a - o.centre();
            let c = f.dot(&f) - r * r;
            if c < 0.0 {
                return Some(0.0);
            }
            // |f + s d|² = r²: its smaller root, where the leg enters.
            let bh = f.dot(&d);
            let disc = bh * bh - dd * c;
            if dd < 1e-12 || disc < 0.0 {
                return None;
            }
            let s = (-bh - disc.sqrt()) / dd;
            (0.0..=1.0).contains(&s).then_some(s)
        })
        .reduce(f64::min)
}

/// Every other vehicle that stands still over the rest of its prediction (held, lost or
/// faulted; arrived, once its prediction has settled on its end point), as a hard sphere of
/// d_min plus the separation buffer round where it stands (a crawler's repair goes round it,
/// see [`crawler_scenario`]). A re-timing cannot pass a vehicle that stands on the path (the
/// repair would be unsafe at every timing, and the crawler would wait behind it as long as it
/// stands): the repair goes round it as round an obstacle, leaving the ground near it
/// uncovered. A crawler that will already be inside such a sphere at `t0` (a conflict is seen
/// only `--horizon` ahead) gets a smaller one, down to d_min, that leaves it room to turn away
/// (and its finish outside, when that keeps d_min); one already within d_min of the standing
/// vehicle is left to the separation check, which lets it move away. A tour still waits: the
/// way round would skip the inspection points near the standing vehicle.
pub(super) fn stopped_vehicles(r: &Request) -> Vec<Obstacle> {
    let d_min = r.scenario.fleet.d_min_m;
    let d = d_min + r.separation_buffer_m.max(0.0);
    let turn = r.ground.map_or(0.0, |g| g.min_turn_radius_m);
    let finish = r.current.points.last().copied().unwrap_or(r.p0);
    if d_min <= 0.0 {
        return Vec::new();
    }
    r.others
        .iter()
        .enumerate()
        .filter(|(j, _)| *j != r.vehicle)
        .filter_map(|(j, o)| {
            let at = o.position_at(r.t0);
            let rest = o.since(r.t0);
            let still = rest.points.iter().all(|p| (p - at).norm() < STILL_M);
            // Room left outside the sphere for the crawler's start, which the search needs
            // free, and for a turn away from it; and for its finish.
            let dist = (r.p0 - at).norm();
            let to_finish = (finish - at).norm();
            let radius = (dist - WAY_ROUND_MARGIN_M - STILL_M - turn)
                .min(to_finish - WAY_ROUND_MARGIN_M - STILL_M)
                .clamp(d_min, d);
            let room = dist >= d_min + WAY_ROUND_MARGIN_M + STILL_M;
            (still && room).then(|| Obstacle {
                id: format!("{} (standing still)", r.scenario.vehicles[j].id),
                kind: ObstacleKind::Hard,
                centre: at.into(),
                radius_m: radius,
                inflation_m: 0.0,
            })
        })
        .collect()
}

/// The scenario a coverage crawler's repair plans in (`None`: `r.scenario` as it is).
///
/// - Every vehicle standing still near its path is an obstacle ([`stopped_vehicles`]).
/// - A hard obstacle whose margin (its inflation) the crawler is already inside at `t0` (it
///   appeared there, or the crawler stopped short of it inside) has its margin eased, down to
///   none, to leave the crawler room to turn away at its turning radius: the way round then
///   takes it out of the margin, where it would otherwise hold (a search cannot start in a
///   keep-out) until the obstacle is gone. Its physical sphere is never eased, nor is the
///   margin of an obstacle the crawler is outside.
pub(super) fn crawler_scenario(r: &Request) -> Option<Scenario> {
    r.scenario.coverage.as_ref()?;
    let turn = r.ground.map_or(0.0, |g| g.min_turn_radius_m);
    let mut s = r.scenario.clone();
    let mut changed = false;
    for o in s
        .obstacles
        .iter_mut()
        .filter(|o| o.kind == ObstacleKind::Hard)
    {
        let dist = (r.p0 - o.centre()).norm();
        let room = dist - WAY_ROUND_MARGIN_M - STILL_M - turn - o.radius_m;
        if dist < o.inflated_radius() + WAY_ROUND_MARGIN_M && room < o.inflation_m {
            o.inflation_m = room.max(0.0);
            changed = true;
        }
    }
    let stopped = stopped_vehicles(r);
    changed |= !stopped.is_empty();
    s.obstacles.extend(stopped);
    changed.then_some(s)
}

/// A vehicle whose prediction stays within this of where it is at `t0` stands still, metres.
pub(super) const STILL_M: f64 = 1.0;

/// Margin a crawler's way round keeps outside the inflated spheres, metres: its points are
/// checked every half metre on the map and thinned by 5 cm, and a leg that grazed a sphere would
/// make the repair unsafe.
pub(super) const WAY_ROUND_MARGIN_M: f64 = 1.0;

/// Whether `p` is within [`WAY_ROUND_MARGIN_M`] of a hard obstacle's inflated sphere.
pub(super) fn near_obstacle(scenario: &Scenario, p: &Vec3) -> bool {
    keep_out_at(scenario, p).is_some()
}

/// The first hard obstacle within [`WAY_ROUND_MARGIN_M`] of whose inflated sphere `p` is.
pub(super) fn keep_out_at<'s>(scenario: &'s Scenario, p: &Vec3) -> Option<&'s Obstacle> {
    scenario
        .hard_obstacles()
        .find(|o| (p - o.centre()).norm() < o.inflated_radius() + WAY_ROUND_MARGIN_M)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_leg_enters_a_keep_out_where_it_comes_within_the_margin_of_the_inflated_sphere() {
        let rock = |x: f64, kind: ObstacleKind| Obstacle {
            id: "rock".into(),
            kind,
            centre: [x, 3.0, 0.0],
            radius_m: 4.0,
            inflation_m: 1.0,
        };
        let (a, b) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(100.0, 0.0, 0.0));
        // 4 + 1 m and the 1 m margin: 6 m from (50, 3), at x = 50 − √(36 − 9) = 44.804.
        let s = entry_along(&[rock(50.0, ObstacleKind::Hard)], &a, &b).unwrap_or(f64::NAN);
        assert!((s - (50.0 - 27f64.sqrt()) / 100.0).abs() < 1e-12, "{s}");
        // The nearer of two; a soft one is no keep-out; one beyond the leg's end is not reached
        // ((105, 3) is 5.8 m from (100, 0), but 6 m from (104, 0) on: past the end).
        let both = [
            rock(50.0, ObstacleKind::Hard),
            rock(20.0, ObstacleKind::Hard),
        ];
        let s = entry_along(&both, &a, &b).unwrap_or(f64::NAN);
        assert!((s - (20.0 - 27f64.sqrt()) / 100.0).abs() < 1e-12, "{s}");
        assert_eq!(entry_along(&[rock(20.0, ObstacleKind::Soft)], &a, &b), None);
        assert_eq!(
            entry_along(&[rock(110.0, ObstacleKind::Hard)], &a, &b),
            None
        );
        // Starting within it: at once.
        assert_eq!(
            entry_along(&[rock(2.0, ObstacleKind::Hard)], &a, &b),
            Some(0.0)
        );

        // Driven along two legs: the first (0–40) clear, the second cut at 44.804.
        let pts = [a, Vec3::new(40.0, 0.0, 0.0), b];
        let (mut out, mut speeds) = (vec![a], Vec::new());
        let (driven, short) = drive_to_keep_out(
            &[rock(50.0, ObstacleKind::Hard)],
            &pts,
            &[1.0, 2.0],
            &mut out,
            &mut speeds,
        );
        let edge = 50.0 - 27f64.sqrt();
        assert!((driven - edge).abs() < 1e-9 && (short - (100.0 - edge)).abs() < 1e-9);
        assert_eq!(out.len(), 3);
        assert!((out[2] - Vec3::new(edge, 0.0, 0.0)).norm() < 1e-9);
        assert_eq!(speeds, vec![1.0, 2.0]);
    }
}
