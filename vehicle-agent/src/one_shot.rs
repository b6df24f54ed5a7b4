//! One-shot missions in an agent: the vehicle's share of the work follows from the scenario
//! alone, so the agent plans it once — its inspection tour (Hu et al. 2023) or its coverage strip
//! (CPP-DSMV) — sends it up, and is done. While it plans, a `Stop` from the coordinator or the
//! agent's own shutdown cuts the work short; the result still goes up, marked.

use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::sync::Arc;
use std::time::Duration;

use shoal_common::coverage::fleet::FleetCoverage;
use shoal_common::tour::FleetTours;
use shoal_common::wire::agent_to_coordinator::AgentToCoordinator;
use shoal_common::wire::coordinator_to_agent::CoordinatorToAgent;

use crate::assignment::{Assignment, MissionReport};

/// A tour mission (Hu et al. 2023): this vehicle's share of the inspection points follows from the
/// scenario alone ([`FleetTours`]), so the agent plans its tour at once, sends it, and is done.
///
/// While it plans, a `Stop` from the coordinator (Ctrl-C there) or the agent's own shutdown
/// (`stop`) cuts the tour's swarms short. The tour, complete but less optimised, is still sent,
/// marked interrupted: a coordinator that is stopping takes it as the best found so far; one
/// that is not plans the share itself.
pub(crate) fn run_tour(
    a: &Assignment,
    inbox: &Receiver<CoordinatorToAgent>,
    send: &dyn Fn(AgentToCoordinator),
    dropped: &AtomicU32,
    stop: &AtomicBool,
) -> MissionReport {
    run_share(a, send, dropped, &|a| {
        let job = FleetTours::new(&a.scenario).map_err(|e| e.to_string())?;
        let (tour, why) = plan_watched(inbox, stop, |cut| job.plan_vehicle(a.index, Some(cut)));
        let mut words = format!(
            "tour of {} points planned: {:.1} m",
            tour.order.len(),
            tour.tour_length_m
        );
        if tour.interrupted {
            let why = why.unwrap_or_else(|| "stopped".into());
            words = format!("{why}; {words}, cut short");
        }
        Ok((
            AgentToCoordinator::tour(&a.mission, &a.vehicle, &tour),
            words,
        ))
    })
}

/// Runs `plan` on its own thread while [`watch_while_planning`] reads the inbox; `plan` gets
/// the flag a stop raises. Returns its result and why it was cut short, if it was.
fn plan_watched<T: Send>(
    inbox: &Receiver<CoordinatorToAgent>,
    stop: &AtomicBool,
    plan: impl Fn(&Arc<AtomicBool>) -> T + Sync,
) -> (T, Option<String>) {
    let cut = Arc::new(AtomicBool::new(false));
    std::thread::scope(|s| {
        let planning = s.spawn(|| plan(&cut));
        let why = watch_while_planning(inbox, stop, &cut, || planning.is_finished());
        // The planning thread cannot panic on scenario data; if it did, plan here (cut short
        // if a stop came).
        let result = planning.join().unwrap_or_else(|_| plan(&cut));
        (result, why)
    })
}

/// Waits until `finished`, reading the inbox: a `Stop` from the coordinator, or the agent
/// shutting down (`stop`, or the inbox closing), raises `cut`; returns why it did.
fn watch_while_planning(
    inbox: &Receiver<CoordinatorToAgent>,
    stop: &AtomicBool,
    cut: &AtomicBool,
    finished: impl Fn() -> bool,
) -> Option<String> {
    let mut why: Option<String> = None;
    while !finished() {
        if why.is_none() && stop.load(Ordering::Relaxed) {
            why = Some("the agent is shutting down".into());
        }
        match inbox.recv_timeout(Duration::from_millis(50)) {
            Ok(CoordinatorToAgent::Stop { reason, .. }) if why.is_none() => {
                why = Some(format!("stopped: {reason}"));
            }
            Ok(_) | Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => {
                if why.is_none() {
                    why = Some("the agent is shutting down".into());
                }
                std::thread::sleep(Duration::from_millis(20));
            }
        }
        if why.is_some() {
            cut.store(true, Ordering::Relaxed);
        }
    }
    why
}

