//! The checker's own view of Zhang et al. 2022 (energy-planned AUVs) and Hu et al. 2023 (cage-inspection tours):
//! the turning radius, pitch and seabed clearance of an energy plan, and that a tour visits the
//! inspection points it names, recomputed from the trajectory alone.

use crate::model::{Obstacle, ObstacleKind, Scenario, Vehicle};
use crate::sections::{eight, two, CurrentsSection, EnergySection, PlanEnergy, PlanTour};

/// Relative and absolute slack of recomputed figures.
const TOL: f64 = 1e-6;

impl CurrentsSection {
    /// The current at `p` under Zhang et al. 2022, eq. (2): the surface value scaled by
    /// `(ζ_bd − ζ) / ζ_bd`, the surface being the top of the box and ζ_bd its height; `None`
    /// for a gridded field.
    fn depth_decay(&self, bounds: &crate::model::Bounds, p: [f64; 3]) -> Option<[f64; 3]> {
        if self.model.as_deref().is_some_and(|m| m != "depth-decay") {
            return None;
        }
        let [u, v] = self.surface_velocity_mps.unwrap_or([0.0, 0.0]);
        let max_depth = bounds.max[2] - bounds.min[2];
        let depth = (bounds.max[2] - p[2]).clamp(0.0, max_depth);
        let s = if max_depth > 0.0 {
            (max_depth - depth) / max_depth
        } else {
            0.0
        };
        Some([u * s, v * s, 0.0])
    }
}

