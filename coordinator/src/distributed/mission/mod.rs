//! The coordinator's mission loop: agents join, then exchange rounds (Zhi & Zuo 2024, Fig. 5) until
//! the budget is spent. Each round every agent's elites come up, the leader exchanges, and the
//! new context (when due) and the migrants go back down. A vehicle whose agent vanishes or
//! stops answering is planned here from its last elites (degraded mode) and the plan says so.
//!
//! With every agent answering in time a run is the lockstep reference
//! ([`shoal_common::distributed::lockstep`]) message for message, so the same seed gives the
//! same plan.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use shoal_common::cost::FleetModel;
use shoal_common::distributed::follower::FollowerSettings;
use shoal_common::distributed::leader::Leader;
use shoal_common::distributed::lockstep::context_due;
use shoal_common::distributed::{round_iterations, rounds, Chromosome, Context};
use shoal_common::plan::{AgentFigures, DistributedFigures, RoundFigures};
use shoal_common::scenario::Scenario;
use shoal_common::swarm::{Progress, Termination};
use shoal_common::wire::agent_to_coordinator::AgentToCoordinator;
use shoal_common::wire::coordinator_to_agent::CoordinatorToAgent;
use shoal_common::wire::{WireChromosome, WireContext};

mod join;
mod seat;
mod share;
mod shares;
mod state;

use seat::{RoundSpan, Seat};
pub use share::{Share, ShareJob};
use state::{Run, GONE_GRACE};
pub use state::{Status, Timing};

use super::agents::LocalAgents;
use super::network::{Event, Network};
use crate::cpu::cpu_time;
use crate::planning::finish::CHECKPOINT_EVERY;
use crate::planning::solver::RunResult;

