//! One vehicle's seat in a mission: what its agent sent, and its followers once the
//! coordinator plans it here (degraded mode).

use std::sync::Arc;
use std::time::Instant;

use shoal_common::cost::FleetModel;
use shoal_common::distributed::follower::{FollowerSettings, Followers};
use shoal_common::distributed::{Chromosome, Context};
use shoal_common::plan::DegradedVehicle;
use shoal_common::wire::WireChromosome;

use super::share::Share;

/// The exchange round being collected: its index and its iterations `start..start + len`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct RoundSpan {
    pub index: u32,
    pub start: usize,
    pub len: usize,
}

/// One vehicle's seat in the mission.
pub(super) struct Seat {
    pub id: String,
    pub alive: bool,
    pub joined: bool,
    /// Followers run here after the agent was lost.
    pub local: Option<Followers>,
    pub degraded: Option<DegradedVehicle>,
    pub last_elites: Vec<Chromosome>,
    pub this_round: Option<Vec<Chromosome>>,
    pub elites_received: u32,
    pub agent_iterations: u32,
    /// Evaluations the agent last reported.
    pub agent_evaluations: u64,
    pub done: Option<(u32, u64, u32)>,
    /// When and why its agent was seen to go (token gone, process exited).
    pub gone: Option<(Instant, String)>,
    /// One-shot missions: the vehicle's share, from its agent or planned here.
    pub share: Option<Share>,
}

impl Seat {
    /// An empty seat for vehicle `id`, before its agent joined.
    pub fn new(id: &str) -> Seat {
        Seat {
            id: id.to_string(),
            alive: false,
            joined: false,
            local: None,
            degraded: None,
            last_elites: Vec::new(),
            this_round: None,
            elites_received: 0,
            agent_iterations: 0,
            agent_evaluations: 0,
            done: None,
            gone: None,
            share: None,
        }
    }

    /// Keeps an agent's elites for the current round, with the figures they report.
    pub fn take_elites(
        &mut self,
        iteration: u32,
        evaluations: u64,
        particles: Vec<WireChromosome>,
    ) {
        self.elites_received += 1;
        self.agent_iterations = iteration;
        self.agent_evaluations = evaluations;
        self.this_round = Some(particles.into_iter().map(Chromosome::from).collect());
    }

    /// Where planning goes on here when the agent is lost during round `span`: an agent that
    /// already sent this round's elites ran the round, so its followers resume from those
    /// elites with the round counted (the mission loop does not step them again this round);
    /// otherwise from the last round's elites at the round's start.
    pub fn resume_point(&self, span: RoundSpan) -> (&[Chromosome], usize) {
        match &self.this_round {
            Some(elites) => (elites, span.start + span.len),
            None => (&self.last_elites, span.start),
        }
    }

