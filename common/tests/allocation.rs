//! The swarm's fitness calls allocate nothing once their buffers have grown: a counting global
//! allocator (this test binary's own) counts every allocation made while the fitness scores
//! random fleets it has scored before.

use std::alloc::System;
use std::path::Path;

use rand::rngs::StdRng;
use rand::SeedableRng;
use shoal_common::cost::FleetModel;
use shoal_common::scenario::Scenario;
use shoal_common::swarm::Problem;
use stats_alloc::{Region, StatsAlloc, INSTRUMENTED_SYSTEM};

#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

/// Allocations and reallocations made while `f` runs (by any thread: this binary's one test
/// scores on its own thread, and nothing else runs meanwhile).
fn allocations_during(f: impl FnOnce()) -> usize {
    let region = Region::new(GLOBAL);
    f();
    let change = region.change();
    change.allocations + change.reallocations
}

/// `n` AUVs crossing a 3 km box both ways and `spheres` hard and soft spheres on a grid in the
/// middle: above five vehicles and twelve spheres, so both broad phases run.
fn crossing(n: usize, spheres: usize) -> Result<Scenario, Box<dyn std::error::Error>> {
    let mut text = String::from(
        "name = \"allocation\"\n[bounds]\nmin = [0.0, 0.0, 0.0]\nmax = [3000.0, 3000.0, 600.0]\n\
         [fleet]\nd_min_m = 50.0\nmission_time_s = 2500.0\n[optimizer]\nwaypoints = 8\n",
    );
    for k in 0..spheres {
        let (x, y) = (
            900.0 + 300.0 * (k % 5) as f64,
            600.0 + 400.0 * (k / 5) as f64,
        );
        let kind = if k % 2 == 0 { "hard" } else { "soft" };
        text += &format!(
            "[[obstacles]]\nid = \"o{k}\"\nkind = \"{kind}\"\ncentre = [{x:?}, {y:?}, 300.0]\n\
             radius_m = 60.0\ninflation_m = 10.0\n"
        );
    }
    for k in 0..n {
        let y = 100.0 + 2800.0 * k as f64 / n as f64;
        let (from, to) = if k % 2 == 0 {
            (50.0, 2950.0)
        } else {
            (2950.0, 50.0)
        };
        text += &format!(
            "[[vehicles]]\nid = \"v{k}\"\nkind = \"auv\"\nstart = [{from:?}, {y:?}, 200.0]\n\
             goal = [{to:?}, {:?}, 400.0]\nspeed_min_mps = 0.5\nspeed_max_mps = 2.0\n\
             max_turn_deg = 35.0\nmax_pitch_deg = 20.0\n",
            3000.0 - y
        );
    }
    Ok(Scenario::parse(&text, Path::new("allocation.toml"))?)
}

/// Allocations made while scoring every particle of `particles` once more, after a first pass
/// over them has grown every buffer.
fn allocations_of_a_second_pass(model: &FleetModel, particles: &[Vec<f64>]) -> usize {
    let mut parts = vec![0.0; model.blocks()];
    for x in particles {
        model.cost_parts(x, &mut parts);
    }
    allocations_during(|| {
        for x in particles {
            model.cost_parts(x, &mut parts);
        }
    })
}

#[test]
fn scoring_fleets_allocates_nothing_once_warm() -> Result<(), Box<dyn std::error::Error>> {
    for (vehicles, spheres) in [(3, 4), (24, 16)] {
        let model = FleetModel::new(&crossing(vehicles, spheres)?);
        let mut rng = StdRng::seed_from_u64(7);
        let particles: Vec<Vec<f64>> = (0..100).map(|_| model.sample(&mut rng)).collect();
        assert_eq!(
            allocations_of_a_second_pass(&model, &particles),
            0,
            "{vehicles} vehicles"
        );
        // The counter counts: a whole evaluation returned by value allocates.
        let mut total = 0.0;
        assert!(allocations_during(|| total = model.evaluate(&particles[0]).total) > 0);
        assert_eq!(total, model.cost(&particles[0]));
    }
    Ok(())
}
