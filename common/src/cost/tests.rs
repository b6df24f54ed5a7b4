//! Unit tests of `cost`.

use super::*;
use crate::geometry::chord_inside_sphere;
use crate::scenario::VehicleKind;
use approx::assert_abs_diff_eq;

fn v(x: f64, y: f64, z: f64) -> Vec3 {
    Vec3::new(x, y, z)
}

fn vehicle() -> Vehicle {
    Vehicle {
        id: "a".into(),
        kind: VehicleKind::Auv,
        start: [0.0, 0.0, 0.0],
        goal: [300.0, 0.0, 0.0],
        speed_min_mps: 0.5,
        speed_max_mps: 1.5,
        max_turn_deg: 35.0,
        max_pitch_deg: 20.0,
        turn_radius_m: None,
    }
}

#[test]
fn length_term_by_hand() {
    // A 3-4-5 detour: 5 + 5 = 10 m against a straight 8 m.
    let pts = [v(0., 0., 0.), v(4., 3., 0.), v(8., 0., 0.)];
    let len: f64 = pts.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    assert_abs_diff_eq!(length_term(len, 8.0), 1.25, epsilon = 1e-12);
}

#[test]
fn depth_term_by_hand() {
    // Surface at z = 100, column 100 m. Leg 1: 10 m at depth 50 → 50 average.
    // Leg 2: 30 m from depth 50 to depth 80 (vertical) → average 65.
    // Weighted mean (10·50 + 30·65) / 40 = 61.25 m → 0.6125.
    let pts = [v(0., 0., 50.), v(10., 0., 50.), v(10., 0., 20.)];
    assert_abs_diff_eq!(depth_term(&pts, 100.0, 100.0), 0.6125, epsilon = 1e-12);
    // Along the surface: 0.
    assert_abs_diff_eq!(
        depth_term(&[v(0., 0., 100.), v(5., 0., 100.)], 100.0, 100.0),
        0.0
    );
}

#[test]
fn soft_threat_by_hand() {
    // Straight through the centre of a soft sphere of inflated radius 20: 40 m inside,
    // straight distance 100 → 0.4. A second sphere missed entirely adds nothing.
    let soft = [
        Sphere {
            centre: v(50., 0., 0.),
            radius: 20.0,
        },
        Sphere {
            centre: v(50., 50., 0.),
            radius: 20.0,
        },
    ];
    let pts = [v(0., 0., 0.), v(100., 0., 0.)];
    assert_abs_diff_eq!(soft_threat_term(&pts, &soft, 100.0), 0.4, epsilon = 1e-9);
}

#[test]
fn time_term_by_hand() {
    let veh = vehicle();
    // 300 m: window [200, 600] s. Mission 400 → 0; 150 → (200 − 150)/150; 900 → 300/900.
    assert_abs_diff_eq!(time_term(300.0, &veh, 400.0), 0.0);
    assert_abs_diff_eq!(time_term(300.0, &veh, 150.0), 50.0 / 150.0, epsilon = 1e-12);
    assert_abs_diff_eq!(
        time_term(300.0, &veh, 900.0),
        300.0 / 900.0,
        epsilon = 1e-12
    );
}

#[test]
fn hard_penalty_counts_legs_that_cross_between_waypoints() {
    // Both waypoints are outside the sphere (radius 10 at (50, 5, 0)); the leg passes 5 m
    // from the centre: one hit, penalty 1 + 5/10.
    let hard = [Sphere {
        centre: v(50., 5., 0.),
        radius: 10.0,
    }];
    let (p, n) = hard_penalty(&[v(0., 0., 0.), v(100., 0., 0.)], &hard);
    assert_eq!(n, 1);
    assert_abs_diff_eq!(p, 1.5, epsilon = 1e-12);
    let (p, n) = hard_penalty(&[v(0., 20., 0.), v(100., 20., 0.)], &hard);
    assert_eq!((p, n), (0.0, 0));
}

