//! The executed track of a vehicle as the coordinator reconstructs it from sparse fixes, and
//! what the figures measure on it.

use shoal_common::geometry::{segment_point_distance, Vec3};
use shoal_common::scenario::{Obstacle, ObstacleKind};
use shoal_common::terrain::{path_min_hazard_clearance, Hazard, Terrain};
use shoal_common::trajectory::Trajectory;

/// Spacing of the seabed samples along a track, metres: finer than the sensor height or
/// clearance of any shipped scenario, coarse enough for kilometres of track.
const SEABED_STEP_M: f64 = 0.5;

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

/// Closest approach of `track` to the surface of any hard obstacle, metres; obstacle `i` is
/// measured on the track from point `since[i]` on (0 when `since` is shorter). `None` without
/// a hard obstacle or fixes to measure.
pub(super) fn obstacle_clearance(
    track: &Trajectory,
    obstacles: &[Obstacle],
    since: &[usize],
) -> Option<f64> {
    let mut best: Option<f64> = None;
    for (i, o) in obstacles.iter().enumerate() {
        if o.kind != ObstacleKind::Hard {
            continue;
        }
        let from = since.get(i).copied().unwrap_or(0);
        let points = track.points.get(from..).unwrap_or(&[]);
        let c = o.centre();
        let d = match points.len() {
            0 => continue,
            1 => (points[0] - c).norm(),
            _ => points
                .windows(2)
                .map(|w| segment_point_distance(&w[0], &w[1], &c))
                .fold(f64::INFINITY, f64::min),
        };
        let clearance = d - o.radius_m;
        best = Some(best.map_or(clearance, |b: f64| b.min(clearance)));
    }
    best
}

/// Lowest height of `track` above `seabed`, metres (negative: through it), sampled every
/// [`SEABED_STEP_M`] along each segment; `None` without fixes. An AUV's simulator does not
/// stop at the seabed, so this is how a run learns that a vehicle would have hit it.
pub(super) fn seabed_clearance(track: &Trajectory, seabed: &Terrain) -> Option<f64> {
    seabed
        .lowest_height_on_path(&track.points, SEABED_STEP_M)
        .map(|(h, _)| h)
}

/// Closest `track` came to any of `hazards` horizontally, metres (negative: inside one); `None`
/// without hazards or fixes.
pub(super) fn hazard_clearance(track: &Trajectory, hazards: &[Hazard]) -> Option<f64> {
    if hazards.is_empty() || track.points.is_empty() {
        return None;
    }
    let xy: Vec<[f64; 2]> = track.points.iter().map(|p| [p.x, p.y]).collect();
    Some(path_min_hazard_clearance(hazards, &xy))
}

/// The earliest plan time in `[from, to]` (sampled every second) at which `plan` comes within
/// [`STOP_MATCH_M`] of its closest approach there to `p`: where a vehicle that drove on along
/// its plan from `from` stopped. The earliest, not the closest: a path that comes back near
/// itself (a loop, the next row) passes the stop again later, where the vehicle never went.
pub fn first_near(plan: &Trajectory, p: Vec3, from: f64, to: f64) -> f64 {
    let n = (to - from).ceil().max(1.0) as usize;
    let dist: Vec<(f64, f64)> = (0..=n)
        .map(|k| {
            let tau = from + (to - from) * k as f64 / n as f64;
            (tau, (plan.position_at(tau) - p).norm())
        })
        .collect();
    let closest = dist.iter().map(|d| d.1).fold(f64::INFINITY, f64::min);
    dist.iter()
        .find(|d| d.1 <= closest + STOP_MATCH_M)
        .map_or(from, |d| d.0)
}

/// Slack of [`first_near`] over the closest approach, metres: a few times a vehicle's tracking
/// error and fix noise.
const STOP_MATCH_M: f64 = 3.0;

#[cfg(test)]
mod tests {
    use super::*;
    use shoal_common::terrain::Mountain;

    fn line(z: f64) -> Trajectory {
        Trajectory {
            times: vec![0.0, 100.0],
            points: vec![Vec3::new(0.0, 0.0, z), Vec3::new(100.0, 0.0, z)],
        }
    }

    #[test]
    fn seabed_clearance_finds_the_hill_between_two_fixes() {
        // One hill of 10 m at x = 50 (spread 10 m); the track's ends are over flat seabed
        // (10·e⁻²⁵ ≈ 0), so only the samples between them see it.
        let seabed = Terrain::Hills(vec![Mountain {
            centre: [50.0, 0.0],
            height_m: 10.0,
            spread_m: [10.0, 10.0],
        }]);
        let over = seabed_clearance(&line(15.0), &seabed).unwrap_or(f64::NAN);
        assert!((over - 5.0).abs() < 1e-9, "{over}");
        let through = seabed_clearance(&line(8.0), &seabed).unwrap_or(f64::NAN);
        assert!((through + 2.0).abs() < 1e-9, "{through}");
        // A single fix is its own height; no fix, no figure.
        let one = Trajectory {
            times: vec![0.0],
            points: vec![Vec3::new(50.0, 0.0, 12.5)],
        };
        assert!((seabed_clearance(&one, &seabed).unwrap_or(f64::NAN) - 2.5).abs() < 1e-9);
        let none = Trajectory {
            times: vec![],
            points: vec![],
        };
        assert_eq!(seabed_clearance(&none, &seabed), None);
    }

    #[test]
    fn hazard_clearance_is_horizontal_and_signed() {
        // A 10 m hazard centred 15 m off the track's line: 5 m clear; centred 4 m off it, the
        // track is 6 m inside. The track's height does not matter (a cylinder).
        let hazard = |y: f64| Hazard {
            id: "h".into(),
            centre: [50.0, y],
            radius_m: 10.0,
            height_m: 3.0,
        };
        let clear = hazard_clearance(&line(40.0), &[hazard(15.0)]).unwrap_or(f64::NAN);
        assert!((clear - 5.0).abs() < 1e-9, "{clear}");
        let inside = hazard_clearance(&line(0.0), &[hazard(15.0), hazard(-4.0)]);
        assert!(
            (inside.unwrap_or(f64::NAN) + 6.0).abs() < 1e-9,
            "{inside:?}"
        );
        assert_eq!(hazard_clearance(&line(0.0), &[]), None);
    }
}
