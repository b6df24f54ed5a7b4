//! The vehicle-link seam: everything the agent asks of a vehicle goes through [`VehicleLink`],
//! so a real vehicle's link plugs in here without touching the swarm or the transport.
//!
//! - [`sim`]: a kinematic simulator per vehicle kind (AUV in an optional current, crawler on
//!   the seabed with slip), with position noise, on the mission clock (real time or faster).
//!
//! Times are mission seconds (0 = the plan's start); positions are in the scenario frame.

pub mod sim;

use shoal_common::execution::VehicleState;
use shoal_common::scenario::Scenario;
use shoal_common::trajectory::Trajectory;

/// Why a link could not do what was asked.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LinkError {
    /// The vehicle did not answer in time (after the link's retries).
    #[error("the vehicle did not answer: {0}")]
    Timeout(String),
    /// The vehicle refused (e.g. a mission item out of its limits).
    #[error("the vehicle refused: {0}")]
    Refused(String),
    /// The link itself failed (socket, I/O).
    #[error("link failure: {0}")]
    Io(String),
}

/// A vehicle as the agent drives it.
pub trait VehicleLink: Send {
    /// Short name for logs (`sim`, `mavlink udp:…`).
    fn name(&self) -> String;
    /// Loads a timed trajectory (mission-timed samples); the vehicle follows it from now on,
    /// replacing what it followed before (and leaving a hold).
    fn upload(&mut self, plan: &Trajectory) -> Result<(), LinkError>;
    /// The vehicle's state at mission time `now` (a simulator advances to it; a real vehicle
    /// reports its latest fix, stamped `now`).
    fn state(&mut self, now: f64) -> Result<VehicleState, LinkError>;
    /// Hold where it is until the next upload.
    fn hold(&mut self) -> Result<(), LinkError>;
    /// Stop: the mission is over for this vehicle.
    fn stop(&mut self) -> Result<(), LinkError>;
}

/// Which link an agent drives its vehicle through.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum LinkKind {
    /// The kinematic simulator.
    #[default]
    Sim,
}

/// Settings of the links, from the agent's command line.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkSettings {
    /// Which link.
    pub kind: LinkKind,
    /// Simulated position noise (standard deviation per axis), metres.
    pub position_noise_m: f64,
}

/// Opens the link of vehicle `index` of `scenario`.
pub fn open(
    settings: &LinkSettings,
    scenario: &Scenario,
    index: usize,
    seed: u64,
) -> Result<Box<dyn VehicleLink>, LinkError> {
    match settings.kind {
        LinkKind::Sim => Ok(Box::new(sim::SimLink::new(
            scenario,
            index,
            settings.position_noise_m,
            seed,
        )?)),
    }
}