/// Runs the mission and returns the best plan's run result and the network figures.
pub fn run(
    scenario: &Scenario,
    net: &mut Network,
    mission: &str,
    timing: Timing,
    mut local: Option<&mut LocalAgents>,
    stop: &AtomicBool,
    observe: &mut dyn FnMut(&Status),
) -> anyhow::Result<(RunResult, DistributedFigures)> {
    let started = Instant::now();
    let o = scenario.optimizer.clone();
    let model = Arc::new(FleetModel::new(scenario));
    let settings = FollowerSettings::of(&o);
    let mut leader = Leader::new(Arc::clone(&model), &o, settings.schedule);
    let mut context = leader.context(0);
    let mut r = Run::new(scenario, model, net, timing, mission);
    r.join(&context, local.as_deref_mut(), stop)?;
    let total_rounds = rounds(o.iterations, o.distributed.exchange_every);
    let mut convergence = Vec::with_capacity(o.iterations);
    let mut iteration = 0usize;
    let mut stale = false;
    let mut interrupted = false;
    let mut checkpoints = Vec::new();
    let mut clock = RoundClock::default();
    for round in 0..total_rounds {
        if stop.load(Ordering::Relaxed) {
            interrupted = true;
            break;
        }
        let n = round_iterations(o.iterations, o.distributed.exchange_every, round);
        let span = RoundSpan {
            index: round as u32,
            start: iteration,
            len: n,
        };
        let asked = clock.start();
        r.collect(span, &context, local.as_deref_mut())?;
        let collected = Instant::now();
        for seat in &mut r.seats {
            // An agent lost after it sent this round's elites is planned here from the next.
            if seat.this_round.is_some() {
                continue;
            }
            if let Some(f) = &mut seat.local {
                for k in 0..n {
                    f.step(Progress {
                        iteration: iteration + k,
                        max_iterations: o.iterations,
                    });
                }
                seat.this_round = Some(f.emigrants());
            }
        }
        for _ in 0..n {
            convergence.push(leader.best_cost());
        }
        iteration += n;
        let elites: Vec<Vec<Chromosome>> = r
            .seats
            .iter_mut()
            .map(|s| {
                let e = s.this_round.take().unwrap_or_else(|| s.last_elites.clone());
                s.last_elites.clone_from(&e);
                e
            })
            .collect();
        let progress = Progress {
            iteration: iteration.saturating_sub(1),
            max_iterations: o.iterations,
        };
        let (migrants, improved) = leader.exchange(&elites, progress);
        stale |= improved;
        // The leader's best after every sweep of the adaptive schedule, finished like the
        // run's end (`planning::finish`), as the in-process executor keeps them.
        let sweeps = |i: usize| i / CHECKPOINT_EVERY;
        if sweeps(iteration) > sweeps(iteration - n) && iteration < o.iterations {
            checkpoints.push(leader.best_x().to_vec());
        }
        if stale && context_due(round, o.distributed.context_every) {
            stale = false;
            context = leader.context(round as u32 + 1);
            if round + 1 < total_rounds {
                let ids = r.ids();
                let ids: Vec<&str> = ids.iter().map(String::as_str).collect();
                r.net.broadcast(CoordinatorToAgent::Context {
                    mission: r.mission.clone(),
                    context: WireContext::new(&context, &ids),
                })?;
            }
            for seat in &mut r.seats {
                if let Some(f) = &mut seat.local {
                    f.set_context(context.clone());
                }
            }
        }
        if let Some(last) = convergence.last_mut() {
            *last = leader.best_cost();
        }
        clock.end(asked, collected);
        if round + 1 < total_rounds {
            r.send_migrants(round as u32, context.round, migrants)?;
        }
        observe(&Status {
            iteration,
            max_iterations: o.iterations,
            best_cost: leader.best_cost(),
            alive: r.seats.iter().filter(|s| s.local.is_none()).count(),
            vehicles: r.seats.len(),
        });
    }
    r.finish(if interrupted {
        "the coordinator was interrupted"
    } else {
        "plan complete"
    });
    let agents_evaluations: u64 = r
        .seats
        .iter()
        .map(|s| {
            s.done
                .map_or(s.agent_evaluations, |d| d.1.max(s.agent_evaluations))
                + s.local.as_ref().map_or(0, |f| f.evaluations)
        })
        .sum();
    let figures = DistributedFigures {
        mission: r.mission.clone(),
        exchanges: leader.exchanges,
        messages_dropped: r.net.dropped,
        agents: r
            .seats
            .iter()
            .map(|s| AgentFigures {
                vehicle: s.id.clone(),
                iterations: s
                    .local
                    .as_ref()
                    .map_or(s.agent_iterations, |f| f.iterations as u32),
                elites_sent: s.elites_received,
                messages_dropped: s.done.map(|d| d.2),
                degraded: s.degraded.is_some(),
            })
            .collect(),
        degraded: r.seats.iter().filter_map(|s| s.degraded.clone()).collect(),
        rounds: Some(clock.figures()),
    };
    let result = RunResult {
        best_x: leader.best_x().to_vec(),
        convergence,
        evaluations: leader.evaluations + agents_evaluations,
        termination: if interrupted {
            Termination::Interrupted
        } else {
            Termination::MaxIterations
        },
        runtime_s: started.elapsed().as_secs_f64(),
        checkpoints,
    };
    Ok((result, figures))
}

/// Runs a one-shot mission (tours of Hu et al. 2023, coverage strips of CPP-DSMV): every agent plans
/// its own share; see `shares`. Returns every vehicle's share and the figures.
#[allow(clippy::too_many_arguments)] // `run`'s inputs plus the job
pub fn run_share_mission(
    scenario: &Scenario,
    job: ShareJob,
    net: &mut Network,
    mission: &str,
    timing: Timing,
    local: Option<&mut LocalAgents>,
    stop: &Arc<AtomicBool>,
    observe: &mut dyn FnMut(&Status),
) -> anyhow::Result<(Vec<Share>, DistributedFigures)> {
    let model = Arc::new(FleetModel::new(scenario));
    let mut r = Run::new(scenario, model, net, timing, mission);
    shares::run_shares(&mut r, job, local, stop, observe)
}

impl<'a> Run<'a> {
    fn new(
        scenario: &'a Scenario,
        model: Arc<FleetModel>,
        net: &'a mut Network,
        timing: Timing,
        mission: &str,
    ) -> Run<'a> {
        let seats = scenario.vehicles.iter().map(|v| Seat::new(&v.id)).collect();
        Run {
            scenario,
            model,
            net,
            seats,
            timing,
            mission: mission.to_string(),
            job: None,
            stop: None,
        }
    }
}

