//! Local refinement of a fleet plan after the swarm (a memetic step): the swarm finds which side
//! of each obstacle every path goes and who passes first; a gradient-based constrained search
//! then pulls each path tight inside its vehicle's limits and the fleet's separation.
//!
//! Not part of Zhi & Zuo 2024's algorithm, whose swarm ends where it ends: the swarm leaves paths
//! a few per cent longer than the limits allow (a particle swarm converges slowly in the last
//! metres of a 600-gene problem), and on scenario 3 the fleet arrived late because of it.
//!
//! The search is sequential quadratic programming with an ℓ1 penalty and a trust region
//! (Fletcher's Sℓ1QP, Nocedal & Wright 2006, §18.5), one vehicle at a time against the others'
//! timed trajectories (block coordinate descent, as the distributed planner's vehicle agents
//! search):
//! - the objective is the vehicle's smooth part of eq. (12): F(L), F(D), F(O) and F(T) (its
//!   gradient by central differences; its model Hessian the path length's, exact);
//! - the limits are rows with analytic gradients ([`constraints`]): pitch and turn at every leg
//!   and waypoint, clearance of every hard sphere, separation from every other vehicle sampled
//!   along the timed trajectories, and a length that arrives by the target arrival at top speed;
//! - each step is one convex program for Clarabel ([`qp`]);
//! - a step is kept only when the *true* fleet fitness (eq. (12) plus every penalty, as the swarm
//!   scores it) plus a penalty on arriving after the target gets lower, so the refinement never
//!   returns a plan that is worse by that measure, whatever its model leaves out (a swimmer's
//!   seabed clearance, the retiming a shorter path causes). A plan that arrives on time never
//!   leaves with a higher fitness; a late one may trade a little fitness for punctuality.
//!
//! The target arrival is the mission time when every vehicle's pitch limit lets it arrive by
//! then ([`target_arrival`]), so a fleet the swarm left late is pulled back on time where the
//! paths allow it. Crawlers (their path is a B-spline draped on the seabed) are left as they are.

pub mod constraints;
pub mod qp;
pub mod reroute;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use crate::bspline::polyline_length;
use crate::cost::{depth_term, soft_threat_term, time_term, FleetEvaluation, FleetModel};
use crate::geometry::Vec3;
use crate::scenario::Scenario;
use crate::trajectory::shortest_pitch_feasible_length;
use constraints::{Limits, Row};
use qp::Program;

/// How the refinement searches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefineSettings {
    /// Passes over the vehicles (a pass that keeps nothing ends it).
    pub rounds: usize,
    /// Programs solved per vehicle and pass.
    pub steps: usize,
    /// First trust radius, metres per coordinate.
    pub radius_m: f64,
    /// Trust radius below which a vehicle's search ends, metres.
    pub min_radius_m: f64,
    /// Degrees kept inside the pitch and turn limits (the fitness's tests are sharp: a plan on
    /// the limit is one rounding away from a penalty).
    pub angle_margin_deg: f64,
    /// Metres kept outside every hard sphere and added to d_min.
    pub distance_margin_m: f64,
    /// Separation samples along the timed trajectories, seconds apart.
    pub sample_step_s: f64,
}

impl Default for RefineSettings {
    /// Three passes of up to 40 programs per vehicle; a first trust radius of 20 m; margins of
    /// 0.05° and 0.5 m; separation sampled every 2 s (at 3 m/s closing speed a pair moves 6 m
    /// between samples and the closest approach between them is at most 0.1 m under the
    /// nearer sample's at d_min = 50 m).
    fn default() -> Self {
        RefineSettings {
            rounds: 3,
            steps: 40,
            radius_m: 20.0,
            min_radius_m: 0.01,
            angle_margin_deg: 0.05,
            distance_margin_m: 0.5,
            sample_step_s: 2.0,
        }
    }
}

/// What a refinement did.
#[derive(Debug, Clone, PartialEq)]
pub struct Refinement {
    /// The fleet position after it (the input when no step was kept).
    pub x: Vec<f64>,
    /// Fleet fitness before and after.
    pub total: (f64, f64),
    /// Summed path length of the fleet before and after, metres.
    pub length_m: (f64, f64),
    /// Common arrival before and after, seconds.
    pub arrival_s: (f64, f64),
    /// The arrival the search aimed for ([`target_arrival`]), seconds.
    pub target_arrival_s: f64,
    /// Steps kept.
    pub steps: usize,
    /// Fleet evaluations spent (one per program).
    pub evaluations: u64,
    /// The stop flag ended it early.
    pub interrupted: bool,
}

