//! Unit tests of the comparison: cells in seed order, the significance rows, the swarms' own plans.

use super::*;
use std::path::Path;

/// Two AUVs crossing a 1 km box, on a tiny budget.
fn two_auvs() -> Scenario {
    let auv = |id: &str, start: [f64; 3], goal: [f64; 3]| {
        format!(
                "[[vehicles]]\nid = \"{id}\"\nkind = \"auv\"\nstart = {start:?}\ngoal = {goal:?}\n\
                 speed_min_mps = 0.5\nspeed_max_mps = 1.5\nmax_turn_deg = 35.0\nmax_pitch_deg = 20.0\n"
            )
    };
    let text = format!(
        "name = \"pair\"\n[bounds]\nmin = [0.0, 0.0, 0.0]\nmax = [1000.0, 1000.0, 500.0]\n{}{}\
             [fleet]\nd_min_m = 50.0\nmission_time_s = 1000.0\n\
             [optimizer]\nwaypoints = 4\nparticles = 10\niterations = 5\n",
        auv("a", [100.0, 100.0, 100.0], [900.0, 900.0, 100.0]),
        auv("b", [100.0, 900.0, 100.0], [900.0, 100.0, 100.0]),
    );
    match Scenario::parse(&text, Path::new("pair.toml")) {
        Ok(s) => s,
        Err(e) => panic!("fixture does not parse: {e}"),
    }
}

#[test]
fn cells_hold_every_seeds_fitness_in_seed_order_and_their_median_and_range() {
    let scenario = two_auvs();
    let mut seen: Vec<(String, u64, f64)> = Vec::new();
    let cells = compare(
        std::slice::from_ref(&scenario),
        &[Algorithm::Pso, Algorithm::APso],
        1..4,
        None,
        &Arc::new(AtomicBool::new(false)),
        &mut |p| seen.push((p.algorithm.clone(), p.seed, p.fitness)),
    )
    .unwrap_or_else(|e| panic!("compare failed: {e}"));
    // Each algorithm alone, then refined.
    assert_eq!(cells.len(), 4);
    assert_eq!(seen.len(), 6);
    let modes: Vec<&str> = cells.iter().map(|c| c.mode.as_str()).collect();
    assert_eq!(
        modes,
        [
            "in-process",
            "in-process+refine",
            "in-process",
            "in-process+refine"
        ]
    );
    for pair in cells.chunks(2) {
        for (alone, refined) in pair[0].fitness.iter().zip(&pair[1].fitness) {
            assert!(refined <= alone, "{refined} > {alone}");
        }
    }
    let alone: Vec<&Cell> = cells.iter().step_by(2).collect();
    for (c, name) in alone.into_iter().zip(["pso", "a-pso"]) {
        let own: Vec<&(String, u64, f64)> = seen.iter().filter(|s| s.0 == name).collect();
        assert_eq!(own.iter().map(|s| s.1).collect::<Vec<_>>(), [1, 2, 3]);
        let fitness: Vec<f64> = own.iter().map(|s| s.2).collect();
        assert_eq!(c.fitness, fitness);
        assert_eq!((c.runs, c.mode.as_str()), (3, "in-process"));
        let mut sorted = fitness.clone();
        sorted.sort_by(f64::total_cmp);
        assert_eq!(c.median_fitness(), sorted[1]);
        assert_eq!(c.fitness_range(), (sorted[0], sorted[2]));
    }
    // The first algorithm named is the reference of the significance rows, alone and refined.
    let rows = crate::report::significance::significance(&cells);
    assert_eq!(rows.len(), 2);
    for (row, mode) in rows.iter().zip(["in-process", "in-process+refine"]) {
        assert_eq!(
            (row.reference, row.other, row.mode.as_str()),
            (Algorithm::Pso, Algorithm::APso, mode)
        );
    }
}

/// `compare` measures the algorithms themselves: a plan the swarm leaves over a limit is
/// not touched up there, whatever the scenario says (the refined rows beside them refine the
/// same swarm plans without touching them up).
#[test]
fn compare_measures_the_swarms_own_plans_without_the_touch_up() {
    // Scenario 3 on a budget of 3 iterations of 10 particles: plans that break limits.
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/amp-pso-3.toml");
    let mut scenario = Scenario::load(Path::new(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
    scenario.optimizer.iterations = 3;
    scenario.optimizer.particles = 10;
    assert!(scenario.optimizer.touch_up, "the file's default");
    let cells = compare(
        std::slice::from_ref(&scenario),
        &[Algorithm::Pso],
        1..4,
        None,
        &Arc::new(AtomicBool::new(false)),
        &mut |_| {},
    )
    .unwrap_or_else(|e| panic!("compare failed: {e}"));
    let mut touched_differs = 0;
    for seed in 1..4u64 {
        let mut s = scenario.clone();
        s.optimizer.algorithm = Algorithm::Pso;
        s.optimizer.seed = seed;
        s.optimizer.refine = false;
        let touched = crate::planning::planner::plan_in_process(&s, None, &mut |_| {});
        s.optimizer.touch_up = false;
        let own = crate::planning::planner::plan_in_process(&s, None, &mut |_| {});
        assert_eq!(
            cells[0].fitness[seed as usize - 1],
            own.fitness,
            "seed {seed}"
        );
        if touched.fitness < own.fitness {
            touched_differs += 1;
        }
    }
    // The swarm's plans break limits and `plan` would touch them up, so the equality above
    // is not trivial.
    assert!(touched_differs > 0);
}

#[test]
fn a_raised_stop_returns_the_cells_completed_so_far() {
    let scenario = two_auvs();
    let cells = compare(
        &[scenario],
        &[Algorithm::Pso],
        1..3,
        None,
        &Arc::new(AtomicBool::new(true)),
        &mut |_| {},
    )
    .unwrap_or_else(|e| panic!("compare failed: {e}"));
    assert!(cells.is_empty());
}

/// A scenario of crawlers alone has nothing the refinement touches: one row per algorithm,
/// not a refined copy of it.
#[test]
fn crawlers_alone_get_no_refined_rows() -> Result<(), Box<dyn std::error::Error>> {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/ipso-dsmv.toml");
    let mut s = Scenario::load(Path::new(file))?;
    s.optimizer.iterations = 5;
    let cells = compare(
        std::slice::from_ref(&s),
        &[Algorithm::Ipso],
        1..2,
        None,
        &Arc::new(AtomicBool::new(false)),
        &mut |_| {},
    )?;
    let modes: Vec<&str> = cells.iter().map(|c| c.mode.as_str()).collect();
    assert_eq!(modes, ["in-process"]);
    Ok(())
}
