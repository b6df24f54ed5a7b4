//! Hu et al.'s cage-inspection tours behind the `plan` contract: the inspection points are shared
//! among the scenario's AUVs (balanced tour lengths), each AUV's tour is ordered by the
//! swap-operator PSO and its legs planned by the scenario's leg swarm (DE-PSO, LDIW-PSO or
//! LCPSO), and the tours are timed so every AUV is back at its base at the same instant.
//!
//! Each vehicle's tour is planned on its own thread here, or by its agent in a distributed run
//! (`distributed::mission::tours`); [`assemble`] turns either into the plan. The vehicles
//! interact only through the separation check of the timed trajectories, which `assess` reports
//! like for any plan.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Instant;

use shoal_common::geometry::Vec3;
use shoal_common::plan::{assess, Plan};
use shoal_common::scenario::Scenario;
use shoal_common::swarm::IterationReport;
use shoal_common::tour::{summed_curve, FleetTours, TourFigures, TourPlan};
use shoal_common::trajectory::Trajectory;

use crate::planning::energy::unplannable;
use crate::report::tour_gap;

/// Plans the scenario's inspection tours in this process, one thread per vehicle. A raised
/// `stop` cuts every swarm short; the tours are still complete (see [`assemble`]).
pub fn plan(
    scenario: &Scenario,
    stop: Option<Arc<AtomicBool>>,
    observe: &mut dyn FnMut(&IterationReport),
) -> Plan {
    let started = Instant::now();
    let job = match FleetTours::new(scenario) {
        Ok(j) => j,
        Err(why) => return unplannable(scenario, why.to_string()),
    };
    let n = scenario.vehicles.len();
    // Progress, as in a distributed run: the tours finished so far, their summed length.
    let (mut evaluations, mut length) = (0, 0.0);
    let tours: Vec<TourPlan> = std::thread::scope(|s| {
        let (job, stop) = (&job, stop.as_ref());
        let handles: Vec<_> = (0..n)
            .map(|v| s.spawn(move || job.plan_vehicle(v, stop)))
            .collect();
        handles
            .into_iter()
            .enumerate()
            .map(|(v, h)| {
                // A planning thread cannot panic on scenario data; if it did, plan again here.
                let t = h.join().unwrap_or_else(|_| job.plan_vehicle(v, stop));
                evaluations += t.evaluations;
                length += t.tour_length_m;
                observe(&IterationReport {
                    iteration: v + 1,
                    max_iterations: n,
                    best_cost: length,
                    evaluations,
                });
                t
            })
            .collect()
    });
    assemble(scenario, &job, &tours, "in-process", started)
}