/// The arrival the fleet can make: the mission time, or the latest arrival a vehicle's pitch
/// limit forces at its top speed when that is later (the bound `plan`'s late-arrival notice
/// names).
pub fn target_arrival(scenario: &Scenario) -> f64 {
    scenario
        .vehicles
        .iter()
        .map(|v| shortest_pitch_feasible_length(v) / v.speed_max_mps)
        .fold(scenario.fleet.mission_time_s, f64::max)
}

/// What a refinement step must lower, and what picks the best finished plan: the fleet
/// fitness, plus the penalty weight times the arrival's delay past `target` over `target`.
/// Eq. (10)'s F(T) weighs a late arrival lightly (λ4 = 0.1 over the mission time: 0.004 for
/// 100 s at 2700 s), less than the depth a shorter path may give up; arriving when the fleet was
/// told to is a constraint of the mission (Zhi & Zuo 2024, §2.2.2's temporal coupling), so
/// lateness the limits do not force is paid like a breach.
pub fn merit(scenario: &Scenario, e: &FleetEvaluation, target: f64) -> f64 {
    let late = (e.common_arrival - target).max(0.0) / target;
    e.total + scenario.optimizer.penalty_weight * late
}

/// Refines fleet position `x`. A raised `stop` ends it at its next program with what it kept.
pub fn refine(
    model: &FleetModel,
    x: &[f64],
    settings: &RefineSettings,
    stop: Option<&Arc<AtomicBool>>,
) -> Refinement {
    let mut search = Search {
        model,
        settings,
        stop,
        target: target_arrival(&model.scenario),
        x: x.to_vec(),
        eval: model.evaluate(x),
        evaluations: 1,
        steps: 0,
        interrupted: false,
    };
    let before = (
        search.eval.total,
        fleet_length(&search.eval),
        search.eval.common_arrival,
    );
    let swimmers: Vec<usize> = (0..model.layout.vehicles)
        .filter(|i| model.crawlers[*i].is_none())
        .collect();
    for _ in 0..settings.rounds {
        let kept = search.steps;
        // The latest vehicles first: they hold the fleet's arrival.
        let mut order = swimmers.clone();
        let lateness = |i: usize| {
            polyline_length(&search.eval.trajectories[i].points)
                / model.scenario.vehicles[i].speed_max_mps
        };
        order.sort_by(|a, b| lateness(*b).total_cmp(&lateness(*a)));
        for i in order {
            search.vehicle(i);
            if search.interrupted {
                break;
            }
        }
        if search.interrupted || search.steps == kept {
            break;
        }
    }
    if !search.interrupted {
        for i in swimmers {
            search.reroute_if_late(i);
        }
    }
    Refinement {
        total: (before.0, search.eval.total),
        length_m: (before.1, fleet_length(&search.eval)),
        arrival_s: (before.2, search.eval.common_arrival),
        target_arrival_s: search.target,
        steps: search.steps,
        evaluations: search.evaluations,
        interrupted: search.interrupted,
        x: search.x,
    }
}

/// Summed path length of a fleet's trajectories, metres.
fn fleet_length(eval: &FleetEvaluation) -> f64 {
    eval.trajectories
        .iter()
        .map(|t| polyline_length(&t.points))
        .sum()
}

/// The state of one refinement.
struct Search<'a> {
    model: &'a FleetModel,
    settings: &'a RefineSettings,
    stop: Option<&'a Arc<AtomicBool>>,
    target: f64,
    x: Vec<f64>,
    eval: FleetEvaluation,
    evaluations: u64,
    steps: usize,
    interrupted: bool,
}

