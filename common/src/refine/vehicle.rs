//! The refinement of one vehicle's path against the others' fixed trajectories: a replan's
//! answer (the follower problem of Zhi & Zuo 2024's distributed algorithm, eq. (9)–(12) for one
//! vehicle) pulled tight as a fleet plan's paths are, within what is left of its budget.
//!
//! A step is kept only when the vehicle's own cost ([`VehicleProblem::evaluate`]: its terms,
//! its penalties and its pairs' separation), plus the penalty weight times its lateness past
//! the target over the target, gets lower, so the answer is never worse by that measure.

use std::ops::Range;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use super::constraints::{entry_turn_row, Limits, Row};
use super::search::{Arena, Samples, Search};
use super::settings::RefineSettings;
use crate::cost::FleetModel;
use crate::geometry::{polyline_length, Vec3};
use crate::vehicle_problem::{VehicleEvaluation, VehicleProblem};

/// What the refinement of one vehicle did.
#[derive(Debug, Clone, PartialEq)]
pub struct VehicleRefinement {
    /// The chromosome after it (the input when no step was kept).
    pub genes: Vec<f64>,
    /// The vehicle's cost before and after.
    pub total: (f64, f64),
    /// Its path length before and after, metres.
    pub length_m: (f64, f64),
    /// Steps kept.
    pub steps: usize,
    /// Evaluations spent.
    pub evaluations: u64,
    /// The stop flag or the deadline ended it early.
    pub interrupted: bool,
}

/// Refines `genes`, a chromosome of `problem`'s vehicle, aiming to arrive by `target` seconds
/// (the problem's own time). A raised `stop` or the settings' deadline ends it at its next
/// program with what it kept.
pub fn refine_vehicle(
    problem: &VehicleProblem,
    genes: &[f64],
    target: f64,
    settings: &RefineSettings,
    stop: Option<&Arc<AtomicBool>>,
) -> VehicleRefinement {
    let arena = VehicleArena { problem, target };
    let i = problem.vehicle();
    let mut search = Search::new(&arena, genes, target, settings, stop);
    let before = (
        search.eval.total,
        polyline_length(&search.eval.trajectory.points),
    );
    if problem.model().crawlers[i].is_none() {
        for _ in 0..settings.rounds {
            let kept = search.steps;
            search.vehicle(i);
            if search.interrupted || search.steps == kept {
                break;
            }
        }
    }
    VehicleRefinement {
        total: (before.0, search.eval.total),
        length_m: (before.1, polyline_length(&search.eval.trajectory.points)),
        steps: search.steps,
        evaluations: search.evaluations,
        interrupted: search.interrupted,
        genes: search.x,
    }
}

/// One vehicle against fixed others, judged by its cost plus lateness past `target`.
struct VehicleArena<'a, 'p> {
    problem: &'p VehicleProblem<'a>,
    target: f64,
}

impl Arena for VehicleArena<'_, '_> {
    type Eval = VehicleEvaluation;

    fn model(&self) -> &FleetModel {
        self.problem.model()
    }

    fn evaluate(&self, x: &[f64]) -> VehicleEvaluation {
        self.problem.evaluate(x)
    }

    fn genes(&self, _i: usize) -> Range<usize> {
        0..self.problem.model().layout.chromosome_len()
    }

    fn merit(&self, e: &VehicleEvaluation) -> f64 {
        let late = (e.trajectory.arrival() - self.target).max(0.0) / self.target.max(1e-9);
        e.total + self.model().scenario.optimizer.penalty_weight * late
    }

    fn penalty(&self, e: &VehicleEvaluation) -> f64 {
        e.terms.hard + e.terms.motion + e.terms.separation
    }

    fn common_arrival(&self, _e: &VehicleEvaluation) -> Option<f64> {
        self.problem
            .synchronised()
            .then_some(self.problem.arrival())
    }

    fn mine<'e>(&'e self, e: &'e VehicleEvaluation, _i: usize) -> Samples<'e> {
        (&e.trajectory.times, &e.trajectory.points)
    }

    fn others<'e>(&'e self, _e: &'e VehicleEvaluation, _i: usize) -> Vec<Samples<'e>> {
        self.problem.others().iter().collect()
    }

    fn extra_rows(&self, points: &[Vec3], limits: &Limits, rows: &mut Vec<Row>) {
        if let Some(h) = self.problem.heading_in() {
            rows.extend(entry_turn_row(h, points, limits));
        }
    }
}
