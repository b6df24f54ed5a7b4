//! Joining: every vehicle's agent must be up (its liveliness token seen) and accept the
//! mission before the first round.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use shoal_common::distributed::Context;
use shoal_common::wire::agent_to_coordinator::AgentToCoordinator;

use super::super::agents::LocalAgents;
use super::super::network::{Event, POLL};
use super::state::Run;

impl Run<'_> {
    /// Waits until every vehicle's agent is up and has accepted the mission, re-sending the
    /// assignment every second (a message sent just as a subscriber appears can be lost).
    pub(super) fn join(
        &mut self,
        context: &Context,
        mut local: Option<&mut LocalAgents>,
        stop: &AtomicBool,
    ) -> anyhow::Result<()> {
        let deadline = Instant::now() + self.timing.join;
        let mut resend = Instant::now();
        while self.seats.iter().any(|s| !s.joined) {
            if stop.load(Ordering::Relaxed) {
                anyhow::bail!("interrupted while waiting for the agents to join");
            }
            if let Some(agents) = local.as_deref_mut() {
                for (v, status) in agents.exited() {
                    let Some(i) = self.index(&v) else { continue };
                    if !self.left_while_joining(i, format!("its agent process exited ({status})")) {
                        anyhow::bail!(
                            "the agent of {v} exited before joining ({status}); see its log"
                        );
                    }
                }
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(self.join_error());
            }
            if now >= resend {
                for i in 0..self.seats.len() {
                    if self.seats[i].alive && !self.seats[i].joined {
                        self.assign(i, context)?;
                    }
                }
                resend = now + Duration::from_secs(1);
            }
            match self.net.next(deadline.min(resend).min(now + POLL)) {
                Some(Event::Alive(v)) => {
                    if let Some(i) = self.index(&v) {
                        self.seats[i].alive = true;
                        self.seats[i].gone = None;
                        self.assign(i, context)?;
                    }
                }
                Some(Event::Gone(v)) => {
                    if let Some(i) = self.index(&v) {
                        self.left_while_joining(
                            i,
                            "its agent left the network (liveliness token gone)".into(),
                        );
                    }
                }
                Some(Event::Message(AgentToCoordinator::Joined { vehicle, .. })) => {
                    if let Some(i) = self.index(&vehicle) {
                        if !self.seats[i].joined {
                            tracing::info!("the agent of {vehicle} joined");
                        }
                        self.seats[i].joined = true;
                        self.seats[i].alive = true;
                    }
                }
                // An agent plans as soon as it joins: its first elites can come before the
                // last agent has joined. Keep them for round 0.
                Some(Event::Message(AgentToCoordinator::Elites {
                    vehicle,
                    round: 0,
                    iteration,
                    evaluations,
                    particles,
                    ..
                })) => {
                    if let Some(i) = self.index(&vehicle) {
                        let seat = &mut self.seats[i];
                        seat.joined = true;
                        seat.take_elites(iteration, evaluations, particles);
                    }
                }
                // A one-shot mission's agent can finish its share before the others join.
                Some(Event::Message(
                    m @ (AgentToCoordinator::Tour { .. } | AgentToCoordinator::Coverage { .. }),
                )) => match self.job.clone() {
                    Some(job) => self.take_share(&job, m),
                    None => self.net.out_of_turn(&format!(
                        "a one-shot result from {} in an exchange mission",
                        m.vehicle()
                    )),
                },
                Some(Event::Message(AgentToCoordinator::Done {
                    vehicle,
                    iterations,
                    evaluations,
                    dropped,
                    ..
                })) if self.job.is_some() => {
                    if let Some(job) = self.job.clone() {
                        self.share_done(&job, &vehicle, iterations, evaluations, dropped);
                    }
                }
                Some(Event::Message(m)) => self.net.out_of_turn(&format!(
                    "{} sent a message out of turn while the fleet was joining",
                    m.vehicle()
                )),
                None => {}
            }
        }
        Ok(())
    }

    /// Vehicle `i`'s agent went (its process exited, or its liveliness token went) while the
    /// fleet was joining. Returns whether the fleet goes on without it.
    ///
    /// In a one-shot mission, or once the agent has joined, it is only marked gone: a one-shot
    /// agent may finish (and exit) before the last one joins, its `Joined`, result or `Done` may
    /// still be in flight, and an agent killed just after it accepted may never have sent its
    /// `Joined` at all. Its share is then planned here after the grace period if nothing comes
    /// (in an exchange mission: its followers, see [`Run::collect`]). Otherwise the seat waits
    /// for an agent to come (back) until the join deadline.
    fn left_while_joining(&mut self, i: usize, why: String) -> bool {
        if self.job.is_some() || self.seats[i].joined {
            self.lost(i, why);
            self.seats[i].joined = true;
            true
        } else {
            self.seats[i].alive = false;
            false
        }
    }

    fn join_error(&self) -> anyhow::Error {
        let missing: Vec<&str> = self
            .seats
            .iter()
            .filter(|s| !s.alive)
            .map(|s| s.id.as_str())
            .collect();
        let silent: Vec<&str> = self
            .seats
            .iter()
            .filter(|s| s.alive && !s.joined)
            .map(|s| s.id.as_str())
            .collect();
        let mut parts = Vec::new();
        if !missing.is_empty() {
            parts.push(format!(
                "no agent joined for vehicle(s) {} (start one per vehicle: shoal-agent --vehicle <ID> --connect {})",
                missing.join(", "),
                self.net.endpoints.join(",")
            ));
        }
        if !silent.is_empty() {
            parts.push(format!(
                "the agent(s) of {} are up but did not accept mission {}",
                silent.join(", "),
                self.mission
            ));
        }
        anyhow::anyhow!(
            "{} within {:.0} s",
            parts.join("; "),
            self.timing.join.as_secs_f64()
        )
    }
}
