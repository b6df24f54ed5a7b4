//! Fitness of a fleet particle: Zhi & Zuo 2024, eq. (9)–(12) plus the constraint penalties that make the
//! constrained problem unconstrained (§3.3.1). Lower is better.
//!
//! `F = λ1 Σ F_i(L) + λ2 Σ F_i(D) + λ3 Σ F_i(O) + λ4 Σ F_i(T) + λ5 Σ F_i(S) + W · P` (eq. (12)),
//! every term dimensionless so the weights λ of §4.1.4 compare like with like:
//!
//! | term | definition | units before normalising | normalised by |
//! |---|---|---|---|
//! | F_i(L) | path length | m | straight-line distance start→goal |
//! | F_i(D) | length-weighted mean depth below the surface | m | water-column height |
//! | F_i(O) | length of path inside inflated soft spheres | m | straight-line distance |
//! | F_i(T) | eq. (10) with `t_i` the mission time and `[t_min, t_max]` from eq. (2) | s | mission time |
//! | F_i(S) | eq. (11) integrated over time: seconds closer than d_min to any other vehicle | s | 1 s ("one point per second") |
//!
//! The penalty `P` (weight `W = optimizer.penalty_weight`) counts what makes a plan infeasible:
//! hard-obstacle intrusions, an AUV's legs closer to the seabed than its clearance
//! ([`seabed_penalty`]), turns beyond the limit, pitch beyond the limit, a path too short to
//! arrive with the others even at the vehicle's slowest ([`early_arrival_penalty`]) and
//! separation breaches, each as `count + depth of the breach relative to its limit`, so the
//! swarm feels both how many and how bad.

use crate::crawler::{CrawlerModel, CrawlerTerms};
use crate::fleet_trajectories::FleetTrajectories;
use crate::geometry::{leg_lengths, polyline_length, Vec3};
use crate::scenario::{Scenario, Vehicle};
use crate::terrain::Terrain;
use crate::trajectory::{common_arrival, leg_times, retime_legs, Layout, Path};
use spheres::{sphere_terms, SphereIndex};

pub use coupling::{separation_penalty, space_term, PairTerms};
pub use motion::{entry_turn_penalty, pitch_penalty, turn_and_pitch_penalty, turn_penalty};
use motion::{turn_and_pitch_penalty_within, MotionLimits};
pub use spheres::Sphere;

/// F_i(L) of eq. (9): path length over straight-line distance (1 for a straight path).
pub fn length_term(length: f64, straight: f64) -> f64 {
    length / straight.max(1e-9)
}

/// F_i(D) of eq. (9): the length-weighted mean depth below `surface_z`, over the water-column
/// height `column`. Depth is linear along a leg, so each leg contributes `l (d_a + d_b) / 2`.
/// 0 for a path along the surface, 1 for one along the bottom of the box.
pub fn depth_term(points: &[Vec3], surface_z: f64, column: f64) -> f64 {
    depth_term_of_legs(points, leg_lengths(points), surface_z, column)
}

/// [`depth_term`] with the legs' lengths given (in order, as [`leg_lengths`] gives them): the
/// fitness has them already, so the term takes no square root of its own.
pub fn depth_term_of_legs(
    points: &[Vec3],
    legs: impl IntoIterator<Item = f64>,
    surface_z: f64,
    column: f64,
) -> f64 {
    let (mut weighted, mut total) = (0.0, 0.0);
    for (w, l) in points.windows(2).zip(legs) {
        weighted += l * 0.5 * ((surface_z - w[0].z) + (surface_z - w[1].z));
        total += l;
    }
    if total <= 0.0 {
        return points.first().map_or(0.0, |p| (surface_z - p.z) / column);
    }
    weighted / total / column
}

/// F_i(O) of eq. (9): metres of path inside inflated soft obstacles, over the straight-line
/// distance. A path crossing a soft sphere through its centre pays its diameter; a graze pays
/// almost nothing.
pub fn soft_threat_term(points: &[Vec3], soft: &[Sphere], straight: f64) -> f64 {
    sphere_terms(points, &[], soft).soft_inside / straight.max(1e-9)
}

