//! The update lead: a replan's update takes effect one replan budget (plus a delivery margin)
//! of wall time ahead, 275 mission seconds at 500×, and until then the vehicle drives the course
//! it is on. So conflicts are looked for that much further ahead, and a vehicle whose course
//! until then enters a hard obstacle or comes within d_min of another vehicle is told to hold
//! (obeyed at once) instead: no update could change that course in time.

use std::time::Duration;

use shoal_common::execution::picture::{self, Conflict};
use shoal_common::geometry::segment_hits_sphere;
use shoal_common::scenario::{Obstacle, ObstacleKind, Scenario};
use shoal_common::trajectory::Trajectory;

/// How far ahead of now a replan's update takes effect, mission seconds: it must reach the
/// vehicle before it is due, so it starts one replan budget (plus a margin for the delivery)
/// of wall time ahead.
pub(super) fn update_lead_s(budget: Duration, time_scale: f64) -> f64 {
    (budget + UPDATE_MARGIN).as_secs_f64() * time_scale
}

/// How far ahead conflicts are looked for, mission seconds: the horizon beyond the update lead.
/// A conflict seen less than the lead ahead can only be met by a hold (at 500× the lead is
/// 275 mission seconds, more than the 180 s horizon), so each is seen at least the horizon
/// before an update can act on it.
pub(super) fn conflict_horizon_s(o: &super::state::ExecOptions) -> f64 {
    o.horizon_s + update_lead_s(o.replan_budget, o.time_scale)
}

/// Wall time an update is given, over the replan budget, to reach the vehicle.
const UPDATE_MARGIN: Duration = Duration::from_millis(250);

/// How long a vehicle's answer to a hold is waited for before the other vehicle of its
/// conflict gives way: two report periods and the delivery margin (1.25 s at 2 Hz). The agent
/// reports at once after giving the hold, so a hold that reached it is answered (held, or
/// pending while its link tries) within a report or two; a longer wait, at 500×, let a lost
/// hold's conflict come before anyone else was told.
pub(super) fn hold_answer_patience(telemetry_hz: f64) -> Duration {
    let hz = if telemetry_hz.is_nan() {
        0.01
    } else {
        telemetry_hz.clamp(0.01, 100.0)
    };
    let period = Duration::from_secs_f64(1.0 / hz);
    period * 2 + UPDATE_MARGIN
}

/// Mission seconds between two retries of a held vehicle's replan: the others move 15–90 m in
/// that time at 0.5–3 m/s, enough for a way to open, and a real vehicle stands no longer.
pub(super) const HOLD_RETRY_S: f64 = 30.0;

/// Wall time from a held vehicle's last attempt (or its hold) to its next retry:
/// [`HOLD_RETRY_S`] of mission time, at most `cool_down` (at 1× a retry every 2 s, as every
/// other reaction), but never less than twice the wall time the last attempt took, so a vehicle
/// held for good keeps at most a third of a core busy and the replans of the others their
/// turn (one runs at a time, `replan_queue`). A fixed wall-time cool-down made a hold cost 1000
/// mission seconds per retry at 500×. (The checks run every 100 ms of wall time, 50 mission
/// seconds at 500×: no retry comes sooner.)
pub(super) fn hold_retry_after(
    time_scale: f64,
    last_attempt: Duration,
    cool_down: Duration,
) -> Duration {
    let mission = Duration::from_secs_f64((HOLD_RETRY_S / time_scale.max(1e-9)).min(1e6));
    mission.min(cool_down).max(last_attempt * 2)
}

/// Whether `course` (a vehicle's, from now until the update lead is over) enters a hard
/// obstacle's inflated sphere.
pub(super) fn course_enters_obstacle(course: &Trajectory, scenario: &Scenario) -> bool {
    enters_any(course, &scenario.obstacles)
}

/// Whether `course` enters the inflated sphere of a hard obstacle of `obstacles`.
pub(super) fn enters_any(course: &Trajectory, obstacles: &[Obstacle]) -> bool {
    course.points.windows(2).any(|w| {
        obstacles.iter().any(|o| {
            o.kind == ObstacleKind::Hard
                && segment_hits_sphere(&w[0], &w[1], &o.centre(), o.inflated_radius())
        })
    })
}

/// The closest approach under `d_min` of vehicle `i`'s course to another vehicle's, both as
/// `course` predicts them from now until the update lead is over (each trajectory of `course`
/// ends there), or `None` when it keeps d_min. A replan answers only from the lead's end on:
/// one that starts past a conflict on the way reports the separation after it, and the
/// vehicles meet.
pub(super) fn course_conflict(course: &[Trajectory], i: usize, d_min: f64) -> Option<Conflict> {
    picture::predicted_conflicts(course, d_min)
        .into_iter()
        .find(|c| c.a == i || c.b == i)
}

#[cfg(test)]
mod tests {
    use super::*;
    use shoal_common::geometry::Vec3;
    use shoal_common::scenario::{Obstacle, ObstacleKind};