    /// Starts planning this vehicle (scenario index `i`) here from round `span`; the first
    /// reason given is kept. Does nothing when it is already planned here.
    pub fn take_over(
        &mut self,
        model: &Arc<FleetModel>,
        i: usize,
        settings: FollowerSettings,
        context: &Context,
        span: RoundSpan,
        why: String,
    ) {
        if self.local.is_some() {
            return;
        }
        tracing::warn!(
            "planning {} in the coordinator from round {}: {why}",
            self.id,
            span.index
        );
        let (elites, done) = self.resume_point(span);
        let f = Followers::resume(
            Arc::clone(model),
            i,
            settings,
            context.clone(),
            elites,
            done,
        );
        self.local = Some(f);
        self.alive = false;
        self.degraded = Some(DegradedVehicle {
            vehicle: self.id.clone(),
            from_round: span.index,
            reason: why,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shoal_common::distributed::leader::Leader;
    use shoal_common::scenario::Scenario;
    use std::path::PathBuf;

    type TestResult = Result<(), Box<dyn std::error::Error>>;

    /// Scenario 1 with a tiny swarm: 2 populations of 4 particles.
    fn model() -> Result<Arc<FleetModel>, Box<dyn std::error::Error>> {
        let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenarios/amp-pso-1.toml");
        let mut s = Scenario::load(&path)?;
        s.optimizer.populations = 2;
        s.optimizer.particles = 4;
        s.optimizer.leader_particles = 4;
        Ok(Arc::new(FleetModel::new(&s)))
    }

    /// Scenario 1's model, follower settings, the leader's first context and two valid
    /// elites of vehicle 0 (from followers of another seed).
    type Mission = (Arc<FleetModel>, FollowerSettings, Context, Vec<Chromosome>);

    fn mission() -> Result<Mission, Box<dyn std::error::Error>> {
        let model = model()?;
        let o = model.scenario.optimizer.clone();
        let settings = FollowerSettings::of(&o);
        let context = Leader::new(Arc::clone(&model), &o, settings.schedule).context(0);
        let mut other = settings.clone();
        other.seed = 99;
        let elites = Followers::new(Arc::clone(&model), 0, other, context.clone()).emigrants();
        Ok((model, settings, context, elites))
    }

    /// A one-gene elite `x` at velocity `v`.
    fn elite(x: f64, v: f64) -> Vec<Chromosome> {
        vec![Chromosome {
            x: vec![x],
            v: vec![v],
        }]
    }

    const SPAN: RoundSpan = RoundSpan {
        index: 2,
        start: 10,
        len: 5,
    };

    #[test]
    fn an_agent_lost_before_its_elites_resumes_at_the_round_start_from_the_last_ones() {
        let mut seat = Seat::new("auv1");
        seat.last_elites = elite(1.0, 0.0);
        let (from, done) = seat.resume_point(SPAN);
        assert_eq!(done, 10);
        assert_eq!(from, seat.last_elites.as_slice());
    }

    #[test]
    fn an_agent_lost_after_its_elites_resumes_after_the_round_from_those_elites() {
        let mut seat = Seat::new("auv1");
        seat.last_elites = elite(1.0, 0.0);
        let newer = elite(2.0, 0.5);
        seat.take_elites(15, 400, newer.iter().map(WireChromosome::from).collect());
        let (from, done) = seat.resume_point(SPAN);
        assert_eq!(done, 15);
        assert_eq!(from, newer.as_slice());
    }

    /// The loopback test's race, made certain: the agent's elites of round 2 arrived, then it
    /// ended. Planned here from then on, the vehicle must still count every iteration of the
    /// run once the mission loop has stepped the rounds after this one.
    #[test]
    fn a_vehicle_taken_over_after_its_elites_counts_the_round_its_agent_ran() -> TestResult {
        let (model, settings, context, elites) = mission()?;
        let mut seat = Seat::new("auv1");
        seat.last_elites = elites;
        seat.take_elites(
            15,
            400,
            seat.last_elites.iter().map(WireChromosome::from).collect(),
        );
        seat.take_over(&model, 0, settings.clone(), &context, SPAN, "gone".into());
        let f = seat.local.as_ref().ok_or("not planned here")?;
        assert_eq!(f.iterations, 15);
        assert_eq!(f.vehicle(), 0);
        assert!(!seat.alive);
        let d = seat.degraded.as_ref().ok_or("not marked degraded")?;
        assert_eq!((d.vehicle.as_str(), d.from_round), ("auv1", 2));
        assert_eq!(d.reason, "gone");
        // A second loss keeps the first takeover and its reason.
        let later = RoundSpan {
            index: 3,
            start: 15,
            len: 5,
        };
        seat.take_over(&model, 0, settings, &context, later, "again".into());
        let d = seat.degraded.as_ref().ok_or("not marked degraded")?;
        assert_eq!((d.from_round, d.reason.as_str()), (2, "gone"));
        assert_eq!(seat.local.as_ref().map(|f| f.iterations), Some(15));
        Ok(())
    }

    #[test]
    fn a_vehicle_taken_over_before_its_elites_resumes_at_the_round_start() -> TestResult {
        let (model, settings, context, elites) = mission()?;
        let mut seat = Seat::new("auv2");
        seat.last_elites = elites;
        seat.take_over(&model, 1, settings, &context, SPAN, "silent".into());
        let f = seat.local.as_ref().ok_or("not planned here")?;
        assert_eq!((f.iterations, f.vehicle()), (10, 1));
        Ok(())
    }
}
