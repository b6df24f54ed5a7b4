//! Tours and legs: plans of cage group A, the stop flag, the velocity cap, convergence curves.

use super::*;
use crate::geometry::{polyline_length, Vec3};
use approx::assert_abs_diff_eq;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

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
            refine: false,
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
    assert_abs_diff_eq!(
        plan.tour_length_m,
        polyline_length(&plan.path),
        epsilon = 1e-6
    );
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

/// Hu et al. 2023, §V-B at full Table 3 / Table 5 budgets on both groups (slow in a debug build:
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
        assert_abs_diff_eq!(
            plan.tour_length_m,
            polyline_length(&plan.path),
            epsilon = 1e-6
        );
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
        convergence: vec![],
        cost: 100.0,
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
            convergence,
            cost,
        } = with(None);
        assert!(!interrupted);
        // One best cost per iteration, never rising, ending at the kept path's cost, and never
        // above the straight leg's (which crosses the cage: 100 m plus its penalty).
        assert_eq!(convergence.len(), 10, "{algorithm:?}");
        assert!(
            convergence.windows(2).all(|w| w[1] <= w[0]),
            "{convergence:?}"
        );
        assert_eq!(convergence.last(), Some(&cost), "{algorithm:?}");
        assert_abs_diff_eq!(cost, p.path_cost(&own), epsilon = 1e-9);
        let straight_cost = p.path_cost(&[p.start, p.end]);
        assert!(straight_cost > 100.0 + 1.0);
        assert!(convergence.iter().all(|&c| c <= straight_cost));
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

/// A leg of `cost` whose swarm's curve is `convergence`.
fn leg_with(cost: f64, convergence: Vec<f64>) -> Leg {
    Leg {
        path: vec![],
        evaluations: 0,
        interrupted: false,
        convergence,
        cost,
    }
}

#[test]
fn a_tours_curve_sums_its_legs_holding_each_at_its_final_cost() {
    // Leg 1 needed no swarm (10 m); leg 2's swarm ran 3 iterations; leg 3's was stopped after
    // one; leg 4 needed none (5 m).
    let legs = [
        leg_with(10.0, vec![]),
        leg_with(20.0, vec![30.0, 25.0, 20.0]),
        leg_with(12.0, vec![12.0]),
        leg_with(5.0, vec![]),
    ];
    let curve =
        |legs: &[Leg]| summed_curve(legs.iter().map(|l| (l.convergence.as_slice(), l.cost)));
    // 10 + 30 + 12 + 5, 10 + 25 + 12 + 5, 10 + 20 + 12 + 5: the last entry is the sum of the
    // legs' final costs.
    assert_eq!(curve(&legs), [57.0, 52.0, 47.0]);
    // Order does not matter: the short curve first, the long one last.
    let reversed: Vec<Leg> = legs.iter().rev().cloned().collect();
    assert_eq!(curve(&reversed), [57.0, 52.0, 47.0]);
}

#[test]
fn a_tours_curve_ends_at_its_length_and_a_straight_tour_has_one_point() {
    let (_, plan) = group_a_plan(LegAlgorithm::DePso, 1);
    assert_eq!(plan.cage_intersections, 0);
    assert_eq!(plan.convergence.len(), small().leg.iterations);
    assert!(plan.convergence.windows(2).all(|w| w[1] <= w[0]));
    let last = plan.convergence.last().copied().unwrap_or(f64::NAN);
    assert_abs_diff_eq!(last, plan.tour_length_m, epsilon = 1e-6);
    // The first entry is above the end: the leg swarms improved on their first iteration's best.
    assert!(plan.convergence[0] > last, "{:?}", &plan.convergence[..3]);

    // One point and no cage: both legs are straight and clear, no swarm runs.
    let far = InspectionPoint {
        cage: 0,
        position: Vec3::new(0.0, 10.0, 0.0),
    };
    let plan = plan_tour(
        paper_base(),
        &[far],
        &[],
        paper_bounds(),
        LegAlgorithm::DePso,
        &small(),
        1,
    );
    assert_eq!(plan.convergence, [20.0]);
    assert_abs_diff_eq!(plan.tour_length_m, 20.0, epsilon = 1e-12);
}