/// F_i(T) of eq. (10), over the mission time: how far the mission time `t_e` lies outside the
/// window `[L / v_max, L / v_min]` the path allows (eq. (2)). 0 when the vehicle can arrive on time.
pub fn time_term(length: f64, vehicle: &Vehicle, mission_time: f64) -> f64 {
    let t_min = length / vehicle.speed_max_mps;
    let t_max = length / vehicle.speed_min_mps;
    let miss = if mission_time < t_min {
        t_min - mission_time
    } else if mission_time > t_max {
        mission_time - t_max
    } else {
        0.0
    };
    miss / mission_time
}

/// How far apart arrivals may be before the plan calls them unsynchronised, seconds.
pub const ARRIVAL_SPREAD_TOLERANCE_S: f64 = 1.0;

/// Penalty for a vehicle whose path is too short to arrive at the common arrival `target` even
/// at its minimum speed: it arrives at `L / v_min`, early, and the fleet's arrivals are not
/// synchronised (Zhi & Zuo 2024, §2.2.2's temporal coupling; eq. (10) only measures the window against
/// the mission time, not against the time the fleet is timed for). `1 + (target − L / v_min) /
/// target` when it would arrive early at all, else 0: penalising from zero, not from
/// [`ARRIVAL_SPREAD_TOLERANCE_S`], keeps the swarm's plans clear of the assessment's threshold
/// instead of on it. The cure is a longer path, which the swarm can find.
pub fn early_arrival_penalty(length: f64, vehicle: &Vehicle, target: f64) -> f64 {
    let early = target - length / vehicle.speed_min_mps;
    if early > 1e-6 {
        1.0 + early / target
    } else {
        0.0
    }
}

/// Hard-obstacle penalty: for every (leg, obstacle) whose leg enters the inflated sphere, `1 + how
/// deep it gets / inflated radius`. Returns the penalty and the number of such intrusions.
pub fn hard_penalty(points: &[Vec3], hard: &[Sphere]) -> (f64, usize) {
    let t = sphere_terms(points, hard, &[]);
    (t.hard_penalty, t.hard_hits)
}

/// Sample spacing of the seabed check along a swimmer's leg, metres (the cost's and the plan
/// check's: a plan the swarm found clear is checked at the same points). Hills of Shoal's
/// scenarios spread over 15 m or more; between samples 1 m apart such a hill's summit can rise
/// less than a centimetre above the nearer sample.
pub const SEABED_STEP_M: f64 = 1.0;

/// Seabed penalty of a swimmer (an AUV over a seabed; Zhi & Zuo 2024 has none, so Shoal adds it as a
/// hard constraint like the obstacles): for every leg whose lowest height above the seabed
/// ([`Terrain::lowest_height_along`], every [`SEABED_STEP_M`]) is under `clearance`,
/// `1 + shortfall / max(clearance, 1 m)`. Returns the penalty and the number of such legs.
pub fn seabed_penalty(points: &[Vec3], terrain: &Terrain, clearance: f64) -> (f64, usize) {
    let mut penalty = 0.0;
    let mut legs = 0;
    // Legs wholly above the highest seabed plus the clearance cannot be short of it.
    let safe = terrain.ceiling() + clearance;
    for w in points.windows(2) {
        if w[0].z.min(w[1].z) >= safe {
            continue;
        }
        let (height, _) = terrain.lowest_height_along(&w[0], &w[1], SEABED_STEP_M);
        if height < clearance {
            penalty += 1.0 + (clearance - height) / clearance.max(1.0);
            legs += 1;
        }
    }
    (penalty, legs)
}