    #[test]
    fn a_hold_is_retried_after_30_mission_seconds_bounded_by_the_loop() {
        let two = Duration::from_secs(2);
        let ms = Duration::from_millis;
        // 500×: 30 s of mission time is 60 ms of wall time, when the last attempt took 5 ms.
        assert_eq!(hold_retry_after(500.0, ms(5), two), ms(60));
        // A 300 ms attempt: 600 ms (300 mission seconds), leaving the loop two thirds of its time.
        assert_eq!(hold_retry_after(500.0, ms(300), two), ms(600));
        // 1×: 30 s is capped at the 2 s cool-down of every reaction.
        assert_eq!(hold_retry_after(1.0, ms(5), two), two);
        // An 8 × budget attempt of 2.4 s at 1×: 4.8 s.
        assert_eq!(hold_retry_after(1.0, ms(2400), two), ms(4800));
        // 10×: 3 s → capped at 2 s.
        assert_eq!(hold_retry_after(10.0, Duration::ZERO, two), two);
        // 100×: 300 ms.
        assert_eq!(hold_retry_after(100.0, Duration::ZERO, two), ms(300));
    }

    #[test]
    fn a_hold_is_answered_within_two_reports_and_the_delivery_margin() {
        assert_eq!(hold_answer_patience(2.0), Duration::from_millis(1250));
        assert_eq!(hold_answer_patience(10.0), Duration::from_millis(450));
        // A rate out of bounds is clamped, never a panic.
        assert_eq!(hold_answer_patience(0.0), Duration::from_millis(200_250));
        assert_eq!(
            hold_answer_patience(f64::NAN),
            Duration::from_millis(200_250)
        );
    }

    #[test]
    fn conflicts_are_looked_for_the_horizon_beyond_the_update_lead() {
        let mut o = super::super::state::ExecOptions {
            time_scale: 500.0,
            telemetry_hz: 2.0,
            horizon_s: 180.0,
            deviation_m: 25.0,
            separation_buffer_m: 10.0,
            lost_after: Duration::from_secs(3),
            replan_budget: Duration::from_millis(300),
            arrival_window_s: 30.0,
            log: std::path::PathBuf::from("mission.ndjson"),
            inject: Vec::new(),
            quiet: true,
            seed: 1,
            live: None,
        };
        // (0.3 s + 0.25 s) · 500 = 275 s of lead.
        assert!((update_lead_s(o.replan_budget, o.time_scale) - 275.0).abs() < 1e-9);
        assert!((conflict_horizon_s(&o) - 455.0).abs() < 1e-9);
        // At 50×, 27.5 s.
        o.time_scale = 50.0;
        assert!((conflict_horizon_s(&o) - 207.5).abs() < 1e-9);
    }

    #[test]
    fn a_course_enters_an_obstacle_only_between_the_times_it_passes_it(
    ) -> Result<(), Box<dyn std::error::Error>> {
        let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/amp-pso-1.toml");
        let mut s = Scenario::load(std::path::Path::new(file))?;
        s.obstacles = vec![Obstacle {
            id: "rock".into(),
            kind: ObstacleKind::Hard,
            centre: [50.0, 3.0, 0.0],
            radius_m: 4.0,
            inflation_m: 1.0,
        }];
        // 1 m/s along the x axis: it passes 3 m from the centre (inside 4 + 1 m) at t = 50 s.
        let course = Trajectory {
            times: vec![0.0, 100.0],
            points: vec![Vec3::new(0.0, 0.0, 0.0), Vec3::new(100.0, 0.0, 0.0)],
        };
        let between = |from: f64, to: f64| course.since(from).until(to);
        // Up to (40, 0): √(10² + 3²) = 10.4 m from the centre; from (60, 0) on, the same.
        assert!(!course_enters_obstacle(&between(0.0, 40.0), &s));
        assert!(!course_enters_obstacle(&between(60.0, 100.0), &s));
        assert!(course_enters_obstacle(&between(0.0, 60.0), &s));
        assert!(course_enters_obstacle(&between(48.0, 52.0), &s));
        // A soft obstacle is not in the way.
        s.obstacles[0].kind = ObstacleKind::Soft;
        assert!(!course_enters_obstacle(&between(0.0, 60.0), &s));
        Ok(())
    }

    #[test]
    fn a_course_conflict_is_the_closest_approach_of_that_vehicle_under_d_min(
    ) -> Result<(), Box<dyn std::error::Error>> {
        let line = |from: [f64; 3], to: [f64; 3]| Trajectory {
            times: vec![0.0, 100.0],
            points: vec![Vec3::from(from), Vec3::from(to)],
        };
        // a east along y = 0 and b west along y = 30 pass 30 m apart at t = 50; c stands
        // 200 m north.
        let course = vec![
            line([0., 0., 0.], [100., 0., 0.]),
            line([100., 30., 0.], [0., 30., 0.]),
            line([50., 200., 0.], [50., 200., 0.]),
        ];
        let c = course_conflict(&course, 1, 50.0).ok_or("no conflict")?;
        assert_eq!((c.a, c.b), (0, 1));
        assert!((c.min_distance_m - 30.0).abs() < 1e-9, "{c:?}");
        assert!((c.at_s - 50.0).abs() < 1e-9, "{c:?}");
        assert!(course_conflict(&course, 0, 50.0).is_some());
        // c is 170 m from both at its closest: nothing under 50 m, nor for a or b under 20 m.
        assert!(course_conflict(&course, 2, 50.0).is_none());
        assert!(course_conflict(&course, 1, 20.0).is_none());
        Ok(())
    }
}
