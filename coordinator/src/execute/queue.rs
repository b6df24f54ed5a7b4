//! The replan queue's bookkeeping: the replans waiting, the one under way on its thread, and
//! the owned job that thread runs; the loop's side of it (what is queued when, and what a
//! result does) is [`super::replan_queue`].

use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::Receiver;
use std::sync::Arc;
use std::time::{Duration, Instant};

use shoal_common::coverage::reroute::CrawlerGround;
use shoal_common::geometry::Vec3;
use shoal_common::scenario::Scenario;
use shoal_common::trajectory::Trajectory;

use super::repair;
use super::replan::{self, Replanned, Request};

/// The replans waiting and the one under way.
#[derive(Default)]
pub(super) struct ReplanQueue {
    pub(super) waiting: VecDeque<Waiting>,
    pub(super) under_way: Option<UnderWay>,
}

/// A replan waiting for its turn.
pub(super) struct Waiting {
    pub(super) vehicle: usize,
    pub(super) why: String,
    /// When the obstacle that asked for it came (for the decision time).
    pub(super) obstacle_received: Option<Instant>,
    pub(super) budget: Duration,
}

/// The replan under way on its thread.
pub(super) struct UnderWay {
    /// What was asked for (its budget the one it runs with).
    pub(super) asked: Waiting,
    /// Mission time its update takes effect; the vehicle drives `course` until then.
    pub(super) t0: f64,
    pub(super) course: Trajectory,
    /// Whether the vehicle was told to hold when it started.
    pub(super) was_holding: bool,
    /// Whether it stood still on a hold it had confirmed when it started: its replan starts
    /// where it stands, with no course to keep (one told to hold that has not confirmed it
    /// drives on, and is replanned as a vehicle under way).
    pub(super) was_standing: bool,
    /// Obstacles the scenario had when it started: any published since are checked against
    /// its result.
    pub(super) obstacles: usize,
    pub(super) started: Instant,
    pub(super) result: Receiver<Replanned>,
    /// Raised when a held vehicle's retry yields to a vehicle under way.
    pub(super) stop: Arc<AtomicBool>,
}

impl UnderWay {
    /// Whether it is a held vehicle's retry told to yield.
    pub(super) fn yielded(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }
}

impl ReplanQueue {
    /// Whether vehicle `i` has a replan waiting or under way.
    pub(super) fn busy(&self, i: usize) -> bool {
        self.under_way
            .as_ref()
            .is_some_and(|u| u.asked.vehicle == i)
            || self.waiting.iter().any(|w| w.vehicle == i)
    }

    /// Wall time until a replan queued behind the first `ahead` waiting ones starts: the rest of
    /// the budget of the one under way (none once it yields) plus the budgets of those.
    pub(super) fn wait_for(&self, ahead: usize) -> Duration {
        let rest = self
            .under_way
            .as_ref()
            .filter(|u| !u.yielded())
            .map_or(Duration::ZERO, |u| {
                u.asked.budget.saturating_sub(u.started.elapsed())
            });
        rest + self
            .waiting
            .iter()
            .take(ahead)
            .map(|w| w.budget)
            .sum::<Duration>()
    }

    /// Where a replan of a vehicle under way is queued: before every standing vehicle's retry
    /// (`standing` tells which vehicles confirmed their hold). A vehicle standing still is safe
    /// where it is; one under way (a hold it has not confirmed included) drives on into what it
    /// must avoid while it waits.
    pub(super) fn slot(&self, standing: impl Fn(usize) -> bool) -> usize {
        self.waiting
            .iter()
            .position(|w| standing(w.vehicle))
            .unwrap_or(self.waiting.len())
    }

    /// A standing vehicle's retry under way stops at its next iteration and gives its best so
    /// far (for a vehicle under way that needs the thread, see [`Self::slot`]).
    pub(super) fn yield_retry(&self) {
        if let Some(u) = self.under_way.as_ref().filter(|u| u.was_standing) {
            u.stop.store(true, Ordering::Relaxed);
        }
    }
}

/// Everything a replan needs, owned, for its thread.
pub(super) struct Job {
    pub(super) scenario: Scenario,
    pub(super) vehicle: usize,
    pub(super) t0: f64,
    pub(super) p0: Vec3,
    pub(super) heading: Option<Vec3>,
    pub(super) current: Trajectory,
    pub(super) resume_s: Option<f64>,
    pub(super) others: Vec<Trajectory>,
    pub(super) arrival_s: f64,
    pub(super) budget: Duration,
    pub(super) separation_buffer_m: f64,
    pub(super) seed: u64,
    pub(super) ground: Option<Arc<CrawlerGround>>,
    pub(super) stop: Arc<AtomicBool>,
}

impl Job {
    pub(super) fn run(&self) -> Replanned {
        let request = Request {
            scenario: &self.scenario,
            vehicle: self.vehicle,
            t0: self.t0,
            p0: self.p0,
            heading: self.heading,
            current: &self.current,
            resume_s: self.resume_s,
            others: &self.others,
            arrival_s: self.arrival_s,
            budget: self.budget,
            separation_buffer_m: self.separation_buffer_m,
            seed: self.seed,
            ground: self.ground.as_deref(),
            stop: Some(Arc::clone(&self.stop)),
        };
        // A tour must still pass its remaining inspection points, an energy plan (Zhang et al. 2022)
        // keeps the path its cost chose over the seabed, its turning radius and the current,
        // and a coverage crawler (CPP-DSMV) must still drive its remaining rows, none of which
        // Zhi & Zuo's replan models: all three are repaired, not replanned.
        let algorithm = self.scenario.optimizer.algorithm;
        if algorithm.is_tour_planner()
            || algorithm.is_energy_planner()
            || self.scenario.coverage.is_some()
        {
            repair::repair(&request)
        } else {
            replan::replan(&request)
        }
    }
}