impl Run<'_> {
    fn ids(&self) -> Vec<String> {
        self.seats.iter().map(|s| s.id.clone()).collect()
    }

    fn index(&self, vehicle: &str) -> Option<usize> {
        self.seats.iter().position(|s| s.id == vehicle)
    }

    fn assign(&self, i: usize, context: &Context) -> anyhow::Result<()> {
        let ids = self.ids();
        let ids: Vec<&str> = ids.iter().map(String::as_str).collect();
        self.net.send(
            &self.seats[i].id,
            CoordinatorToAgent::Assign {
                mission: self.mission.clone(),
                vehicle: self.seats[i].id.clone(),
                scenario_toml: toml::to_string(self.scenario)?,
                context: WireContext::new(context, &ids),
            },
        )
    }

    /// An agent's liveliness token came (`alive`) or went, once the fleet has joined.
    fn presence(&mut self, vehicle: &str, alive: bool) {
        let Some(i) = self.index(vehicle) else {
            return;
        };
        if alive {
            self.seats[i].gone = None;
            self.seats[i].alive = true;
        } else {
            self.lost(
                i,
                "its agent left the network (liveliness token gone)".into(),
            );
        }
    }

    /// Vehicle `i`'s agent was seen to go: after [`GONE_GRACE`] without its elites it is
    /// planned here (see [`Run::collect`]).
    fn lost(&mut self, i: usize, why: String) {
        let seat = &mut self.seats[i];
        seat.alive = false;
        if seat.gone.is_none() {
            seat.gone = Some((Instant::now(), why));
        }
    }

    /// Whether vehicle `i`'s agent ran every iteration (it may then leave, e.g. with `--once`).
    fn finished(&self, i: usize) -> bool {
        self.seats[i].agent_iterations as usize >= self.scenario.optimizer.iterations
    }

    /// Plans vehicle `i` here from now on.
    fn degrade(&mut self, i: usize, span: RoundSpan, context: &Context, why: String) {
        let settings = FollowerSettings::of(&self.scenario.optimizer);
        self.seats[i].take_over(&self.model, i, settings, context, span, why);
    }

    /// Gathers round `span`'s elites from every agent still planning.
    fn collect(
        &mut self,
        span: RoundSpan,
        context: &Context,
        mut local: Option<&mut LocalAgents>,
    ) -> anyhow::Result<()> {
        let round = span.index;
        let deadline = Instant::now() + self.timing.round;
        loop {
            let waiting: Vec<usize> = (0..self.seats.len())
                .filter(|&i| self.seats[i].local.is_none() && self.seats[i].this_round.is_none())
                .collect();
            if waiting.is_empty() {
                return Ok(());
            }
            if let Some(agents) = local.as_deref_mut() {
                for (v, status) in agents.exited() {
                    if let Some(i) = self.index(&v) {
                        self.lost(i, format!("its agent process exited ({status})"));
                    }
                }
            }
            for &i in &waiting {
                let expired = self.seats[i]
                    .gone
                    .as_ref()
                    .filter(|(since, _)| since.elapsed() >= GONE_GRACE)
                    .map(|(_, why)| why.clone());
                if let Some(why) = expired {
                    if !self.finished(i) {
                        self.degrade(i, span, context, why);
                    }
                }
            }
            if Instant::now() >= deadline {
                for i in waiting {
                    let why = format!(
                        "no elites from its agent within {:.1} s in round {round}",
                        self.timing.round.as_secs_f64()
                    );
                    self.degrade(i, span, context, why);
                }
                return Ok(());
            }
            let until = deadline.min(Instant::now() + super::network::POLL);
            match self.net.next(until) {
                Some(Event::Message(AgentToCoordinator::Elites {
                    vehicle,
                    round: r,
                    iteration: it,
                    evaluations,
                    particles,
                    ..
                })) => {
                    let Some(i) = self.index(&vehicle) else {
                        continue;
                    };
                    let seat = &mut self.seats[i];
                    if r != round || seat.local.is_some() {
                        self.net.out_of_turn(&format!(
                            "elites of round {r} from {vehicle} during round {round}"
                        ));
                        continue;
                    }
                    seat.take_elites(it, evaluations, particles);
                }
                Some(Event::Message(AgentToCoordinator::Done {
                    vehicle,
                    iterations,
                    evaluations,
                    dropped,
                    ..
                })) => {
                    if let Some(i) = self.index(&vehicle) {
                        self.seats[i].done = Some((iterations, evaluations, dropped));
                        self.seats[i].agent_iterations = iterations;
                        if !self.finished(i) {
                            let why = "its agent ended the mission early (shut down or lost the coordinator)";
                            self.degrade(i, span, context, why.into());
                        }
                    }
                }
                Some(Event::Gone(v)) => self.presence(&v, false),
                Some(Event::Alive(v)) => self.presence(&v, true),
                Some(Event::Message(AgentToCoordinator::Joined { .. })) => {}
                Some(Event::Message(
                    m @ (AgentToCoordinator::Tour { .. } | AgentToCoordinator::Coverage { .. }),
                )) => self.net.out_of_turn(&format!(
                    "a one-shot result from {} in an exchange mission",
                    m.vehicle()
                )),
                None => {}
            }
        }
    }

    fn send_migrants(
        &mut self,
        round: u32,
        context_round: u32,
        migrants: Vec<Vec<Chromosome>>,
    ) -> anyhow::Result<()> {
        for (i, ms) in migrants.into_iter().enumerate() {
            let seat = &mut self.seats[i];
            match &mut seat.local {
                Some(f) => f.immigrate_all(ms.into_iter().enumerate()),
                None => self.net.send(
                    &seat.id,
                    CoordinatorToAgent::Migrants {
                        mission: self.mission.clone(),
                        vehicle: seat.id.clone(),
                        round,
                        context_round,
                        particles: ms.iter().map(WireChromosome::from).collect(),
                    },
                )?,
            }
        }
        Ok(())
    }

    /// Tells every agent of the mission to stop.
    fn tell_stop(&mut self, reason: &str) {
        if let Err(e) = self.net.broadcast(CoordinatorToAgent::Stop {
            mission: self.mission.clone(),
            reason: reason.to_string(),
        }) {
            tracing::warn!("cannot tell the agents to stop: {e:#}");
        }
    }

    /// Tells the agents the mission is over and collects their figures (2 s at most).
    fn finish(&mut self, reason: &str) {
        self.tell_stop(reason);
        let deadline = Instant::now() + Duration::from_secs(2);
        while self
            .seats
            .iter()
            .any(|s| s.local.is_none() && s.done.is_none())
        {
            match self.net.next(deadline) {
                Some(Event::Message(AgentToCoordinator::Done {
                    vehicle,
                    iterations,
                    evaluations,
                    dropped,
                    ..
                })) => {
                    if let Some(i) = self.index(&vehicle) {
                        self.seats[i].done = Some((iterations, evaluations, dropped));
                    }
                }
                Some(_) => {}
                None => break,
            }
        }
    }
}

