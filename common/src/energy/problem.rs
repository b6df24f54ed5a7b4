//! One AUV's energy-saving path as a swarm [`Problem`] (Zhang et al. 2022, §3).
//!
//! A particle holds the x, y, z of `control_points` free control points; with the start and the
//! goal they define a clamped cubic B-spline (the smoothing of Lu et al. 2023, eq. (12)–(13)) sampled
//! into the n_p path points the costs are measured on. A spline, not a polygon, because the
//! turning-radius limit of eq. (5) needs a path whose curvature is defined at every point.
//!
//! Two objectives, as in the paper's comparison (§4): `Length` (the PSO baseline, q_path only)
//! and `Full` (eq. (6) with the self-adjusting weights; M-PSO and EPA-PSO). Both keep the path
//! above the seabed and outside hard obstacles. `Full` also treats eq. (6)'s "s.t." rows — turning
//! radius ≥ R_AUV and θ_min ≤ θ ≤ θ_max — as hard: a path breaking one pays
//! `penalty_weight · (1 + relative depth of the worst breach)` on top of q_r and q_a, so no
//! breaking path can beat one that keeps every limit.

use rand::rngs::StdRng;
use rand::Rng;

use super::{EnergyModel, EnergyTerms};
use crate::bspline;
use crate::cost::{hard_penalty, Sphere};
use crate::current::StillWater;
use crate::geometry::Vec3;
use crate::scenario::{Scenario, VehicleKind};
use crate::swarm::Problem;

/// What the swarm minimises.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Objective {
    /// q_path alone (the paper's PSO baseline).
    Length,
    /// Eq. (6) with every term and the mobility limits.
    Full,
}

/// One evaluation, with every figure.
#[derive(Debug, Clone)]
pub struct Evaluation {
    /// The sampled path.
    pub path: Vec<Vec3>,
    /// Zhang et al. 2022 figures.
    pub terms: EnergyTerms,
    /// Eq. (6), normalised (see [`EnergyProblem::scales`]).
    pub weighted: f64,
    /// Unweighted constraint penalty (0: every limit kept).
    pub penalty: f64,
    /// What the swarm sees.
    pub cost: f64,
}

/// The energy-saving path problem of one vehicle.
#[derive(Debug, Clone)]
pub struct EnergyProblem {
    /// Costs and the water.
    pub model: EnergyModel,
    /// Start point.
    pub start: Vec3,
    /// Goal point.
    pub goal: Vec3,
    /// Inflated hard spheres of the scenario.
    pub hard: Vec<Sphere>,
    /// Objective.
    pub objective: Objective,
    /// Divisors of (length, energy, radius, angle) in eq. (6): the straight line's length, the
    /// straight line's energy, R_AUV² and θ_max².
    pub scales: [f64; 4],
    /// Weight of the constraint penalty.
    pub penalty_weight: f64,
    /// Basis of every sample point against every control point (start, free points, goal): the
    /// spline is a fixed linear map of the control points, so it is computed once.
    basis: Vec<Vec<f64>>,
    lower: Vec<f64>,
    upper: Vec<f64>,
}

/// Why a scenario's vehicle cannot be planned by the energy-saving planner.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NotPlannable {
    /// The vehicle index is past the scenario's vehicles.
    #[error("the scenario has no vehicle {0}")]
    NoVehicle(usize),
    /// The planner's model (Zhang et al. 2022) is an AUV's: a crawler has no pitch or currents.
    #[error("{id} is a {kind:?}: the energy-saving planner (Zhang et al. 2022) plans AUVs")]
    NotAnAuv {
        /// The vehicle's id.
        id: String,
        /// What it is.
        kind: VehicleKind,
    },
}

impl EnergyProblem {
    /// The problem of vehicle `i` of `scenario`. Errors say why the scenario cannot be planned
    /// this way.
    pub fn new(scenario: &Scenario, i: usize, objective: Objective) -> Result<Self, NotPlannable> {
        let v = scenario.vehicles.get(i).ok_or(NotPlannable::NoVehicle(i))?;
        if v.kind != VehicleKind::Auv {
            return Err(NotPlannable::NotAnAuv {
                id: v.id.clone(),
                kind: v.kind,
            });
        }
        let e = &scenario.energy;
        let b = &scenario.bounds;
        let current = match &scenario.currents {
            Some(c) => c.field(b.min[2], b.max[2]),
            None => std::sync::Arc::new(StillWater),
        };
        let model = EnergyModel {
            terrain: scenario.terrain().cloned(),
            terrain_clearance_m: e.terrain_clearance_m,
            current,
            ground_speed_mps: e.ground_speed_mps.unwrap_or(v.speed_max_mps),
            min_turn_radius_m: e.min_turn_radius_m,
            pitch_range_deg: (-v.max_pitch_deg, v.max_pitch_deg),
            weights: e.weights(),
        };
        let n = e.control_points;
        let knots_points = n + 2;
        let knots = bspline::clamped_knots(knots_points, 3);
        let k = 3.min(knots_points - 1);
        let samples = e.path_points.max(2);
        let basis = (0..samples)
            .map(|s| {
                let u = s as f64 / (samples - 1) as f64;
                (0..knots_points)
                    .map(|c| bspline::basis(c, k, u, &knots))
                    .collect()
            })
            .collect();
        let lower = (0..3 * n).map(|d| b.min[d % 3]).collect();
        let upper = (0..3 * n).map(|d| b.max[d % 3]).collect();
        let (start, goal) = (v.start(), v.goal());
        let mut p = EnergyProblem {
            model,
            start,
            goal,
            hard: scenario
                .hard_obstacles()
                .map(|o| Sphere {
                    centre: o.centre(),
                    radius: o.inflated_radius(),
                })
                .collect(),
            objective,
            scales: [1.0; 4],
            penalty_weight: scenario.optimizer.penalty_weight,
            basis,
            lower,
            upper,
        };
        let straight: Vec<Vec3> = (0..samples)
            .map(|s| start + (goal - start) * (s as f64 / (samples - 1) as f64))
            .collect();
        let (t, _) = p.model.terms(&straight);
        p.scales = [
            t.q_path.max(1e-9),
            t.q_e.max(1e-9),
            e.min_turn_radius_m.powi(2),
            v.max_pitch_deg.max(1e-9).powi(2),
        ];
        Ok(p)
    }

