//! The two layers put together: the visiting order, then every leg by a continuous swarm, with
//! the settings of both and the plan they give (Hu et al. 2023, §III–IV, Tables 3, 5 and 6).

use super::cages::{Cage, InspectionPoint};
use super::leg::{intersections, safety_spheres, LegProblem};
use super::order::{distance_matrix, tour_length, Ordered, SwapPso};
use crate::geometry::polyline_length;

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use crate::geometry::Vec3;
use crate::refine::descent::{self, DescentSettings};
use crate::swarm::catalog::{with_solver, LegAlgorithm, SolverSettings, SolverVisitor};
use crate::swarm::population::stream_seed;
use crate::swarm::{Executor, Solver, SolverState, Termination};

/// Clearance the leg planner keeps from a cage's surface, metres. The seed treats the AUV as a
/// point and the cage sphere itself as the obstacle; 1 m of margin stays well inside the 5 m
/// standoff of the inspection points ([`MONITOR_STANDOFF_M`](super::MONITOR_STANDOFF_M)), so
/// those remain reachable.
pub const LEG_CLEARANCE_M: f64 = 1.0;

/// Budgets and geometry of one leg's optimisation.
#[derive(Debug, Clone, PartialEq)]
pub struct LegSettings {
    /// Swarm size M (Table 5: 60).
    pub particles: usize,
    /// Iterations (Table 5: 400).
    pub iterations: usize,
    /// Intermediate waypoints n (Table 5's `path_num = 30` segments: 29).
    pub waypoints: usize,
    /// Margin added to every cage radius, metres ([`LEG_CLEARANCE_M`]).
    pub clearance_m: f64,
    /// Velocity cap for the leg's swarm (a fraction of each range); `None` keeps the
    /// algorithm's own (Table 5's solvers: 0.2).
    pub velocity_cap: Option<f64>,
    /// Descend from the swarm's best on the same cost ([`descent`]): not part of Hu et al.'s
    /// algorithm, which ends with the swarm.
    pub refine: bool,
}

impl LegSettings {
    /// Hu et al. 2023, Table 5.
    pub fn table5() -> LegSettings {
        LegSettings {
            particles: 60,
            iterations: 400,
            waypoints: 29,
            clearance_m: LEG_CLEARANCE_M,
            velocity_cap: None,
            refine: false,
        }
    }
}

/// Settings of [`plan_tour`].
#[derive(Debug, Clone)]
pub struct TourSettings {
    /// The ordering swarm; its `seed` is replaced by one derived from the plan's seed and its
    /// `stop` by the one below.
    pub order: SwapPso,
    /// The leg swarms.
    pub leg: LegSettings,
    /// Raised to cut every swarm of the tour short (Ctrl-C, shutdown): each keeps the best it
    /// has, so the tour is still complete, only less optimised ([`TourPlan::interrupted`]).
    pub stop: Option<Arc<AtomicBool>>,
}

impl TourSettings {
    /// Hu et al.'s settings: Table 3 for the order, Table 5 for the legs.
    pub fn paper() -> TourSettings {
        TourSettings {
            order: SwapPso::table3(0),
            leg: LegSettings::table5(),
            stop: None,
        }
    }
}

/// A planned inspection tour with the measures of Hu et al. 2023, Table 6.
#[derive(Debug, Clone, PartialEq)]
pub struct TourPlan {
    /// Visiting order: indices into the inspection points (the base is implicit at both ends).
    pub order: Vec<usize>,
    /// The full polyline: base, every leg's waypoints and inspection points, base.
    pub path: Vec<Vec3>,
    /// Length of each leg (base → first point, …, last point → base), metres.
    pub leg_lengths: Vec<f64>,
    /// Length of `path`, metres.
    pub tour_length_m: f64,
    /// Length of the same visiting order with straight legs, metres.
    pub straight_tour_length_m: f64,
    /// `tour_length_m − straight_tour_length_m` ("path growth length", Table 6), metres.
    pub growth_m: f64,
    /// `growth_m / straight_tour_length_m` ("path growth rate"; 0 for a zero-length tour).
    pub growth_rate: f64,
    /// Segment–cage intersections along `path`, against the cages inflated by the clearance,
    /// with the contact guard (0 for a safe tour).
    pub cage_intersections: usize,
    /// Cost evaluations spent on it: the order swarm's tour lengths plus every leg swarm's path
    /// costs (a straight leg that is already clear costs none).
    pub evaluations: u64,
    /// The stop flag cut the order swarm or a leg swarm short: the tour is complete but was
    /// not optimised with the whole budget.
    pub interrupted: bool,
    /// The tour's convergence curve: entry `t` is the summed cost of its legs (length plus the
    /// leg swarms' intersection penalty, [`LegProblem::path_cost`]) when every leg swarm has run
    /// `t + 1` iterations. A leg that needs no swarm, or whose swarm stopped early, counts at its
    /// final cost; each leg counts at most its straight chord's cost, as [`plan_leg`] keeps the
    /// cheaper. One entry per leg-swarm iteration run, and one more with the legs' final summed
    /// cost when their refinement ([`LegSettings::refine`]) lowered it; a tour none of whose
    /// legs needed a swarm has one entry, its cost.
    pub convergence: Vec<f64>,
}

