use super::*;
use crate::geometry::Vec3;
use crate::scenario::ScenarioError;
use crate::trajectory::Trajectory;
use std::f64::consts::PI;
use std::time::Instant;

/// One or two AUVs in a 1000 × 1000 × 500 m box, 12 waypoints, length the only objective term.
fn scenario(extra: &str, vehicles: &[String]) -> Result<Scenario, ScenarioError> {
    let text = format!(
        "name = \"refine\"\n[bounds]\nmin = [0.0, 0.0, 0.0]\nmax = [1000.0, 1000.0, 500.0]\n\
         {extra}\n{}[fleet]\nd_min_m = 50.0\nmission_time_s = 1000.0\n[optimizer]\n\
         waypoints = 12\nweights = [1.0, 0.0, 0.0, 0.0, 0.0]\n",
        vehicles.concat()
    );
    Scenario::parse(&text, std::path::Path::new("refine.toml"))
}

fn vehicle(id: &str, start: [f64; 3], goal: [f64; 3]) -> String {
    crate::fixtures::vehicle_toml(id, start, goal)
}

/// A chromosome through `points(s)` at s = j / (M + 1), requesting 1 m/s.
fn chromosome(m: usize, points: impl Fn(f64) -> [f64; 3]) -> Vec<f64> {
    let mut x = Vec::new();
    for j in 1..=m {
        x.extend_from_slice(&points(j as f64 / (m + 1) as f64));
    }
    x.extend(std::iter::repeat_n(1.0, m));
    x
}

fn length(model: &FleetModel, x: &[f64], i: usize) -> f64 {
    model
        .decode(i, &x[model.layout.chromosome(i)])
        .leg_lengths()
        .iter()
        .sum()
}

/// Around a sphere of inflated radius 200 m whose centre is 400 m from both ends, the shortest
/// path is two tangents and an arc: 2 √(400² − 200²) + 200 (π − 2 arccos ½) = 902.26 m. A wide
/// feasible detour is pulled to within 1 % of it, never below it, and stays clear.
#[test]
fn a_detour_round_a_sphere_is_pulled_onto_the_tangents_and_the_arc() -> Result<(), ScenarioError> {
    let s = scenario(
        "[[obstacles]]\nid = \"rock\"\nkind = \"hard\"\ncentre = [500.0, 500.0, 250.0]\n\
         radius_m = 150.0\ninflation_m = 50.0\n",
        &[vehicle("a", [100.0, 500.0, 250.0], [900.0, 500.0, 250.0])],
    )?;
    let model = FleetModel::new(&s);
    let x = chromosome(12, |u| {
        [100.0 + 800.0 * u, 500.0 + 300.0 * (PI * u).sin(), 250.0]
    });
    assert_eq!(model.evaluate(&x).penalty, 0.0);
    let r = refine(&model, &x, &RefineSettings::default(), None);
    let bound = 2.0 * (400f64.powi(2) - 200f64.powi(2)).sqrt() + 200.0 * (PI - 2.0 * 0.5f64.acos());
    let l = length(&model, &r.x, 0);
    assert!(l > bound - 0.01 && l < 1.01 * bound, "{l} against {bound}");
    assert!(length(&model, &x, 0) > 1.1 * bound);
    assert_eq!(model.evaluate(&r.x).penalty, 0.0);
    assert!(r.total.1 < r.total.0 && r.steps > 0, "{r:?}");
    Ok(())
}

