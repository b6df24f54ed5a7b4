//! The coordinator's leader population (Zhi & Zuo 2024, §3.2.2, Fig. 5): whole-fleet particles, scored
//! on the fleet fitness (eq. 12) with the coupling between every pair of vehicles.
//!
//! One exchange: the followers' best chromosomes immigrate (5a) — the k-th immigrant is the
//! fleet particle made of every vehicle's k-th emigrant —, the leader's own particles and the
//! immigrants move by eq. (6), towards the leader's best and the followers' best o_f_gbest with
//! c3 of eq. (8) (5b), and each immigrant's chromosomes go back to the followers they came from
//! (5c). The best fleet position ever truly evaluated is the plan, and the context the followers
//! score against next.

use std::sync::Arc;

use super::{Chromosome, Context};
use crate::cost::FleetModel;
use crate::scenario::OptimizerSettings;
use crate::swarm::multi::{move_leader, AMP_PSO_VELOCITY_CAP};
use crate::swarm::parallel;
use crate::swarm::population::{stream_seed, trusted_best, Limits, Particle, Population, Schedule};
use crate::swarm::{Problem, Progress};

/// The leader population and the best fleet plan so far.
#[derive(Debug, Clone)]
pub struct Leader {
    model: Arc<FleetModel>,
    schedule: Schedule,
    threads: usize,
    leader: Population,
    limits: Limits,
    best_x: Vec<f64>,
    best_cost: f64,
    /// Fleet evaluations so far.
    pub evaluations: u64,
    /// Exchanges done.
    pub exchanges: u32,
}

impl Leader {
    /// The leader's own `o.leader_particles` particles, sampled and scored; their best is the
    /// first plan (and the followers' first context).
    pub fn new(model: Arc<FleetModel>, o: &OptimizerSettings, schedule: Schedule) -> Leader {
        // The same stream the in-process leader uses (population index = populations).
        let leader = Population::sample(
            model.as_ref(),
            o.leader_particles.max(1),
            stream_seed(o.seed, o.populations as u64),
        );
        let limits = Limits::of(model.as_ref(), o.velocity_cap(AMP_PSO_VELOCITY_CAP));
        Leader {
            evaluations: leader.evaluations,
            best_x: leader.elite_x.clone(),
            best_cost: leader.elite_cost,
            model,
            schedule,
            threads: o.threads,
            leader,
            limits,
            exchanges: 0,
        }
    }

    /// Best fleet position so far (a true evaluation).
    pub fn best_x(&self) -> &[f64] {
        &self.best_x
    }

    /// Its fitness.
    pub fn best_cost(&self) -> f64 {
        self.best_cost
    }

    /// The best plan as the followers' context, stamped with `round`.
    pub fn context(&self, round: u32) -> Context {
        Context::of(round, &self.model.evaluate(&self.best_x))
    }

    /// Keeps `x` (truly evaluated at `cost`) if it beats the best.
    fn offer(&mut self, x: &[f64], cost: f64) -> bool {
        keep_better(&mut self.best_x, &mut self.best_cost, x, cost)
    }

    /// One exchange (Fig. 5). `elites[i]` are vehicle `i`'s emigrants, one per follower
    /// population; a vehicle with none is taken from the best plan. Returns the migrants:
    /// `migrants[i][k]` goes back to vehicle `i`'s population `k`. Also returns whether the best
    /// plan improved.
    pub fn exchange(
        &mut self,
        elites: &[Vec<Chromosome>],
        progress: Progress,
    ) -> (Vec<Vec<Chromosome>>, bool) {
        let model = Arc::clone(&self.model);
        let model = model.as_ref();
        let layout = &model.layout;
        let c = self.schedule.at(progress);
        let count = elites.iter().map(Vec::len).max().unwrap_or(0).max(1);
        // (a) immigrants: the k-th fleet particle takes every vehicle's k-th emigrant.
        let xs: Vec<Vec<f64>> = (0..count)
            .map(|k| {
                let mut x = self.best_x.clone();
                for (i, es) in elites.iter().enumerate().take(layout.vehicles) {
                    let r = layout.chromosome(i);
                    if let Some(e) = es.get(k % es.len().max(1)) {
                        if e.x.len() == r.len() {
                            x[r].copy_from_slice(&e.x);
                        }
                    }
                }
                clamp_into(model, &mut x);
                x
            })
            .collect();
        let mut immigrants: Vec<Particle> =
            parallel::map(&xs, self.threads, |x| Particle::new(model, x.clone()));
        self.evaluations += immigrants.len() as u64;
        let mut improved = false;
        for p in &immigrants {
            improved |= self.offer(&p.x, p.cost);
        }
        // o_f_gbest: assembled vehicle by vehicle from the immigrants, trusted only if truly
        // better than the best immigrant.
        let (fx, fc) = immigrants
            .iter()
            .min_by(|a, b| a.cost.total_cmp(&b.cost))
            .map_or((self.best_x.clone(), self.best_cost), |p| {
                (p.x.clone(), p.cost)
            });
        let f_best = trusted_best(model, immigrants.iter(), &fx, fc);
        let f_gbest = match f_best {
            Some(b) => {
                self.evaluations += b.evaluations;
                improved |= self.offer(&b.x, b.cost);
                b.x
            }
            None => fx.clone(),
        };
        // (b) the leader's own particles and the immigrants move by eq. (6).
        let (lx, lc) = if fc < self.leader.elite_cost {
            (fx, fc)
        } else {
            (self.leader.elite_x.clone(), self.leader.elite_cost)
        };
        let moved = move_leader(
            model,
            &mut self.leader,
            &mut immigrants,
            (&lx, lc),
            &f_gbest,
            c,
            &self.limits,
            self.threads,
        );
        self.evaluations += moved.evaluations;
        if let Some(b) = &moved.gbest {
            improved |= self.offer(&b.x, b.cost);
        }
        for p in self.leader.particles.iter().chain(immigrants.iter()) {
            improved |= keep_better(&mut self.best_x, &mut self.best_cost, &p.x, p.cost);
        }
        improved |= self.offer(&self.leader.elite_x.clone(), self.leader.elite_cost);
        self.exchanges += 1;
        // (c) every immigrant's chromosomes go home.
        let migrants = (0..layout.vehicles)
            .map(|i| {
                let r = layout.chromosome(i);
                immigrants
                    .iter()
                    .map(|p| Chromosome {
                        x: p.x[r.clone()].to_vec(),
                        v: p.v[r.clone()].to_vec(),
                    })
                    .collect()
            })
            .collect();
        (migrants, improved)
    }
}