#[test]
fn hard_penalty_guards_a_leg_that_grazes_the_inflated_sphere() {
    // The leg runs exactly on the surface (5 + 10 = 15 from the centre's line): a checker
    // calls that clear, but the planner demands the contact guard beyond it, so it is one hit
    // with penalty 1. A leg 1 mm further out is clear.
    let hard = [Sphere {
        centre: v(50., 15., 0.),
        radius: 15.0,
    }];
    let (p, n) = hard_penalty(&[v(0., 0., 0.), v(100., 0., 0.)], &hard);
    assert_eq!(n, 1);
    assert_abs_diff_eq!(p, 1.0, epsilon = 1e-12);
    let (p, n) = hard_penalty(&[v(0., -0.001, 0.), v(100., -0.001, 0.)], &hard);
    assert_eq!((p, n), (0.0, 0));
}

#[test]
fn entering_a_path_against_the_heading_costs_its_turn() {
    let max = 35f64.to_radians();
    // Heading east; the first leg goes north-east: 45°, 1 + 10/35. The first leg is short but
    // horizontal, so it is the one that counts, not the later ones.
    let pts = [v(0., 0., 0.), v(1., 1., 0.), v(1., 2., 0.)];
    assert_abs_diff_eq!(
        entry_turn_penalty(v(2., 0., 0.), &pts, max),
        1.0 + 10.0 / 35.0,
        epsilon = 1e-9
    );
    // A vertical first leg is skipped: the next leg, due west, is a 180° turn, 1 + 145/35.
    let pts = [v(0., 0., 0.), v(0., 0., 5.), v(-3., 0., 5.)];
    assert_abs_diff_eq!(
        entry_turn_penalty(v(1., 0., 0.), &pts, max),
        1.0 + 145.0 / 35.0,
        epsilon = 1e-9
    );
    // Within 35°, or with a heading that has no horizontal part (climbing straight up), or a
    // path with no horizontal leg: nothing.
    let c = 30f64.to_radians();
    let pts = [v(0., 0., 0.), v(c.cos(), c.sin(), 0.)];
    assert_abs_diff_eq!(entry_turn_penalty(v(1., 0., 0.), &pts, max), 0.0);
    assert_abs_diff_eq!(entry_turn_penalty(v(0., 0., 1.), &pts, max), 0.0);
    let pts = [v(0., 0., 0.), v(0., 0., 9.)];
    assert_abs_diff_eq!(entry_turn_penalty(v(1., 0., 0.), &pts, max), 0.0);
    assert_abs_diff_eq!(entry_turn_penalty(v(1., 0., 0.), &[], max), 0.0);
}

#[test]
fn turn_and_pitch_penalties_by_hand() {
    let max = 35f64.to_radians();
    // A 45° turn exceeds 35° by 10°: 1 + 10/35. A 30° turn is free.
    let pts = [v(0., 0., 0.), v(1., 0., 0.), v(2., 1., 0.)];
    assert_abs_diff_eq!(turn_penalty(&pts, max), 1.0 + 10.0 / 35.0, epsilon = 1e-9);
    let c = 30f64.to_radians();
    let pts = [v(0., 0., 0.), v(1., 0., 0.), v(1. + c.cos(), c.sin(), 0.)];
    assert_abs_diff_eq!(turn_penalty(&pts, max), 0.0);
    // A vertical leg between an eastward and a westward leg hides nothing: 180° turn,
    // 1 + 145/35.
    let pts = [v(0., 0., 0.), v(1., 0., 0.), v(1., 0., 1.), v(0., 0., 1.)];
    assert_abs_diff_eq!(turn_penalty(&pts, max), 1.0 + 145.0 / 35.0, epsilon = 1e-9);
    // A 45° climb exceeds 20° by 25°: 1 + 25/20; a 10° climb is free.
    let pmax = 20f64.to_radians();
    let pts = [
        v(0., 0., 0.),
        v(1., 0., 1.),
        v(2., 0., 1.0 + 10f64.to_radians().tan()),
    ];
    assert_abs_diff_eq!(pitch_penalty(&pts, pmax), 1.0 + 25.0 / 20.0, epsilon = 1e-9);
    // Both at once: the climb's 1 + 25/20 and no turn (every leg heads east).
    assert_abs_diff_eq!(
        turn_and_pitch_penalty(&pts, max, pmax),
        1.0 + 25.0 / 20.0,
        epsilon = 1e-9
    );
}

