//! Cage-inspection tours, seed 003 (Hu et al. 2023): an AUV leaves a base, visits two inspection
//! points on opposite sides of every spherical net cage and returns, on the shortest path that
//! never touches a cage.
//!
//! Two layers, as in the seed:
//! 1. the visiting order, by the swap-operator PSO (§III-B, Table 3) on straight-line distances
//!    ([`SwapPso`]);
//! 2. every leg between consecutive visits, by a continuous swarm (DE-PSO, LDIW-PSO or LCPSO,
//!    Table 5) over the leg's intermediate waypoints with the cages as spherical obstacles
//!    ([`LegProblem`], §IV-C).
//!
//! [`plan_tour`] puts them together and reports the seed's Table 6 measures (path growth over
//! the straight tour and its rate). [`split_points`] shares the points among several AUVs.

mod cages;
mod figures;
mod fleet;
mod leg;
mod order;
mod split;

pub use cages::{
    cage_group_a, cage_group_b, inspection_points, paper_base, paper_bounds, Cage, FirstPoint,
    InspectionPoint, MONITOR_STANDOFF_M,
};
pub use figures::TourFigures;
pub use fleet::{leg_algorithm, shares, FleetTours};
pub use leg::{
    feasible, intersections, path_length, safety_spheres, segment_hits, LegProblem, Sphere,
    CHORD_WEIGHT, HIT_PENALTY_M,
};
pub use order::{
    distance_matrix, open_order_length, swap_sequence, tour_length, two_opt, Ordered, SwapPso,
};
pub use split::{short_tour, split_points};

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use crate::geometry::Vec3;
use crate::swarm::depso::DePso;
use crate::swarm::lcpso::Lcpso;
use crate::swarm::ldiwpso::LdiwPso;
use crate::swarm::multi::stream_seed;
use crate::swarm::{Executor, Outcome, SolverState, Termination, VelocityCapped};

/// Clearance the leg planner keeps from a cage's surface, metres. The seed treats the AUV as a
/// point and the cage sphere itself as the obstacle; 1 m of margin stays well inside the 5 m
/// standoff of the inspection points ([`MONITOR_STANDOFF_M`]), so those remain reachable.
pub const LEG_CLEARANCE_M: f64 = 1.0;

/// The swarm that plans the legs (the three algorithms of seed 003 Table 6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LegAlgorithm {
    /// DE-PSO, §IV-A, eq. (14)–(20).
    DePso,
    /// LDIW-PSO, eq. (3).
    LdiwPso,
    /// LCPSO, eq. (4)–(10).
    Lcpso,
}

impl LegAlgorithm {
    /// The solver's name ("de-pso", "ldiw-pso", "lcpso").
    pub fn name(&self) -> &'static str {
        match self {
            LegAlgorithm::DePso => "de-pso",
            LegAlgorithm::LdiwPso => "ldiw-pso",
            LegAlgorithm::Lcpso => "lcpso",
        }
    }
}

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
}

impl LegSettings {
    /// Seed 003 Table 5.
    pub fn table5() -> LegSettings {
        LegSettings {
            particles: 60,
            iterations: 400,
            waypoints: 29,
            clearance_m: LEG_CLEARANCE_M,
            velocity_cap: None,
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
    /// Seed 003's settings: Table 3 for the order, Table 5 for the legs.
    pub fn paper() -> TourSettings {
        TourSettings {
            order: SwapPso::table3(0),
            leg: LegSettings::table5(),
            stop: None,
        }
    }
}

/// A planned inspection tour with the measures of seed 003 Table 6.
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
        return Leg {
            path: straight,
            evaluations: 0,
            interrupted: false,
        };
    }
    let mut ex = Executor::new(settings.iterations);
    ex.stop = stop.cloned();
    let m = settings.particles;
    let cap = settings.velocity_cap;
    let (best, evaluations, interrupted) = match algorithm {
        LegAlgorithm::DePso => {
            best_of(ex.run(problem, &mut DePso::table5(m, seed).capped(cap), |_| {}))
        }
        LegAlgorithm::LdiwPso => {
            best_of(ex.run(problem, &mut LdiwPso::table5(m, seed).capped(cap), |_| {}))
        }
        LegAlgorithm::Lcpso => {
            best_of(ex.run(problem, &mut Lcpso::table5(m, seed).capped(cap), |_| {}))
        }
    };
    let path = problem.path(&best);
    let path = if problem.path_cost(&path) <= problem.path_cost(&straight) {
        path
    } else {
        straight
    };
    Leg {
        path,
        evaluations,
        interrupted,
    }
}

/// The best position of a finished run, the evaluations it made and whether it was stopped.
fn best_of<S: SolverState>(run: Outcome<S>) -> (Vec<f64>, u64, bool) {
    (
        run.state.best_position().to_vec(),
        run.state.evaluations(),
        run.termination == Termination::Interrupted,
    )
}