    /// The sampled B-spline of a particle.
    pub fn path(&self, x: &[f64]) -> Vec<Vec3> {
        let control: Vec<Vec3> = std::iter::once(self.start)
            .chain(x.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])))
            .chain(std::iter::once(self.goal))
            .collect();
        self.basis
            .iter()
            .map(|row| {
                row.iter()
                    .zip(&control)
                    .filter(|(w, _)| **w != 0.0)
                    .fold(Vec3::zeros(), |acc, (w, c)| acc + c * *w)
            })
            .collect()
    }

    /// The penalty of a path's broken limits; mobility limits count only for `Full`.
    fn penalty(&self, t: &EnergyTerms, path: &[Vec3]) -> f64 {
        let m = &self.model;
        let mut p = 0.0;
        if t.terrain_violations > 0 {
            p += 1.0 + (-t.terrain_margin_m) / m.terrain_clearance_m.max(1.0);
        }
        p += hard_penalty(path, &self.hard).0;
        if self.objective == Objective::Full {
            if t.min_turn_radius_m < m.min_turn_radius_m {
                p += 1.0 + (m.min_turn_radius_m - t.min_turn_radius_m) / m.min_turn_radius_m;
            }
            let (lo, hi) = m.pitch_range_deg;
            let excess = (t.max_pitch_deg - hi).max(lo - t.min_pitch_deg);
            if excess > 0.0 {
                p += 1.0 + excess / hi.abs().max(lo.abs()).max(1e-9);
            }
        }
        p
    }

    /// Every figure of a particle.
    pub fn evaluate(&self, x: &[f64]) -> Evaluation {
        let path = self.path(x);
        let (terms, pieces) = self.model.terms(&path);
        let weighted = self.model.weighted(&pieces, self.scales);
        let penalty = self.penalty(&terms, &path);
        let objective = match self.objective {
            Objective::Length => terms.q_path / self.scales[0],
            Objective::Full => weighted,
        };
        Evaluation {
            cost: objective + self.penalty_weight * penalty,
            path,
            terms,
            weighted,
            penalty,
        }
    }

    /// True when a path keeps every limit of eq. (5), the seabed clearance and the hard
    /// obstacles, whatever the objective.
    pub fn keeps_every_limit(&self, t: &EnergyTerms, path: &[Vec3]) -> bool {
        let m = &self.model;
        let (lo, hi) = m.pitch_range_deg;
        t.terrain_violations == 0
            && hard_penalty(path, &self.hard).1 == 0
            && t.min_turn_radius_m >= m.min_turn_radius_m
            && t.max_pitch_deg <= hi
            && t.min_pitch_deg >= lo
    }
}

impl Problem for EnergyProblem {
    fn lower(&self) -> &[f64] {
        &self.lower
    }
    fn upper(&self) -> &[f64] {
        &self.upper
    }
    fn cost(&self, x: &[f64]) -> f64 {
        self.evaluate(x).cost
    }
    fn move_groups(&self) -> Vec<std::ops::Range<usize>> {
        (0..self.lower.len() / 3)
            .map(|c| 3 * c..3 * c + 3)
            .collect()
    }
    fn feasible(&self, x: &[f64]) -> bool {
        let e = self.evaluate(x);
        self.keeps_every_limit(&e.terms, &e.path)
    }
    /// Half the swarm uniform in the box (the paper's random start); the other half winding
    /// control polygons: the straight line plus a circle of random radius (1.2–4 R_AUV), phase,
    /// sense and number of turns (0–3), because a climb steeper than the pitch limit (the paper's
    /// start and goal are 72 m apart in depth and 57 m horizontally) can only be flown by
    /// circling, and uniform control points almost never circle.
    fn sample(&self, rng: &mut StdRng) -> Vec<f64> {
        if rng.random_bool(0.5) {
            return self
                .lower
                .iter()
                .zip(&self.upper)
                .map(|(lo, hi)| rng.random_range(*lo..=*hi))
                .collect();
        }
        let n = self.lower.len() / 3;
        let r = self.model.min_turn_radius_m * rng.random_range(1.2..4.0);
        let turns = rng.random_range(0.0..3.0);
        let sense = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
        let phase = rng.random_range(0.0..std::f64::consts::TAU);
        let mut x = Vec::with_capacity(3 * n);
        for c in 1..=n {
            let t = c as f64 / (n + 1) as f64;
            let a = phase + sense * std::f64::consts::TAU * turns * t;
            let p = self.start
                + (self.goal - self.start) * t
                + Vec3::new(
                    r * (a.cos() - phase.cos()),
                    r * (a.sin() - phase.sin()),
                    0.0,
                );
            for d in 0..3 {
                x.push(p[d].clamp(self.lower[3 * (c - 1) + d], self.upper[3 * (c - 1) + d]));
            }
        }
        x
    }
}