/// Replaces `(best_x, best_cost)` by `(x, cost)` when `cost` is lower; says whether it did.
fn keep_better(best_x: &mut Vec<f64>, best_cost: &mut f64, x: &[f64], cost: f64) -> bool {
    if cost < *best_cost {
        *best_cost = cost;
        best_x.clear();
        best_x.extend_from_slice(x);
        true
    } else {
        false
    }
}

/// Puts every gene inside the box (a NaN goes to the lower bound): chromosomes come from other
/// processes.
fn clamp_into(model: &FleetModel, x: &mut [f64]) {
    for ((g, lo), hi) in x.iter_mut().zip(model.lower()).zip(model.upper()) {
        *g = if g.is_finite() {
            g.clamp(*lo, *hi)
        } else {
            *lo
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures;
    use crate::scenario::Scenario;

    fn crossing() -> Result<Scenario, crate::scenario::ScenarioError> {
        let mut s = fixtures::scenario(
            800.0,
            "",
            &[
                fixtures::vehicle_toml("a", [100.0, 500.0, 250.0], [900.0, 500.0, 250.0]),
                fixtures::vehicle_toml("b", [500.0, 100.0, 250.0], [500.0, 900.0, 250.0]),
            ],
        )?;
        s.optimizer.leader_particles = 4;
        s.optimizer.threads = 2;
        Ok(s)
    }

    #[test]
    fn exchange_returns_one_migrant_per_population_and_keeps_the_best(
    ) -> Result<(), Box<dyn std::error::Error>> {
        let s = crossing()?;
        let model = Arc::new(FleetModel::new(&s));
        let mut leader = Leader::new(Arc::clone(&model), &s.optimizer, Schedule::Adaptive);
        let first = leader.best_cost();
        // The straight plan as every vehicle's emigrant 0, twice as good as a random one.
        let straight = fixtures::straight_particle(&model);
        let layout = &model.layout;
        let elites: Vec<Vec<Chromosome>> = (0..2)
            .map(|i| {
                let x = straight[layout.chromosome(i)].to_vec();
                let v = vec![0.0; x.len()];
                vec![Chromosome { x, v }; 3]
            })
            .collect();
        let progress = Progress {
            iteration: 0,
            max_iterations: 10,
        };
        let (migrants, _) = leader.exchange(&elites, progress);
        assert_eq!(migrants.len(), 2);
        assert!(migrants.iter().all(|m| m.len() == 3));
        assert!(migrants
            .iter()
            .flatten()
            .all(|c| c.x.len() == layout.chromosome_len()));
        // The best is a true evaluation and never gets worse.
        assert!(leader.best_cost() <= first);
        assert!((model.evaluate(leader.best_x()).total - leader.best_cost()).abs() < 1e-9);
        let ctx = leader.context(1);
        assert_eq!(ctx.round, 1);
        assert_eq!(ctx.trajectories.len(), 2);
        assert_eq!(leader.exchanges, 1);
        Ok(())
    }

    #[test]
    fn garbage_chromosomes_do_not_poison_the_leader() -> Result<(), Box<dyn std::error::Error>> {
        let s = crossing()?;
        let model = Arc::new(FleetModel::new(&s));
        let mut leader = Leader::new(Arc::clone(&model), &s.optimizer, Schedule::Adaptive);
        let n = model.layout.chromosome_len();
        let bad = vec![
            vec![Chromosome {
                x: vec![f64::NAN; n],
                v: vec![0.0; n],
            }],
            vec![Chromosome {
                x: vec![1.0; 2],
                v: vec![],
            }],
        ];
        let (migrants, _) = leader.exchange(
            &bad,
            Progress {
                iteration: 1,
                max_iterations: 10,
            },
        );
        assert!(leader.best_cost().is_finite());
        assert!(migrants
            .iter()
            .flatten()
            .flat_map(|c| &c.x)
            .all(|g| g.is_finite()));
        Ok(())
    }
}