/// Sums what the rounds cost the coordinator ([`RoundFigures`]).
#[derive(Debug, Default)]
struct RoundClock {
    /// Rounds timed.
    rounds: u32,
    /// Summed collect time, seconds.
    collect_s: f64,
    /// Summed leader time (from holding the elites to the migrants ready), seconds.
    leader_s: f64,
    /// Process CPU time when the current round started.
    cpu_at_start: Duration,
    /// Summed process CPU time, seconds.
    cpu_s: f64,
}

impl RoundClock {
    /// A round starts now.
    fn start(&mut self) -> Instant {
        self.cpu_at_start = cpu_time().unwrap_or_default();
        Instant::now()
    }

    /// The round that started at `asked` held every agent's elites at `collected` and its
    /// leader step is done now.
    fn end(&mut self, asked: Instant, collected: Instant) {
        self.rounds += 1;
        self.collect_s += (collected - asked).as_secs_f64();
        self.leader_s += collected.elapsed().as_secs_f64();
        let cpu = cpu_time().unwrap_or_default();
        self.cpu_s += cpu.saturating_sub(self.cpu_at_start).as_secs_f64();
    }

    /// The means.
    fn figures(&self) -> RoundFigures {
        let n = f64::from(self.rounds.max(1));
        RoundFigures {
            rounds: self.rounds,
            collect_s: self.collect_s / n,
            leader_s: self.leader_s / n,
            coordinator_cpu_s: self.cpu_s / n,
        }
    }
}