/// A 300 m descent over 400 m of straight distance at a 20° pitch limit: no path is shorter
/// than 300 / sin 20° = 877.1 m (the vehicle must wander to lose depth). A 1 km horizontal
/// arc descending evenly (15 % longer) is pulled to within 1 % of that bound, inside the pitch and turn limits.
#[test]
fn a_descent_longer_than_its_pitch_needs_is_pulled_onto_the_pitch_bound(
) -> Result<(), ScenarioError> {
    let s = scenario(
        "",
        &[vehicle("a", [300.0, 500.0, 400.0], [700.0, 500.0, 100.0])],
    )?;
    let model = FleetModel::new(&s);
    // A 240° arc of a circle through both ends (radius 200 / sin 120°, centre 115.5 m off the
    // chord): 967 m seen from above, 18.5° of turn per waypoint; the depth falls evenly.
    let radius = 200.0 / 120f64.to_radians().sin();
    let centre = [500.0, 500.0 + radius * 0.5];
    let x = chromosome(12, |u| {
        let phi = (-150.0 - 240.0 * u).to_radians();
        [
            centre[0] + radius * phi.cos(),
            centre[1] + radius * phi.sin(),
            400.0 - 300.0 * u,
        ]
    });
    assert_eq!(model.evaluate(&x).penalty, 0.0);
    let r = refine(&model, &x, &RefineSettings::default(), None);
    let bound = 300.0 / 20f64.to_radians().sin();
    let l = length(&model, &r.x, 0);
    assert!(
        l > bound - 0.01 && l < 1.01 * bound,
        "{l} against {bound}, {r:?}"
    );
    assert!(length(&model, &x, 0) > 1.1 * bound);
    assert_eq!(model.evaluate(&r.x).penalty, 0.0);
    Ok(())
}

/// The fresh ways at the pitch bound are scored, and the best refined, on the optimizer's
/// threads: the refined plan is the same, bit for bit, on one thread or several. One program
/// leaves the 15 % longer arc of the descent above over the bound, so the ways are drawn.
#[test]
fn the_refinement_does_not_depend_on_the_thread_count() -> Result<(), ScenarioError> {
    let mut s = scenario(
        "",
        &[vehicle("a", [300.0, 500.0, 400.0], [700.0, 500.0, 100.0])],
    )?;
    let radius = 200.0 / 120f64.to_radians().sin();
    let x = chromosome(12, |u| {
        let phi = (-150.0 - 240.0 * u).to_radians();
        [
            500.0 + radius * phi.cos(),
            500.0 + radius * 0.5 + radius * phi.sin(),
            400.0 - 300.0 * u,
        ]
    });
    let settings = RefineSettings {
        rounds: 1,
        steps: 1,
        ..RefineSettings::default()
    };
    let mut runs = Vec::new();
    for threads in [1, 2, 3] {
        s.optimizer.threads = threads;
        runs.push(refine(&FleetModel::new(&s), &x, &settings, None));
    }
    assert!(
        runs[0].evaluations > pitch_routes::DRAWN as u64,
        "{:?}",
        runs[0]
    );
    assert!(runs[0].total.1 < runs[0].total.0, "{:?}", runs[0]);
    for r in &runs[1..] {
        assert_eq!(r, &runs[0]);
    }
    Ok(())
}

/// Two AUVs cross at the same moment; the first bows 150 m out of the second's way. Pulling it
/// straight would bring them together: the refinement shortens it only as far as d_min allows.
#[test]
fn a_path_is_pulled_tight_only_as_far_as_the_separation_allows() -> Result<(), ScenarioError> {
    let s = scenario(
        "",
        &[
            vehicle("a", [100.0, 500.0, 250.0], [900.0, 500.0, 250.0]),
            vehicle("b", [500.0, 100.0, 250.0], [500.0, 900.0, 250.0]),
        ],
    )?;
    let model = FleetModel::new(&s);
    let mut x = chromosome(12, |u| {
        [100.0 + 800.0 * u, 500.0 + 150.0 * (PI * u).sin(), 250.0]
    });
    x.extend(chromosome(12, |u| [500.0, 100.0 + 800.0 * u, 250.0]));
    let before = model.evaluate(&x);
    assert_eq!(before.penalty, 0.0);
    let r = refine(&model, &x, &RefineSettings::default(), None);
    let after = model.evaluate(&r.x);
    assert_eq!(after.penalty, 0.0, "{:?}", after.vehicles);
    assert!(
        length(&model, &r.x, 0) < length(&model, &x, 0) - 10.0,
        "{r:?}"
    );
    assert!(length(&model, &r.x, 0) > 800.0 + 1.0);
    assert!(after.total < before.total);
    Ok(())
}

