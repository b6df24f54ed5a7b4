//! Multi-population PSO with a leader population (Zhi & Zuo 2024, §3.2–3.3): AMP-PSO with the adaptive
//! coefficients of eq. (7)–(8), and MP-PSO with Table 5's fixed ones (c3 = 1.5).
//!
//! Every iteration each follower population moves by eq. (5) on its own. Every `exchange_every`
//! iterations the best particle of each follower immigrates into the leader population (Fig. 5a);
//! immigrants and the leader's own particles move by eq. (6), pulled also towards the followers'
//! global best o_f_gbest (Fig. 5b); the updated immigrants then return to their own follower
//! population and replace its worst particle (Fig. 5c).

use crate::swarm::core::population::{
    stream_seed, trusted_best, update, Coefficients, Limits, Particle, Population, Schedule,
    TrustedBest,
};
use crate::swarm::core::{parallel, Problem, Progress, Solver, SolverState};

/// Velocity cap of Zhi & Zuo's solvers, as a fraction of each dimension's range: eq. (7) starts
/// ω at 2, which diverges without a limit; 0.1 is the common PSO choice (docs/AMP-PSO.md).
pub const AMP_PSO_VELOCITY_CAP: f64 = 0.1;

/// Multi-population PSO with a leader.
#[derive(Debug, Clone)]
pub struct MultiPso {
    /// Follower populations (Table 5: 20).
    pub populations: usize,
    /// Particles per follower population (Table 5: 50).
    pub particles: usize,
    /// The leader's own particles, besides the immigrants.
    pub leader_particles: usize,
    /// Exchange period, iterations.
    pub exchange_every: usize,
    /// Fixed (MP-PSO) or adaptive (AMP-PSO) coefficients.
    pub schedule: Schedule,
    /// Velocity cap as a fraction of each dimension's range.
    pub max_velocity_fraction: f64,
    /// Threads that step follower populations; the result does not depend on it.
    pub threads: usize,
    /// RNG seed.
    pub seed: u64,
}

impl MultiPso {
    /// AMP-PSO with Table 5's sizes.
    pub fn amp(seed: u64) -> MultiPso {
        MultiPso {
            populations: 20,
            particles: 50,
            leader_particles: 20,
            exchange_every: 1,
            schedule: Schedule::Adaptive,
            max_velocity_fraction: AMP_PSO_VELOCITY_CAP,
            threads: 2,
            seed,
        }
    }

    /// MP-PSO: the same structure with Table 5's fixed coefficients.
    pub fn mp(seed: u64) -> MultiPso {
        MultiPso {
            schedule: Schedule::TABLE5_FIXED,
            ..MultiPso::amp(seed)
        }
    }
}

/// State of a multi-population run.
#[derive(Debug, Clone)]
pub struct MultiState {
    /// Follower populations.
    pub followers: Vec<Population>,
    /// The leader's own particles (immigrants join it only during an exchange).
    pub leader: Population,
    /// Box and velocity limits.
    pub limits: Limits,
    /// Best position found by any population.
    pub best_x: Vec<f64>,
    /// Its cost.
    pub best_cost: f64,
    /// Evaluations so far.
    pub evaluations: u64,
}

impl MultiState {
    /// Keeps the best truly evaluated position of any population as the run's best.
    fn absorb_elites(&mut self) {
        for pop in self.followers.iter().chain(std::iter::once(&self.leader)) {
            if pop.elite_cost < self.best_cost {
                self.best_cost = pop.elite_cost;
                self.best_x.clone_from(&pop.elite_x);
            }
        }
    }
}

impl SolverState for MultiState {
    fn best_cost(&self) -> f64 {
        self.best_cost
    }
    fn best_position(&self) -> &[f64] {
        &self.best_x
    }
    fn evaluations(&self) -> u64 {
        self.evaluations
    }
}

impl MultiPso {
    /// Steps every follower by eq. (5), spread over `threads` scoped threads.
    fn step_followers<P: Problem>(
        &self,
        problem: &P,
        state: &mut MultiState,
        progress: Progress,
    ) -> u64 {
        let c = self.schedule.at(progress);
        let limits = &state.limits;
        let before: u64 = state.followers.iter().map(|p| p.evaluations).sum();
        parallel::for_each_mut(&mut state.followers, self.threads, |pop| {
            pop.step(problem, c, None, limits);
        });
        state.followers.iter().map(|p| p.evaluations).sum::<u64>() - before
    }

