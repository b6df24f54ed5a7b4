//! A fleet's inspection job (Hu et al. 2023 for several AUVs): which cages, which points, which AUV
//! visits which points, and the settings every tour is planned with. It is a pure function of
//! the scenario, so the coordinator and every agent derive the same job from the same file and
//! each agent can plan its own share without being told more than the scenario.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use crate::geometry::Vec3;
use crate::scenario::{FirstPointMode, Scenario};
use crate::swarm::catalog::{leg_algorithm, LegAlgorithm};
use crate::swarm::population::stream_seed;

use super::cages::{inspection_points, Cage, FirstPoint, InspectionPoint};
use super::order::SwapPso;
use super::plan::{plan_tour, LegSettings, TourPlan, TourSettings};
use super::split::{short_tour, split_points};

/// Everything needed to plan any vehicle's tour of a scenario.
#[derive(Debug, Clone)]
pub struct FleetTours {
    /// The inspected cages at their physical radius (the inspection points are measured from it).
    pub cages: Vec<Cage>,
    /// The same cages grown by their clearance (`inflation_m`): what every leg keeps out of.
    pub inflated: Vec<Cage>,
    /// Every inspection point; cage `k`'s are entries `2k` and `2k + 1`.
    pub points: Vec<InspectionPoint>,
    /// Per vehicle (scenario order): indices into `points` it visits.
    pub shares: Vec<Vec<usize>>,
    /// Each vehicle's base (its start, which is also its goal).
    pub bases: Vec<Vec3>,
    /// The planning box.
    pub bounds: (Vec3, Vec3),
    /// The leg swarm.
    pub algorithm: LegAlgorithm,
    /// Order and leg settings.
    pub settings: TourSettings,
    /// The plan's seed.
    pub seed: u64,
}

/// A scenario that is no inspection mission: it names no `[inspection]` table or no tour
/// algorithm.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0} needs an [inspection] table and a tour algorithm (de-pso, ldiw-pso, lcpso)")]
pub struct NoTours(
    /// The scenario's name.
    pub String,
);

impl FleetTours {
    /// The job of `scenario`; the error says why the scenario has none.
    pub fn new(scenario: &Scenario) -> Result<FleetTours, NoTours> {
        let o = &scenario.optimizer;
        let (Some(inspection), Some(algorithm)) =
            (&scenario.inspection, leg_algorithm(o.algorithm))
        else {
            return Err(NoTours(scenario.name.clone()));
        };
        let chosen: Vec<(Cage, f64)> = inspection
            .cage_indices(scenario)
            .into_iter()
            .map(|i| {
                let ob = &scenario.obstacles[i];
                let cage = Cage {
                    id: ob.id.clone(),
                    centre: ob.centre(),
                    radius_m: ob.radius_m,
                };
                (cage, ob.inflation_m)
            })
            .collect();
        let cages: Vec<Cage> = chosen.iter().map(|(c, _)| c.clone()).collect();
        let inflated = chosen
            .iter()
            .map(|(c, inflation)| Cage {
                radius_m: c.radius_m + inflation,
                ..c.clone()
            })
            .collect();
        let bases: Vec<Vec3> = scenario.vehicles.iter().map(|v| v.start()).collect();
        let first = match inspection.first_point {
            FirstPointMode::TowardBase => FirstPoint::Toward(mean(&bases)),
            FirstPointMode::Random => FirstPoint::Random {
                seed: stream_seed(o.seed, 1000),
            },
        };
        let points = inspection_points(&cages, inspection.standoff_m, first);
        let shares = shares(&points, &bases);
        let b = &scenario.bounds;
        Ok(FleetTours {
            cages,
            inflated,
            shares,
            bases,
            bounds: (Vec3::from(b.min), Vec3::from(b.max)),
            algorithm,
            settings: TourSettings {
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
                    velocity_cap: o.max_velocity_fraction,
                    refine: o.refine,
                },
                stop: None,
            },
            seed: o.seed,
            points,
        })
    }

    /// Plans vehicle `v`'s tour (an empty tour at its base for a vehicle the job does not know).
    /// `stop`, when raised, cuts its swarms short ([`TourPlan::interrupted`]).
    pub fn plan_vehicle(&self, v: usize, stop: Option<&Arc<AtomicBool>>) -> TourPlan {
        let base = self.bases.get(v).copied().unwrap_or_else(Vec3::zeros);
        let mine: Vec<InspectionPoint> = self
            .shares
            .get(v)
            .map(|s| s.iter().map(|&k| self.points[k]).collect())
            .unwrap_or_default();
        plan_tour(
            base,
            &mine,
            &self.inflated,
            self.bounds,
            self.algorithm,
            &TourSettings {
                stop: stop.cloned(),
                ..self.settings.clone()
            },
            stream_seed(self.seed, v as u64),
        )
    }

    /// The label of point `k`: `<cage id>.<1|2>`.
    pub fn label(&self, k: usize) -> String {
        let cage = self.points.get(k).map(|p| p.cage).unwrap_or(0);
        let id = self.cages.get(cage).map(|c| c.id.as_str()).unwrap_or("?");
        format!("{id}.{}", k % 2 + 1)
    }
}

fn mean(points: &[Vec3]) -> Vec3 {
    points.iter().fold(Vec3::zeros(), |a, b| a + b) / points.len().max(1) as f64
}

/// Which share of the points each vehicle flies: one share per vehicle from [`split_points`]
/// around the fleet's mean base, then shares matched to vehicles so that the longest
/// straight-line tour from each vehicle's own base is shortest (every matching for up to 7
/// vehicles; in split order beyond).
pub fn shares(points: &[InspectionPoint], bases: &[Vec3]) -> Vec<Vec<usize>> {
    let n = bases.len();
    if n <= 1 {
        return vec![(0..points.len()).collect()];
    }
    let groups = split_points(points, mean(bases), n);
    let table: Vec<Vec<f64>> = (0..n)
        .map(|v| {
            groups
                .iter()
                .map(|g| {
                    let pts: Vec<Vec3> = g.iter().map(|&k| points[k].position).collect();
                    short_tour(bases[v], &pts).1
                })
                .collect()
        })
        .collect();
    let mut best: Vec<usize> = (0..n).collect();
    if n <= 7 {
        let worst = |p: &[usize]| (0..n).map(|v| table[v][p[v]]).fold(0.0, f64::max);
        let mut perm = best.clone();
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
}
