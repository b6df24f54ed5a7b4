//! The planners: a fleet's swarm in this process ([`planner`], its best finished by [`finish`]), one AUV's energy-aware path
//! ([`energy`]), inspection tours ([`tour`]) and coverage missions ([`coverage`],
//! [`coverage_fleet`]), on the one solver loop of [`solver`]; and random fleet scenarios to plan
//! ([`generated`]).

pub mod coverage;
pub mod coverage_fleet;
pub mod energy;
pub mod finish;
pub mod generated;
pub mod planner;
pub mod solver;
pub mod tour;
