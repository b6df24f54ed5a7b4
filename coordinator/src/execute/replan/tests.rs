use super::*;

fn line(t0: f64, t1: f64) -> Trajectory {
    Trajectory {
        times: vec![t0, t1],
        points: vec![Vec3::new(0.0, 0.0, 100.0), Vec3::new(1000.0, 0.0, 100.0)],
    }
}

#[test]
fn the_warm_start_is_the_rest_of_the_plan_evenly_spaced() {
    // 1000 m in 1000 s; from t0 = 200 the rest is 800 m in 800 s from x = 200.
    let g = warm_chromosome(
        &line(0.0, 1000.0),
        200.0,
        Vec3::new(200.0, 0.0, 100.0),
        3,
        (0.5, 2.0),
    );
    assert_eq!(g.len(), 12);
    for (k, x) in [400.0, 600.0, 800.0].iter().enumerate() {
        assert!((g[3 * k] - x).abs() < 1e-9, "{g:?}");
        assert!(g[3 * k + 1].abs() < 1e-9);
    }
    // 1 m/s, inside the range.
    assert!(g[9..].iter().all(|v| (v - 1.0).abs() < 1e-9), "{g:?}");
}

/// The shipped scenario 1.
fn scenario_1() -> Result<Scenario, Box<dyn std::error::Error>> {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/amp-pso-1.toml");
    Ok(Scenario::load(std::path::Path::new(file))?)
}

/// Every vehicle of `s` straight from its start to its goal in 2100 s.
fn straight_plans(s: &Scenario) -> Vec<Trajectory> {
    s.vehicles
        .iter()
        .map(|v| Trajectory {
            times: vec![0.0, 2100.0],
            points: vec![v.start(), v.goal()],
        })
        .collect()
}

#[test]
fn a_raised_stop_flag_ends_the_swarm_long_before_its_budget(
) -> Result<(), Box<dyn std::error::Error>> {
    let s = scenario_1()?;
    let plans = straight_plans(&s);
    let stop = Arc::new(AtomicBool::new(true));
    let r = Request {
        scenario: &s,
        vehicle: 0,
        t0: 100.0,
        p0: plans[0].position_at(100.0),
        heading: None,
        current: &plans[0],
        resume_s: None,
        others: &plans,
        arrival_s: 2100.0,
        budget: Duration::from_secs(5),
        separation_buffer_m: 10.0,
        seed: 1,
        ground: None,
        stop: Some(Arc::clone(&stop)),
    };
    let out = replan(&r);
    // It still answers: the warm start, the rest of the straight plan.
    assert_eq!(out.trajectory.points.len(), s.optimizer.waypoints + 2);
    // Not raised, the swarm runs to its budget or its iteration cap: 818 ms against 3.9 ms
    // stopped (266 ms when the flag stopped only the swarm: the coarse way round's search,
    // 263 ms of that, stops for it too).
    stop.store(false, Ordering::Relaxed);
    let full = replan(&r);
    assert!(
        out.elapsed * 20 < full.elapsed,
        "stopped {:?}, not stopped {:?}",
        out.elapsed,
        full.elapsed
    );
    Ok(())
}

#[test]
fn a_waypoint_inside_an_obstacle_is_pushed_sideways() -> Result<(), Box<dyn std::error::Error>> {
    let mut s = scenario_1()?;
    s.obstacles = vec![shoal_common::scenario::Obstacle {
        id: "new".into(),
        kind: shoal_common::scenario::ObstacleKind::Hard,
        centre: [500.0, 0.0, 100.0],
        radius_m: 40.0,
        inflation_m: 50.0,
    }];
    let mut g = vec![
        250.0, 0.0, 100.0, 500.0, 0.0, 100.0, 750.0, 0.0, 100.0, 1.0, 1.0, 1.0,
    ];
    push_out_of_obstacles(&mut g, &s, 3);
    // The middle one is on the path through the centre: pushed horizontally across it, to
    // 1.4 × 90 m from the centre; the others are outside 1.4 r and stay.
    let p = Vec3::new(g[3], g[4], g[5]);
    assert!(
        ((p - Vec3::new(500.0, 0.0, 100.0)).norm() - 126.0).abs() < 1e-9,
        "{p}"
    );
    assert!(
        (p.x - 500.0).abs() < 1e-9 && (p.z - 100.0).abs() < 1e-9,
        "{p}"
    );
    assert_eq!(&g[0..3], &[250.0, 0.0, 100.0]);
    assert_eq!(&g[6..9], &[750.0, 0.0, 100.0]);
    Ok(())
}

fn candidate(hits: usize, separation: f64, motion: f64, total: f64) -> VehicleEvaluation {
    VehicleEvaluation {
        trajectory: line(0.0, 1.0),
        terms: shoal_common::cost::VehicleTerms {
            hard_hits: hits,
            motion,
            ..Default::default()
        },
        min_separation: separation,
        total,
    }
}