    /// Fig. 5: immigrate, update the leader by eq. (6), return the immigrants.
    fn exchange<P: Problem>(&self, problem: &P, state: &mut MultiState, progress: Progress) -> u64 {
        let c = self.schedule.at(progress);
        let threads = self.threads;
        // (a) the best of each follower immigrates (a fresh evaluation when its best is assembled).
        let mut immigrants: Vec<Particle> =
            parallel::map(&state.followers, threads, |f| f.emigrant(problem))
                .into_iter()
                .flatten()
                .collect();
        let mut evaluations = if problem.blocks() > 1 {
            immigrants.len() as u64
        } else {
            0
        };
        // o_f_gbest: the followers' global best, assembled over all followers' particles and
        // trusted only if it beats the best follower elite.
        let (f_elite_x, f_elite_cost) = state
            .followers
            .iter()
            .min_by(|a, b| a.elite_cost.total_cmp(&b.elite_cost))
            .map_or((Vec::new(), f64::INFINITY), |f| {
                (f.elite_x.clone(), f.elite_cost)
            });
        let Some(f_best) = trusted_best(
            problem,
            state.followers.iter().flat_map(|f| f.particles.iter()),
            &f_elite_x,
            f_elite_cost,
        ) else {
            return evaluations;
        };
        evaluations += f_best.evaluations;
        let f_gbest = f_best.x;
        // (b) leader and immigrants move by eq. (6), towards the leader's own best and o_f_gbest;
        // the moves draw from the leader's RNG in order, the evaluations run in parallel.
        let (l_elite_x, l_elite_cost) =
            std::iter::once((&state.leader.elite_x, state.leader.elite_cost))
                .chain(immigrants.iter().map(|p| (&p.x, p.cost)))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .map_or((Vec::new(), f64::INFINITY), |(x, c)| (x.clone(), c));
        let moved = move_leader(
            problem,
            &mut state.leader,
            &mut immigrants,
            (&l_elite_x, l_elite_cost),
            &f_gbest,
            c,
            &state.limits,
            threads,
        );
        evaluations += moved.evaluations;
        // (c) the updated immigrants return home and replace the worst particle there.
        for (pop, immigrant) in state.followers.iter_mut().zip(immigrants) {
            let worst = pop.worst();
            pop.particles[worst] = immigrant;
        }
        let before: u64 = state.followers.iter().map(|p| p.evaluations).sum();
        parallel::for_each_mut(&mut state.followers, threads, |pop| {
            pop.refresh(problem);
        });
        evaluations + state.followers.iter().map(|p| p.evaluations).sum::<u64>() - before
    }
}

/// What [`move_leader`] did: the attractor the movers followed, when one was trusted, and the
/// evaluations it cost.
#[derive(Debug, Clone)]
pub struct LeaderMove {
    /// The leader's o_gbest the particles moved towards (`None`: they followed o_f_gbest).
    pub gbest: Option<TrustedBest>,
    /// Evaluations spent: the attractor's check, the movers, the leader's refresh.
    pub evaluations: u64,
}

/// Fig. 5b, the leader update of Zhi & Zuo 2024, §3.2.2 that the in-process solver and the
/// coordinator's distributed leader both run: the leader's own particles and the `immigrants`
/// move by eq. (6) towards the leader's o_gbest (assembled from them, trusted only if it beats
/// `elite`, the best truly evaluated position they know) and the followers' `f_gbest`. The moves
/// draw from the leader's RNG in order; the evaluations run on `threads` threads. The
/// immigrants then count towards the leader's elite and the leader's o_gbest is refreshed.
#[allow(clippy::too_many_arguments)]
pub fn move_leader<P: Problem>(
    problem: &P,
    leader: &mut Population,
    immigrants: &mut [Particle],
    elite: (&[f64], f64),
    f_gbest: &[f64],
    c: Coefficients,
    limits: &Limits,
    threads: usize,
) -> LeaderMove {
    let gbest = trusted_best(
        problem,
        leader.particles.iter().chain(immigrants.iter()),
        elite.0,
        elite.1,
    );
    let mut evaluations = gbest.as_ref().map_or(0, |b| b.evaluations);
    let attractor = gbest.as_ref().map_or(f_gbest, |b| b.x.as_slice());
    let rng = &mut leader.rng;
    let mut movers: Vec<&mut Particle> = leader
        .particles
        .iter_mut()
        .chain(immigrants.iter_mut())
        .collect();
    for p in movers.iter_mut() {
        update(p, attractor, Some(f_gbest), c, limits, rng);
    }
    parallel::for_each_mut(&mut movers, threads, |p| p.evaluate(problem));
    evaluations += movers.len() as u64;
    for im in immigrants.iter() {
        if im.cost < leader.elite_cost {
            leader.elite_cost = im.cost;
            leader.elite_x.clone_from(&im.x);
        }
    }
    evaluations += leader.refresh(problem);
    LeaderMove { gbest, evaluations }
}

impl<P: Problem> Solver<P> for MultiPso {
    type State = MultiState;

    fn name(&self) -> &'static str {
        match self.schedule {
            Schedule::Adaptive => "amp-pso",
            Schedule::Fixed(_) => "mp-pso",
        }
    }

    fn init(&mut self, problem: &P) -> MultiState {
        // Populations are independent (own seed, own stream): sample them in parallel.
        let ks: Vec<usize> = (0..self.populations).collect();
        let followers: Vec<Population> = parallel::map(&ks, self.threads, |&k| {
            Population::sample(problem, self.particles, stream_seed(self.seed, k as u64))
        });
        let leader = Population::sample(
            problem,
            self.leader_particles,
            stream_seed(self.seed, self.populations as u64),
        );
        let mut state = MultiState {
            evaluations: followers
                .iter()
                .chain(std::iter::once(&leader))
                .map(|p| p.evaluations)
                .sum(),
            limits: Limits::of(problem, self.max_velocity_fraction),
            best_x: Vec::new(),
            best_cost: f64::INFINITY,
            followers,
            leader,
        };
        state.absorb_elites();
        state
    }

    fn step(&mut self, problem: &P, mut state: MultiState, progress: Progress) -> MultiState {
        state.evaluations += self.step_followers(problem, &mut state, progress);
        if progress
            .iteration
            .is_multiple_of(self.exchange_every.max(1))
        {
            state.evaluations += self.exchange(problem, &mut state, progress);
        }
        state.absorb_elites();
        state
    }
}

velocity_capped!(MultiPso);
