//! Seed 003's cage-inspection tours behind the `plan` contract: the inspection points are shared
//! among the scenario's AUVs (balanced tour lengths), each AUV's tour is ordered by the
//! swap-operator PSO and its legs planned by the scenario's leg swarm (DE-PSO, LDIW-PSO or
//! LCPSO), and the tours are timed so every AUV is back at its base at the same instant.
//!
//! Each vehicle's tour is planned on its own thread here; the vehicles interact only through the
//! separation check of the timed trajectories, which `assess` reports like for any plan.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Instant;

use shoal_common::geometry::Vec3;
use shoal_common::plan::{assess, Plan};
use shoal_common::scenario::{Algorithm, FirstPointMode, InspectionSettings, Scenario};
use shoal_common::swarm::multi::stream_seed;
use shoal_common::swarm::IterationReport;
use shoal_common::tour::{
    inspection_points, plan_tour, split_points, Cage, FirstPoint, InspectionPoint, LegAlgorithm,
    LegSettings, SwapPso, TourFigures, TourPlan, TourSettings,
};
use shoal_common::trajectory::Trajectory;

use crate::energy_planner::unplannable;

/// The leg swarm of an algorithm.
pub fn leg_algorithm(a: Algorithm) -> Option<LegAlgorithm> {
    match a {
        Algorithm::DePso => Some(LegAlgorithm::DePso),
        Algorithm::LdiwPso => Some(LegAlgorithm::LdiwPso),
        Algorithm::Lcpso => Some(LegAlgorithm::Lcpso),
        _ => None,
    }
}

/// The cages (physical radius, for the inspection points) and their ids.
fn cages(scenario: &Scenario, inspection: &InspectionSettings) -> Vec<(Cage, f64)> {
    inspection
        .cage_indices(scenario)
        .into_iter()
        .map(|i| {
            let o = &scenario.obstacles[i];
            (
                Cage {
                    id: o.id.clone(),
                    centre: o.centre(),
                    radius_m: o.radius_m,
                },
                o.inflation_m,
            )
        })
        .collect()
}

/// Which share of the points each vehicle flies: one share per vehicle from
/// [`split_points`] around the fleet's mean base, then shares matched to vehicles so that the
/// longest straight tour from each vehicle's own base is shortest (every matching for up to 7
/// vehicles, greedily beyond).
fn shares(points: &[InspectionPoint], bases: &[Vec3]) -> Vec<Vec<usize>> {
    let n = bases.len();
    if n <= 1 {
        return vec![(0..points.len()).collect()];
    }
    let centre = bases.iter().fold(Vec3::zeros(), |a, b| a + b) / n as f64;
    let groups = split_points(points, centre, n);
    let cost = |v: usize, g: &[usize]| {
        let pts: Vec<Vec3> = g.iter().map(|&k| points[k].position).collect();
        shoal_common::tour::short_tour(bases[v], &pts).1
    };
    let table: Vec<Vec<f64>> = (0..n)
        .map(|v| groups.iter().map(|g| cost(v, g)).collect())
        .collect();
    let mut best: Vec<usize> = (0..n).collect();
    if n <= 7 {
        let mut perm: Vec<usize> = (0..n).collect();
        let worst = |p: &[usize]| (0..n).map(|v| table[v][p[v]]).fold(0.0, f64::max);
        let mut best_worst = worst(&perm);
        // Heap's algorithm over every matching.
        let mut c = vec![0; n];
        let mut i = 0;
        while i < n {
            if c[i] < i {
                if i % 2 == 0 {
                    perm.swap(0, i);
                } else {
                    perm.swap(c[i], i);
                }
                let w = worst(&perm);
                if w < best_worst {
                    best_worst = w;
                    best.clone_from(&perm);
                }
                c[i] += 1;
                i = 0;
            } else {
                c[i] = 0;
                i += 1;
            }
        }
    }
    best.into_iter().map(|g| groups[g].clone()).collect()
}

