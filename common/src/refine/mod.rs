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
//!   and waypoint, clearance of every hard sphere (and of every soft sphere a leg is outside:
//!   F(O)'s chord is not differentiable where a leg touches one), separation from every other
//!   vehicle sampled
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
//! paths allow it. A local search keeps the way round the obstacles the swarm chose, which can be
//! longer than needed: a vehicle left more than 1 % over the length its pitch limit allows is
//! offered fresh ways at that bound ([`pitch_routes`]), and one still late a fresh route of its
//! own ([`reroute`]); each is pulled tight and kept only if it lowers the merit. Then a last pass
//! with margins a tenth as wide (a late vehicle may be pressed against several limits at once).
//! Crawlers (their path is a B-spline draped on the seabed) are left as they are: a gradient
//! descent of the fleet's fitness over a crawler's genes ([`descent`], which refines energy
//! plans and inspection legs) lowered the seabed scenarios' fitness by less than 10⁻⁵ for
//! 5 000 fleet evaluations per crawler, the swarm's crawler paths being at a local optimum of
//! their cost already.

mod concurrent;
pub mod constraints;
pub mod descent;
mod objective;
pub mod pitch_routes;
pub mod qp;
pub mod reroute;
mod search;
mod settings;
pub mod vehicle;

use std::ops::Range;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use crate::cost::{FleetEvaluation, FleetModel};
use crate::geometry::polyline_length;
use crate::scenario::Scenario;
use crate::swarm::core::parallel;
use crate::trajectory::shortest_pitch_feasible_length;
use search::{Arena, Samples, Search};
pub use settings::RefineSettings;
pub use vehicle::refine_vehicle;

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
    /// The stop flag or the deadline ended it early.
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

/// Refines fleet position `x`. A raised `stop` (or the settings' deadline) ends it at its next
/// program with what it kept.
pub fn refine(
    model: &FleetModel,
    x: &[f64],
    settings: &RefineSettings,
    stop: Option<&Arc<AtomicBool>>,
) -> Refinement {
    let arena = FleetArena {
        model,
        target: target_arrival(&model.scenario),
    };
    // The last pass of a vehicle still late: margins a tenth as wide (the acceptance test is
    // the fitness's own sharp limits, so a narrower margin risks a refused step, not a breach).
    let fine = RefineSettings {
        angle_margin_deg: settings.angle_margin_deg / 10.0,
        distance_margin_m: settings.distance_margin_m / 10.0,
        ..*settings
    };
    let mut search = Search::new(&arena, x, arena.target, settings, stop);
    let before = (
        search.eval.total,
        fleet_length(&search.eval),
        search.eval.common_arrival,
    );
    let swimmers: Vec<usize> = (0..model.layout.vehicles)
        .filter(|i| model.crawlers[*i].is_none())
        .collect();
    // Vehicles whose trajectories are this far apart are refined side by side: neither's
    // separation rows (taken within 2 d_min + margin + 4 trust radii) can see the other.
    let apart =
        2.0 * model.scenario.fleet.d_min_m + settings.distance_margin_m + 4.0 * settings.radius_m;
    let threads = model.scenario.optimizer.threads;
    for _ in 0..settings.rounds {
        let kept = search.steps;
        // The latest vehicles first: they hold the fleet's arrival.
        let mut order = swimmers.clone();
        let lateness = |i: usize| {
            polyline_length(search.eval.trajectories.points(i))
                / model.scenario.vehicles[i].speed_max_mps
        };
        order.sort_by(|a, b| lateness(*b).total_cmp(&lateness(*a)));
        let extents = concurrent::trajectory_extents(&search);
        for batch in concurrent::far_apart_batches(&order, &extents, apart) {
            concurrent::refine_batch(&mut search, &batch, threads);
            if search.interrupted {
                break;
            }
        }
        if search.interrupted || search.steps == kept {
            break;
        }
    }
    for &i in &swimmers {
        if search.interrupted {
            break;
        }
        tighten_if_long(&mut search, i);
    }
    for &i in &swimmers {
        if search.interrupted {
            break;
        }
        reroute_if_late(&mut search, i);
    }
    search.settings = &fine;
    for &i in &swimmers {
        if search.interrupted {
            break;
        }
        if late(&search, i) {
            search.vehicle(i);
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
        .map(|(_, points)| polyline_length(points))
        .sum()
}

/// The whole fleet, judged by its fitness plus lateness past the target ([`merit`]).
struct FleetArena<'a> {
    model: &'a FleetModel,
    target: f64,
}

impl Arena for FleetArena<'_> {
    type Eval = FleetEvaluation;

    fn model(&self) -> &FleetModel {
        self.model
    }

    fn evaluate(&self, x: &[f64]) -> FleetEvaluation {
        self.model.evaluate(x)
    }

    fn evaluate_change(&self, base: &FleetEvaluation, x: &[f64], i: usize) -> FleetEvaluation {
        self.model.evaluate_change(base, x, i)
    }

    fn genes(&self, i: usize) -> Range<usize> {
        self.model.layout.chromosome(i)
    }

    fn merit(&self, e: &FleetEvaluation) -> f64 {
        merit(&self.model.scenario, e, self.target)
    }

    fn penalty(&self, e: &FleetEvaluation) -> f64 {
        e.penalty
    }

    fn common_arrival(&self, e: &FleetEvaluation) -> Option<f64> {
        Some(e.common_arrival)
    }

    fn mine<'e>(&'e self, e: &'e FleetEvaluation, i: usize) -> Samples<'e> {
        (e.trajectories.times(i), e.trajectories.points(i))
    }

    fn others<'e>(&'e self, e: &'e FleetEvaluation, i: usize) -> Vec<Samples<'e>> {
        (e.trajectories.iter().enumerate())
            .filter(|(j, _)| *j != i)
            .map(|(_, t)| t)
            .collect()
    }
}