/// Plans a closed inspection tour from `base` through every point of `points` (seed 003 §V).
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
        leg_lengths.push(path_length(&leg.path));
        path.extend(leg.path.into_iter().skip(1));
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
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    fn small() -> TourSettings {
        TourSettings {
            order: SwapPso {
                particles: 50,
                iterations: 300,
                ..SwapPso::table3(0)
            },
            leg: LegSettings {
                particles: 30,
                iterations: 150,
                waypoints: 9,
                clearance_m: LEG_CLEARANCE_M,
                velocity_cap: None,
            },
            stop: None,
        }
    }

    fn group_a_plan(algorithm: LegAlgorithm, seed: u64) -> (Vec<InspectionPoint>, TourPlan) {
        group_a_plan_with(algorithm, seed, &small())
    }

    fn group_a_plan_with(
        algorithm: LegAlgorithm,
        seed: u64,
        settings: &TourSettings,
    ) -> (Vec<InspectionPoint>, TourPlan) {
        let cages = cage_group_a();
        let base = paper_base();
        let pts = inspection_points(&cages, MONITOR_STANDOFF_M, FirstPoint::Toward(base));
        let plan = plan_tour(
            base,
            &pts,
            &cages,
            paper_bounds(),
            algorithm,
            settings,
            seed,
        );
        (pts, plan)
    }

    /// Every inspection point exactly once, in the tour's order along its path.
    fn assert_visits_every_point_in_order(pts: &[InspectionPoint], plan: &TourPlan) {
        let mut seen = plan.order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..pts.len()).collect::<Vec<_>>());
        let mut cursor = 0;
        for &i in &plan.order {
            let at = plan.path[cursor..]
                .iter()
                .position(|p| *p == pts[i].position)
                .map(|k| k + cursor);
            assert!(at.is_some(), "point {i} missing after {cursor}");
            cursor = at.unwrap_or(cursor) + 1;
        }
        assert_eq!(plan.path.first(), Some(&paper_base()));
        assert_eq!(plan.path.last(), Some(&paper_base()));
    }

    #[test]
    fn de_pso_tour_of_group_a_is_safe_and_complete() {
        let (pts, plan) = group_a_plan(LegAlgorithm::DePso, 1);
        assert_eq!(plan.cage_intersections, 0, "{plan:?}");
        // The order swarm's 50 × (300 + 1) tours, plus the swarms of the legs that had to bend
        // round a cage (the tour is longer than its straight legs, so at least one did).
        assert!(plan.growth_m > 0.0);
        assert!(plan.evaluations > 50 * 301, "{}", plan.evaluations);
        assert!(!plan.interrupted);
        assert_visits_every_point_in_order(&pts, &plan);
        // Table 6's measures are consistent.
        assert_eq!(plan.leg_lengths.len(), pts.len() + 1);
        assert_abs_diff_eq!(plan.tour_length_m, path_length(&plan.path), epsilon = 1e-6);
        assert!(plan.growth_m >= 0.0, "{}", plan.growth_m);
        assert_abs_diff_eq!(
            plan.growth_m,
            plan.tour_length_m - plan.straight_tour_length_m,
            epsilon = 1e-9
        );
        assert_abs_diff_eq!(
            plan.growth_rate,
            plan.growth_m / plan.straight_tour_length_m,
            epsilon = 1e-12
        );
        // The straight tour collides (the two points of a cage face each other through it), so
        // avoiding the cages must cost something.
        let straight: Vec<Vec3> = std::iter::once(paper_base())
            .chain(plan.order.iter().map(|&i| pts[i].position))
            .chain(std::iter::once(paper_base()))
            .collect();
        assert!(intersections(&straight, &safety_spheres(&cage_group_a(), 1.0)) > 0);
        assert!(plan.growth_m > 1.0, "{}", plan.growth_m);
    }

    #[test]
    fn a_raised_stop_still_gives_a_complete_tour_from_the_initial_swarms() {
        let settings = TourSettings {
            stop: Some(Arc::new(AtomicBool::new(true))),
            ..small()
        };
        let (pts, plan) = group_a_plan_with(LegAlgorithm::DePso, 1, &settings);
        assert!(plan.interrupted);
        assert_visits_every_point_in_order(&pts, &plan);
        assert_eq!(plan.leg_lengths.len(), pts.len() + 1);
        // No iteration ran: the order swarm evaluated its 50 initial tours, and every leg that
        // needed a swarm its 30 initial particles (at least one leg did: the straight tour
        // crosses the cages).
        let legs = (plan.evaluations - 50) / 30;
        assert_eq!(plan.evaluations, 50 + 30 * legs, "{}", plan.evaluations);
        assert!((1..=pts.len() as u64 + 1).contains(&legs), "{legs}");
    }

    /// Seed 003 §V-B at full Table 3 / Table 5 budgets on both groups (slow in a debug build:
    /// `cargo test -p shoal-common --lib tour::tests::paper_budgets -- --ignored --nocapture`).
    #[test]
    #[ignore = "full Table 5 budgets; run on demand"]
    fn paper_budgets_give_safe_de_pso_tours_on_both_groups() {
        for (group, cages) in [("A", cage_group_a()), ("B", cage_group_b())] {
            let base = paper_base();
            let pts = inspection_points(&cages, MONITOR_STANDOFF_M, FirstPoint::Toward(base));
            for alg in [
                LegAlgorithm::LdiwPso,
                LegAlgorithm::Lcpso,
                LegAlgorithm::DePso,
            ] {
                let plan = plan_tour(
                    base,
                    &pts,
                    &cages,
                    paper_bounds(),
                    alg,
                    &TourSettings::paper(),
                    1,
                );
                println!(
                    "group {group} {:>8}: straight {:.1} m, tour {:.1} m, growth {:.1} m ({:.2} %), \
                     intersections {}",
                    alg.name(),
                    plan.straight_tour_length_m,
                    plan.tour_length_m,
                    plan.growth_m,
                    100.0 * plan.growth_rate,
                    plan.cage_intersections
                );
                if alg == LegAlgorithm::DePso {
                    assert_eq!(plan.cage_intersections, 0, "group {group}");
                }
            }
        }
    }

    #[test]
    fn plans_are_reproducible_from_the_seed() {
        let (_, a) = group_a_plan(LegAlgorithm::DePso, 3);
        let (_, b) = group_a_plan(LegAlgorithm::DePso, 3);
        assert_eq!(a, b);
    }

    #[test]
    fn every_algorithm_plans_a_complete_tour() {
        for alg in [LegAlgorithm::LdiwPso, LegAlgorithm::Lcpso] {
            let (pts, plan) = group_a_plan(alg, 2);
            assert_eq!(plan.order.len(), pts.len(), "{}", alg.name());
            assert!(plan.growth_m >= 0.0, "{}: {}", alg.name(), plan.growth_m);
            assert_abs_diff_eq!(plan.tour_length_m, path_length(&plan.path), epsilon = 1e-6);
        }
    }

    #[test]
    fn a_clear_straight_leg_is_kept() {
        let s = safety_spheres(&[Cage::new("X", 50.0, 50.0, 0.0, 10.0)], 1.0);
        let p = LegProblem::new(
            Vec3::zeros(),
            Vec3::new(100.0, 0.0, 0.0),
            s,
            paper_bounds(),
            5,
        );
        let leg = plan_leg(&p, LegAlgorithm::DePso, &small().leg, 0, None);
        let straight = Leg {
            path: vec![p.start, p.end],
            evaluations: 0,
            interrupted: false,
        };
        assert_eq!(leg, straight, "no swarm, no evaluation");
        // A raised stop changes nothing for a leg that runs no swarm.
        let raised = Arc::new(AtomicBool::new(true));
        let leg = plan_leg(&p, LegAlgorithm::DePso, &small().leg, 0, Some(&raised));
        assert_eq!(leg, straight);
        assert_eq!(LegAlgorithm::Lcpso.name(), "lcpso");
    }

    #[test]
    fn a_legs_swarm_moves_under_the_settings_velocity_cap() {
        // The cage sits on the straight line, so the swarm has to plan.
        let s = safety_spheres(&[Cage::new("X", 50.0, 0.0, 0.0, 10.0)], 1.0);
        let p = LegProblem::new(
            Vec3::zeros(),
            Vec3::new(100.0, 0.0, 0.0),
            s,
            paper_bounds(),
            5,
        );
        // Evaluations: 30 particles at the start, then each particle once per iteration (its
        // move), and DE-PSO once more (its DE trial): 30 + 10 × 30 = 330, 30 + 10 × 60 = 630.
        for (algorithm, evaluations) in [
            (LegAlgorithm::DePso, 630),
            (LegAlgorithm::LdiwPso, 330),
            (LegAlgorithm::Lcpso, 330),
        ] {
            let with = |cap| {
                let settings = LegSettings {
                    iterations: 10,
                    velocity_cap: cap,
                    ..small().leg
                };
                plan_leg(&p, algorithm, &settings, 3, None)
            };
            let Leg {
                path: own,
                evaluations: spent,
                interrupted,
            } = with(None);
            assert!(!interrupted);
            assert_ne!(
                own,
                vec![p.start, p.end],
                "{algorithm:?} kept a blocked leg"
            );
            assert_eq!(spent, evaluations, "{algorithm:?}");
            let with = |cap| with(cap).path;
            // Table 5's solvers' own cap is 0.2: naming it changes nothing, another cap does.
            assert_eq!(own, with(Some(0.2)), "{algorithm:?}");
            assert_ne!(own, with(Some(0.005)), "{algorithm:?}");
        }
    }
}