/// One planned leg.
#[derive(Debug, Clone, PartialEq)]
pub struct Leg {
    /// Its polyline, both end points included.
    pub path: Vec<Vec3>,
    /// Cost evaluations its swarm made (0 when no swarm ran).
    pub evaluations: u64,
    /// The stop flag ended its swarm before the iteration budget.
    pub interrupted: bool,
    /// Its swarm's best cost after each iteration it ran, capped at the straight chord's cost
    /// (empty when no swarm ran).
    pub convergence: Vec<f64>,
    /// The cost of `path` ([`LegProblem::path_cost`]).
    pub cost: f64,
}

/// Plans one leg with `algorithm`. `stop`, when raised, ends its swarm after the current
/// iteration (before the first if it is raised already: only the initial swarm is evaluated).
///
/// A straight leg that is already clear is kept as it is: nothing is shorter, so no swarm is run.
/// Otherwise the swarm's best path is returned, or the straight one if the swarm did worse by the
/// leg's cost (possible only when both collide).
pub fn plan_leg(
    problem: &LegProblem,
    algorithm: LegAlgorithm,
    settings: &LegSettings,
    seed: u64,
    stop: Option<&Arc<AtomicBool>>,
) -> Leg {
    let straight = vec![problem.start, problem.end];
    if problem.waypoints == 0 || problem.feasible(&straight) {
        let cost = problem.path_cost(&straight);
        return Leg {
            path: straight,
            evaluations: 0,
            interrupted: false,
            convergence: Vec::new(),
            cost,
        };
    }
    let mut executor = Executor::new(settings.iterations);
    executor.stop = stop.cloned();
    let solver = SolverSettings::single(settings.particles, seed, settings.velocity_cap);
    let run = with_solver(
        algorithm.algorithm(),
        &solver,
        LegRunner { problem, executor },
    );
    let mut evaluations = run.evaluations;
    let mut best = run.best;
    if settings.refine && !run.interrupted {
        let stop = stop.map(|s| s.as_ref());
        let d = descent::descend(problem, &best, &LEG_DESCENT, stop);
        evaluations += d.evaluations as u64;
        if d.cost.1 < d.cost.0 {
            best = d.x;
        }
    }
    let path = problem.path(&best);
    let (swarm_cost, straight_cost) = (problem.path_cost(&path), problem.path_cost(&straight));
    let (path, cost) = if swarm_cost <= straight_cost {
        (path, swarm_cost)
    } else {
        (straight, straight_cost)
    };
    Leg {
        path,
        evaluations,
        interrupted: run.interrupted,
        convergence: run
            .convergence
            .into_iter()
            .map(|c| c.min(straight_cost))
            .collect(),
        cost,
    }
}

/// The refinement's budget for one leg: its gradient over 29 waypoints takes 174 evaluations,
/// so this is about fifty steps, a tenth of Table 5's leg swarm (60 × 400).
const LEG_DESCENT: DescentSettings = DescentSettings {
    max_evaluations: 10_000,
    difference_step: 1e-7,
    tolerance: 1e-9,
};

/// What [`plan_leg`] keeps of a swarm's run.
struct LegRun {
    best: Vec<f64>,
    evaluations: u64,
    interrupted: bool,
    convergence: Vec<f64>,
}

/// Runs the leg swarm the catalog builds and keeps the best position of the finished run, the
/// evaluations it made, whether it was stopped and its convergence curve.
struct LegRunner<'a> {
    /// The leg.
    problem: &'a LegProblem,
    /// Its iteration budget and stop flag.
    executor: Executor,
}

