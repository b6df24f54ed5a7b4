//! One-shot missions: the agents join as for any mission, then each plans its own share once
//! and sends it up — the inspection tour of its share of the points (Hu et al. 2023, [`FleetTours`])
//! or the coverage of its strip of the area (CPP-DSMV, [`FleetCoverage`]). Every process derives
//! the shares from the scenario alone. A vehicle whose agent leaves, ends without a result, or
//! stays silent past the deadline has its share planned here instead (degraded mode), so a plan
//! is always produced.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use shoal_common::distributed::Context;
use shoal_common::plan::{AgentFigures, DegradedVehicle, DistributedFigures};
use shoal_common::trajectory::Trajectory;
use shoal_common::wire::agent_to_coordinator::AgentToCoordinator;

use super::super::agents::LocalAgents;
use super::super::network::{Event, POLL};
pub use super::share::{Share, ShareJob};
use super::state::{Run, Status, GONE_GRACE};

/// Shortest time the coordinator waits for the results once every agent has joined.
const MIN_SHARE_WAIT: Duration = Duration::from_secs(60);

/// After Ctrl-C, how long the coordinator waits for the shares its `Stop` cut short before it
/// finishes the missing ones itself (an agent needs milliseconds to end its swarms or its
/// tracking simulation).
const STOP_GRACE: Duration = Duration::from_secs(2);

/// The assignment's context for a one-shot mission: every vehicle at its start (the agents do
/// not score against it; `Assign` carries one for every mission).
pub(super) fn base_context(run: &Run) -> Context {
    Context {
        round: 0,
        arrival: 0.0,
        trajectories: run
            .scenario
            .vehicles
            .iter()
            .map(|v| Trajectory {
                times: vec![0.0],
                points: vec![v.start()],
            })
            .collect(),
    }
}

