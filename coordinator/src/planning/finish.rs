//! What happens to a fleet swarm's best before it becomes a plan: the touch-up of a plan that
//! breaks a limit ([`shoal_common::touch_up`]) and the refinement that pulls every path tight
//! ([`shoal_common::refine`]), each as the scenario's settings ask.
//!
//! A run longer than one sweep of the adaptive schedule ([`ADAPTIVE_SPAN`] iterations) leaves
//! the swarm's best after each sweep as a checkpoint; each is finished like the last, and the
//! best finished plan is the answer. The first sweep repeats the default run exactly, so a
//! longer budget never ends with a worse plan than the default, even where the touch-up or the
//! refinement of the longer run's best happens to end higher.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

use shoal_common::cost::{FleetEvaluation, FleetModel};
use shoal_common::refine::{merit, refine, target_arrival, RefineSettings, Refinement};
use shoal_common::scenario::{OptimizerSettings, Scenario};
use shoal_common::swarm::multi::AMP_PSO_VELOCITY_CAP;
use shoal_common::swarm::population::ADAPTIVE_SPAN;
use shoal_common::touch_up::{touch_up, TouchUp, TouchUpSettings};

use super::solver::RunResult;

/// How often a run keeps its best for [`finish`]: every sweep of the adaptive schedule.
pub const CHECKPOINT_EVERY: usize = ADAPTIVE_SPAN;

/// A finished fleet position and what made it.
#[derive(Debug, Clone)]
pub struct Finished {
    /// Its evaluation.
    pub eval: FleetEvaluation,
    /// What the touch-up did, when it ran.
    pub touched: Option<TouchUp>,
    /// What the refinement did, when it kept a step.
    pub refined: Option<Refinement>,
    /// Evaluations spent finishing, over every checkpoint.
    pub evaluations: u64,
    /// The iteration of the checkpoint the answer came from, when not the run's end.
    pub from_checkpoint: Option<usize>,
}

impl Finished {
    /// The notices the plan carries about it.
    pub fn notices(&self, scenario: &Scenario, feasible: bool) -> Vec<String> {
        let mut out = Vec::new();
        if let Some(at) = self.from_checkpoint {
            out.push(format!(
                "the swarm's best after iteration {at} finished better than its best at the end \
                 of the run; this plan is that one"
            ));
        }
        if let Some(t) = &self.touched {
            out.push(touch_up_notice(scenario, t, feasible));
        }
        if let Some(r) = &self.refined {
            out.push(refine_notice(r));
        }
        out
    }
}

/// Lateness past the target arrival that choosing among finished plans counts as on time,
/// seconds: the margins the refinement keeps inside the pitch limits (0.05°) leave a fleet
/// whose pitch limits set its arrival about 0.3 s past that bound (scenario 1: 2273.7 s against
/// 2273.4 s), and a tenth of a second earlier must not outweigh a lower fitness.
pub const ON_TIME_TOLERANCE_S: f64 = 1.0;

/// Finishes the run's best and every checkpoint; returns the best by the refinement's own
/// measure ([`merit`]), lateness within [`ON_TIME_TOLERANCE_S`] of the target counted as on
/// time: a longer budget, whose first checkpoint is the default run, never ends with a higher
/// fitness unless its plan arrives that much earlier.
pub fn finish(
    model: &FleetModel,
    run: &RunResult,
    o: &OptimizerSettings,
    stop: Option<&Arc<AtomicBool>>,
) -> Finished {
    let target = target_arrival(&model.scenario);
    let merit = |e: &FleetEvaluation| merit(&model.scenario, e, target + ON_TIME_TOLERANCE_S);
    let mut best = finish_one(model, &run.best_x, o, stop);
    let mut spent = best.evaluations;
    for (k, x) in run.checkpoints.iter().enumerate() {
        if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
            break;
        }
        let mut f = finish_one(model, x, o, stop);
        spent += f.evaluations;
        if merit(&f.eval) < merit(&best.eval) {
            f.from_checkpoint = Some((k + 1) * CHECKPOINT_EVERY);
            best = f;
        }
    }
    best.evaluations = spent;
    best
}

/// Touches up and refines one fleet position as the settings ask.
fn finish_one(
    model: &FleetModel,
    x: &[f64],
    o: &OptimizerSettings,
    stop: Option<&Arc<AtomicBool>>,
) -> Finished {
    let stopped = || stop.is_some_and(|s| s.load(Ordering::Relaxed));
    let started = Instant::now();
    let touched = (o.touch_up && !stopped())
        .then(|| {
            let settings = TouchUpSettings::new(o.seed, o.velocity_cap(AMP_PSO_VELOCITY_CAP));
            touch_up(model, x, settings, stop)
        })
        .flatten();
    tracing::debug!(
        seconds = started.elapsed().as_secs_f64(),
        "touch-up finished"
    );
    let swarm_x = touched.as_ref().map_or(x, |t| &t.x);
    let started = Instant::now();
    let refined = (o.refine && !stopped())
        .then(|| refine(model, swarm_x, &RefineSettings::default(), stop))
        .filter(shows);
    tracing::debug!(
        seconds = started.elapsed().as_secs_f64(),
        "refinement finished"
    );
    let evaluations = touched.as_ref().map_or(0, |t| t.evaluations)
        + refined.as_ref().map_or(0, |r| r.evaluations);
    Finished {
        eval: model.evaluate(refined.as_ref().map_or(swarm_x, |r| &r.x)),
        touched,
        refined,
        evaluations,
        from_checkpoint: None,
    }
}