impl Search<'_> {
    /// Up to `steps` programs for vehicle `i`, the others held.
    fn vehicle(&mut self, i: usize) {
        let s = &self.model.scenario;
        let v = &s.vehicles[i];
        let margin = self.settings.angle_margin_deg;
        let limits = Limits {
            max_pitch: (v.max_pitch_deg - margin).to_radians(),
            max_turn: (v.max_turn_deg - margin).to_radians(),
            clearance_margin: self.settings.distance_margin_m,
            separation: s.fleet.d_min_m + self.settings.distance_margin_m,
            d_min: s.fleet.d_min_m,
        };
        let range = self.model.layout.chromosome(i);
        let n = 3 * self.model.layout.waypoints;
        let coords = range.start..range.start + n;
        let mut radius = self.settings.radius_m;
        let floors =
            constraints::spacing_floors(&self.model.decode(i, &self.x[range.clone()]).points);
        for _ in 0..self.settings.steps {
            if self.stop.is_some_and(|f| f.load(Ordering::Relaxed)) {
                self.interrupted = true;
                return;
            }
            let points = self.model.decode(i, &self.x[range.clone()]).points;
            let mut rows = self.rows(i, &points, &limits, radius);
            constraints::spacing_rows(&points, &floors, &mut rows);
            if self.eval.penalty <= 0.0 {
                // A plan that keeps every limit may sit inside a margin: it holds its ground
                // there instead of paying (in the model) for leaving it.
                for row in rows.iter_mut() {
                    row.value = row.value.min(0.0);
                }
            }
            let gradient = objective_gradient(self.model, i, &points);
            let hessian = model_hessian(self.model, i, &points);
            let (lo, hi): (Vec<f64>, Vec<f64>) = coords
                .clone()
                .map(|g| {
                    (
                        (self.model.lower[g] - self.x[g]).max(-radius),
                        (self.model.upper[g] - self.x[g]).min(radius),
                    )
                })
                .unzip();
            let program = Program {
                hessian: &hessian,
                gradient: &gradient,
                rows: &rows,
                lo: &lo,
                hi: &hi,
                rho: s.optimizer.penalty_weight,
            };
            let Some(step) = program.solve() else {
                return;
            };
            if step.predicted > -1e-12 * self.merit(&self.eval).abs().max(1.0) {
                return;
            }
            let longest = step.d.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
            match self.try_step(&coords, &step.d) {
                Some((scale, actual)) => {
                    self.steps += 1;
                    let ratio = actual / step.predicted;
                    if scale < 1.0 {
                        radius = scale * longest;
                    } else if ratio > 0.75 && longest > 0.9 * radius {
                        radius = (2.0 * radius).min(8.0 * self.settings.radius_m);
                    } else if ratio < 0.25 {
                        radius = 0.5 * longest;
                    }
                }
                None => radius = 0.125 * longest,
            }
            if radius < self.settings.min_radius_m {
                return;
            }
        }
    }

    /// When vehicle `i` alone still makes the fleet late, a fresh route for it
    /// ([`reroute::fresh_route`]) refined like the others, kept if it lowers the merit.
    fn reroute_if_late(&mut self, i: usize) {
        let v = &self.model.scenario.vehicles[i];
        let length = polyline_length(&self.eval.trajectories[i].points);
        if self.interrupted || length / v.speed_max_mps <= self.target * (1.0 + 1e-9) {
            return;
        }
        let executor = crate::swarm::Executor {
            stop: self.stop.cloned(),
            ..crate::swarm::Executor::default()
        };
        let (genes, spent) = reroute::fresh_route(self.model, &self.x, i, self.target, &executor);
        self.evaluations += spent;
        let kept = (self.x.clone(), self.eval.clone(), self.steps);
        self.x[self.model.layout.chromosome(i)].copy_from_slice(&genes);
        self.eval = self.model.evaluate(&self.x);
        self.evaluations += 1;
        self.steps += 1;
        for _ in 0..self.settings.rounds {
            self.vehicle(i);
        }
        if self.merit(&self.eval) >= self.merit(&kept.1) {
            (self.x, self.eval, self.steps) = kept;
        }
    }

    /// [`merit`] against this search's target.
    fn merit(&self, e: &FleetEvaluation) -> f64 {
        merit(&self.model.scenario, e, self.target)
    }

    /// Moves the genes `coords` by `d`, or by a half or a quarter of it when the whole step
    /// does not lower the fleet fitness (a step the linearised limits allowed may cross a
    /// curved limit: halving it quarters that second-order error). Returns the fraction kept
    /// and the change of fitness, or `None` when no fraction lowered it.
    fn try_step(&mut self, coords: &std::ops::Range<usize>, d: &[f64]) -> Option<(f64, f64)> {
        let mut scale = 1.0;
        for _ in 0..3 {
            let mut trial = self.x.clone();
            for (g, d) in coords.clone().zip(d) {
                trial[g] += scale * d;
            }
            let e = self.model.evaluate(&trial);
            self.evaluations += 1;
            let actual = self.merit(&e) - self.merit(&self.eval);
            if actual < 0.0 {
                self.x = trial;
                self.eval = e;
                return Some((scale, actual / scale));
            }
            scale *= 0.5;
        }
        None
    }

    /// The limits of vehicle `i` near its path `points`, the others as the fleet has them.
    fn rows(&self, i: usize, points: &[Vec3], limits: &Limits, radius: f64) -> Vec<Row> {
        let s = &self.model.scenario;
        let v = &s.vehicles[i];
        // Limits a step of `radius` per coordinate could reach, with room to spare.
        let reach = 4.0 * radius + s.fleet.d_min_m;
        let mut rows = Vec::new();
        constraints::pitch_rows(points, limits, &mut rows);
        constraints::turn_rows(points, limits, &mut rows);
        constraints::hard_rows(points, &self.model.hard, limits, reach, &mut rows);
        let mine = &self.eval.trajectories[i];
        for (j, other) in self.eval.trajectories.iter().enumerate() {
            if j != i {
                let step = self.settings.sample_step_s;
                constraints::separation_rows(mine, other, limits, step, reach, &mut rows);
            }
        }
        let latest = v.speed_max_mps * self.target;
        rows.extend(constraints::length_row(points, latest, 1.0));
        let earliest = v.speed_min_mps * self.eval.common_arrival;
        rows.extend(constraints::length_row(points, earliest, -1.0));
        rows
    }
}