proptest::proptest! {
    /// The one pass the fitness takes is the two penalties' sum to the last bit, on paths
    /// with vertical legs and repeated points (a leg without a heading) among the others.
    #[test]
    fn turn_and_pitch_in_one_pass_are_the_two_penalties(
        pts in proptest::collection::vec((0u8..4, -500.0f64..500.0, -500.0f64..500.0, -300.0f64..300.0), 2..30),
        turn_deg in 5.0f64..90.0,
        pitch_deg in 5.0f64..60.0,
    ) {
        let mut path = vec![v(0.0, 0.0, 0.0)];
        for (kind, x, y, z) in pts {
            let last = path[path.len() - 1];
            path.push(match kind {
                0 => last,
                1 => last + v(0.0, 0.0, z),
                _ => last + v(x, y, z),
            });
        }
        let (turn, pitch) = (turn_deg.to_radians(), pitch_deg.to_radians());
        let both = turn_penalty(&path, turn) + pitch_penalty(&path, pitch);
        proptest::prop_assert_eq!(turn_and_pitch_penalty(&path, turn, pitch).to_bits(), both.to_bits());
    }

    #[test]
    fn sphere_terms_match_the_brute_force(
        pts in proptest::collection::vec((0.0f64..1000.0, 0.0f64..1000.0, 0.0f64..1000.0), 2..30),
        spheres in proptest::collection::vec((0.0f64..1000.0, 0.0f64..1000.0, 0.0f64..1000.0, 1.0f64..300.0, proptest::bool::ANY), 1..40),
        spread in 0.05f64..1.0,
    ) {
        // Paths over a part of the box too, so the grid of more than a dozen spheres culls.
        let pts: Vec<Vec3> = pts.iter().map(|p| v(p.0 * spread, p.1 * spread, p.2)).collect();
        let (mut hard, mut soft) = (Vec::new(), Vec::new());
        for s in &spheres {
            let sp = Sphere { centre: v(s.0, s.1, s.2), radius: s.3 };
            if s.4 { hard.push(sp) } else { soft.push(sp) }
        }
        let fast = sphere_terms(&pts, &hard, &soft);
        let (mut p, mut hits, mut inside) = (0.0, 0, 0.0);
        for w in pts.windows(2) {
            for s in &hard {
                let d = crate::geometry::segment_point_distance(&w[0], &w[1], &s.centre);
                if d < s.radius {
                    p += 1.0 + (s.radius - d) / s.radius;
                    hits += 1;
                }
            }
            for s in &soft {
                inside += chord_inside_sphere(&w[0], &w[1], &s.centre, s.radius);
            }
        }
        proptest::prop_assert_eq!(fast.hard_hits, hits);
        proptest::prop_assert!((fast.hard_penalty - p).abs() < 1e-9);
        proptest::prop_assert!((fast.soft_inside - inside).abs() < 1e-6);
        // The grid-culled pass gives the same terms to the last bit.
        let indexed = spheres::SphereIndex::new(&hard, &soft).terms(&pts, &hard, &soft);
        proptest::prop_assert_eq!(indexed, fast);
    }
}

#[test]
fn separation_penalty_by_hand() {
    assert_abs_diff_eq!(separation_penalty(30.0, 50.0), 1.4, epsilon = 1e-12);
    assert_abs_diff_eq!(separation_penalty(50.0, 50.0), 0.0);
    assert_abs_diff_eq!(space_term(12.5), 12.5);
}