/// A raised stop flag, or a deadline already past, returns the plan as it came, marked as
/// interrupted.
#[test]
fn a_raised_stop_flag_or_a_passed_deadline_returns_the_plan_unchanged() -> Result<(), ScenarioError>
{
    let s = scenario(
        "",
        &[vehicle("a", [100.0, 500.0, 250.0], [900.0, 500.0, 250.0])],
    )?;
    let model = FleetModel::new(&s);
    let x = chromosome(12, |u| {
        [100.0 + 800.0 * u, 500.0 + 300.0 * (PI * u).sin(), 250.0]
    });
    let stop = Arc::new(AtomicBool::new(true));
    let r = refine(&model, &x, &RefineSettings::default(), Some(&stop));
    assert!(r.interrupted);
    assert_eq!(r.x, x);
    assert_eq!(r.steps, 0);
    let settings = RefineSettings {
        deadline: Some(Instant::now()),
        ..RefineSettings::default()
    };
    let r = refine(&model, &x, &settings, None);
    assert!(r.interrupted && r.steps == 0 && r.x == x);
    Ok(())
}

/// The target arrival is the mission time unless a pitch limit forbids it: a 1200 m descent at
/// 20° needs 3508.5 m, 2339 s at 1.5 m/s.
#[test]
fn the_target_arrival_is_the_mission_time_unless_a_pitch_limit_forbids_it(
) -> Result<(), ScenarioError> {
    let s = scenario(
        "",
        &[vehicle("a", [100.0, 500.0, 250.0], [900.0, 500.0, 250.0])],
    )?;
    assert_eq!(target_arrival(&s), 1000.0);
    let mut deep = s.clone();
    deep.bounds.max[2] = 2000.0;
    deep.vehicles[0].start[2] = 1400.0;
    deep.vehicles[0].goal[2] = 200.0;
    let need = 1200.0 / 20f64.to_radians().sin() / 1.5;
    assert!((target_arrival(&deep) - need).abs() < 1e-6);
    Ok(())
}

/// One vehicle refined against fixed others (a replan's answer): the sphere detour above is
/// pulled onto the same bound, and a second vehicle parked on the tangent line (its fixed
/// trajectory holds still at (500, 740, 250)) keeps the path d_min away from it.
#[test]
fn one_vehicle_against_fixed_others_is_pulled_tight_around_them() -> Result<(), ScenarioError> {
    let s = scenario(
        "[[obstacles]]\nid = \"rock\"\nkind = \"hard\"\ncentre = [500.0, 500.0, 250.0]\n\
         radius_m = 150.0\ninflation_m = 50.0\n",
        &[
            vehicle("a", [100.0, 500.0, 250.0], [900.0, 500.0, 250.0]),
            vehicle("b", [900.0, 900.0, 450.0], [950.0, 950.0, 450.0]),
        ],
    )?;
    let model = FleetModel::new(&s);
    let genes = chromosome(12, |u| {
        [100.0 + 800.0 * u, 500.0 + 330.0 * (PI * u).sin(), 250.0]
    });
    let parked = crate::trajectory::Trajectory {
        times: vec![0.0, 1000.0],
        points: vec![Vec3::new(500.0, 740.0, 250.0); 2],
    };
    let context = [parked.clone(), parked.clone()];
    let problem = crate::vehicle_problem::VehicleProblem::new(&model, 0, &context, 1000.0)
        .early_arrival_allowed();
    let before = problem.evaluate(&genes);
    assert_eq!(
        before.terms.hard + before.terms.motion + before.terms.separation,
        0.0
    );
    let r = refine_vehicle(&problem, &genes, 1000.0, &RefineSettings::default(), None);
    let after = problem.evaluate(&r.genes);
    assert_eq!(
        after.terms.hard + after.terms.motion + after.terms.separation,
        0.0
    );
    assert!(after.min_separation >= 50.0, "{}", after.min_separation);
    // The tangent-and-arc bound is 902.26 m; the parked vehicle's 50 m ring sits on the arc
    // (740 − 50 = 690 m against the arc's 700 m top), so the path may not reach it.
    let bound = 2.0 * (400f64.powi(2) - 200f64.powi(2)).sqrt() + 200.0 * (PI - 2.0 * 0.5f64.acos());
    assert!(r.length_m.1 < r.length_m.0 - 50.0, "{r:?}");
    assert!(r.length_m.1 > bound, "{r:?}");
    assert!(r.total.1 < r.total.0 && r.steps > 0);
    assert_eq!(r.total.1, after.total);
    Ok(())
}