/// Vehicle `i`'s smooth share of eq. (12): λ1 F(L) + λ2 F(D) + λ3 F(O) + λ4 F(T) (F(S) is
/// zero while the separation rows hold).
fn smooth_objective(model: &FleetModel, i: usize, points: &[Vec3]) -> f64 {
    let s = &model.scenario;
    let w = &s.optimizer.weights;
    let straight = model.straight[i].max(1e-9);
    let length = polyline_length(points);
    let column = s.bounds.max[2] - s.bounds.min[2];
    w[0] * length / straight
        + w[1] * depth_term(points, s.bounds.max[2], column)
        + w[2] * soft_threat_term(points, &model.soft, straight)
        + w[3] * time_term(length, &s.vehicles[i], s.fleet.mission_time_s)
}

/// Central differences of [`smooth_objective`] in the inner waypoints' coordinates (1 cm
/// steps: the terms bend over tens of metres).
fn objective_gradient(model: &FleetModel, i: usize, points: &[Vec3]) -> Vec<f64> {
    const H: f64 = 0.01;
    let inner = points.len().saturating_sub(2);
    let mut work = points.to_vec();
    let mut gradient = Vec::with_capacity(3 * inner);
    for k in 1..=inner {
        for c in 0..3 {
            let x = work[k][c];
            work[k][c] = x + H;
            let up = smooth_objective(model, i, &work);
            work[k][c] = x - H;
            let down = smooth_objective(model, i, &work);
            work[k][c] = x;
            gradient.push((up - down) / (2.0 * H));
        }
    }
    gradient
}

/// The model Hessian: the path length's, exact (each leg adds `(I − û ûᵀ) / |d|` to its ends),
/// weighted as F(L) (and F(T) while the vehicle is late) weigh the length, plus a small ridge
/// that keeps the program strictly convex.
fn model_hessian(model: &FleetModel, i: usize, points: &[Vec3]) -> Vec<f64> {
    let s = &model.scenario;
    let v = &s.vehicles[i];
    let w = &s.optimizer.weights;
    let inner = points.len().saturating_sub(2);
    let n = 3 * inner;
    let length = polyline_length(points);
    let mission = s.fleet.mission_time_s;
    let mut scale = w[0] / model.straight[i].max(1e-9);
    if length / v.speed_max_mps > mission {
        scale += w[3] / (v.speed_max_mps * mission);
    }
    let mut h = vec![0.0; n * n];
    let mut add = |a: usize, b: usize, block: &nalgebra::Matrix3<f64>, sign: f64| {
        if a == 0 || b == 0 || a > inner || b > inner {
            return;
        }
        for r in 0..3 {
            for c in 0..3 {
                h[(3 * (a - 1) + r) * n + 3 * (b - 1) + c] += sign * block[(r, c)];
            }
        }
    };
    for (k, p) in points.windows(2).enumerate() {
        let d = p[1] - p[0];
        let l = d.norm();
        if l <= 1e-9 {
            continue;
        }
        let u = d / l;
        let block = (nalgebra::Matrix3::identity() - u * u.transpose()) * (scale / l);
        add(k, k, &block, 1.0);
        add(k + 1, k + 1, &block, 1.0);
        add(k, k + 1, &block, -1.0);
        add(k + 1, k, &block, -1.0);
    }
    let ridge = scale * 1e-4;
    for j in 0..n {
        h[j * n + j] += ridge;
    }
    h
}

#[cfg(test)]
mod tests;
