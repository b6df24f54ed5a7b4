//! The wire protocol between the coordinator and the vehicle agents (distributed AMP-PSO).
//!
//! - [`topics`] builds every Zenoh key expression; nothing else formats one.
//! - [`coordinator_to_agent`] and [`agent_to_coordinator`] hold the messages, one module per
//!   direction, each a serde enum inside a versioned [`Envelope`].
//! - [`codec`] is the only code that names the codec (bincode 1.3.3, size-limited, trailing
//!   bytes rejected).
//! - [`session`] is the only code that builds a Zenoh configuration (coordinator = embedded
//!   router, agents = clients, multicast scouting off). Note: in zenoh 1.10 `open(...).await`
//!   runs synchronously, so a timeout around it bounds nothing; open on a thread of its own.

pub mod agent_to_coordinator;
pub mod codec;
pub mod coordinator_to_agent;
pub mod session;
pub mod topics;

use serde::{Deserialize, Serialize};

use crate::swarm::population::Particle;
use crate::trajectory::Trajectory;

/// Protocol version every message carries; a peer speaking another version is ignored.
pub const PROTOCOL_VERSION: u16 = 1;

/// A message of either direction with its protocol version.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Envelope<T> {
    /// [`PROTOCOL_VERSION`] of the sender. It is the first field, so a receiver can read it
    /// before it knows how to read the rest.
    pub version: u16,
    /// The message.
    pub body: T,
}

impl<T> Envelope<T> {
    /// `body` stamped with this build's protocol version.
    pub fn new(body: T) -> Envelope<T> {
        Envelope {
            version: PROTOCOL_VERSION,
            body,
        }
    }
}

/// One vehicle's particle on the wire: a chromosome, its velocity and its memory.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WireParticle {
    /// Position (the chromosome's genes).
    pub x: Vec<f64>,
    /// Velocity.
    pub v: Vec<f64>,
    /// Cost of `x` where it was evaluated.
    pub cost: f64,
    /// Personal best position.
    pub best_x: Vec<f64>,
    /// Cost of `best_x`.
    pub best_cost: f64,
}

impl From<&Particle> for WireParticle {
    fn from(p: &Particle) -> Self {
        WireParticle {
            x: p.x.clone(),
            v: p.v.clone(),
            cost: p.cost,
            best_x: p.best_x.clone(),
            best_cost: p.best_cost,
        }
    }
}

impl WireParticle {
    /// A one-block particle (the receiver re-evaluates it in its own context before trusting
    /// the costs).
    pub fn into_particle(self) -> Particle {
        Particle {
            parts: vec![self.cost],
            best_parts: vec![self.best_cost],
            x: self.x,
            v: self.v,
            cost: self.cost,
            best_x: self.best_x,
            best_cost: self.best_cost,
        }
    }
}

/// A timed trajectory on the wire: `[t_s, x_m, y_m, z_m]` samples, as in `plan.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WireTrajectory {
    /// Vehicle id.
    pub vehicle: String,
    /// Samples.
    pub samples: Vec<[f64; 4]>,
}

impl WireTrajectory {
    /// `t` for vehicle `vehicle`.
    pub fn new(vehicle: &str, t: &Trajectory) -> WireTrajectory {
        WireTrajectory {
            vehicle: vehicle.to_string(),
            samples: t
                .times
                .iter()
                .zip(&t.points)
                .map(|(s, p)| [*s, p.x, p.y, p.z])
                .collect(),
        }
    }

    /// Back to a trajectory.
    pub fn to_trajectory(&self) -> Trajectory {
        Trajectory {
            times: self.samples.iter().map(|s| s[0]).collect(),
            points: self
                .samples
                .iter()
                .map(|s| crate::geometry::Vec3::new(s[1], s[2], s[3]))
                .collect(),
        }
    }
}