/// The hill of `terrain::tests` (10 m, σ = 10 m, at x = 50): a leg at z = 8 goes 2 m into it,
/// 4 m short of a 2 m clearance: 1 + 4 / 2 = 3. At z = 12 it keeps exactly 2 m: no penalty. A
/// clearance under 1 m is measured against 1 m: 0.5 m required, 2 m in, 1 + 2.5 / 1.
#[test]
fn seabed_penalty_by_hand() {
    let hill = Terrain::Hills(vec![crate::terrain::Mountain {
        centre: [50.0, 0.0],
        height_m: 10.0,
        spread_m: [10.0, 10.0],
    }]);
    let low = [v(0., 0., 8.), v(100., 0., 8.)];
    let (p, legs) = seabed_penalty(&low, &hill, 2.0);
    assert_abs_diff_eq!(p, 3.0, epsilon = 1e-9);
    assert_eq!(legs, 1);
    assert_eq!(
        seabed_penalty(&[v(0., 0., 12.), v(100., 0., 12.)], &hill, 2.0),
        (0.0, 0)
    );
    assert_abs_diff_eq!(seabed_penalty(&low, &hill, 0.5).0, 3.5, epsilon = 1e-9);
    // Two legs, each over half of the hill, each short.
    let (p, legs) = seabed_penalty(&[low[0], v(50., 0., 8.), low[1]], &hill, 2.0);
    assert_abs_diff_eq!(p, 6.0, epsilon = 1e-9);
    assert_eq!(legs, 2);
}

/// An AUV of a fleet scenario whose straight line runs through a seabed hill pays the seabed
/// penalty; over it, it does not; a crawler's seabed is not a swimmer's.
#[test]
fn a_swimmer_through_the_seabed_pays_for_it() -> Result<(), crate::scenario::ScenarioError> {
    use crate::fixtures::{scenario, straight_particle, vehicle_toml};
    let hill = "[[seabed.mountains]]\ncentre = [500.0, 500.0]\nheight_m = 100.0\nspread_m = [100.0, 100.0]\n";
    let at = |z: f64| vehicle_toml("a", [0.0, 500.0, z], [1000.0, 500.0, z]);
    let through = FleetModel::new(&scenario(2000.0, hill, &[at(50.0)])?);
    let e = through.evaluate(&straight_particle(&through));
    assert!(e.vehicles[0].hard > 1.0, "{:?}", e.vehicles[0]);
    assert_eq!(e.vehicles[0].hard_hits, 0, "no obstacle was hit");
    let over = FleetModel::new(&scenario(2000.0, hill, &[at(300.0)])?);
    let e = over.evaluate(&straight_particle(&over));
    assert_eq!(e.vehicles[0].hard, 0.0, "{:?}", e.vehicles[0]);
    // Without a seabed the low line is clear.
    let open = FleetModel::new(&scenario(2000.0, "", &[at(50.0)])?);
    assert_eq!(
        open.evaluate(&straight_particle(&open)).vehicles[0].hard,
        0.0
    );
    Ok(())
}

/// The fitness takes each vehicle's own limits: the same 45° climb costs 1 + 25/20 against a
/// 20° pitch limit and 1 + 15/30 against a 30° one, as the penalties give them from degrees.
#[test]
fn each_vehicle_is_held_to_its_own_turn_and_pitch_limits(
) -> Result<(), crate::scenario::ScenarioError> {
    use crate::fixtures::{scenario, vehicle_toml};
    let a = vehicle_toml("a", [0.0, 100.0, 250.0], [200.0, 100.0, 250.0]);
    let b = vehicle_toml("b", [0.0, 900.0, 250.0], [200.0, 900.0, 250.0])
        .replace("max_pitch_deg = 20.0", "max_pitch_deg = 30.0");
    let model = FleetModel::new(&scenario(400.0, "", &[a, b])?);
    let climb = [v(0., 0., 0.), v(10., 0., 10.), v(20., 0., 10.)];
    let legs: Vec<f64> = leg_lengths(&climb).collect();
    let length: f64 = legs.iter().sum();
    for (i, pitch_deg, by_hand) in [
        (0, 20.0f64, 1.0 + 25.0 / 20.0),
        (1, 30.0, 1.0 + 15.0 / 30.0),
    ] {
        let motion = model.vehicle_terms(i, &climb, &legs, length).motion;
        assert_abs_diff_eq!(motion, by_hand, epsilon = 1e-9);
        let direct = turn_and_pitch_penalty(&climb, 35f64.to_radians(), pitch_deg.to_radians());
        assert_eq!(motion.to_bits(), direct.to_bits());
    }
    Ok(())
}

