//! Tour missions (seed 003 with several AUVs): the agents join as for any mission, then each
//! plans the inspection tour of its own share of the points — a share every process derives from
//! the scenario alone ([`FleetTours`]) — and sends it up once. A vehicle whose agent leaves,
//! ends without a tour, or stays silent past the deadline has its tour planned here instead
//! (degraded mode), so a plan is always produced.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use shoal_common::distributed::Context;
use shoal_common::plan::{AgentFigures, DegradedVehicle, DistributedFigures};
use shoal_common::tour::{FleetTours, TourPlan};
use shoal_common::trajectory::Trajectory;
use shoal_common::wire::agent_to_coordinator::{tour_from_wire, AgentToCoordinator};

use super::super::agents::LocalAgents;
use super::super::network::{Event, POLL};
use super::{Run, Status, GONE_GRACE};

/// Shortest time the coordinator waits for the tours once every agent has joined.
const MIN_TOUR_WAIT: Duration = Duration::from_secs(60);

/// The assignment's context for a tour mission: every vehicle at its base (the agents do not
/// score against it; `Assign` carries one for every mission).
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
    /// Plans vehicle `i`'s tour here and records why.
    fn degrade_tour(&mut self, i: usize, job: &FleetTours, why: String) {
        let seat = &mut self.seats[i];
        if seat.tour.is_some() {
            return;
        }
        tracing::warn!("planning {}'s tour in the coordinator: {why}", seat.id);
        seat.tour = Some(job.plan_vehicle(i));
        seat.alive = false;
        seat.degraded = Some(DegradedVehicle {
            vehicle: seat.id.clone(),
            from_round: 0,
            reason: why,
        });
    }

    /// Keeps a `Tour` message for its seat, or drops it (counted) when it does not fit.
    pub(super) fn take_tour(&mut self, job: &FleetTours, m: AgentToCoordinator) {
        let AgentToCoordinator::Tour {
            vehicle,
            order,
            path,
            leg_lengths,
            straight_m,
            intersections,
            ..
        } = m
        else {
            return;
        };
        let Some(i) = self.index(&vehicle) else {
            return;
        };
        let share = job.shares.get(i).map_or(0, Vec::len);
        match tour_from_wire(
            &order,
            &path,
            &leg_lengths,
            straight_m,
            intersections,
            share,
        ) {
            Ok(t) if self.seats[i].tour.is_none() => {
                self.seats[i].tour = Some(t);
                self.seats[i].joined = true;
            }
            Ok(_) => self
                .net
                .out_of_turn(&format!("a second tour from {vehicle}")),
            Err(why) => self.net.out_of_turn(&format!("{vehicle}: {why}")),
        }
    }

    /// Waits for every vehicle's tour (see the module doc).
    fn collect_tours(
        &mut self,
        job: &FleetTours,
        stop: &AtomicBool,
        observe: &mut dyn FnMut(&Status),
    ) {
        let deadline = Instant::now() + self.timing.round.max(MIN_TOUR_WAIT);
        let n = self.seats.len();
        loop {
            let waiting: Vec<usize> = (0..n).filter(|&i| self.seats[i].tour.is_none()).collect();
            observe(&Status {
                iteration: n - waiting.len(),
                max_iterations: n,
                best_cost: self
                    .seats
                    .iter()
                    .filter_map(|s| s.tour.as_ref())
                    .map(|t| t.tour_length_m)
                    .sum(),
                alive: self.seats.iter().filter(|s| s.degraded.is_none()).count(),
                vehicles: n,
            });
            if waiting.is_empty() {
                return;
            }
            if stop.load(Ordering::Relaxed) {
                for i in waiting {
                    self.degrade_tour(i, job, "the coordinator was interrupted".into());
                }
                continue;
            }
            for &i in &waiting {
                let expired = self.seats[i]
                    .gone
                    .as_ref()
                    .filter(|(since, _)| since.elapsed() >= GONE_GRACE)
                    .map(|(_, why)| why.clone());
                if let Some(why) = expired {
                    self.degrade_tour(i, job, why);
                }
            }
            if Instant::now() >= deadline {
                for i in waiting {
                    let why = format!(
                        "no tour from its agent within {:.0} s",
                        self.timing.round.max(MIN_TOUR_WAIT).as_secs_f64()
                    );
                    self.degrade_tour(i, job, why);
                }
                continue;
            }
            match self.net.next(deadline.min(Instant::now() + POLL)) {
                Some(Event::Message(m @ AgentToCoordinator::Tour { .. })) => self.take_tour(job, m),
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
                        let why = "its agent ended the mission without a tour".to_string();
                        self.degrade_tour(i, job, why);
                    }
                }
                Some(Event::Gone(v)) => self.presence(&v, false),
                Some(Event::Alive(v)) => self.presence(&v, true),
                Some(Event::Message(AgentToCoordinator::Joined { .. })) | None => {}
                Some(Event::Message(m)) => self
                    .net
                    .out_of_turn(&format!("{} sent elites in a tour mission", m.vehicle())),
            }
        }
    }
}

/// Runs a tour mission: join, collect (or plan here) every vehicle's tour, stop the agents.
pub fn run_tours(
    run: &mut Run,
    job: &FleetTours,
    local: Option<&mut LocalAgents>,
    stop: &AtomicBool,
    observe: &mut dyn FnMut(&Status),
) -> anyhow::Result<(Vec<TourPlan>, DistributedFigures)> {
    let context = base_context(run);
    run.tours = Some(job.clone());
    run.join(&context, local, stop)?;
    run.collect_tours(job, stop, observe);
    run.finish("plan complete");
    let tours = (0..run.seats.len())
        .map(|i| {
            run.seats[i]
                .tour
                .clone()
                .unwrap_or_else(|| job.plan_vehicle(i))
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
    };
    Ok((tours, figures))
}