impl Run<'_> {
    /// Plans vehicle `i`'s share here and records why.
    fn degrade_share(&mut self, i: usize, job: &ShareJob, why: String) {
        let seat = &mut self.seats[i];
        if seat.share.is_some() {
            return;
        }
        tracing::warn!(
            "planning {}'s {} in the coordinator: {why}",
            seat.id,
            job.noun()
        );
        seat.share = Some(job.plan_here(i, self.stop.as_ref()));
        seat.alive = false;
        seat.joined = true;
        seat.degraded = Some(DegradedVehicle {
            vehicle: seat.id.clone(),
            from_round: 0,
            reason: why,
        });
    }

    /// Keeps a result message for its seat, or drops it (counted) when it does not fit.
    pub(super) fn take_share(&mut self, job: &ShareJob, m: AgentToCoordinator) {
        let vehicle = m.vehicle().to_string();
        let Some(i) = self.index(&vehicle) else {
            return;
        };
        match job.read(i, m) {
            Some(Ok(_)) if self.seats[i].share.is_some() => self
                .net
                .out_of_turn(&format!("a second {} from {vehicle}", job.noun())),
            // Cut short without this coordinator asking (its agent is shutting down): the
            // share deserves its whole budget, here.
            Some(Ok(share)) if share.interrupted() && !self.stopping() => {
                self.seats[i].joined = true;
                let why = format!("its agent stopped before its {} was finished", job.noun());
                self.degrade_share(i, job, why);
            }
            Some(Ok(share)) => {
                self.seats[i].share = Some(share);
                self.seats[i].joined = true;
            }
            Some(Err(why)) => self.net.out_of_turn(&format!("{vehicle}: {why}")),
            None => self.net.out_of_turn(&format!(
                "{vehicle} sent another kind of result than a {}",
                job.noun()
            )),
        }
    }

    /// An agent's `Done`: its figures are kept; without its result before it, its share is
    /// planned here (a result always comes before `Done` on the agent's one publisher).
    pub(super) fn share_done(
        &mut self,
        job: &ShareJob,
        vehicle: &str,
        iterations: u32,
        evaluations: u64,
        dropped: u32,
    ) {
        let Some(i) = self.index(vehicle) else {
            return;
        };
        self.seats[i].done = Some((iterations, evaluations, dropped));
        self.seats[i].agent_iterations = iterations;
        let why = format!("its agent ended the mission without a {}", job.noun());
        self.degrade_share(i, job, why);
    }

    /// Whether this coordinator was told to stop (Ctrl-C).
    fn stopping(&self) -> bool {
        self.stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::Relaxed))
    }

    /// Waits for every vehicle's share (see the module doc). On Ctrl-C the agents still
    /// planning are told to stop; what they send within [`STOP_GRACE`] is kept (a tour or a
    /// strip's tracking cut short), and the shares still missing are planned here, cut short as
    /// well.
    fn collect_shares(&mut self, job: &ShareJob, observe: &mut dyn FnMut(&Status)) {
        let deadline = Instant::now() + self.timing.round.max(MIN_SHARE_WAIT);
        let n = self.seats.len();
        let mut stopping_since: Option<Instant> = None;
        loop {
            let waiting: Vec<usize> = (0..n).filter(|&i| self.seats[i].share.is_none()).collect();
            observe(&Status {
                iteration: n - waiting.len(),
                max_iterations: n,
                best_cost: self
                    .seats
                    .iter()
                    .filter_map(|s| s.share.as_ref())
                    .map(Share::length_m)
                    .sum(),
                alive: self.seats.iter().filter(|s| s.degraded.is_none()).count(),
                vehicles: n,
            });
            if waiting.is_empty() {
                return;
            }
            if self.stopping() {
                let since = match stopping_since {
                    Some(t) => t,
                    None => {
                        self.tell_stop("the coordinator was interrupted");
                        *stopping_since.insert(Instant::now())
                    }
                };
                if since.elapsed() >= STOP_GRACE {
                    for i in waiting {
                        let why = format!(
                            "the coordinator was interrupted and its agent sent nothing within {:.0} s",
                            STOP_GRACE.as_secs_f64()
                        );
                        self.degrade_share(i, job, why);
                    }
                    continue;
                }
            }
            for &i in &waiting {
                let expired = self.seats[i]
                    .gone
                    .as_ref()
                    .filter(|(since, _)| since.elapsed() >= GONE_GRACE)
                    .map(|(_, why)| why.clone());
                if let Some(why) = expired {
                    self.degrade_share(i, job, why);
                }
            }
            if Instant::now() >= deadline {
                for i in waiting {
                    let why = format!(
                        "no {} from its agent within {:.0} s",
                        job.noun(),
                        self.timing.round.max(MIN_SHARE_WAIT).as_secs_f64()
                    );
                    self.degrade_share(i, job, why);
                }
                continue;
            }
            match self.net.next(deadline.min(Instant::now() + POLL)) {
                Some(Event::Message(
                    m @ (AgentToCoordinator::Tour { .. } | AgentToCoordinator::Coverage { .. }),
                )) => self.take_share(job, m),
                Some(Event::Message(AgentToCoordinator::Done {
                    vehicle,
                    iterations,
                    evaluations,
                    dropped,
                    ..
                })) => self.share_done(job, &vehicle, iterations, evaluations, dropped),
                Some(Event::Gone(v)) => self.presence(&v, false),
                Some(Event::Alive(v)) => self.presence(&v, true),
                Some(Event::Message(AgentToCoordinator::Joined { .. })) | None => {}
                Some(Event::Message(m)) => self.net.out_of_turn(&format!(
                    "{} sent elites in a one-shot mission",
                    m.vehicle()
                )),
            }
        }
    }
}

/// Runs a one-shot mission: join, collect (or plan here) every vehicle's share, stop the agents.
pub fn run_shares(
    run: &mut Run,
    job: ShareJob,
    local: Option<&mut LocalAgents>,
    stop: &Arc<AtomicBool>,
    observe: &mut dyn FnMut(&Status),
) -> anyhow::Result<(Vec<Share>, DistributedFigures)> {
    let context = base_context(run);
    let job = Arc::new(job);
    run.job = Some(Arc::clone(&job));
    run.stop = Some(Arc::clone(stop));
    run.join(&context, local, stop)?;
    run.collect_shares(&job, observe);
    run.finish("plan complete");
    let shares = (0..run.seats.len())
        .map(|i| {
            run.seats[i]
                .share
                .clone()
                .unwrap_or_else(|| job.plan_here(i, Some(stop)))
        })
        .collect();
    let iterations = run.scenario.optimizer.iterations as u32;
    let figures = DistributedFigures {
        mission: run.mission.clone(),
        exchanges: 0,
        messages_dropped: run.net.dropped,
        agents: run
            .seats
            .iter()
            .map(|s| AgentFigures {
                vehicle: s.id.clone(),
                iterations: s.done.map_or(iterations, |d| d.0),
                elites_sent: 0,
                messages_dropped: s.done.map(|d| d.2),
                degraded: s.degraded.is_some(),
            })
            .collect(),
        degraded: run
            .seats
            .iter()
            .filter_map(|s| s.degraded.clone())
            .collect(),
        rounds: None,
    };
    Ok((shares, figures))
}