/// A replan under way northwards keeps the turn off that course within the limit while its
/// path is pulled tight towards a goal due east.
#[test]
fn a_path_entered_under_way_keeps_its_first_turn_within_the_limit() -> Result<(), ScenarioError> {
    let s = scenario(
        "",
        &[vehicle("a", [100.0, 300.0, 250.0], [900.0, 300.0, 250.0])],
    )?;
    let model = FleetModel::new(&s);
    let north = Vec3::new(0.0, 1.0, 0.0);
    // Leaves northwards, swings round to the east: a wide, flyable arc.
    let genes = chromosome(12, |u| {
        [100.0 + 800.0 * u * u, 300.0 + 500.0 * (PI * u).sin(), 250.0]
    });
    let context = [Trajectory {
        times: vec![0.0, 1000.0],
        points: vec![Vec3::new(0.0, 0.0, 0.0); 2],
    }];
    let problem = crate::vehicle_problem::VehicleProblem::new(&model, 0, &context, 1000.0)
        .early_arrival_allowed()
        .entering_along(north);
    let max_turn = s.vehicles[0].max_turn_deg.to_radians();
    let entry =
        |g: &[f64]| crate::cost::entry_turn_penalty(north, &model.decode(0, g).points, max_turn);
    assert_eq!(entry(&genes), 0.0);
    assert_eq!(problem.evaluate(&genes).terms.motion, 0.0);
    let r = refine_vehicle(&problem, &genes, 1000.0, &RefineSettings::default(), None);
    assert!(r.length_m.1 < 0.95 * r.length_m.0, "{r:?}");
    assert_eq!(entry(&r.genes), 0.0);
    assert_eq!(problem.evaluate(&r.genes).terms.motion, 0.0);
    Ok(())
}

/// Round a soft sphere that costs more to cross than to go round (F(O) weighted ten times
/// F(L)), the detour is pulled onto the same tangents and arc as round a hard one, 902.26 m,
/// and never dips in.
#[test]
fn a_detour_round_a_costly_soft_sphere_is_pulled_tight_without_entering_it(
) -> Result<(), ScenarioError> {
    let mut s = scenario(
        "[[obstacles]]\nid = \"zone\"\nkind = \"soft\"\ncentre = [500.0, 500.0, 250.0]\n\
         radius_m = 150.0\ninflation_m = 50.0\n",
        &[vehicle("a", [100.0, 500.0, 250.0], [900.0, 500.0, 250.0])],
    )?;
    s.optimizer.weights = [1.0, 0.0, 10.0, 0.0, 0.0];
    let model = FleetModel::new(&s);
    let x = chromosome(12, |u| {
        [100.0 + 800.0 * u, 500.0 + 300.0 * (PI * u).sin(), 250.0]
    });
    let r = refine(&model, &x, &RefineSettings::default(), None);
    let bound = 2.0 * (400f64.powi(2) - 200f64.powi(2)).sqrt() + 200.0 * (PI - 2.0 * 0.5f64.acos());
    let l = length(&model, &r.x, 0);
    assert!(l > bound - 0.01 && l < 1.01 * bound, "{l} against {bound}");
    let soft = crate::cost::soft_threat_term(&model.decode(0, &r.x[..]).points, &model.soft, 800.0);
    assert_eq!(soft, 0.0);
    Ok(())
}

