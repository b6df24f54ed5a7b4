//! Messages vehicle agents send to the coordinator.

use serde::{Deserialize, Serialize};

use super::WireChromosome;
use crate::coverage::fleet::StripPlan;
use crate::geometry::Vec3;
use crate::tour::TourPlan;

/// Agent → coordinator. Variants are only ever added at the end: their index is on the wire.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum AgentToCoordinator {
    /// The best chromosome of each of the agent's follower populations after exchange round
    /// `round`'s iterations (Zhi & Zuo 2024, Fig. 5a), for the leader.
    Elites {
        /// Mission id.
        mission: String,
        /// The vehicle they belong to.
        vehicle: String,
        /// Exchange round.
        round: u32,
        /// Iterations the agent has run.
        iteration: u32,
        /// Cost evaluations its followers have made so far.
        evaluations: u64,
        /// The chromosomes, one per follower population.
        particles: Vec<WireChromosome>,
    },
    /// The agent finished its share of the mission.
    Done {
        /// Mission id.
        mission: String,
        /// The vehicle.
        vehicle: String,
        /// Iterations the agent ran.
        iterations: u32,
        /// Elite messages it sent.
        elites_sent: u32,
        /// Cost evaluations its followers made.
        evaluations: u64,
        /// Messages it dropped (malformed, wrong version, unknown mission or vehicle).
        dropped: u32,
    },
    /// The agent took the assignment and is planning.
    Joined {
        /// Mission id.
        mission: String,
        /// The vehicle.
        vehicle: String,
    },
    /// Tour missions (Hu et al. 2023): the inspection tour the agent planned for its share of the
    /// points. Sent once, before `Done`.
    Tour {
        /// Mission id.
        mission: String,
        /// The vehicle.
        vehicle: String,
        /// Visiting order: indices into the vehicle's share of the inspection points.
        order: Vec<u32>,
        /// The flown polyline, base to base, metres.
        path: Vec<[f64; 3]>,
        /// Leg lengths, metres.
        leg_lengths: Vec<f64>,
        /// Length of the same order with straight legs, metres.
        straight_m: f64,
        /// Segment–cage intersections of `path`.
        intersections: u32,
        /// Cost evaluations the agent spent on the tour (protocol version 2).
        evaluations: u64,
        /// A stop (the coordinator's, or the agent shutting down) cut the tour's swarms short:
        /// the tour is complete but less optimised (protocol version 3).
        interrupted: bool,
        /// The tour's convergence curve, [`TourPlan::convergence`] (protocol version 5).
        convergence: Vec<f64>,
    },
    /// Fleet coverage missions (CPP-DSMV with several crawlers): the plan of the agent's strip
    /// (its figures and its exact path). Sent once, before `Done`.
    Coverage {
        /// Mission id.
        mission: String,
        /// The vehicle.
        vehicle: String,
        /// The strip planned (the vehicle's index in the scenario).
        strip: u32,
        /// The strip's plan.
        plan: Box<StripPlan>,
    },
}

impl AgentToCoordinator {
    /// The `Tour` message of a planned tour.
    pub fn tour(mission: &str, vehicle: &str, t: &TourPlan) -> AgentToCoordinator {
        AgentToCoordinator::Tour {
            mission: mission.to_string(),
            vehicle: vehicle.to_string(),
            order: t.order.iter().map(|&k| k as u32).collect(),
            path: t.path.iter().map(|p| [p.x, p.y, p.z]).collect(),
            leg_lengths: t.leg_lengths.clone(),
            straight_m: t.straight_tour_length_m,
            intersections: t.cage_intersections as u32,
            evaluations: t.evaluations,
            interrupted: t.interrupted,
            convergence: t.convergence.clone(),
        }
    }

    /// The mission the message belongs to.
    pub fn mission(&self) -> &str {
        match self {
            AgentToCoordinator::Elites { mission, .. }
            | AgentToCoordinator::Done { mission, .. }
            | AgentToCoordinator::Joined { mission, .. }
            | AgentToCoordinator::Tour { mission, .. }
            | AgentToCoordinator::Coverage { mission, .. } => mission,
        }
    }

    /// The vehicle the message speaks for.
    pub fn vehicle(&self) -> &str {
        match self {
            AgentToCoordinator::Elites { vehicle, .. }
            | AgentToCoordinator::Done { vehicle, .. }
            | AgentToCoordinator::Joined { vehicle, .. }
            | AgentToCoordinator::Tour { vehicle, .. }
            | AgentToCoordinator::Coverage { vehicle, .. } => vehicle,
        }
    }
}

