//! One vehicle as the coordinator sees it during an execution: its plan, its latest report and
//! where that puts it on the plan, and where it stands when it is told to hold.

use std::time::{Duration, Instant};

use shoal_common::execution::picture::{self, Progress};
use shoal_common::execution::{CommandState, VehicleCommand, VehicleStatus};
use shoal_common::geometry::Vec3;
use shoal_common::trajectory::Trajectory;
use shoal_common::wire::open::Telemetry;

/// How far either side of the mission time a report's nearest plan point is searched,
/// mission seconds (a path that passes near itself must not make progress jump).
pub(super) const PROGRESS_WINDOW_S: f64 = 300.0;
/// Seconds over which a prediction closes the vehicle's cross-track offset.
pub(super) const CONVERGE_S: f64 = 60.0;
/// How much farther a fix may be from one pass of its plan than from the nearest and still be
/// matched to it, because that pass is where its previous fix, carried on, has it (see
/// [`picture::progress_near`]), metres: above a crawler's tracking error (3.4 m measured at
/// 1000×) and under half the 10 m between coverage rows.
pub(super) const MATCH_SLACK_M: f64 = 5.0;

/// How far an agent's mission clock may lag the coordinator's, mission seconds: a command's
/// `given_s` (the agent's clock) is compared with when it was sent (the coordinator's).
pub(super) const CLOCK_SKEW_S: f64 = 1.0;

/// One vehicle as the coordinator sees it.
#[derive(Debug, Clone)]
pub struct Tracked {
    /// Vehicle id.
    pub id: String,
    /// The trajectory it follows (mission-timed).
    pub plan: Trajectory,
    /// Revision of `plan`.
    pub revision: u32,
    /// Its latest report.
    pub last: Option<Telemetry>,
    /// When that report came (wall).
    pub heard: Option<Instant>,
    /// Where the latest report puts it on its plan.
    pub progress: Option<Progress>,
    /// The plan revision `progress` was found on.
    pub(super) progress_revision: u32,
    /// Executed track: every reported fix and, between two fixes, the corners of the plan at
    /// the later one shifted by the fixes' offsets from it (the earlier fix placed on that plan
    /// when the vehicle was replanned in between; fixes of a holding vehicle are joined
    /// directly): [`super::fleet::Fleet::report`].
    pub track: Trajectory,
    /// Fixes in `track`.
    pub fixes: usize,
    /// The last fix in `track`: its plan time, its offset from the plan there, the plan's
    /// revision.
    pub(super) anchor: Option<(f64, Vec3, u32)>,
    /// Cross-track error of every report, metres.
    pub cross_track: Vec<f64>,
    /// Mission time of its first `arrived` report.
    pub arrived_s: Option<f64>,
    /// When its first plan has it arrive, mission seconds: its arrival window is around this
    /// (the common arrival of a synchronised fleet; a coverage crawler's own finish).
    pub planned_arrival_s: f64,
    /// Declared lost (silent too long).
    pub lost: bool,
    /// Commanded to hold.
    pub holding: bool,
    /// When the hold was commanded, mission seconds (`None` unless holding).
    pub held_since_s: Option<f64>,
    /// When the hold was commanded, wall time: how long its answer has been awaited.
    pub held_at: Option<Instant>,
    /// Since when its link reports a fault (its latest report does), mission seconds: it is
    /// not driven any more, so it is neither re-planned nor waited for.
    pub fault_s: Option<f64>,
}

impl Tracked {
    /// Whether it holds as the vehicle itself confirmed: told to hold, and its latest report
    /// says it holds (or stopped). A vehicle that has not confirmed a hold is predicted to keep
    /// going: a real one may not have heard, or refused.
    pub fn hold_confirmed(&self) -> bool {
        let still = [VehicleStatus::Holding, VehicleStatus::Stopped];
        self.holding
            && self
                .last
                .as_ref()
                .is_some_and(|t| still.contains(&t.state.status))
    }

    /// Whether it is still driven: neither lost, arrived nor faulted (a vehicle that is not is
    /// neither re-planned nor waited for).
    pub fn driven(&self) -> bool {
        !self.lost && self.arrived_s.is_none() && self.fault_s.is_none()
    }

