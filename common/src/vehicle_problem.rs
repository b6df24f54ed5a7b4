//! One vehicle's chromosome scored against the fixed, timed trajectories of the other vehicles:
//! the problem a vehicle agent's follower populations solve in distributed AMP-PSO,
//! where each agent optimises its own chromosome and the coordinator sends it the fleet's
//! current best plan as context.
//!
//! The terms are the fleet fitness's (Zhi & Zuo 2024, eq. (9)–(12), see [`crate::cost`]), restricted to
//! this vehicle: its own F(L), F(D), F(O), F(T), its hard-obstacle, turn and pitch penalties, and
//! the coupling with every other vehicle *as the context has it* — F(S) and the whole separation
//! penalty of each pair it belongs to (the others cannot move out of its way here).
//!
//! Timing: the others keep the context's timing. This vehicle is timed for the context's common
//! arrival, or later if its path is too long for that (it then arrives late, which F(T) and the
//! coordinator's next fleet evaluation see).

use rand::rngs::StdRng;

use crate::broad_phase::{SlabBoxes, SlabIndex};
use crate::cost::{
    early_arrival_penalty, entry_turn_penalty, separation_penalty, space_term, FleetModel,
    VehicleTerms,
};
use crate::fleet_trajectories::FleetTrajectories;
use crate::geometry::Vec3;
use crate::separation::{motion_separation, Motion};
use crate::swarm::Problem;
use crate::trajectory::{retime_legs, Trajectory};

/// Vehicle `vehicle`'s chromosome against the other vehicles' fixed trajectories.
#[derive(Debug, Clone)]
pub struct VehicleProblem<'a> {
    /// The fleet model (scenario, obstacles, weights).
    model: &'a FleetModel,
    /// Which vehicle, in scenario order.
    vehicle: usize,
    /// The other vehicles' trajectories, in scenario order without `vehicle`, in one buffer
    /// per kind (every candidate path is measured against them).
    others: FleetTrajectories,
    /// Their legs' velocities ([`Motion::velocities_into`]), computed once, one vehicle after
    /// another.
    other_velocities: Vec<Vec3>,
    /// Where each other vehicle's velocities are in `other_velocities`, and its top speed.
    other_legs: Vec<(std::ops::Range<usize>, f64)>,
    /// Their space-time boxes ([`SlabBoxes`]) over `[0, horizon]`: a pair whose boxes never come
    /// within d_min is skipped (its terms are exactly zero).
    other_boxes: SlabBoxes,
    /// `other_boxes` sorted per slab, so a candidate path finds the others near it by
    /// bisection.
    other_index: SlabIndex,
    /// The time span of `other_boxes`, seconds: the later of the others' last arrival and the
    /// context's arrival (this vehicle's positions after it fall in the last slab).
    horizon: f64,
    /// The arrival time the context was timed for, seconds.
    arrival: f64,
    /// Gene bounds of this vehicle's chromosome.
    lower: Vec<f64>,
    /// Upper gene bounds.
    upper: Vec<f64>,
    /// The course the vehicle is on at its start, when it starts under way (a replan): the
    /// turn onto the first leg is then limited like every other turn.
    heading_in: Option<Vec3>,
    /// Whether a path too short to arrive with the others pays [`early_arrival_penalty`]:
    /// planning wants every vehicle to arrive together; a replan under way may arrive early.
    synchronised: bool,
}

/// Everything one evaluation found.
#[derive(Debug, Clone)]
pub struct VehicleEvaluation {
    /// The timed trajectory this chromosome gives.
    pub trajectory: Trajectory,
    /// Its terms (`separation` holds the whole penalty of its pairs).
    pub terms: VehicleTerms,
    /// Smallest distance to any other vehicle, metres, exact when under d_min; at least d_min
    /// otherwise, and `INFINITY` when no other vehicle comes within d_min (or it is alone).
    pub min_separation: f64,
    /// The cost the swarm minimises.
    pub total: f64,
}