/// Each term of one vehicle, unweighted.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct VehicleTerms {
    /// F_i(L).
    pub length: f64,
    /// F_i(D).
    pub depth: f64,
    /// F_i(O).
    pub soft: f64,
    /// F_i(T).
    pub time: f64,
    /// F_i(S).
    pub space: f64,
    /// Hard-obstacle penalty (see [`hard_penalty`]), plus a swimmer's [`seabed_penalty`]
    /// (a crawler's: its hazard penalty).
    pub hard: f64,
    /// Turn, pitch (a crawler's slope) and early-arrival penalties: what the vehicle's
    /// kinematic limits forbid.
    pub motion: f64,
    /// This vehicle's half of the separation penalty of every pair it belongs to.
    pub separation: f64,
    /// Hard-obstacle intrusions (leg × obstacle).
    pub hard_hits: usize,
    /// A crawler's Lu et al. 2023, eq. (10) objective (standardised, without penalties), which takes
    /// the place of F(L) + F(D) + F(O); `None` for swimmers.
    pub crawler: Option<f64>,
}

/// Everything the fitness computed for one fleet particle.
#[derive(Debug, Clone, Default)]
pub struct FleetEvaluation {
    /// Timed trajectories (what the vehicles fly), in vehicle order, in one buffer per kind.
    pub trajectories: FleetTrajectories,
    /// The arrival time every vehicle was timed for, seconds.
    pub common_arrival: f64,
    /// Unweighted terms per vehicle.
    pub vehicles: Vec<VehicleTerms>,
    /// Sum of the separation penalties over all pairs.
    pub separation_penalty: f64,
    /// eq. (12): the weighted sum of the five objective terms.
    pub objective: f64,
    /// Penalty sum P (unweighted).
    pub penalty: f64,
    /// objective + W · P.
    pub total: f64,
    /// The exact terms of every pair the broad phase kept, in row order (the others are at
    /// least d_min apart throughout): what [`FleetModel::evaluate_change`] starts from.
    pub pairs: Vec<PairTerms>,
}

/// The fleet planning problem of one scenario, precomputed for fast evaluation.
#[derive(Debug, Clone)]
pub struct FleetModel {
    /// The scenario this model was built from.
    pub scenario: Scenario,
    /// Gene layout of a fleet particle.
    pub layout: Layout,
    /// Lower gene bounds.
    pub lower: Vec<f64>,
    /// Upper gene bounds.
    pub upper: Vec<f64>,
    /// Inflated hard spheres.
    pub hard: Vec<Sphere>,
    /// Inflated soft spheres.
    pub soft: Vec<Sphere>,
    /// `hard` and `soft` indexed by where they are, so a path meets only the spheres near it.
    spheres: SphereIndex,
    /// Straight-line distance of every vehicle, metres.
    pub straight: Vec<f64>,
    /// Per vehicle: the crawler cost model and its straight path's terms (the standardisation
    /// scales), or `None` for a swimmer.
    pub crawlers: Vec<Option<(CrawlerModel, CrawlerTerms)>>,
    /// Every vehicle's turn and pitch limits, with their cosine and tangent.
    motion_limits: Vec<MotionLimits>,
}

impl FleetModel {
    /// Builds the model of a (validated) scenario.
    pub fn new(scenario: &Scenario) -> FleetModel {
        let layout = Layout::of(scenario);
        let (lower, upper) = layout.gene_bounds(scenario);
        let sphere = |o: &crate::scenario::Obstacle| Sphere {
            centre: o.centre(),
            radius: o.inflated_radius(),
        };
        let hard: Vec<Sphere> = scenario.hard_obstacles().map(sphere).collect();
        let soft: Vec<Sphere> = scenario.soft_obstacles().map(sphere).collect();
        FleetModel {
            layout,
            lower,
            upper,
            spheres: SphereIndex::new(&hard, &soft),
            hard,
            soft,
            straight: scenario
                .vehicles
                .iter()
                .map(|v| (v.goal() - v.start()).norm())
                .collect(),
            crawlers: (0..scenario.vehicles.len())
                .map(|i| {
                    scenario.crawler_model(i).map(|m| {
                        let r = m.reference();
                        (m, r)
                    })
                })
                .collect(),
            motion_limits: (scenario.vehicles.iter())
                .map(|v| {
                    MotionLimits::new(v.max_turn_deg.to_radians(), v.max_pitch_deg.to_radians())
                })
                .collect(),
            scenario: scenario.clone(),
        }
    }