/// Plans the scenario's inspection tours.
pub fn plan(
    scenario: &Scenario,
    _stop: Option<Arc<AtomicBool>>,
    observe: &mut dyn FnMut(&IterationReport),
) -> Plan {
    let started = Instant::now();
    let o = &scenario.optimizer;
    let (Some(inspection), Some(algorithm)) = (&scenario.inspection, leg_algorithm(o.algorithm))
    else {
        return unplannable(
            scenario,
            format!(
                "{} needs an [inspection] table and a tour algorithm (de-pso, ldiw-pso, lcpso)",
                scenario.name
            ),
        );
    };
    let cages = cages(scenario, inspection);
    let physical: Vec<Cage> = cages.iter().map(|(c, _)| c.clone()).collect();
    // The legs keep each cage's own clearance: the spheres they avoid are radius + inflation.
    let inflated: Vec<Cage> = cages
        .iter()
        .map(|(c, inflation)| Cage {
            radius_m: c.radius_m + inflation,
            ..c.clone()
        })
        .collect();
    let bases: Vec<Vec3> = scenario.vehicles.iter().map(|v| v.start()).collect();
    let centre = bases.iter().fold(Vec3::zeros(), |a, b| a + b) / bases.len().max(1) as f64;
    let first = match inspection.first_point {
        FirstPointMode::TowardBase => FirstPoint::Toward(centre),
        FirstPointMode::Random => FirstPoint::Random {
            seed: stream_seed(o.seed, 1000),
        },
    };
    let points = inspection_points(&physical, inspection.standoff_m, first);
    let shares = shares(&points, &bases);
    let b = &scenario.bounds;
    let bounds = (Vec3::from(b.min), Vec3::from(b.max));
    let settings = TourSettings {
        order: SwapPso {
            particles: inspection.order_particles,
            iterations: inspection.order_iterations,
            ..SwapPso::table3(0)
        },
        leg: LegSettings {
            particles: o.particles,
            iterations: o.iterations,
            waypoints: o.waypoints,
            clearance_m: 0.0,
        },
    };
    let n = scenario.vehicles.len();
    let tours: Vec<TourPlan> = std::thread::scope(|s| {
        let handles: Vec<_> = shares
            .iter()
            .enumerate()
            .map(|(v, share)| {
                let mine: Vec<InspectionPoint> = share.iter().map(|&k| points[k]).collect();
                let (inflated, settings) = (&inflated, &settings);
                let base = bases[v];
                s.spawn(move || {
                    plan_tour(
                        base,
                        &mine,
                        inflated,
                        bounds,
                        algorithm,
                        settings,
                        stream_seed(o.seed, v as u64),
                    )
                })
            })
            .collect();
        handles
            .into_iter()
            .enumerate()
            .map(|(v, h)| {
                let t = h.join().unwrap_or_else(|_| TourPlan {
                    order: Vec::new(),
                    path: vec![bases[v]],
                    leg_lengths: Vec::new(),
                    tour_length_m: 0.0,
                    straight_tour_length_m: 0.0,
                    growth_m: 0.0,
                    growth_rate: 0.0,
                    cage_intersections: 0,
                });
                observe(&IterationReport {
                    iteration: v + 1,
                    max_iterations: n,
                    best_cost: t.tour_length_m,
                    evaluations: 0,
                });
                t
            })
            .collect()
    });
    // Common return time: the slowest tour at its vehicle's top speed; faster vehicles slow
    // down (not below their slowest speed) and hold at the base for what is left.
    let finish = scenario
        .vehicles
        .iter()
        .zip(&tours)
        .map(|(v, t)| t.tour_length_m / v.speed_max_mps)
        .fold(0.0, f64::max);
    let trajectories: Vec<Trajectory> = scenario
        .vehicles
        .iter()
        .zip(&tours)
        .map(|(v, t)| {
            let speed = if finish > 0.0 {
                (t.tour_length_m / finish).clamp(v.speed_min_mps, v.speed_max_mps)
            } else {
                v.speed_max_mps
            };
            let mut times = Vec::with_capacity(t.path.len() + 1);
            let mut clock = 0.0;
            for (k, p) in t.path.iter().enumerate() {
                if k > 0 {
                    clock += (p - t.path[k - 1]).norm() / speed;
                }
                times.push(clock);
            }
            let mut points = t.path.clone();
            if clock < finish {
                times.push(finish);
                points.push(*t.path.last().unwrap_or(&v.start()));
            }
            Trajectory { times, points }
        })
        .collect();
    let mut assessment = assess(scenario, &trajectories);
    let label = |k: usize| format!("{}.{}", physical[points[k].cage].id, k % 2 + 1);
    for ((vp, t), share) in assessment.vehicles.iter_mut().zip(&tours).zip(&shares) {
        let visited: Vec<usize> = t.order.iter().map(|&k| share[k]).collect();
        vp.tour = Some(TourFigures {
            order: visited.iter().map(|&k| label(k)).collect(),
            points: visited.iter().map(|&k| points[k].position.into()).collect(),
            tour_length_m: t.tour_length_m,
            straight_tour_length_m: t.straight_tour_length_m,
            growth_m: t.growth_m,
            growth_rate: t.growth_rate,
            leg_lengths_m: t.leg_lengths.clone(),
            cage_intersections: t.cage_intersections,
        });
        if t.cage_intersections > 0 {
            assessment.violations.push(format!(
                "{}'s tour crosses a cage's clearance sphere {} times",
                vp.id, t.cage_intersections
            ));
        }
    }
    let total: f64 = tours.iter().map(|t| t.tour_length_m).sum();
    let penalty = tours.iter().map(|t| t.cage_intersections).sum::<usize>() as f64;
    let mut notices = Vec::new();
    if n > 1 {
        notices.push(format!(
            "{} inspection points shared among {n} AUVs; every AUV is back at its base at {finish:.0} s",
            points.len()
        ));
    }
    Plan {
        scenario: scenario.name.clone(),
        algorithm: o.algorithm.as_str().to_string(),
        mode: "in-process".to_string(),
        seed: o.seed,
        runtime_s: started.elapsed().as_secs_f64(),
        fitness: total + o.penalty_weight * penalty,
        objective: total,
        penalty,
        feasible: assessment.violations.is_empty(),
        violations: assessment.violations,
        notices,
        mission_time_s: scenario.fleet.mission_time_s,
        common_arrival_s: finish,
        d_min_m: scenario.fleet.d_min_m,
        iterations: o.iterations,
        evaluations: 0,
        termination: "MaxIterations".to_string(),
        vehicles: assessment.vehicles,
        fleet: assessment.fleet,
        convergence: Vec::new(),
        distributed: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(cage: usize, x: f64, y: f64) -> InspectionPoint {
        InspectionPoint {
            cage,
            position: Vec3::new(x, y, 0.0),
        }
    }

    #[test]
    fn shares_go_to_the_nearer_base_and_cover_every_point_once() {
        // Two clusters, one by each base: each vehicle gets the cluster at its own base whatever
        // order the split returns them in.
        let points = [
            at(0, 10.0, 0.0),
            at(0, 12.0, 2.0),
            at(1, 990.0, 0.0),
            at(1, 988.0, 2.0),
        ];
        let bases = [Vec3::new(1000.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 0.0)];
        let s = shares(&points, &bases);
        assert_eq!(s.len(), 2);
        let mut first = s[0].clone();
        first.sort();
        let mut second = s[1].clone();
        second.sort();
        assert_eq!((first, second), (vec![2, 3], vec![0, 1]));
        // One vehicle takes everything.
        assert_eq!(shares(&points, &bases[..1]), vec![vec![0, 1, 2, 3]]);
    }

    #[test]
    fn only_tour_algorithms_have_a_leg_swarm() {
        assert_eq!(leg_algorithm(Algorithm::DePso), Some(LegAlgorithm::DePso));
        assert_eq!(leg_algorithm(Algorithm::Lcpso), Some(LegAlgorithm::Lcpso));
        assert_eq!(leg_algorithm(Algorithm::AmpPso), None);
    }
}
