//! What the coordinator repeats, once a second, to a vehicle it has not heard from yet.
//!
//! An agent takes orders for a mission only once it has the mission (its `Execute`), and it may
//! join after the execution started: an update or a hold sent to it before is dropped on its
//! side. The coordinator meanwhile counts that vehicle as replanned or held. So until the
//! vehicle's first report, every second it is sent its mission again and then, in the order
//! the coordinator gave them, what it holds the vehicle to since: the latest plan revision and
//! a hold (a replan ends a hold, so a hold still standing came after it). An update of a
//! revision the agent has changes nothing, nor does a hold its vehicle confirmed and keeps (the
//! agent does not give it again). So the first report shows what the coordinator believes of it.

use super::tracked::Tracked;

/// An order repeated to a vehicle not yet heard from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Repeated {
    /// The mission, with the plan it was planned with (revision 0).
    Execute,
    /// The plan revision the coordinator has it on.
    Update,
    /// The hold it is told to keep.
    Hold,
}

/// What to send vehicle `v` again, in order: nothing once it has reported.
pub(super) fn repeated(v: &Tracked) -> Vec<Repeated> {
    if v.last.is_some() {
        return Vec::new();
    }
    let mut orders = vec![Repeated::Execute];
    if v.revision > 0 {
        orders.push(Repeated::Update);
    }
    if v.holding {
        orders.push(Repeated::Hold);
    }
    orders
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::execute::fleet::Fleet;
    use crate::execute::live::test_telemetry;
    use shoal_common::geometry::Vec3;
    use shoal_common::trajectory::Trajectory;

    fn vehicle() -> Tracked {
        let plan = Trajectory {
            times: vec![0.0, 100.0],
            points: vec![Vec3::zeros(), Vec3::new(100.0, 0.0, 0.0)],
        };
        let fleet = Fleet::new(&["auv1".to_string()], &[plan], 20.0, 60.0);
        fleet.vehicles[0].clone()
    }

    #[test]
    fn a_vehicle_not_heard_from_is_sent_its_mission_then_what_it_was_told_since() {
        let mut v = vehicle();
        assert_eq!(repeated(&v), vec![Repeated::Execute]);
        v.revision = 2;
        assert_eq!(repeated(&v), vec![Repeated::Execute, Repeated::Update]);
        v.holding = true;
        assert_eq!(
            repeated(&v),
            vec![Repeated::Execute, Repeated::Update, Repeated::Hold]
        );
        v.revision = 0;
        assert_eq!(repeated(&v), vec![Repeated::Execute, Repeated::Hold]);
    }

    #[test]
    fn a_vehicle_that_reported_is_sent_nothing_again() {
        let mut v = vehicle();
        v.revision = 1;
        v.holding = true;
        v.last = Some(test_telemetry("auv1", 1, 1.0, [0.0; 3]));
        assert_eq!(repeated(&v), Vec::new());
    }
}