#[test]
fn early_arrival_penalty_by_hand() {
    // 300 m at 0.5 m/s at the slowest: it cannot arrive later than 600 s.
    let a = vehicle();
    assert_eq!(early_arrival_penalty(300.0, &a, 600.0), 0.0);
    assert_eq!(early_arrival_penalty(300.0, &a, 450.0), 0.0);
    // Timed for 1000 s it arrives 400 s early: 1 + 400 / 1000.
    assert_abs_diff_eq!(
        early_arrival_penalty(300.0, &a, 1000.0),
        1.4,
        epsilon = 1e-12
    );
    // Half a second early already pays (so the swarm keeps clear of the 1 s threshold).
    assert_abs_diff_eq!(
        early_arrival_penalty(300.0, &a, 600.5),
        1.0 + 0.5 / 600.5,
        epsilon = 1e-12
    );
}

/// eq. (12) added up by hand on two straight AUVs at half depth, and the early-arrival penalty
/// of a vehicle too short to arrive with a slower one.
#[test]
fn the_fleet_fitness_adds_the_weighted_terms_by_hand() -> Result<(), crate::scenario::ScenarioError>
{
    use crate::fixtures::{scenario, straight_particle, vehicle_toml};
    // a: 200 m, b: 900 m, both at z = 250 in a 500 m column, 800 m apart, mission time 400 s.
    let a = vehicle_toml("a", [0.0, 100.0, 250.0], [200.0, 100.0, 250.0]);
    let b = vehicle_toml("b", [0.0, 900.0, 250.0], [900.0, 900.0, 250.0]);
    let model = FleetModel::new(&scenario(400.0, "", &[a.clone(), b])?);
    let e = model.evaluate(&straight_particle(&model));
    // b needs 600 s at 1.5 m/s, so everyone is timed for 600 s; a at 0.5 m/s takes 400 s.
    assert_abs_diff_eq!(e.common_arrival, 600.0, epsilon = 1e-9);
    assert_abs_diff_eq!(e.trajectories.arrival(0), 400.0, epsilon = 1e-6);
    // Per vehicle: λ1·F(L) + λ2·F(D) = 0.2·1 + 0.1·0.5 = 0.25; b also λ4·F(T) = 0.1 · (600 −
    // 400) / 400 = 0.05. F(O) = F(S) = 0.
    assert_abs_diff_eq!(e.vehicles[1].time, 0.5, epsilon = 1e-9);
    assert_abs_diff_eq!(e.objective, 0.55, epsilon = 1e-9);
    // a arrives 200 s early: 1 + 200 / 600; nothing else breaks a limit.
    assert_abs_diff_eq!(e.vehicles[0].motion, 1.0 + 200.0 / 600.0, epsilon = 1e-9);
    assert_abs_diff_eq!(e.penalty, 1.0 + 200.0 / 600.0, epsilon = 1e-9);
    assert_abs_diff_eq!(e.total, 0.55 + 10.0 * (4.0 / 3.0), epsilon = 1e-9);
    // With b 300 m long both arrive at the mission time: no penalty, no F(T).
    let b = vehicle_toml("b", [0.0, 900.0, 250.0], [300.0, 900.0, 250.0]);
    let model = FleetModel::new(&scenario(400.0, "", &[a, b])?);
    let e = model.evaluate(&straight_particle(&model));
    assert_abs_diff_eq!(e.common_arrival, 400.0, epsilon = 1e-9);
    assert_abs_diff_eq!(e.objective, 0.5, epsilon = 1e-9);
    assert_eq!(e.penalty, 0.0);
    assert_abs_diff_eq!(e.total, 0.5, epsilon = 1e-9);
    Ok(())
}

