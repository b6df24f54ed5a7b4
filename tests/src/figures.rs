//! Figures recomputed from the trajectories alone, with the checker's own geometry: per vehicle
//! (length, arrival, turn, pitch, leg speeds, clearance, collisions, soft exposure, bounds) and
//! for the fleet (closest approach, breach time, arrival spread).

use crate::geometry::{self, dist, point, P3};
use crate::model::{ObstacleKind, Scenario};
use crate::tolerance::TOL;

/// Figures of one vehicle, recomputed from its trajectory.
#[derive(Debug, Clone, PartialEq)]
pub struct VehicleFigures {
    /// Vehicle id.
    pub id: String,
    /// Sum of leg lengths, metres.
    pub length_m: f64,
    /// Time of the last sample, seconds.
    pub arrival_s: f64,
    /// Largest horizontal heading change between consecutive legs with horizontal extent
    /// (see [`geometry::max_turn_deg`]), degrees.
    pub max_turn_deg: f64,
    /// Largest |pitch|, degrees.
    pub max_pitch_deg: f64,
    /// Slowest leg of non-zero length, m/s (0 when there is none).
    pub min_speed_mps: f64,
    /// Fastest leg of non-zero length, m/s (0 when there is none).
    pub max_speed_mps: f64,
    /// Smallest (segment distance to centre − radius) over hard obstacles; `None` without any.
    pub min_clearance_m: Option<f64>,
    /// (leg, hard obstacle) pairs closer than radius plus inflation.
    pub hard_collisions: usize,
    /// Metres of path inside inflated soft obstacles, summed over obstacles.
    pub soft_exposure_m: f64,
    /// `soft_exposure_m` with every inflated soft sphere shrunk, then grown, by [`TOL`]: the
    /// figure a plan may report. A chord's length is ill-conditioned where a leg grazes a sphere
    /// (`2·√(r² − d²)` has an infinite slope at `d = r`, and the planner's cost drives legs onto
    /// soft spheres' surfaces), so two correct computations can differ by micrometres there; a
    /// leg within [`TOL`] of tangency may count anything from 0 to `2·√(2·r·TOL)`.
    pub soft_exposure_range_m: [f64; 2],
    /// True when every sample lies inside the scenario bounds (± [`TOL`]).
    pub inside_bounds: bool,
    /// `(leg index, speed m/s)` of every leg of non-zero length (infinite for a jump in no time).
    pub leg_speeds_mps: Vec<(usize, f64)>,
}

/// Fleet figures, recomputed.
#[derive(Debug, Clone, PartialEq)]
pub struct FleetFigures {
    /// Smallest separation over all pairs; `None` for fewer than two vehicles.
    pub min_separation_m: Option<f64>,
    /// Pair at that separation.
    pub min_separation_pair: Option<[String; 2]>,
    /// Instant of that separation.
    pub min_separation_time_s: Option<f64>,
    /// Total time pairs spend closer than d_min, seconds.
    pub separation_breach_s: f64,
    /// `separation_breach_s` with d_min lowered, then raised, by [`TOL`]: the figure a plan may
    /// report. Like a chord of a grazed sphere, the time a pair spends inside d_min is
    /// ill-conditioned when its closest approach is d_min itself.
    pub separation_breach_range_s: [f64; 2],
    /// Sum of hard collisions.
    pub hard_collisions: usize,
    /// Latest minus earliest arrival, seconds.
    pub arrival_spread_s: f64,
}