impl<'a> VehicleProblem<'a> {
    /// `context` holds every vehicle's trajectory in scenario order (this vehicle's is ignored),
    /// timed for the common arrival `arrival`.
    pub fn new(
        model: &'a FleetModel,
        vehicle: usize,
        context: &[Trajectory],
        arrival: f64,
    ) -> Self {
        let range = model.layout.chromosome(vehicle);
        let others: FleetTrajectories = (context.iter().enumerate())
            .filter(|(j, _)| *j != vehicle)
            .map(|(_, t)| t)
            .collect();
        let horizon = (0..others.len())
            .map(|k| others.arrival(k))
            .fold(arrival, f64::max);
        let (mut other_velocities, mut other_legs) = (Vec::new(), Vec::new());
        let mut other_boxes = SlabBoxes::new();
        other_boxes.reset(horizon);
        for (times, points) in others.iter() {
            other_boxes.push(times, points);
            let start = other_velocities.len();
            let top = Motion::velocities_into(times, points, &mut other_velocities);
            other_legs.push((start..other_velocities.len(), top));
        }
        VehicleProblem {
            model,
            vehicle,
            other_velocities,
            other_legs,
            other_index: SlabIndex::new(&other_boxes),
            other_boxes,
            horizon,
            others,
            arrival,
            lower: model.lower[range.clone()].to_vec(),
            upper: model.upper[range].to_vec(),
            heading_in: None,
            synchronised: true,
        }
    }

    /// An early arrival is not penalised (a replan under way: the vehicle may wait at its goal).
    pub fn early_arrival_allowed(mut self) -> Self {
        self.synchronised = false;
        self
    }

    /// The vehicle starts under way along `heading` (see [`entry_turn_penalty`]).
    pub fn entering_along(mut self, heading: Vec3) -> Self {
        self.heading_in = Some(heading);
        self
    }

    /// The fleet model it scores with.
    pub fn model(&self) -> &'a FleetModel {
        self.model
    }

    /// Which vehicle, in scenario order.
    pub fn vehicle(&self) -> usize {
        self.vehicle
    }

    /// The other vehicles' trajectories, in scenario order without this one.
    pub fn others(&self) -> &FleetTrajectories {
        &self.others
    }

    /// The arrival the context was timed for, seconds.
    pub fn arrival(&self) -> f64 {
        self.arrival
    }

    /// The course the vehicle starts on, when it starts under way.
    pub fn heading_in(&self) -> Option<Vec3> {
        self.heading_in
    }

    /// Whether an early arrival is penalised.
    pub fn synchronised(&self) -> bool {
        self.synchronised
    }

    /// Decodes and scores one chromosome.
    pub fn evaluate(&self, genes: &[f64]) -> VehicleEvaluation {
        let s = &self.model.scenario;
        let v = &s.vehicles[self.vehicle];
        let path = self.model.decode(self.vehicle, genes);
        let legs = path.leg_lengths();
        let length: f64 = legs.iter().sum();
        let mut terms = self
            .model
            .vehicle_terms(self.vehicle, &path.points, &legs, length);
        if let Some(h) = self.heading_in {
            terms.motion += entry_turn_penalty(h, &path.points, v.max_turn_deg.to_radians());
        }
        let target = self.arrival.max(length / v.speed_max_mps);
        if self.synchronised {
            terms.motion += early_arrival_penalty(length, v, target);
        }
        let trajectory = retime_legs(path, &legs, v, target);
        let mine = Motion::new(&trajectory);
        let mut own = SlabBoxes::new();
        own.reset(self.horizon);
        own.push(&trajectory.times, &trajectory.points);
        let d_min = s.fleet.d_min_m;
        let mut near = Vec::new();
        self.other_index
            .near(&self.other_boxes, &own, 0, d_min, &mut near);
        let mut min_separation = f64::INFINITY;
        for (k, ((times, points), (legs, top))) in
            self.others.iter().zip(&self.other_legs).enumerate()
        {
            if !near[k] {
                continue;
            }
            let velocities = &self.other_velocities[legs.clone()];
            let other = Motion::prepared(times, points, velocities, *top);
            let p = motion_separation(&mine, &other, d_min, false);
            terms.space += space_term(p.breach_s);
            terms.separation += separation_penalty(p.min_distance, s.fleet.d_min_m);
            min_separation = min_separation.min(p.min_distance);
        }
        let total = self.model.objective_of(&terms)
            + s.optimizer.penalty_weight * (terms.hard + terms.motion + terms.separation);
        VehicleEvaluation {
            trajectory,
            terms,
            min_separation,
            total,
        }
    }
}