/// Boxes of points along x at 0, 100, 200, 300 and 1000 m, 150 m apart at least within a batch:
/// the first batch takes 0, skips 1 (100 m from 0), takes 2, skips 3 (100 m from 2), takes 4;
/// the second takes 1 and 3 (200 m apart). Six vehicles 1 km apart fill a batch of four first.
#[test]
fn batches_hold_vehicles_pairwise_apart_in_order_and_at_most_four() {
    let at = |x: f64| (Vec3::new(x, 0.0, 0.0), Vec3::new(x, 0.0, 0.0));
    let extents: Vec<_> = [0.0, 100.0, 200.0, 300.0, 1000.0].map(at).into();
    assert_eq!(
        concurrent::far_apart_batches(&[0, 1, 2, 3, 4], &extents, 150.0),
        vec![vec![0, 2, 4], vec![1, 3]]
    );
    // Another order: 3 opens, 0 and 1 join (300 and 200 m from 3, 100 m apart from each other:
    // only 0 joins), then 4 (700 m from 3).
    assert_eq!(
        concurrent::far_apart_batches(&[3, 0, 1, 4, 2], &extents, 150.0),
        vec![vec![3, 0, 4], vec![1], vec![2]]
    );
    let spread: Vec<_> = (0..6).map(|k| at(1000.0 * k as f64)).collect();
    assert_eq!(
        concurrent::far_apart_batches(&[0, 1, 2, 3, 4, 5], &spread, 150.0),
        vec![vec![0, 1, 2, 3], vec![4, 5]]
    );
}

/// Two AUVs 700 m apart, each bowed 100 m out of its straight line: refined side by side they
/// end where refining one after the other puts them, each pulled tighter.
#[test]
fn far_apart_vehicles_refined_side_by_side_end_where_one_after_the_other_does(
) -> Result<(), ScenarioError> {
    let s = scenario(
        "",
        &[
            vehicle("a", [100.0, 150.0, 250.0], [900.0, 150.0, 250.0]),
            vehicle("b", [100.0, 850.0, 250.0], [900.0, 850.0, 250.0]),
        ],
    )?;
    let model = FleetModel::new(&s);
    let bowed = |y: f64| {
        chromosome(12, move |u| {
            [100.0 + 800.0 * u, y + 100.0 * (PI * u).sin(), 250.0]
        })
    };
    let mut x = bowed(150.0);
    x.extend(bowed(850.0));
    let settings = RefineSettings::default();
    let arena = FleetArena {
        model: &model,
        target: target_arrival(&s),
    };
    let start = search::Search::new(&arena, &x, arena.target, &settings, None);
    let extents = concurrent::trajectory_extents(&start);
    assert_eq!(
        concurrent::far_apart_batches(&[0, 1], &extents, 180.5),
        vec![vec![0, 1]]
    );
    let mut side_by_side = start.fork();
    concurrent::refine_batch(&mut side_by_side, &[0, 1], 2);
    let mut in_turn = start.fork();
    in_turn.vehicle(0);
    in_turn.vehicle(1);
    for i in 0..2 {
        assert!(length(&model, &side_by_side.x, i) < length(&model, &x, i) - 10.0);
    }
    assert_eq!(side_by_side.steps, in_turn.steps);
    for (a, b) in side_by_side.x.iter().zip(&in_turn.x) {
        assert!((a - b).abs() < 1e-9, "{a} vs {b}");
    }
    let (m_side, m_turn) = (arena.merit(&side_by_side.eval), arena.merit(&in_turn.eval));
    assert!((m_side - m_turn).abs() < 1e-12, "{m_side} vs {m_turn}");
    Ok(())
}