/// Recomputes a vehicle's figures from its trajectory against the scenario's obstacles.
pub fn vehicle_figures(id: &str, traj: &[[f64; 4]], scenario: &Scenario) -> VehicleFigures {
    let pts: Vec<P3> = traj.iter().map(point).collect();
    let length_m = pts.windows(2).map(|w| dist(&w[0], &w[1])).sum();
    let max_turn_deg = geometry::max_turn_deg(&pts);
    let max_pitch_deg = pts
        .windows(2)
        .map(|w| geometry::abs_pitch_deg(&w[0], &w[1]))
        .fold(0.0, f64::max);
    let leg_speeds_mps: Vec<(usize, f64)> = traj
        .windows(2)
        .enumerate()
        .filter_map(|(k, w)| {
            let len = dist(&point(&w[0]), &point(&w[1]));
            let dt = w[1][0] - w[0][0];
            if len <= TOL {
                None
            } else if dt > 0.0 {
                Some((k, len / dt))
            } else {
                Some((k, f64::INFINITY))
            }
        })
        .collect();
    let (min_speed_mps, max_speed_mps) = if leg_speeds_mps.is_empty() {
        (0.0, 0.0)
    } else {
        (
            leg_speeds_mps
                .iter()
                .map(|s| s.1)
                .fold(f64::INFINITY, f64::min),
            leg_speeds_mps.iter().map(|s| s.1).fold(0.0, f64::max),
        )
    };
    let mut min_clearance_m: Option<f64> = None;
    let mut hard_collisions = 0;
    let mut soft_exposure_m = 0.0;
    let mut soft_exposure_range_m = [0.0, 0.0];
    for o in &scenario.obstacles {
        let inflated = o.radius_m + o.inflation_m;
        match o.kind {
            ObstacleKind::Hard => {
                let mut closest = f64::INFINITY;
                if pts.len() == 1 {
                    closest = dist(&pts[0], &o.centre);
                }
                for w in pts.windows(2) {
                    let d = geometry::segment_point_distance(&w[0], &w[1], &o.centre);
                    closest = closest.min(d);
                    if d < inflated {
                        hard_collisions += 1;
                    }
                }
                let c = closest - o.radius_m;
                min_clearance_m = Some(min_clearance_m.map_or(c, |m| m.min(c)));
            }
            ObstacleKind::Soft => {
                let exposure = |r: f64| -> f64 {
                    pts.windows(2)
                        .map(|w| geometry::chord_inside_sphere(&w[0], &w[1], &o.centre, r))
                        .sum()
                };
                soft_exposure_m += exposure(inflated);
                soft_exposure_range_m[0] += exposure((inflated - TOL).max(0.0));
                soft_exposure_range_m[1] += exposure(inflated + TOL);
            }
        }
    }
    let (lo, hi) = (scenario.bounds.min, scenario.bounds.max);
    let inside_bounds = pts
        .iter()
        .all(|p| (0..3).all(|k| p[k] >= lo[k] - TOL && p[k] <= hi[k] + TOL));
    VehicleFigures {
        id: id.to_string(),
        length_m,
        arrival_s: geometry::arrival(traj),
        max_turn_deg,
        max_pitch_deg,
        min_speed_mps,
        max_speed_mps,
        min_clearance_m,
        hard_collisions,
        soft_exposure_m,
        soft_exposure_range_m,
        inside_bounds,
        leg_speeds_mps,
    }
}

/// Recomputes the fleet figures from the trajectories (`(id, trajectory)` in scenario order).
pub fn fleet_figures(
    trajectories: &[(&str, &[[f64; 4]])],
    d_min: f64,
    hard_collisions: usize,
) -> FleetFigures {
    let mut out = FleetFigures {
        min_separation_m: None,
        min_separation_pair: None,
        min_separation_time_s: None,
        separation_breach_s: 0.0,
        separation_breach_range_s: [0.0, 0.0],
        hard_collisions,
        arrival_spread_s: 0.0,
    };
    for (i, (ida, a)) in trajectories.iter().enumerate() {
        for (idb, b) in &trajectories[i + 1..] {
            let m = geometry::min_separation(a, b);
            out.separation_breach_s += geometry::breach_time(a, b, d_min);
            out.separation_breach_range_s[0] += geometry::breach_time(a, b, (d_min - TOL).max(0.0));
            out.separation_breach_range_s[1] += geometry::breach_time(a, b, d_min + TOL);
            if out.min_separation_m.is_none_or(|best| m.distance < best) {
                out.min_separation_m = Some(m.distance);
                out.min_separation_pair = Some([ida.to_string(), idb.to_string()]);
                out.min_separation_time_s = Some(m.time);
            }
        }
    }
    let arrivals = trajectories.iter().map(|(_, t)| geometry::arrival(t));
    let first = arrivals.clone().fold(f64::INFINITY, f64::min);
    let last = arrivals.fold(f64::NEG_INFINITY, f64::max);
    if !trajectories.is_empty() {
        out.arrival_spread_s = last - first;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::{approx, SCENARIO};
    use crate::model::parse_scenario;

    #[test]
    fn turn_across_legs_without_horizontal_extent() -> Result<(), String> {
        let scenario = parse_scenario(SCENARIO)?;
        // East, climb straight up, back west: 180°, although no single corner turns.
        let traj = [
            [0., 10., 0., 40.],
            [10., 20., 0., 40.],
            [20., 20., 0., 50.],
            [30., 10., 0., 50.],
        ];
        let f = vehicle_figures("a", &traj, &scenario);
        assert!(approx(f.max_turn_deg, 180.0, 1e-9), "{f:?}");
        assert!(approx(f.max_pitch_deg, 90.0, 1e-9), "{f:?}");
        // East, hold at a repeated point, north: 90°; the held leg has no speed.
        let traj = [
            [0., 0., 0., 50.],
            [10., 10., 0., 50.],
            [15., 10., 0., 50.],
            [25., 10., 10., 50.],
        ];
        let f = vehicle_figures("a", &traj, &scenario);
        assert!(approx(f.max_turn_deg, 90.0, 1e-9), "{f:?}");
        assert_eq!(f.leg_speeds_mps, vec![(0, 1.0), (2, 1.0)]);
        Ok(())
    }
}