/// A fleet coverage mission (CPP-DSMV with several crawlers): the vehicle's strip follows from
/// the scenario alone ([`FleetCoverage`]), so the agent builds the seabed map, plans (and
/// tracks) its strip, sends it, and is done. A heightmap file is looked up from the agent's
/// working directory; when it is not there the coordinator plans the strip instead.
///
/// A `Stop` from the coordinator or the agent's own shutdown cuts the tracking simulation short,
/// as for a tour: the strip, planned whole, is still sent with its tracking marked interrupted.
pub(crate) fn run_strip(
    a: &Assignment,
    inbox: &Receiver<CoordinatorToAgent>,
    send: &dyn Fn(AgentToCoordinator),
    dropped: &AtomicU32,
    stop: &AtomicBool,
) -> MissionReport {
    run_share(a, send, dropped, &|a| {
        let job = FleetCoverage::new(&a.scenario).map_err(|e| e.to_string())?;
        let map = job.map(Path::new(".")).map_err(|e| e.to_string())?;
        let (plan, why) = plan_watched(inbox, stop, |cut| {
            job.plan_vehicle(&map, a.index, Some(cut), &mut |stage, f| {
                tracing::debug!("strip {}: {stage} {:.0} %", a.index, 100.0 * f)
            })
        });
        let plan = plan.map_err(|e| e.to_string())?;
        let mut words = format!(
            "strip {} planned: coverage {:.2} %, {:.0} m",
            a.index,
            100.0 * plan.report.coverage.ratio,
            plan.path.length()
        );
        if plan.report.tracking.as_ref().is_some_and(|t| t.interrupted) {
            let why = why.unwrap_or_else(|| "stopped".into());
            words = format!("{why}; {words}, tracking cut short");
        }
        let message = AgentToCoordinator::Coverage {
            mission: a.mission.clone(),
            vehicle: a.vehicle.clone(),
            strip: a.index as u32,
            plan: Box::new(plan),
        };
        Ok((message, words))
    })
}

/// Plans a one-shot share: the result message and its summary in words, or why there is none.
type SharePlanner<'a> = dyn Fn(&Assignment) -> Result<(AgentToCoordinator, String), String> + 'a;

/// A mission planned in one go: `plan` gives the result message and its summary in words (or
/// why there is none); the result goes up, then `Done`.
fn run_share(
    a: &Assignment,
    send: &dyn Fn(AgentToCoordinator),
    dropped: &AtomicU32,
    plan: &SharePlanner<'_>,
) -> MissionReport {
    let iterations = a.scenario.optimizer.iterations as u32;
    let (outcome, evaluations) = match plan(a) {
        Ok((message, words)) => {
            // A tour's swarms count their evaluations; a coverage strip has no swarm.
            let evaluations = match &message {
                AgentToCoordinator::Tour { evaluations, .. } => *evaluations,
                _ => 0,
            };
            send(message);
            (words, evaluations)
        }
        Err(why) => (why, 0),
    };
    send(AgentToCoordinator::Done {
        mission: a.mission.clone(),
        vehicle: a.vehicle.clone(),
        iterations,
        elites_sent: 0,
        evaluations,
        dropped: dropped.load(Ordering::Relaxed),
    });
    MissionReport {
        iterations,
        elites_sent: 0,
        outcome,
    }
}

#[cfg(test)]
mod tests {
    use std::cell::RefCell;
    use std::path::PathBuf;
    use std::sync::mpsc;

    use shoal_common::distributed::Context;
    use shoal_common::scenario::Scenario;
    use shoal_common::trajectory::Trajectory;
    use shoal_common::wire::agent_to_coordinator::tour_from_wire;

    use super::*;

    /// The `Stop` a coordinator sends on Ctrl-C.
    fn coordinator_stop() -> CoordinatorToAgent {
        CoordinatorToAgent::Stop {
            mission: "m".into(),
            reason: "the coordinator was interrupted".into(),
        }
    }

    /// auv1's share of the cages fleet's tours, with `iterations` for its legs and its order.
    fn tour_assignment(iterations: usize) -> Result<Assignment, String> {
        let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenarios/cages-fleet.toml");
        let mut scenario = Scenario::load(&path).map_err(|e| e.to_string())?;
        scenario.optimizer.iterations = iterations;
        scenario.optimizer.particles = 20;
        if let Some(inspection) = scenario.inspection.as_mut() {
            inspection.order_iterations = iterations;
            inspection.order_particles = 20;
        }
        let trajectories = scenario
            .vehicles
            .iter()
            .map(|v| Trajectory {
                times: vec![0.0],
                points: vec![v.start()],
            })
            .collect();
        Ok(Assignment {
            mission: "m".into(),
            vehicle: scenario.vehicles[0].id.clone(),
            index: 0,
            scenario,
            context: Context {
                round: 0,
                arrival: 0.0,
                trajectories,
            },
        })
    }

    /// crawler1's strip of `cpp-fleet.toml` shrunk to a flat-ish 300 m × 300 m, tracked.
    fn strip_assignment() -> Result<Assignment, String> {
        let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenarios/cpp-fleet.toml");
        let mut scenario = Scenario::load(&path).map_err(|e| e.to_string())?;
        scenario.bounds.max[0] = 300.0;
        scenario.bounds.max[1] = 300.0;
        // Each crawler from the west end of its 100 m strip to the east end.
        for (k, v) in scenario.vehicles.iter_mut().enumerate() {
            let y = 100.0 * k as f64;
            v.start = [5.0, y + 5.0, v.start[2]];
            v.goal = [295.0, y + 95.0, v.goal[2]];
        }
        let coverage = scenario.coverage.as_mut().ok_or("no [coverage]")?;
        coverage.terrain.size_m = [300.0, 300.0];
        // No seamounts or trenches: 8 of them on this small map leave some strips no row.
        coverage.terrain.random_peaks.count = 0;
        coverage.terrain.random_pits.count = 0;
        assert!(coverage.track);
        scenario.validate(&path).map_err(|e| e.to_string())?;
        let mut a = tour_assignment(1)?;
        a.vehicle = scenario.vehicles[0].id.clone();
        a.scenario = scenario;
        Ok(a)
    }