/// What the checks found.
#[derive(Debug, Default)]
pub struct Found {
    /// Reported figures that disagree with the recomputation.
    pub mismatches: Vec<String>,
    /// Broken constraints.
    pub broken: Vec<String>,
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// Circumradius of three points; infinite when collinear or two coincide.
pub fn circumradius(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let (u, v) = (sub(b, a), sub(c, a));
    let cross = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let (ab, bc, ca) = (norm(u), norm(sub(c, b)), norm(v));
    let twice_area = norm(cross);
    if ab == 0.0 || bc == 0.0 || twice_area <= 1e-12 * (ab * bc * ca) {
        f64::INFINITY
    } else {
        ab * bc * ca / (2.0 * twice_area)
    }
}

fn points(traj: &[[f64; 4]]) -> Vec<[f64; 3]> {
    let mut out: Vec<[f64; 3]> = Vec::with_capacity(traj.len());
    for s in traj {
        let p = [s[1], s[2], s[3]];
        // A hold (the same point again) is not a path point.
        if out.last().is_none_or(|q| norm(sub(p, *q)) > 1e-12) {
            out.push(p);
        }
    }
    out
}

fn differs(reported: f64, recomputed: f64) -> bool {
    if reported.is_infinite() || recomputed.is_infinite() {
        return reported != recomputed;
    }
    (reported - recomputed).abs() > TOL * (1.0 + recomputed.abs())
}

/// Checks an energy-planned AUV: its reported figures and its turning radius, pitch and seabed
/// clearance.
pub fn check_energy(scenario: &Scenario, v: &Vehicle, traj: &[[f64; 4]], e: &PlanEnergy) -> Found {
    let mut f = Found::default();
    let id = &v.id;
    let section = scenario.energy.clone().unwrap_or(EnergySection {
        min_turn_radius_m: eight(),
        terrain_clearance_m: two(),
    });
    let pts = points(traj);
    let length: f64 = pts.windows(2).map(|w| norm(sub(w[1], w[0]))).sum();
    let r_min = section.min_turn_radius_m;
    let (mut tightest, mut q_r) = (f64::INFINITY, 0.0);
    for w in pts.windows(3) {
        let r = circumradius(w[0], w[1], w[2]);
        tightest = tightest.min(r);
        if r < r_min {
            q_r += (r - r_min).powi(2);
        }
    }
    let limit = v.max_pitch_deg;
    let mut q_a = 0.0;
    for w in pts.windows(2) {
        let d = sub(w[1], w[0]);
        let pitch = d[2].atan2(d[0].hypot(d[1])).to_degrees();
        if pitch.abs() > limit {
            q_a += (pitch.abs() - limit).powi(2);
        }
    }
    for (what, reported, recomputed) in [
        ("q_path", e.q_path, length),
        ("q_r", e.q_r, q_r),
        ("q_a", e.q_a, q_a),
        ("min_turn_radius_m", e.min_turn_radius_m, tightest),
    ] {
        if differs(reported, recomputed) {
            f.mismatches.push(format!(
                "{id}.energy.{what}: reported {reported} but recomputed {recomputed}"
            ));
        }
    }
    if tightest < r_min {
        f.broken.push(format!(
            "{id} turns on a {tightest:.3} m radius, below R_AUV = {r_min} m"
        ));
    }
    // Speed through the water on each timed segment: ground velocity minus the current at the
    // segment's midpoint (Zhang et al. 2022, eq. (3)), against the vehicle's top speed.
    if let Some(currents) = &scenario.currents {
        let mut fastest: Option<f64> = None;
        for w in traj.windows(2) {
            let dt = w[1][0] - w[0][0];
            if dt <= 0.0 {
                continue;
            }
            let mid = [1, 2, 3].map(|k| 0.5 * (w[0][k] + w[1][k]));
            let Some(c) = currents.depth_decay(&scenario.bounds, mid) else {
                fastest = None;
                break;
            };
            let water = [1, 2, 3].map(|k| (w[1][k] - w[0][k]) / dt - c[k - 1]);
            fastest = Some(fastest.unwrap_or(0.0).max(norm(water)));
        }
        if let Some(fastest) = fastest {
            if let Some(reported) = e.max_water_speed_mps.filter(|r| differs(*r, fastest)) {
                f.mismatches.push(format!(
                    "{id}.energy.max_water_speed_mps: reported {reported} but recomputed {fastest}"
                ));
            }
            if fastest > v.speed_max_mps + TOL {
                f.broken.push(format!(
                    "{id} needs {fastest:.3} m/s through the water, over its top speed of {} m/s",
                    v.speed_max_mps
                ));
            }
        }
    }
    // Seabed of Gaussian hills alone (Zhang et al. 2022, eq. (1)); other seabeds are the crawler check's
    // (`check_swimmer_seabed`).
    if let Some(seabed) = scenario
        .seabed
        .as_ref()
        .filter(|s| s.relief.is_none() && s.grid.is_none())
    {
        let lowest = pts
            .iter()
            .map(|p| p[2] - seabed.hills_elevation(p[0], p[1]) - section.terrain_clearance_m)
            .fold(f64::INFINITY, f64::min);
        if lowest < -TOL {
            f.broken.push(format!(
                "{id} comes {:.3} m closer to the seabed than its {} m clearance",
                -lowest, section.terrain_clearance_m
            ));
        }
    }
    f
}

/// Checks one tour: every point it names lies on its trajectory, in that order, and its length.
pub fn check_tour(v: &Vehicle, traj: &[[f64; 4]], t: &PlanTour) -> Found {
    let mut f = Found::default();
    let id = &v.id;
    let pts = points(traj);
    let length: f64 = pts.windows(2).map(|w| norm(sub(w[1], w[0]))).sum();
    if differs(t.tour_length_m, length) {
        f.mismatches.push(format!(
            "{id}.tour.tour_length_m: reported {} but recomputed {length}",
            t.tour_length_m
        ));
    }
    if t.order.len() != t.points.len() {
        f.mismatches.push(format!(
            "{id}.tour: {} labels for {} points",
            t.order.len(),
            t.points.len()
        ));
    }
    let mut from = 0;
    for (label, p) in t.order.iter().zip(&t.points) {
        match pts[from..].iter().position(|q| norm(sub(*q, *p)) <= TOL) {
            Some(k) => from += k,
            None => f.broken.push(format!(
                "{id} does not pass inspection point {label} at {p:?} (in its visiting order)"
            )),
        }
    }
    f
}

/// The fleet's tours together visit both inspection points of every cage exactly once: on the
/// cage centre's horizontal plane, `radius + standoff` from the centre, mirrored through it.
pub fn check_coverage(scenario: &Scenario, tours: &[(&str, &PlanTour)]) -> Vec<String> {
    let Some(section) = &scenario.inspection else {
        return Vec::new();
    };
    let cages: Vec<&Obstacle> = scenario
        .obstacles
        .iter()
        .filter(|o| {
            o.kind == ObstacleKind::Hard
                && (section.cages.is_empty() || section.cages.contains(&o.id))
        })
        .collect();
    let mut broken = Vec::new();
    let visited: Vec<(&str, [f64; 3])> = tours
        .iter()
        .flat_map(|(_, t)| {
            t.order
                .iter()
                .map(String::as_str)
                .zip(t.points.iter().copied())
        })
        .collect();
    for c in cages {
        let mine: Vec<[f64; 3]> = visited
            .iter()
            .filter(|(l, _)| l.rsplit_once('.').map(|(cage, _)| cage) == Some(c.id.as_str()))
            .map(|(_, p)| *p)
            .collect();
        if mine.len() != 2 {
            broken.push(format!(
                "cage {} is inspected at {} points, not 2",
                c.id,
                mine.len()
            ));
            continue;
        }
        let r = c.radius_m + section.standoff_m;
        for p in &mine {
            let d = sub(*p, c.centre);
            if (d[0].hypot(d[1]) - r).abs() > 1e-6 || d[2].abs() > 1e-6 {
                broken.push(format!(
                    "inspection point {p:?} of cage {} is not on its monitoring circle (radius {r} m on the centre's plane)",
                    c.id
                ));
            }
        }
        let mid = [
            0.5 * (mine[0][0] + mine[1][0]),
            0.5 * (mine[0][1] + mine[1][1]),
            0.5 * (mine[0][2] + mine[1][2]),
        ];
        if norm(sub(mid, c.centre)) > 1e-6 {
            broken.push(format!(
                "the two inspection points of cage {} are not mirrored through its centre",
                c.id
            ));
        }
    }
    broken
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn circumradius_by_hand() {
        let r = circumradius([0., 0., 0.], [10., 0., 0.], [10., 10., 0.]);
        assert!((r - 5.0 * 2f64.sqrt()).abs() < 1e-12);
        assert!(circumradius([0., 0., 0.], [1., 1., 1.], [2., 2., 2.]).is_infinite());
    }

    #[test]
    fn holds_are_not_path_points() {
        let p = points(&[[0., 0., 0., 0.], [1., 1., 0., 0.], [2., 1., 0., 0.]]);
        assert_eq!(p.len(), 2);
    }
}