/// The plan of a fleet's tours (one per vehicle, scenario order), however they were planned.
/// When a stop cut any tour's swarms short, the plan says so (`termination` "Interrupted" and
/// a notice naming those vehicles): it is complete and checked like any plan, but less
/// optimised than the budget would make it.
pub fn assemble(
    scenario: &Scenario,
    job: &FleetTours,
    tours: &[TourPlan],
    mode: &str,
    started: Instant,
) -> Plan {
    let o = &scenario.optimizer;
    let n = scenario.vehicles.len();
    let shares = &job.shares;
    let points = &job.points;
    // Common return time: the slowest tour at its vehicle's top speed; faster vehicles slow
    // down (not below their slowest speed) and hold at the base for what is left.
    let finish = scenario
        .vehicles
        .iter()
        .zip(tours)
        .map(|(v, t)| t.tour_length_m / v.speed_max_mps)
        .fold(0.0, f64::max);
    let trajectories: Vec<Trajectory> = scenario
        .vehicles
        .iter()
        .zip(tours)
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
    for ((vp, t), share) in assessment.vehicles.iter_mut().zip(tours).zip(shares) {
        let visited: Vec<usize> = t
            .order
            .iter()
            .filter_map(|&k| share.get(k).copied())
            .collect();
        vp.tour = Some(TourFigures {
            order: visited.iter().map(|&k| job.label(k)).collect(),
            points: visited
                .iter()
                .filter_map(|&k| points.get(k).map(|p| p.position.into()))
                .collect(),
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
    let cut: Vec<&str> = scenario
        .vehicles
        .iter()
        .zip(tours)
        .filter(|(_, t)| t.interrupted)
        .map(|(v, _)| v.id.as_str())
        .collect();
    if !cut.is_empty() {
        notices.push(format!(
            "planning was interrupted: the tours of {} were finished from what their swarms had found so far (every point is still visited); this is the best plan found so far",
            cut.join(", ")
        ));
    }
    let bases = scenario.vehicles.iter().zip(&job.bases);
    for (((v, base), t), share) in bases.zip(tours).zip(shares) {
        let visited: Vec<Vec3> = share
            .iter()
            .filter_map(|&k| points.get(k).map(|p| p.position))
            .collect();
        notices.push(tour_gap::notice(&v.id, *base, &visited, t));
    }
    if n > 1 {
        notices.push(format!(
            "{} inspection points shared among {n} AUVs; every AUV is back at its base at {finish:.0} s",
            points.len()
        ));
    }
    Plan {
        scenario: scenario.name.clone(),
        algorithm: o.algorithm.as_str().to_string(),
        mode: mode.to_string(),
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
        evaluations: tours.iter().map(|t| t.evaluations).sum(),
        termination: if cut.is_empty() {
            "MaxIterations"
        } else {
            "Interrupted"
        }
        .to_string(),
        vehicles: assessment.vehicles,
        fleet: assessment.fleet,
        convergence: fleet_convergence(tours),
        distributed: None,
        origin: scenario.origin,
    }
}

/// The fleet's convergence curve: entry `t` sums every tour's curve at `t`, a tour whose curve
/// is shorter counting at its last value ([`TourPlan::convergence`]). Its last entry is the
/// tours' summed length when no tour crosses a cage.
pub fn fleet_convergence(tours: &[TourPlan]) -> Vec<f64> {
    summed_curve(tours.iter().map(|t| {
        let held = t.convergence.last().copied().unwrap_or(0.0);
        (t.convergence.as_slice(), held)
    }))
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;

    use super::*;

    /// The cages fleet (two AUVs) with `iterations` for every swarm.
    fn cages_fleet(iterations: usize) -> Result<Scenario, String> {
        let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenarios/cages-fleet.toml");
        let mut s = Scenario::load(&path).map_err(|e| e.to_string())?;
        s.optimizer.iterations = iterations;
        s.optimizer.particles = 20;
        if let Some(inspection) = s.inspection.as_mut() {
            inspection.order_iterations = iterations;
            inspection.order_particles = 20;
        }
        Ok(s)
    }

    /// Inspection points the plan's tours visit, and the scenario's count.
    fn visited(s: &Scenario, plan: &Plan) -> (usize, usize) {
        let visited = plan
            .vehicles
            .iter()
            .filter_map(|v| v.tour.as_ref())
            .map(|t| t.order.len())
            .sum();
        let points = 2 * s.inspection.as_ref().map_or(0, |i| i.cage_indices(s).len());
        (visited, points)
    }

    #[test]
    fn ctrl_c_gives_complete_tours_marked_interrupted() -> Result<(), String> {
        // A budget that would take hours: the plan comes back only if the stop reaches the
        // swarms.
        let s = cages_fleet(1_000_000)?;
        let raised = Arc::new(AtomicBool::new(true));
        let mut reports = Vec::new();
        let plan = plan(&s, Some(raised), &mut |r| {
            reports.push((r.iteration, r.max_iterations, r.best_cost))
        });
        assert_eq!(plan.termination, "Interrupted");
        assert!(
            plan.notices.iter().any(|n| n
                .starts_with("planning was interrupted: the tours of auv1, auv2 were finished")),
            "{:?}",
            plan.notices
        );
        let (visited, points) = visited(&s, &plan);
        assert!(points > 0);
        assert_eq!(visited, points);
        // One progress line per vehicle, with the length of the tours finished so far (the
        // plan's fitness without penalty once all are in), as a distributed run reports it.
        let lengths: Vec<f64> = plan
            .vehicles
            .iter()
            .filter_map(|v| v.tour.as_ref())
            .map(|t| t.tour_length_m)
            .collect();
        assert_eq!(
            reports,
            [(1, 2, lengths[0]), (2, 2, lengths[0] + lengths[1])]
        );
        assert_eq!(plan.objective, lengths[0] + lengths[1]);
        Ok(())
    }

    #[test]
    fn the_fleet_curve_sums_the_tours_holding_a_short_one_at_its_last_value() {
        let tour = |convergence: Vec<f64>| TourPlan {
            order: vec![],
            path: vec![],
            leg_lengths: vec![],
            tour_length_m: 0.0,
            straight_tour_length_m: 0.0,
            growth_m: 0.0,
            growth_rate: 0.0,
            cage_intersections: 0,
            evaluations: 0,
            interrupted: false,
            convergence,
        };
        let tours = [
            tour(vec![9.0, 7.0, 6.0]),
            tour(vec![4.0]),
            tour(vec![5.0, 3.0]),
        ];
        // 9 + 4 + 5, 7 + 4 + 3, 6 + 4 + 3.
        assert_eq!(fleet_convergence(&tours), [18.0, 14.0, 13.0]);
        assert!(fleet_convergence(&[]).is_empty());
    }

    #[test]
    fn a_stop_never_raised_changes_nothing() -> Result<(), String> {
        let s = cages_fleet(20)?;
        let lowered = Arc::new(AtomicBool::new(false));
        let with = plan(&s, Some(lowered), &mut |_| {});
        let without = plan(&s, None, &mut |_| {});
        assert_eq!(with.termination, "MaxIterations");
        assert!(!with.notices.iter().any(|n| n.contains("interrupted")));
        assert_eq!(with.fitness, without.fitness);
        assert_eq!(with.evaluations, without.evaluations);
        // The curve: one entry per leg-swarm iteration and one for the refined legs, ending at
        // the tours' summed length (no tour crosses a cage here).
        assert_eq!(with.convergence, without.convergence);
        assert_eq!(with.convergence.len(), 21);
        assert!(with.convergence.windows(2).all(|w| w[1] <= w[0]));
        assert_eq!(with.penalty, 0.0);
        let last = with.convergence.last().copied().unwrap_or(f64::NAN);
        assert!(
            (last - with.objective).abs() < 1e-6,
            "{last} {}",
            with.objective
        );
        let (visited, points) = visited(&s, &with);
        assert_eq!(visited, points);
        Ok(())
    }
}