impl Problem for VehicleProblem<'_> {
    fn lower(&self) -> &[f64] {
        &self.lower
    }

    fn upper(&self) -> &[f64] {
        &self.upper
    }

    fn cost(&self, x: &[f64]) -> f64 {
        self.evaluate(x).total
    }

    /// The waypoints move as one path and the speeds as one profile, as in the fleet problem.
    fn move_groups(&self) -> Vec<std::ops::Range<usize>> {
        let m = self.model.layout.waypoints;
        vec![0..3 * m, 3 * m..4 * m]
    }

    fn sample(&self, rng: &mut StdRng) -> Vec<f64> {
        let mut x = Vec::with_capacity(self.lower.len());
        self.model.sample_chromosome(self.vehicle, rng, &mut x);
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures;
    use crate::scenario::Scenario;
    use crate::swarm::pso::Pso;
    use crate::swarm::{Executor, SolverState};
    use crate::trajectory::Layout;
    use rand::SeedableRng;

    fn scenario() -> Result<Scenario, crate::scenario::ScenarioError> {
        fixtures::scenario(
            800.0,
            "",
            &[
                fixtures::vehicle_toml("a", [100.0, 500.0, 250.0], [900.0, 500.0, 250.0]),
                fixtures::vehicle_toml("b", [500.0, 100.0, 250.0], [500.0, 900.0, 250.0]),
            ],
        )
    }

    /// Both vehicles on their straight lines at one speed: they cross (500, 500) at t = 400 s.
    fn straight_particle(model: &FleetModel) -> Vec<f64> {
        fixtures::straight_particle(model)
    }

    #[test]
    fn agrees_with_the_fleet_model_on_the_fleet_own_plan() -> Result<(), Box<dyn std::error::Error>>
    {
        let model = FleetModel::new(&scenario()?);
        let x = straight_particle(&model);
        let fleet = model.evaluate(&x);
        let layout = Layout::of(&model.scenario);
        for i in 0..2 {
            let p = VehicleProblem::new(
                &model,
                i,
                &fleet.trajectories.to_vec(),
                fleet.common_arrival,
            );
            let e = p.evaluate(&x[layout.chromosome(i)]);
            let f = fleet.vehicles[i];
            assert_eq!(e.trajectory, fleet.trajectories.trajectory(i));
            assert!((e.terms.length - f.length).abs() < 1e-12);
            assert!((e.terms.space - f.space).abs() < 1e-9);
            // The whole pair penalty here, half of it in the fleet's share.
            assert!((e.terms.separation - 2.0 * f.separation).abs() < 1e-9);
            assert!(e.terms.separation > 1.0, "they meet head-on");
            assert!(e.min_separation < 1e-3, "{}", e.min_separation);
        }
        Ok(())
    }

    #[test]
    fn a_vehicle_alone_finds_its_straight_line() -> Result<(), Box<dyn std::error::Error>> {
        let mut s = scenario()?;
        s.vehicles.truncate(1);
        let model = FleetModel::new(&s);
        let p = VehicleProblem::new(&model, 0, &[], s.fleet.mission_time_s);
        assert_eq!(p.dim(), 24);
        let mut solver = Pso::adaptive(40, 3);
        let out = Executor::new(300).run(&p, &mut solver, |_| {});
        let e = p.evaluate(out.state.best_position());
        // The straight line is a candidate (F(L) = 1, F(D) = 0.5); F(D) rewards rising towards
        // the surface, so the optimum trades a little length for depth, and no penalty.
        let straight = p.evaluate(&straight_particle(&model)[..24]);
        assert!(
            e.total <= straight.total + 1e-9,
            "{} vs {}",
            e.total,
            straight.total
        );
        assert!(
            e.terms.length < 1.05 && e.terms.depth < 0.5,
            "{:?}",
            e.terms
        );
        assert_eq!(e.terms.hard + e.terms.motion + e.terms.separation, 0.0);
        assert_eq!(e.min_separation, f64::INFINITY);
        Ok(())
    }

    #[test]
    fn the_swarm_steps_out_of_a_crossing_vehicles_way() -> Result<(), Box<dyn std::error::Error>> {
        let model = FleetModel::new(&scenario()?);
        let x = straight_particle(&model);
        let fleet = model.evaluate(&x);
        // b keeps its straight line and timing; a must avoid meeting it at the centre.
        let p = VehicleProblem::new(
            &model,
            0,
            &fleet.trajectories.to_vec(),
            fleet.common_arrival,
        );
        let mut rng = StdRng::seed_from_u64(9);
        assert!(p.sample(&mut rng).len() == p.dim());
        let mut solver = Pso::adaptive(40, 5);
        let out = Executor::new(200).run(&p, &mut solver, |_| {});
        let e = p.evaluate(out.state.best_position());
        assert!(e.min_separation >= 50.0, "{}", e.min_separation);
        assert_eq!(e.terms.separation, 0.0);
        assert!(
            e.total < fleet.total / 2.0,
            "{} vs {}",
            e.total,
            fleet.total
        );
        Ok(())
    }

    #[test]
    fn a_path_too_short_for_the_common_arrival_pays_unless_early_is_allowed(
    ) -> Result<(), Box<dyn std::error::Error>> {
        let mut s = scenario()?;
        s.vehicles.truncate(1);
        let model = FleetModel::new(&s);
        let x = &straight_particle(&model)[..24];
        // a's straight 800 m take at least 1600 s at 0.5 m/s: timed for 2000 s it is 400 s
        // early, 1 + 400 / 2000 in the motion penalty; timed for 1600 s, on time.
        let late = VehicleProblem::new(&model, 0, &[], 2000.0);
        let e = late.evaluate(x);
        assert!((e.terms.motion - 1.2).abs() < 1e-9, "{:?}", e.terms);
        assert!((e.trajectory.arrival() - 1600.0).abs() < 1e-6);
        let allowed = late.early_arrival_allowed().evaluate(x);
        assert_eq!(allowed.terms.motion, 0.0);
        assert!((e.total - allowed.total - 10.0 * 1.2).abs() < 1e-9);
        let on_time = VehicleProblem::new(&model, 0, &[], 1600.0).evaluate(x);
        assert_eq!(on_time.terms.motion, 0.0);
        Ok(())
    }

    #[test]
    fn a_vehicle_under_way_pays_for_turning_onto_its_first_leg(
    ) -> Result<(), Box<dyn std::error::Error>> {
        let mut s = scenario()?;
        s.vehicles.truncate(1);
        let model = FleetModel::new(&s);
        let x = &straight_particle(&model)[..24];
        let p = VehicleProblem::new(&model, 0, &[], s.fleet.mission_time_s);
        let base = p.evaluate(x);
        // a's first leg runs east. Moving north-east (45°) it pays 1 + 10/35 in the motion
        // penalty; moving east, nothing.
        let ne = p
            .clone()
            .entering_along(Vec3::new(1.0, 1.0, 0.0))
            .evaluate(x);
        assert!((ne.terms.motion - base.terms.motion - (1.0 + 10.0 / 35.0)).abs() < 1e-9);
        let weight = s.optimizer.penalty_weight;
        assert!((ne.total - base.total - weight * (1.0 + 10.0 / 35.0)).abs() < 1e-6);
        let east = p.entering_along(Vec3::new(3.0, 0.0, 0.0)).evaluate(x);
        assert_eq!(east.terms.motion, base.terms.motion);
        Ok(())
    }

    #[test]
    fn skipping_vehicles_that_never_come_near_changes_no_term(
    ) -> Result<(), crate::scenario::ScenarioError> {
        let model = FleetModel::new(&fixtures::crossing_fleet()?);
        let d_min = model.scenario.fleet.d_min_m;
        let mut rng = StdRng::seed_from_u64(3);
        let (mut close, mut skipped) = (0, 0);
        for _ in 0..30 {
            let e = model.evaluate(&model.sample(&mut rng));
            for i in 0..model.layout.vehicles {
                let problem =
                    VehicleProblem::new(&model, i, &e.trajectories.to_vec(), e.common_arrival);
                let genes = model.sample(&mut rng)[model.layout.chromosome(i)].to_vec();
                let got = problem.evaluate(&genes);
                // Every other vehicle, as the fitness measures a pair.
                let mine = Motion::new(&got.trajectory);
                let (mut space, mut penalty, mut min) = (0.0, 0.0, f64::INFINITY);
                for other in problem.others().to_vec() {
                    let p = motion_separation(&mine, &Motion::new(&other), d_min, false);
                    space += space_term(p.breach_s);
                    penalty += separation_penalty(p.min_distance, d_min);
                    min = min.min(p.min_distance);
                    skipped += usize::from(p.min_distance >= d_min);
                }
                assert_eq!(got.terms.space.to_bits(), space.to_bits());
                assert_eq!(got.terms.separation.to_bits(), penalty.to_bits());
                if min < d_min {
                    close += 1;
                    assert_eq!(got.min_separation, min);
                } else {
                    assert!(got.min_separation >= d_min);
                }
            }
        }
        assert!(close > 20 && skipped > 20, "{close} {skipped}");
        Ok(())
    }
}