    /// Vehicle `i`'s path from its chromosome: the waypoint polygon for a swimmer; for a
    /// crawler the clamped cubic B-spline through its horizontal waypoints, sampled and draped
    /// on the seabed (Lu et al. 2023, eq. (12)–(13)), each sample leg taking the speed gene of the
    /// control leg it belongs to.
    pub fn decode(&self, i: usize, genes: &[f64]) -> Path {
        let mut path = Path {
            points: Vec::new(),
            speeds: Vec::new(),
        };
        self.decode_into(i, genes, &mut path.points, &mut path.speeds);
        path
    }

    /// [`FleetModel::decode`] appending the points to `points` and the legs' speeds to
    /// `speeds`, buffers the caller reuses. A swimmer's decoding allocates nothing; a crawler's
    /// drapes a fresh spline on the seabed.
    fn decode_into(&self, i: usize, genes: &[f64], points: &mut Vec<Vec3>, speeds: &mut Vec<f64>) {
        let v = &self.scenario.vehicles[i];
        let Some((crawler, _)) = &self.crawlers[i] else {
            return Path::decode_into(v, genes, points, speeds);
        };
        let m = genes.len() / crate::trajectory::GENES_PER_WAYPOINT;
        let (coords, status) = genes.split_at(3 * m);
        let draped = crawler.path_through(coords.chunks_exact(3).map(|g| [g[0], g[1]]));
        let legs = draped.len().saturating_sub(1);
        speeds.extend((0..legs).map(|k| {
            let control_leg = k * (m + 1) / legs.max(1);
            status
                .get(control_leg.min(m.saturating_sub(1)))
                .copied()
                .unwrap_or(v.speed_max_mps)
        }));
        points.extend(draped);
    }

    /// Vehicle-local terms of vehicle `i` (everything but F(S) and the separation penalty), its
    /// path through `points` with its legs' lengths `legs` (in order, as [`leg_lengths`]) and
    /// their sum `length`: every caller has both already.
    pub fn vehicle_terms(
        &self,
        i: usize,
        points: &[Vec3],
        legs: &[f64],
        length: f64,
    ) -> VehicleTerms {
        let s = &self.scenario;
        let v = &s.vehicles[i];
        if let Some((crawler, reference)) = &self.crawlers[i] {
            let t = crawler.terms(points);
            return VehicleTerms {
                length: length_term(length, self.straight[i]),
                time: time_term(length, v, s.fleet.mission_time_s),
                hard: t.hazard_penalty,
                motion: turn_penalty(points, v.max_turn_deg.to_radians()) + t.slope_penalty,
                hard_hits: t.hazard_intrusions,
                crawler: Some(crawler.objective_of(&t, reference)),
                ..VehicleTerms::default()
            };
        }
        let surface = s.bounds.max[2];
        let column = s.bounds.max[2] - s.bounds.min[2];
        let spheres = self.spheres.terms(points, &self.hard, &self.soft);
        let seabed = s
            .swimmer_seabed()
            .map_or(0.0, |(t, c)| seabed_penalty(points, t, c).0);
        VehicleTerms {
            length: length_term(length, self.straight[i]),
            depth: depth_term_of_legs(points, legs.iter().copied(), surface, column),
            soft: spheres.soft_inside / self.straight[i].max(1e-9),
            time: time_term(length, v, s.fleet.mission_time_s),
            space: 0.0,
            separation: 0.0,
            hard: spheres.hard_penalty + seabed,
            motion: turn_and_pitch_penalty_within(points, &self.motion_limits[i]),
            hard_hits: spheres.hard_hits,
            crawler: None,
        }
    }

    /// Vehicle `t`'s weighted share of eq. (12). For a crawler, Lu et al.'s eq. (10) objective
    /// stands in for the three path terms and takes their weights: `(λ1 + λ2 + λ3) F_c`.
    pub fn objective_of(&self, t: &VehicleTerms) -> f64 {
        let w = &self.scenario.optimizer.weights;
        let path = match t.crawler {
            Some(c) => (w[0] + w[1] + w[2]) * c,
            None => w[0] * t.length + w[1] * t.depth + w[2] * t.soft,
        };
        path + w[3] * t.time + w[4] * t.space
    }