    /// Runs the mission's share with `queued` already in its inbox; returns its report and what it
    /// sent.
    fn run_one_shot(
        a: Assignment,
        queued: Option<CoordinatorToAgent>,
        shutting_down: bool,
    ) -> (MissionReport, Vec<AgentToCoordinator>) {
        let (tx, rx) = mpsc::channel();
        if let Some(m) = queued {
            let _ = tx.send(m);
        }
        let sent = RefCell::new(Vec::new());
        let send = |m| sent.borrow_mut().push(m);
        let (dropped, stop) = (AtomicU32::new(0), AtomicBool::new(shutting_down));
        // The choice the agent's mission loop makes: a coverage share, else a tour share.
        let report = match a.scenario.coverage.is_some() {
            true => run_strip(&a, &rx, &send, &dropped, &stop),
            false => run_tour(&a, &rx, &send, &dropped, &stop),
        };
        (report, sent.into_inner())
    }

    #[test]
    fn a_tour_is_planned_sent_and_followed_by_done() -> Result<(), String> {
        let (report, sent) = run_one_shot(tour_assignment(30)?, None, false);
        assert!(report.outcome.starts_with("tour of "), "{}", report.outcome);
        let [AgentToCoordinator::Tour {
            evaluations,
            interrupted: false,
            ..
        }, AgentToCoordinator::Done {
            evaluations: done, ..
        }] = sent.as_slice()
        else {
            return Err(format!("sent {sent:?}"));
        };
        // The order swarm alone evaluates 20 × (30 + 1) tours.
        assert!(*evaluations >= 20 * 31, "{evaluations}");
        assert_eq!(done, evaluations);
        Ok(())
    }

    #[test]
    fn a_stop_from_the_coordinator_cuts_the_tour_short_and_sends_it_marked() -> Result<(), String> {
        // A budget that would take hours in a debug build: the test ends only if the stop
        // reaches the swarms.
        let (report, sent) =
            run_one_shot(tour_assignment(1_000_000)?, Some(coordinator_stop()), false);
        assert!(
            report
                .outcome
                .starts_with("stopped: the coordinator was interrupted; tour of "),
            "{}",
            report.outcome
        );
        assert!(
            report.outcome.ends_with(", cut short"),
            "{}",
            report.outcome
        );
        // The tour as it stood goes up, marked, then Done.
        let [tour @ AgentToCoordinator::Tour {
            interrupted: true,
            evaluations,
            ..
        }, AgentToCoordinator::Done {
            evaluations: done, ..
        }] = sent.as_slice()
        else {
            return Err(format!("sent {sent:?}"));
        };
        assert_eq!(done, evaluations);
        let share = FleetTours::new(&tour_assignment(1)?.scenario)
            .map_err(|e| e.to_string())?
            .shares[0]
            .len();
        let t = tour_from_wire(tour, share).ok_or("not a tour")??;
        assert_eq!(t.order.len(), share, "every point of the share is visited");
        Ok(())
    }

    #[test]
    fn an_agent_shutting_down_cuts_its_tour_short() -> Result<(), String> {
        let (report, sent) = run_one_shot(tour_assignment(1_000_000)?, None, true);
        assert!(
            report.outcome.starts_with("the agent is shutting down; "),
            "{}",
            report.outcome
        );
        assert!(
            matches!(
                sent.as_slice(),
                [
                    AgentToCoordinator::Tour {
                        interrupted: true,
                        ..
                    },
                    AgentToCoordinator::Done { .. }
                ]
            ),
            "{sent:?}"
        );
        Ok(())
    }

    #[test]
    fn a_stop_from_the_coordinator_cuts_the_strips_tracking_short() -> Result<(), String> {
        // The Stop is in the inbox before planning starts: the strip's tracking must come
        // back interrupted (untouched, it drives 3 km of rows).
        let (report, sent) = run_one_shot(strip_assignment()?, Some(coordinator_stop()), false);
        assert!(
            report
                .outcome
                .starts_with("stopped: the coordinator was interrupted; strip 0 planned: "),
            "{}",
            report.outcome
        );
        assert!(
            report.outcome.ends_with(", tracking cut short"),
            "{}",
            report.outcome
        );
        let [AgentToCoordinator::Coverage { strip: 0, plan, .. }, AgentToCoordinator::Done { .. }] =
            sent.as_slice()
        else {
            return Err(format!("sent {sent:?}"));
        };
        let tracking = plan.report.tracking.as_ref().ok_or("not tracked")?;
        assert!(tracking.interrupted && !tracking.reached_end);
        // The strip itself is planned whole: its path spans the strip's rows.
        assert!(plan.path.length() > 1000.0, "{}", plan.path.length());
        Ok(())
    }
}