#[test]
fn the_answer_is_safe_then_flyable_then_cheapest() {
    // (swarm's best, the one warm start, which wins), each as (hits, separation, motion
    // penalty, cost); d_min 50 m.
    let cases = [
        // The swarm's best is safe and clean: it is the answer.
        ((0, 80.0, 0.0, 1.0), (0, 80.0, 0.0, 3.0), 1.0),
        // It grazes an obstacle, or comes within d_min: the safe warm start wins.
        ((1, 80.0, 0.0, 1.0), (0, 80.0, 0.0, 3.0), 3.0),
        ((0, 49.0, 0.0, 1.0), (0, 80.0, 0.0, 3.0), 3.0),
        // Safe with one slight turn violation (1.1): within the slack of the clean one.
        ((0, 80.0, 1.1, 1.0), (0, 80.0, 0.0, 3.0), 1.0),
        // Safe but a string of reversals (9.0): the clean warm start wins.
        ((0, 80.0, 9.0, 1.0), (0, 80.0, 0.0, 3.0), 3.0),
        // Nothing safe: the swarm's best, reported unsafe by the caller.
        ((2, 80.0, 0.0, 1.0), (1, 80.0, 0.0, 3.0), 1.0),
    ];
    for (swarm, warm, expected) in cases {
        let c = |(h, s, m, t)| candidate(h, s, m, t);
        let all = [c(swarm), c(warm)];
        let got = all[choose(&all, &[50.0])].total;
        assert_eq!(got, expected, "swarm {swarm:?}, warm {warm:?}");
    }
}

#[test]
fn a_candidate_that_keeps_the_buffer_beats_one_that_only_keeps_d_min() {
    // d_min 50 m, buffer 10 m: (swarm's best, warm start) as (separation, cost).
    let c = |s: f64, t: f64| candidate(0, s, 0.0, t);
    let pick = |swarm: (f64, f64), warm: (f64, f64)| {
        let all = [c(swarm.0, swarm.1), c(warm.0, warm.1)];
        all[choose(&all, &[60.0, 50.0])].total
    };
    // The cheaper answer grazes d_min (52 m); the dearer one keeps 61 m: it wins.
    assert_eq!(pick((52.0, 1.0), (61.0, 3.0)), 3.0);
    // Both keep the buffer: the cheaper wins.
    assert_eq!(pick((65.0, 1.0), (61.0, 3.0)), 1.0);
    // Neither keeps it; both keep d_min: the cheaper wins rather than nothing.
    assert_eq!(pick((52.0, 1.0), (55.0, 3.0)), 1.0);
    // Only one keeps d_min: it wins.
    assert_eq!(pick((49.0, 1.0), (55.0, 3.0)), 3.0);
}

/// The chosen answer is pulled tight by the refinement when the scenario asks for it, and left
/// as it is when it does not: a level path bowed 150 m off the rest of a straight plan comes
/// back within a metre of the straight line, as safe as it was.
#[test]
fn the_chosen_answer_is_refined_within_the_budget_unless_turned_off(
) -> Result<(), Box<dyn std::error::Error>> {
    let mut s = scenario_1()?;
    s.obstacles.clear();
    // Level, so the straight line keeps the pitch limit and the bowed path breaks nothing.
    s.vehicles[0].goal[2] = s.vehicles[0].start[2];
    // Length the only term: the depth term alone would trade length for a shallower path.
    s.optimizer.weights = [1.0, 0.0, 0.0, 0.0, 0.0];
    let plans = straight_plans(&s);
    let model = FleetModel::new(&s);
    let problem = VehicleProblem::new(&model, 0, &plans, 2100.0).early_arrival_allowed();
    let v = &s.vehicles[0];
    let m = s.optimizer.waypoints;
    let mut genes = warm_chromosome(
        &plans[0],
        0.0,
        v.start(),
        m,
        (v.speed_min_mps, v.speed_max_mps),
    );
    let across = (v.goal() - v.start()).cross(&Vec3::z()).normalize();
    for j in 0..m {
        let bow = 150.0 * (std::f64::consts::PI * (j + 1) as f64 / (m + 1) as f64).sin();
        for c in 0..3 {
            genes[3 * j + c] += bow * across[c];
        }
    }
    let chosen = problem.evaluate(&genes);
    let straight = (v.goal() - v.start()).norm();
    let penalties = |e: &VehicleEvaluation| e.terms.hard + e.terms.motion + e.terms.separation;
    assert_eq!(penalties(&chosen), 0.0);
    let mut r = Request {
        scenario: &s,
        vehicle: 0,
        t0: 0.0,
        p0: v.start(),
        heading: None,
        current: &plans[0],
        resume_s: None,
        others: &plans,
        arrival_s: 2100.0,
        budget: Duration::from_secs(2),
        separation_buffer_m: 0.0,
        seed: 1,
        ground: None,
        stop: None,
    };
    let tightened = |r: &Request, started: Instant| {
        tighten(&problem, &genes, chosen.clone(), r, started, &[50.0])
    };
    let refined = tightened(&r, Instant::now());
    let length =
        |e: &VehicleEvaluation| shoal_common::geometry::polyline_length(&e.trajectory.points);
    assert!(
        refined.total < chosen.total,
        "{} against {}",
        refined.total,
        chosen.total
    );
    assert!(
        length(&refined) < straight + 1.0 && length(&chosen) > straight + 20.0,
        "{} against {}, straight {}",
        length(&refined),
        length(&chosen),
        straight
    );
    assert_eq!(penalties(&refined), 0.0);
    assert!(is_safe(&refined, 50.0) && is_safe(&chosen, 50.0));
    let mut off = s.clone();
    off.optimizer.refine = false;
    r.scenario = &off;
    assert_eq!(tightened(&r, Instant::now()).total, chosen.total);
    // A budget already spent leaves the answer as it was, too.
    r.scenario = &s;
    let late = tightened(&r, Instant::now() - r.budget);
    assert_eq!(late.total, chosen.total);
    Ok(())
}