/// `x` with vehicle `i`'s chromosome taken from `other`, scored as a change of `base` (the
/// evaluation of `x`) and as a whole: asserts both agree to the last bit and returns the whole.
fn change_scores_as_a_whole(
    model: &FleetModel,
    base: &FleetEvaluation,
    x: &[f64],
    other: &[f64],
    i: usize,
) -> FleetEvaluation {
    let mut y = x.to_vec();
    let r = model.layout.chromosome(i);
    y[r.clone()].copy_from_slice(&other[r]);
    let whole = model.evaluate(&y);
    let changed = model.evaluate_change(base, &y, i);
    assert_eq!(changed.total.to_bits(), whole.total.to_bits());
    assert_eq!(changed.vehicles, whole.vehicles);
    assert_eq!(changed.trajectories, whole.trajectories);
    assert_eq!(changed.pairs, whole.pairs);
    assert_eq!(changed.penalty.to_bits(), whole.penalty.to_bits());
    whole
}

#[test]
fn changing_one_vehicle_scores_as_a_whole_evaluation_to_the_last_bit(
) -> Result<(), crate::scenario::ScenarioError> {
    use crate::swarm::Problem;
    use rand::SeedableRng;
    let model = FleetModel::new(&crate::fixtures::crossing_fleet()?);
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    let (mut incremental, mut breaches) = (0, 0);
    for _ in 0..40 {
        let x = model.sample(&mut rng);
        let base = model.evaluate(&x);
        for i in 0..model.layout.vehicles {
            let whole = change_scores_as_a_whole(&model, &base, &x, &model.sample(&mut rng), i);
            incremental += usize::from(whole.common_arrival == base.common_arrival);
            breaches += usize::from(whole.separation_penalty > 0.0);
        }
    }
    // Both ways through evaluate_change were taken, and pairs did breach.
    assert!(incremental > 20 && incremental < 320, "{incremental}");
    assert!(breaches > 20, "{breaches}");
    Ok(())
}

/// Eight AUVs in lanes 90 m apart, each on its straight line with every waypoint moved up to
/// 40 m: neighbours can come closer than d_min, lanes farther apart never can, so a change
/// measures only the vehicles whose whole trajectories come near.
#[test]
fn changing_one_vehicle_among_far_lanes_scores_as_a_whole_evaluation_to_the_last_bit(
) -> Result<(), crate::scenario::ScenarioError> {
    use crate::fixtures::{scenario, straight_particle, vehicle_toml};
    use rand::{Rng, SeedableRng};
    let lanes: Vec<String> = (0..8)
        .map(|k| {
            let y = 80.0 + 90.0 * k as f64;
            vehicle_toml(&format!("v{k}"), [50.0, y, 250.0], [950.0, y, 250.0])
        })
        .collect();
    let model = FleetModel::new(&scenario(900.0, "", &lanes)?);
    let straight = straight_particle(&model);
    let mut rng = rand::rngs::StdRng::seed_from_u64(11);
    // Coordinates moved by up to 40 m, speeds anywhere in their range.
    let moved = |rng: &mut rand::rngs::StdRng| -> Vec<f64> {
        let (m, len) = (model.layout.waypoints, model.layout.chromosome_len());
        (straight
            .iter()
            .zip(model.lower.iter().zip(&model.upper))
            .enumerate())
        .map(|(g, (x, (lo, hi)))| {
            if g % len >= 3 * m {
                rng.random_range(*lo..=*hi)
            } else {
                (x + rng.random_range(-40.0..40.0)).clamp(*lo, *hi)
            }
        })
        .collect()
    };
    let mut breaches = 0;
    for _ in 0..30 {
        let x = moved(&mut rng);
        let base = model.evaluate(&x);
        for i in 0..model.layout.vehicles {
            let whole = change_scores_as_a_whole(&model, &base, &x, &moved(&mut rng), i);
            breaches += usize::from(whole.separation_penalty > 0.0);
        }
    }
    assert!(breaches > 20, "{breaches}");
    Ok(())
}