/// Whether a refinement changed what its notice prints (fitness to 4 decimals, length and
/// arrival to the metre and the second): one that did not is dropped, and the swarm's plan
/// stands as it was, with no notice of nothing.
fn shows(r: &Refinement) -> bool {
    r.steps > 0
        && (r.total.0 - r.total.1 >= 5e-5
            || (r.length_m.0 - r.length_m.1).abs() >= 0.5
            || (r.arrival_s.0 - r.arrival_s.1).abs() >= 0.5)
}

/// What the refinement changed, in words, for the plan's notices.
pub fn refine_notice(r: &Refinement) -> String {
    let on_time = if r.arrival_s.1 <= r.target_arrival_s + 1e-6 {
        String::new()
    } else {
        format!(" (the limits allow {:.0} s)", r.target_arrival_s)
    };
    format!(
        "refinement: {} local steps pulled the paths tighter inside the vehicles' limits and the \
         fleet's separation: fleet path length {:.0} m -> {:.0} m, fitness {:.4} -> {:.4}, \
         arrival {:.0} s -> {:.0} s{on_time}{} (--no-refine gives the swarm's plan)",
        r.steps,
        r.length_m.0,
        r.length_m.1,
        r.total.0,
        r.total.1,
        r.arrival_s.0,
        r.arrival_s.1,
        if r.interrupted {
            ", cut short by the stop request"
        } else {
            ""
        },
    )
}

/// What the touch-up did, in words, for the plan's notices.
pub fn touch_up_notice(scenario: &Scenario, t: &TouchUp, cleared: bool) -> String {
    // Vehicle ids of scenario indices, each once, in first-seen order.
    let names = |vs: &[usize]| {
        let mut ids: Vec<&str> = Vec::new();
        for vehicle in vs.iter().filter_map(|v| scenario.vehicles.get(*v)) {
            if !ids.contains(&vehicle.id.as_str()) {
                ids.push(vehicle.id.as_str());
            }
        }
        ids
    };
    let (ids, fresh) = (names(&t.changed), names(&t.fresh));
    let what = if ids.is_empty() {
        "no vehicle's path could be improved".to_string()
    } else {
        format!(
            "{} re-planned against the others' paths{} (penalty {:.3} -> {:.3}, fitness {:.4} -> {:.4})",
            ids.join(", "),
            if fresh.is_empty() {
                String::new()
            } else {
                format!(", {} from a fresh search", fresh.join(", "))
            },
            t.penalty.0,
            t.penalty.1,
            t.total.0,
            t.total.1
        )
    };
    format!(
        "touch-up: the swarm's best plan broke a limit; {what} in {} evaluations{}{} \
         (--no-touch-up gives the swarm's own plan)",
        t.evaluations,
        if t.interrupted {
            ", cut short by the stop request"
        } else {
            ""
        },
        if cleared {
            ", which cleared every violation"
        } else {
            "; the violations listed remain"
        }
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn refinement(total: (f64, f64), length_m: (f64, f64), arrival_s: (f64, f64)) -> Refinement {
        Refinement {
            x: Vec::new(),
            total,
            length_m,
            arrival_s,
            target_arrival_s: 420.0,
            steps: 1,
            evaluations: 2,
            interrupted: false,
        }
    }

    /// A refinement whose notice would read "964 m -> 964 m, 0.9322 -> 0.9322, 420 s -> 420 s"
    /// is dropped; a change any of the three figures shows is kept.
    #[test]
    fn a_refinement_that_changes_nothing_the_notice_prints_is_dropped() {
        let same = refinement((0.93221, 0.93220), (964.2, 964.0), (420.1, 420.0));
        assert!(!shows(&same));
        assert!(shows(&refinement(
            (0.9322, 0.9321),
            (964.0, 964.0),
            (420.0, 420.0)
        )));
        assert!(shows(&refinement(
            (0.9322, 0.9322),
            (964.0, 963.4),
            (420.0, 420.0)
        )));
        assert!(shows(&refinement(
            (0.9322, 0.9322),
            (964.0, 964.0),
            (421.0, 420.0)
        )));
        assert!(!shows(&Refinement {
            steps: 0,
            ..refinement((0.9322, 0.9), (964.0, 900.0), (421.0, 400.0))
        }));
    }
}
