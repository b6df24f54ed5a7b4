//! The executed track of a vehicle as the coordinator reconstructs it from sparse fixes, and
//! what the figures measure on it.

use shoal_common::geometry::{segment_point_distance, Vec3};
use shoal_common::scenario::{Obstacle, ObstacleKind};
use shoal_common::trajectory::Trajectory;

/// The executed track between two fixes `(mission time, plan time, offset from the plan)`:
/// the plan's corners between the two plan times, each shifted by the offset interpolated
/// between the fixes' and timed in proportion. Joining the fixes by a straight line instead
/// cuts every corner between them: at 100× real time 2 Hz fixes are 50 mission seconds apart,
/// and the chord of a tour round a 50 m cage passes metres inside the net the vehicle went
/// round. Nothing is added when the plan time does not advance, or advances more than twice
/// as fast as mission time (the fix was matched to another part of a path that passes near
/// itself): then the fixes are joined directly.
pub(super) fn along_plan(
    plan: &Trajectory,
    from: (f64, f64, Vec3),
    to: (f64, f64, Vec3),
) -> Vec<(f64, Vec3)> {
    let ((t0, tau0, o0), (t1, tau1, o1)) = (from, to);
    let (dt, dtau) = (t1 - t0, tau1 - tau0);
    if dt <= 0.0 || dtau <= 0.0 || dtau > 2.0 * dt + 1.0 {
        return Vec::new();
    }
    plan.times
        .iter()
        .zip(&plan.points)
        .filter(|(tau, _)| **tau > tau0 && **tau < tau1)
        .map(|(tau, q)| {
            let s = (tau - tau0) / dtau;
            (t0 + s * dt, q + o0 + (o1 - o0) * s)
        })
        .collect()
}

/// Closest approach of `track` to the surface of any hard obstacle, metres.
pub(super) fn obstacle_clearance(track: &Trajectory, obstacles: &[Obstacle]) -> Option<f64> {
    let mut best: Option<f64> = None;
    for o in obstacles.iter().filter(|o| o.kind == ObstacleKind::Hard) {
        let c = o.centre();
        let d = match track.points.len() {
            0 => continue,
            1 => (track.points[0] - c).norm(),
            _ => track
                .points
                .windows(2)
                .map(|w| segment_point_distance(&w[0], &w[1], &c))
                .fold(f64::INFINITY, f64::min),
        };
        let clearance = d - o.radius_m;
        best = Some(best.map_or(clearance, |b: f64| b.min(clearance)));
    }
    best
}