/// Vehicle `i`'s path is too long to arrive by the target at its top speed.
fn late(search: &Search<FleetArena>, i: usize) -> bool {
    let v = &search.arena.model.scenario.vehicles[i];
    let length = polyline_length(search.eval.trajectories.points(i));
    length / v.speed_max_mps > search.target * (1.0 + 1e-9)
}

/// When vehicle `i` alone still makes the fleet late, a fresh route for it
/// ([`reroute::fresh_route`]) refined like the others, kept if it lowers the merit.
fn reroute_if_late(search: &mut Search<FleetArena>, i: usize) {
    let model = search.arena.model;
    if !late(search, i) {
        return;
    }
    let executor = crate::swarm::Executor {
        stop: search.stop.cloned(),
        ..crate::swarm::Executor::default()
    };
    let (genes, spent) = reroute::fresh_route(model, &search.x, i, search.target, &executor);
    search.evaluations += spent;
    let mut trial = search.x.clone();
    trial[model.layout.chromosome(i)].copy_from_slice(&genes);
    try_ways(search, i, vec![trial]);
}

/// When vehicle `i`'s path is more than [`pitch_routes::SLACK`] longer than its pitch limit
/// allows, [`pitch_routes::DRAWN`] fresh ways at that bound are scored by the merit and the best
/// [`pitch_routes::TRIED`] refined ([`try_ways`]). The scoring and the trials run on the
/// optimizer's threads; the ways are drawn first, so the result does not depend on them.
fn tighten_if_long(search: &mut Search<FleetArena>, i: usize) {
    let model = search.arena.model;
    let v = &model.scenario.vehicles[i];
    let length = polyline_length(search.eval.trajectories.points(i));
    if length <= shortest_pitch_feasible_length(v) * (1.0 + pitch_routes::SLACK) {
        return;
    }
    let genes = model.layout.chromosome(i);
    let speeds = search.x[genes.start + 3 * model.layout.waypoints..genes.end].to_vec();
    let seed =
        crate::swarm::population::stream_seed(model.scenario.optimizer.seed, 9_100_001 + i as u64);
    let mut rng = <rand::rngs::StdRng as rand::SeedableRng>::seed_from_u64(seed);
    let ways = pitch_routes::drawn_ways(model, i, &speeds, pitch_routes::DRAWN, &mut rng);
    let (x, eval, arena) = (&search.x, &search.eval, search.arena);
    let merits = parallel::map(&ways, model.scenario.optimizer.threads, |way| {
        let mut trial = x.clone();
        trial[genes.clone()].copy_from_slice(way);
        arena.merit(&arena.evaluate_change(eval, &trial, i))
    });
    search.evaluations += ways.len() as u64;
    let mut order: Vec<usize> = (0..ways.len()).collect();
    order.sort_by(|&a, &b| merits[a].total_cmp(&merits[b]));
    let trials = (order.iter().take(pitch_routes::TRIED))
        .map(|&k| {
            let mut trial = search.x.clone();
            trial[genes.clone()].copy_from_slice(&ways[k]);
            trial
        })
        .collect();
    try_ways(search, i, trials);
}

/// Refines vehicle `i` for the settings' rounds from each fleet position of `trials` (a new
/// way for vehicle `i` alone), each on its own thread, and moves to the first whose result
/// lowers the merit most; stays put when none lowers it. The same choice as trying them one
/// after the other, keeping each that beats the position kept so far.
fn try_ways(search: &mut Search<FleetArena>, i: usize, trials: Vec<Vec<f64>>) {
    if search.interrupted {
        return;
    }
    let mut branches: Vec<Search<FleetArena>> =
        trials.into_iter().map(|x| search.branch(x)).collect();
    let threads = search.arena.model.scenario.optimizer.threads;
    parallel::for_each_mut(&mut branches, threads, |b| {
        for _ in 0..b.settings.rounds {
            b.vehicle(i);
        }
    });
    let mut best = search.arena.merit(&search.eval);
    let mut chosen = None;
    for b in branches {
        search.evaluations += b.evaluations;
        search.interrupted |= b.interrupted;
        let merit = search.arena.merit(&b.eval);
        if merit < best {
            best = merit;
            chosen = Some(b);
        }
    }
    if let Some(b) = chosen {
        // The move to the new way counts as a step.
        search.steps += b.steps + 1;
        search.x = b.x;
        search.eval = b.eval;
    }
}

#[cfg(test)]
mod tests;
