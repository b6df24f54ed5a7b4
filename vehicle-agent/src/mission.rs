//! One mission's planning loop in an agent: the vehicle's follower populations (Zhi & Zuo 2024
//! §3.2.1) step for a round, their best chromosomes go up to the coordinator's leader, and the
//! migrants (Fig. 5c) and the new context come back. Messages arrive on a channel and leave
//! through a closure, so this loop knows nothing of the transport (or, later, of the vehicle).
//! Tour and coverage missions are planned in one go instead (`one_shot`).

use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::sync::Arc;
use std::time::{Duration, Instant};

use shoal_common::cost::FleetModel;
use shoal_common::distributed::follower::{FollowerSettings, Followers};
use shoal_common::distributed::{round_iterations, rounds, Chromosome, Context};
use shoal_common::swarm::Progress;
use shoal_common::wire::agent_to_coordinator::AgentToCoordinator;
use shoal_common::wire::coordinator_to_agent::CoordinatorToAgent;
use shoal_common::wire::WireChromosome;

use crate::assignment::{Assignment, MissionReport};
use crate::one_shot::{run_strip, run_tour};

/// What waiting for the coordinator gave.
enum Wait {
    /// The migrants of the round, with the context they need.
    Migrants(Vec<WireChromosome>, u32),
    /// The mission ends here.
    End(String),
}

/// Runs the mission to its end. `send` delivers a message to the coordinator; `dropped` is the
/// agent's count of dropped messages (reported in `Done`); `stop` ends the mission early; the
/// mission is abandoned when the coordinator is silent for `idle`.
pub fn run(
    a: Assignment,
    threads: usize,
    inbox: &Receiver<CoordinatorToAgent>,
    send: &dyn Fn(AgentToCoordinator),
    dropped: &AtomicU32,
    stop: &AtomicBool,
    idle: Duration,
) -> MissionReport {
    if a.scenario.coverage.is_some() {
        return run_strip(&a, inbox, send, dropped, stop);
    }
    if a.scenario.optimizer.algorithm.is_tour_planner() {
        return run_tour(&a, inbox, send, dropped, stop);
    }
    let o = a.scenario.optimizer.clone();
    let model = Arc::new(FleetModel::new(&a.scenario));
    let ids: Vec<String> = a.scenario.vehicles.iter().map(|v| v.id.clone()).collect();
    let mut settings = FollowerSettings::of(&o);
    settings.threads = threads.max(1);
    let mut followers = Followers::new(model, a.index, settings, a.context.clone());
    let mut latest = a.context;
    let mut elites_sent = 0;
    let mut iteration = 0usize;
    let total_rounds = rounds(o.iterations, o.distributed.exchange_every);
    let mut outcome = "complete".to_string();
    for round in 0..total_rounds {
        if stop.load(Ordering::Relaxed) {
            outcome = "the agent is shutting down".into();
            break;
        }
        for _ in 0..round_iterations(o.iterations, o.distributed.exchange_every, round) {
            followers.step(Progress {
                iteration,
                max_iterations: o.iterations,
            });
            iteration += 1;
        }
        send(AgentToCoordinator::Elites {
            mission: a.mission.clone(),
            vehicle: a.vehicle.clone(),
            round: round as u32,
            iteration: iteration as u32,
            evaluations: followers.evaluations,
            particles: followers
                .emigrants()
                .iter()
                .map(WireChromosome::from)
                .collect(),
        });
        elites_sent += 1;
        if round + 1 == total_rounds {
            break;
        }
        let ids: Vec<&str> = ids.iter().map(String::as_str).collect();
        match wait_for_migrants(round as u32, &ids, &mut latest, inbox, dropped, stop, idle) {
            Wait::Migrants(particles, context_round) => {
                if latest.round >= context_round && latest.round > followers.context().round {
                    followers.set_context(latest.clone());
                }
                followers.immigrate_all(particles.into_iter().map(Chromosome::from).enumerate());
            }
            Wait::End(why) => {
                outcome = why;
                break;
            }
        }
    }
    let report = MissionReport {
        iterations: iteration as u32,
        elites_sent,
        outcome,
    };
    send(AgentToCoordinator::Done {
        mission: a.mission.clone(),
        vehicle: a.vehicle.clone(),
        iterations: report.iterations,
        elites_sent,
        evaluations: followers.evaluations,
        dropped: dropped.load(Ordering::Relaxed),
    });
    report
}

/// Waits for round `round`'s migrants and the context they need, keeping the newest context in
/// `latest`. Messages of other rounds are stale and skipped.
fn wait_for_migrants(
    round: u32,
    ids: &[&str],
    latest: &mut Context,
    inbox: &Receiver<CoordinatorToAgent>,
    dropped: &AtomicU32,
    stop: &AtomicBool,
    idle: Duration,
) -> Wait {
    let mut heard = Instant::now();
    let mut migrants: Option<(Vec<WireChromosome>, u32)> = None;
    loop {
        if let Some((_, need)) = &migrants {
            if latest.round >= *need {
                return migrants.map_or(Wait::End(String::new()), |(p, r)| Wait::Migrants(p, r));
            }
        }
        if stop.load(Ordering::Relaxed) {
            return Wait::End("the agent is shutting down".into());
        }
        if heard.elapsed() >= idle {
            return Wait::End(format!(
                "the coordinator was silent for {:.0} s at round {round}: mission abandoned",
                idle.as_secs_f64()
            ));
        }
        let message = match inbox.recv_timeout(Duration::from_millis(100)) {
            Ok(m) => m,
            Err(RecvTimeoutError::Timeout) => continue,
            Err(RecvTimeoutError::Disconnected) => {
                return Wait::End("the agent is shutting down".into())
            }
        };
        heard = Instant::now();
        match message {
            CoordinatorToAgent::Context { context, .. } => match context.to_context(ids) {
                Ok(c) if c.round > latest.round => *latest = c,
                Ok(_) => {}
                Err(why) => {
                    dropped.fetch_add(1, Ordering::Relaxed);
                    tracing::warn!("dropped a context: {why}");
                }
            },
            CoordinatorToAgent::Migrants {
                round: r,
                context_round,
                particles,
                ..
            } if r == round => migrants = Some((particles, context_round)),
            CoordinatorToAgent::Migrants { .. }
            | CoordinatorToAgent::Assign { .. }
            | CoordinatorToAgent::Execute { .. }
            | CoordinatorToAgent::Update { .. }
            | CoordinatorToAgent::Hold { .. } => {}
            CoordinatorToAgent::Stop { reason, .. } => {
                return Wait::End(format!("stopped: {reason}"))
            }
        }
    }
}