    /// Vehicle `t`'s share of the total fitness: its eq. (12) terms plus its weighted penalties
    /// (with half of each pair's separation penalty). The shares sum to the total.
    pub fn share_of(&self, t: &VehicleTerms) -> f64 {
        self.objective_of(t)
            + self.scenario.optimizer.penalty_weight * (t.hard + t.motion + t.separation)
    }

    /// Decodes and scores a fleet particle.
    pub fn evaluate(&self, x: &[f64]) -> FleetEvaluation {
        let mut out = FleetEvaluation::default();
        self.evaluate_into(x, &mut out);
        out
    }

    /// [`FleetModel::evaluate`] into `out`, reusing its buffers (and this thread's): once they
    /// have grown, scoring a fleet of swimmers allocates nothing, which is how the swarm calls
    /// it hundreds of thousands of times.
    pub fn evaluate_into(&self, x: &[f64], out: &mut FleetEvaluation) {
        SCRATCH.with(|cell| match cell.try_borrow_mut() {
            Ok(mut scratch) => self.evaluate_with(x, out, &mut scratch),
            Err(_) => self.evaluate_with(x, out, &mut Scratch::default()),
        })
    }

    fn evaluate_with(&self, x: &[f64], out: &mut FleetEvaluation, scratch: &mut Scratch) {
        let s = &self.scenario;
        out.trajectories.clear();
        // Every vehicle's leg lengths and speeds in one buffer each, vehicle i's at `spans[i]`.
        let Scratch {
            legs,
            speeds,
            spans,
            lengths,
        } = scratch;
        legs.clear();
        speeds.clear();
        spans.clear();
        lengths.clear();
        // Each vehicle is taken through as much as it can be while its path is in the
        // first-level cache: decoded, measured and scored here, then timed and boxed below.
        out.vehicles.clear();
        for i in 0..s.vehicles.len() {
            let genes = &x[self.layout.chromosome(i)];
            out.trajectories
                .push_path(|points| self.decode_into(i, genes, points, speeds));
            let points = out.trajectories.points(i);
            let start = legs.len();
            legs.extend(leg_lengths(points));
            spans.push(start..legs.len());
            let length = legs[start..].iter().sum();
            lengths.push(length);
            // Its own terms do not depend on the timing.
            out.vehicles
                .push(self.vehicle_terms(i, points, &legs[start..], length));
        }
        let arrival = common_arrival(
            s.fleet.mission_time_s,
            lengths
                .iter()
                .zip(&s.vehicles)
                .map(|(l, v)| l / v.speed_max_mps),
        );
        let vehicles = &mut out.vehicles;
        coupling::pair_terms_into(
            &mut out.trajectories,
            s.fleet.d_min_m,
            arrival * (1.0 + SLABS_PAST_ARRIVAL),
            &mut out.pairs,
            |i, times| {
                let v = &s.vehicles[i];
                vehicles[i].motion += early_arrival_penalty(lengths[i], v, arrival);
                let span = spans[i].clone();
                leg_times(&legs[span.clone()], &mut speeds[span], v, arrival, times);
            },
        );
        out.common_arrival = arrival;
        self.sum_into(out);
    }