/// The tour a `Tour` message carries, checked: every number finite, a path of at least one
/// point, and no visit index beyond `share_len`. The length is the legs' sum (as the planner
/// adds it up), the growth is recomputed from it. `None` for any other kind of message.
pub fn tour_from_wire(
    m: &AgentToCoordinator,
    share_len: usize,
) -> Option<Result<TourPlan, String>> {
    let AgentToCoordinator::Tour {
        order,
        path,
        leg_lengths,
        straight_m,
        intersections,
        evaluations,
        interrupted,
        convergence,
        ..
    } = m
    else {
        return None;
    };
    let straight_m = *straight_m;
    let finite = path.iter().flatten().all(|v| v.is_finite())
        && leg_lengths.iter().all(|v| v.is_finite())
        && straight_m.is_finite()
        && convergence.iter().all(|v| v.is_finite());
    if !finite || path.is_empty() {
        return Some(Err(
            "a tour with an empty path or a non-finite number".into()
        ));
    }
    if let Some(k) = order.iter().find(|&&k| k as usize >= share_len) {
        return Some(Err(format!(
            "a tour visiting point {k} of a share of {share_len} points"
        )));
    }
    let tour_length_m: f64 = leg_lengths.iter().sum();
    let growth_m = tour_length_m - straight_m;
    Some(Ok(TourPlan {
        order: order.iter().map(|&k| k as usize).collect(),
        path: path.iter().map(|p| Vec3::new(p[0], p[1], p[2])).collect(),
        leg_lengths: leg_lengths.clone(),
        tour_length_m,
        straight_tour_length_m: straight_m,
        growth_m,
        growth_rate: if straight_m > 0.0 {
            growth_m / straight_m
        } else {
            0.0
        },
        cage_intersections: *intersections as usize,
        evaluations: *evaluations,
        interrupted: *interrupted,
        convergence: convergence.clone(),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tour_survives_the_wire_and_bad_ones_do_not() {
        let t = TourPlan {
            order: vec![1, 0],
            path: vec![Vec3::zeros(), Vec3::new(3.0, 4.0, 0.0), Vec3::zeros()],
            leg_lengths: vec![5.0, 5.0],
            tour_length_m: 10.0,
            straight_tour_length_m: 8.0,
            growth_m: 2.0,
            growth_rate: 0.25,
            cage_intersections: 0,
            evaluations: 12_345,
            interrupted: false,
            convergence: vec![12.0, 10.5, 10.0],
        };
        let m = AgentToCoordinator::tour("m", "auv1", &t);
        assert_eq!(tour_from_wire(&m, 2), Some(Ok(t.clone())));
        // A tour cut short says so.
        let cut = TourPlan {
            interrupted: true,
            ..t
        };
        let m = AgentToCoordinator::tour("m", "auv1", &cut);
        assert_eq!(tour_from_wire(&m, 2), Some(Ok(cut)));
        assert!(
            matches!(tour_from_wire(&m, 1), Some(Err(_))),
            "point 1 of a share of 1"
        );
        let tour = |path: Vec<[f64; 3]>| AgentToCoordinator::Tour {
            mission: "m".into(),
            vehicle: "auv1".into(),
            order: vec![],
            path,
            leg_lengths: vec![],
            straight_m: 0.0,
            intersections: 0,
            evaluations: 0,
            interrupted: false,
            convergence: vec![],
        };
        assert!(matches!(
            tour_from_wire(&tour(vec![[f64::NAN, 0.0, 0.0]]), 2),
            Some(Err(_))
        ));
        assert!(matches!(tour_from_wire(&tour(vec![]), 0), Some(Err(_))));
        let mut bad_curve = tour(vec![[0.0; 3]]);
        if let AgentToCoordinator::Tour { convergence, .. } = &mut bad_curve {
            *convergence = vec![3.0, f64::INFINITY];
        }
        assert!(matches!(tour_from_wire(&bad_curve, 0), Some(Err(_))));
        let joined = AgentToCoordinator::Joined {
            mission: "m".into(),
            vehicle: "auv1".into(),
        };
        assert_eq!(tour_from_wire(&joined, 2), None);
    }

    #[cfg(feature = "transport")]
    #[test]
    fn a_coverage_strip_survives_the_codec() {
        use crate::coverage::boxes::Rect;
        use crate::coverage::mission::run_coverage;
        use crate::scenario::CoverageSettings;
        use crate::wire::codec::{decode, encode};
        use crate::wire::Envelope;
        // A 200 m flat map with one 20 m plateau: rows, U-turns and a detour's events.
        let n = 100;
        let mut z = vec![0.0; n * n];
        for j in 45..55 {
            for i in 45..55 {
                z[j * n + i] = 30.0;
            }
        }
        let map = crate::coverage::test_map(n, z);
        let settings = CoverageSettings {
            track: false,
            ..CoverageSettings::default()
        };
        let area = Rect::new(0.0, 0.0, 198.0, 198.0);
        let (report, plan) =
            match run_coverage(&settings, &map, area, Some(1), 1, None, &mut |_, _| {}) {
                Ok(r) => r,
                Err(e) => panic!("{e}"),
            };
        assert!(!report.events.is_empty(), "no events to carry");
        let sent = AgentToCoordinator::Coverage {
            mission: "m".into(),
            vehicle: "crawler1".into(),
            strip: 0,
            plan: Box::new(StripPlan {
                report,
                path: plan.path,
            }),
        };
        let bytes = match encode(&Envelope::new(sent.clone())) {
            Ok(b) => b,
            Err(e) => panic!("{e}"),
        };
        match decode::<AgentToCoordinator>(&bytes) {
            Ok(back) => assert_eq!(back.body, sent),
            Err(e) => panic!("{e}"),
        }
    }
}