    /// Whether it was told to hold less than `patience` ago and has not answered yet: no
    /// report says it holds, nor that its link gave the hold up (`Failed` is not an answer:
    /// a fallback is under way). Until it answers it is predicted to keep going, but the
    /// conflict it was held for is its hold's to settle.
    pub fn awaiting_hold_answer(&self, patience: Duration) -> bool {
        self.holding
            && !self.hold_confirmed()
            && !self.hold_refused()
            && self.held_at.is_some_and(|t| t.elapsed() < patience)
    }

    /// Whether its latest report says its link gave up the hold it was last told (a refusal
    /// of an earlier hold does not count: the hold it reports was given at or after this one
    /// was sent, within `CLOCK_SKEW_S`).
    pub fn hold_refused(&self) -> bool {
        let Some(since) = self.held_since_s.filter(|_| self.holding) else {
            return false;
        };
        self.last
            .as_ref()
            .and_then(|t| t.command.as_ref())
            .is_some_and(|c| {
                c.command == VehicleCommand::Hold
                    && c.state == CommandState::GaveUp
                    && c.given_s >= since - CLOCK_SKEW_S
            })
    }

    /// Where on its plan a holding vehicle stopped, as a plan time: the nearest point of the
    /// plan to where it is, searched around the time it was told to hold (its plan went on
    /// without it). `None` when it is not holding.
    pub fn resume_s(&self) -> Option<f64> {
        let since = self.held_since_s.filter(|_| self.holding)?;
        // Where its latest fix, carried on to the hold, has it: a path that comes back by the
        // stop (a way round an obstacle) passes it twice.
        let expected = match (self.fix_progress(), &self.last) {
            (Some(pr), Some(t)) => pr.plan_time_s + (since - t.state.t_s).max(0.0),
            _ => since,
        };
        let standing = self.standing();
        let pr = picture::progress_near(
            &self.plan,
            standing,
            since,
            PROGRESS_WINDOW_S,
            expected,
            MATCH_SLACK_M,
        );
        Some(pr.plan_time_s)
    }

    /// Where the latest fix is on the current plan: as its report placed it, or, when the
    /// vehicle was replanned since, found afresh on the new plan near the plan time its report
    /// gave. `None` before any report.
    pub fn fix_progress(&self) -> Option<Progress> {
        let t = self.last.as_ref()?;
        match self.progress {
            Some(pr) if self.progress_revision == self.revision => Some(pr),
            // The new plan keeps the old one up to the replan: near the plan time it had.
            Some(pr) => Some(picture::progress_near(
                &self.plan,
                self.position(),
                t.state.t_s,
                PROGRESS_WINDOW_S,
                pr.plan_time_s,
                MATCH_SLACK_M,
            )),
            None => Some(picture::progress(
                &self.plan,
                self.position(),
                t.state.t_s,
                PROGRESS_WINDOW_S,
            )),
        }
    }

    /// Where a vehicle told to hold stands: where its plan, followed from its latest fix, had
    /// it when the hold was commanded, until a fix taken after that comes (then that fix). A
    /// hold takes effect where the vehicle is when it gets it (the agent's link holds at that
    /// mission time), up to a report interval after the latest fix: 250 mission seconds at
    /// 2 Hz and 500×, 125 m of a crawler's path. Picturing it at its latest fix would put a
    /// way round it where it was, not where it stopped. Not holding: its latest fix.
    pub fn standing(&self) -> Vec3 {
        let p = self.position();
        let (Some(since), Some(last)) = (self.held_since_s.filter(|_| self.holding), &self.last)
        else {
            return p;
        };
        let at = last.state.t_s;
        if last.state.status != VehicleStatus::Underway || since <= at {
            return p;
        }
        let Some(pr) = self.fix_progress() else {
            return p;
        };
        picture::predict(&self.plan, p, &pr, at, since - at, CONVERGE_S).position_at(since)
    }

    /// Latest position fix, or the plan's start before any.
    pub fn position(&self) -> Vec3 {
        match &self.last {
            Some(t) => Vec3::from(t.state.position),
            None => self
                .plan
                .points
                .first()
                .copied()
                .unwrap_or_else(Vec3::zeros),
        }
    }
}