    /// [`FleetModel::evaluate`] of `x`, which differs from the position `base` scored only in
    /// vehicle `i`'s chromosome: only vehicle `i` is decoded and scored and only its pairs are
    /// measured, unless its new length moves the common arrival (every vehicle is then
    /// retimed, and the whole fleet scored). The same result to the last bit.
    pub fn evaluate_change(&self, base: &FleetEvaluation, x: &[f64], i: usize) -> FleetEvaluation {
        if base.trajectories.len() <= i {
            return self.evaluate(x);
        }
        let s = &self.scenario;
        let path = self.decode(i, &x[self.layout.chromosome(i)]);
        let legs = path.leg_lengths();
        let length: f64 = legs.iter().sum();
        let arrival = common_arrival(
            s.fleet.mission_time_s,
            (base.trajectories.iter().enumerate()).map(|(k, (_, points))| {
                let l = if k == i {
                    length
                } else {
                    polyline_length(points)
                };
                l / s.vehicles[k].speed_max_mps
            }),
        );
        if arrival.to_bits() != base.common_arrival.to_bits() {
            return self.evaluate(x);
        }
        let mut vehicles = base.vehicles.clone();
        vehicles[i] = self.vehicle_terms(i, &path.points, &legs, length);
        vehicles[i].motion += early_arrival_penalty(length, &s.vehicles[i], arrival);
        let moved = retime_legs(path, &legs, &s.vehicles[i], arrival);
        let mut out = FleetEvaluation {
            trajectories: base.trajectories.with_replaced(i, &moved),
            common_arrival: arrival,
            vehicles,
            ..FleetEvaluation::default()
        };
        let d_min = s.fleet.d_min_m;
        coupling::pair_terms_changed(&out.trajectories, d_min, i, &base.pairs, &mut out.pairs);
        self.sum_into(&mut out);
        out
    }

    /// Completes an evaluation whose trajectories, arrival, vehicle-local terms and pair terms
    /// are in place: the pair terms added to the vehicles', then the sums.
    fn sum_into(&self, out: &mut FleetEvaluation) {
        for t in out.vehicles.iter_mut() {
            t.space = 0.0;
            t.separation = 0.0;
        }
        let sep_penalty = add_pair_terms(&out.pairs, &mut out.vehicles);
        let objective: f64 = out.vehicles.iter().map(|t| self.objective_of(t)).sum();
        let penalty: f64 =
            out.vehicles.iter().map(|t| t.hard + t.motion).sum::<f64>() + sep_penalty;
        out.separation_penalty = sep_penalty;
        out.objective = objective;
        out.penalty = penalty;
        out.total = objective + self.scenario.optimizer.penalty_weight * penalty;
    }
}

/// How far past the common arrival the fitness's time slabs end, relative to it: the timing
/// lands every vehicle's last sample on the arrival to within about 1e-12 of it (the tolerance
/// of [`leg_times`]), and a vehicle still moving when the slabs end would lose its last slab's
/// chord test ([`crate::broad_phase`]), so they end a little later. Where they end changes no
/// term, only how many pairs the broad phase keeps.
const SLABS_PAST_ARRIVAL: f64 = 1e-9;

/// The buffers of [`FleetModel::evaluate_into`] besides the evaluation's own.
#[derive(Debug, Default)]
struct Scratch {
    /// Every vehicle's leg lengths, vehicle after vehicle.
    legs: Vec<f64>,
    /// Every vehicle's leg speeds (then paces), in the same places.
    speeds: Vec<f64>,
    /// Where vehicle `i`'s legs are.
    spans: Vec<std::ops::Range<usize>>,
    /// Every vehicle's path length, metres.
    lengths: Vec<f64>,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Scratch::default());
}

/// Adds every pair's F(S) (to both vehicles) and half its separation penalty (to each) into
/// `vehicles`, and returns the sum of the pairs' penalties. `pairs` in row order, as an
/// all-pairs loop would visit them, so the sums are the same to the last bit.
fn add_pair_terms(pairs: &[PairTerms], vehicles: &mut [VehicleTerms]) -> f64 {
    let mut total = 0.0;
    for p in pairs {
        let (i, j) = (p.i as usize, p.j as usize);
        // eq. (12) sums F_i(S) over vehicles: a breach counts for both of the pair.
        vehicles[i].space += space_term(p.breach_s);
        vehicles[j].space += space_term(p.breach_s);
        vehicles[i].separation += 0.5 * p.penalty;
        vehicles[j].separation += 0.5 * p.penalty;
        total += p.penalty;
    }
    total
}

mod coupling;
mod motion;
mod spheres;
#[cfg(test)]
mod tests;