impl SolverVisitor<LegProblem> for LegRunner<'_> {
    type Output = LegRun;
    fn visit<S: Solver<LegProblem>>(self, mut solver: S) -> LegRun {
        let run = self.executor.run(self.problem, &mut solver, |_| {});
        LegRun {
            best: run.state.best_position().to_vec(),
            evaluations: run.state.evaluations(),
            interrupted: run.termination == Termination::Interrupted,
            convergence: run.convergence,
        }
    }
}

/// The sum of several convergence curves, each given with the value it holds after its last
/// entry (or throughout, when it is empty): entry `t` sums every curve's entry `t`, or that
/// value where a curve is shorter. As long as the longest curve; empty when every curve is.
pub fn summed_curve<'a>(parts: impl IntoIterator<Item = (&'a [f64], f64)> + Clone) -> Vec<f64> {
    let len = parts
        .clone()
        .into_iter()
        .map(|(c, _)| c.len())
        .max()
        .unwrap_or(0);
    (0..len)
        .map(|t| {
            parts
                .clone()
                .into_iter()
                .map(|(c, held)| c.get(t).copied().unwrap_or(held))
                .sum()
        })
        .collect()
}

/// Plans a closed inspection tour from `base` through every point of `points` (Hu et al. 2023, §V).
///
/// The order comes from the swap-operator PSO on straight-line distances (seeded with
/// `stream_seed(seed, 0)`); leg `k` is planned by [`plan_leg`] with `stream_seed(seed, k + 1)`,
/// so a plan is reproducible from `seed` alone (unless `settings.stop` is raised while it runs).
/// Nothing here panics on odd input: an inverted box
/// is put in order, and a point inside a cage simply leaves `cage_intersections` above zero.
pub fn plan_tour(
    base: Vec3,
    points: &[InspectionPoint],
    cages: &[Cage],
    bounds: (Vec3, Vec3),
    algorithm: LegAlgorithm,
    settings: &TourSettings,
    seed: u64,
) -> TourPlan {
    let nodes: Vec<Vec3> = std::iter::once(base)
        .chain(points.iter().map(|p| p.position))
        .collect();
    let dist = distance_matrix(&nodes);
    let orderer = SwapPso {
        seed: stream_seed(seed, 0),
        stop: settings.stop.clone(),
        ..settings.order.clone()
    };
    let Ordered {
        tour,
        mut evaluations,
        mut interrupted,
    } = orderer.order_counted(&dist);
    let order: Vec<usize> = tour
        .iter()
        .skip(1)
        .take(points.len())
        .map(|&k| k - 1)
        .collect();
    let spheres = safety_spheres(cages, settings.leg.clearance_m);
    let mut path = vec![base];
    let mut leg_lengths = Vec::with_capacity(points.len() + 1);
    // Each leg's curve and its final cost, for the tour's curve.
    let mut curves = Vec::with_capacity(points.len() + 1);
    for (k, w) in tour.windows(2).enumerate() {
        let problem = LegProblem::new(
            nodes[w[0]],
            nodes[w[1]],
            spheres.clone(),
            bounds,
            settings.leg.waypoints,
        );
        let leg = plan_leg(
            &problem,
            algorithm,
            &settings.leg,
            stream_seed(seed, k as u64 + 1),
            settings.stop.as_ref(),
        );
        evaluations += leg.evaluations;
        interrupted |= leg.interrupted;
        curves.push((leg.convergence, leg.cost));
        // Hu et al. 2023, eq. (27)–(28).
        leg_lengths.push(polyline_length(&leg.path));
        path.extend(leg.path.into_iter().skip(1));
    }
    let mut convergence = summed_curve(curves.iter().map(|(c, cost)| (c.as_slice(), *cost)));
    // The legs' refinement (when asked) ends below their swarms' curves: one last entry.
    let total: f64 = curves.iter().map(|(_, cost)| cost).sum();
    if convergence.last().is_none_or(|last| total < *last) {
        convergence.push(total);
    }
    let tour_length_m: f64 = leg_lengths.iter().sum();
    let straight_tour_length_m = tour_length(&dist, &tour);
    let growth_m = tour_length_m - straight_tour_length_m;
    TourPlan {
        order,
        cage_intersections: intersections(&path, &spheres),
        path,
        leg_lengths,
        tour_length_m,
        straight_tour_length_m,
        growth_m,
        growth_rate: if straight_tour_length_m > 0.0 {
            growth_m / straight_tour_length_m
        } else {
            0.0
        },
        evaluations,
        interrupted,
        convergence,
    }
}
