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
//! - [`security`] says how members authenticate (TLS, mutual TLS, user/password, access
//!   control from a Zenoh configuration file); [`flags`] is the one flag group for it.
//!
//! The messages, [`topics`] and [`open`] are plain serde types and always built; [`codec`],
//! [`session`], [`security`] and [`flags`] need the `transport` feature (on by default), which
//! brings bincode, zenoh and clap.

pub mod agent_to_coordinator;
#[cfg(feature = "transport")]
pub mod codec;
pub mod coordinator_to_agent;
#[cfg(feature = "transport")]
pub mod flags;
pub mod open;
#[cfg(feature = "transport")]
pub mod security;
#[cfg(feature = "transport")]
pub mod session;
#[cfg(feature = "transport")]
mod session_error;
pub mod topics;

use serde::{Deserialize, Serialize};

use crate::distributed::{Chromosome, Context};
use crate::trajectory::Trajectory;

/// Protocol version every message carries; a peer speaking another version is ignored.
/// Bumped whenever a message's layout changes (bincode is not self-describing):
/// 2 — `AgentToCoordinator::Tour` carries the tour's evaluations;
/// 3 — and whether a stop cut its swarms short;
/// 4 — a coverage strip's tracking report says whether a stop cut the simulation short;
/// 5 — `AgentToCoordinator::Tour` carries the tour's convergence curve;
/// 6 — every [`Envelope`] carries an order sequence number, checked by the agents.
pub const PROTOCOL_VERSION: u16 = 6;

/// A message of either direction with its protocol version.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Envelope<T> {
    /// [`PROTOCOL_VERSION`] of the sender. It is the first field, so a receiver can read it
    /// before it knows how to read the rest.
    pub version: u16,
    /// The coordinator's order number: counts up over everything one coordinator sends for a
    /// mission, so an agent acts on an order on its inbox only if its number is above the last
    /// one it took (a replayed or reordered order is dropped). 0 in what agents send.
    pub seq: u64,
    /// The message.
    pub body: T,
}

impl<T> Envelope<T> {
    /// `body` stamped with this build's protocol version, unsequenced (agents' messages).
    pub fn new(body: T) -> Envelope<T> {
        Envelope::sequenced(body, 0)
    }

    /// `body` stamped with this build's protocol version and order number `seq`.
    pub fn sequenced(body: T, seq: u64) -> Envelope<T> {
        Envelope {
            version: PROTOCOL_VERSION,
            seq,
            body,
        }
    }
}

/// One vehicle's chromosome on the wire: its genes and its velocity (Zhi & Zuo 2024, Fig. 5: what an
/// emigrant carries up to the leader and a migrant carries back).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WireChromosome {
    /// Position (the chromosome's genes).
    pub x: Vec<f64>,
    /// Velocity.
    pub v: Vec<f64>,
}

impl From<&Chromosome> for WireChromosome {
    fn from(c: &Chromosome) -> Self {
        WireChromosome {
            x: c.x.clone(),
            v: c.v.clone(),
        }
    }
}

impl From<WireChromosome> for Chromosome {
    fn from(c: WireChromosome) -> Self {
        Chromosome { x: c.x, v: c.v }
    }
}

/// The fleet plan the followers score against ([`Context`]) on the wire.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WireContext {
    /// Exchange round it comes from.
    pub round: u32,
    /// Common arrival time, seconds.
    pub arrival_s: f64,
    /// Every vehicle's trajectory, in scenario order.
    pub trajectories: Vec<WireTrajectory>,
}

/// Why a context from the coordinator does not fit the agent's fleet.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BadContext {
    /// One trajectory per vehicle is expected.
    #[error("context has {trajectories} trajectories for a fleet of {fleet}")]
    Count {
        /// Trajectories received.
        trajectories: usize,
        /// Vehicles in the fleet.
        fleet: usize,
    },
    /// The trajectories come in scenario order.
    #[error("context names {named:?} where {expected:?} was expected")]
    Vehicle {
        /// The id the context gives.
        named: String,
        /// The id in that place of the scenario.
        expected: String,
    },
    /// A trajectory is unusable.
    #[error(transparent)]
    Trajectory(#[from] BadTrajectory),
    /// The synchronised arrival time is not a number.
    #[error("arrival time {0} is not finite")]
    Arrival(f64),
}

/// A trajectory from the network that is empty, not finite or not timed in order.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("trajectory of {0} is empty, not finite or not timed in order")]
pub struct BadTrajectory(
    /// The vehicle it is said to be of.
    pub String,
);

impl WireContext {
    /// `c` on the wire; `ids` names the vehicles in scenario order.
    pub fn new(c: &Context, ids: &[&str]) -> WireContext {
        WireContext {
            round: c.round,
            arrival_s: c.arrival,
            trajectories: c
                .trajectories
                .iter()
                .zip(ids)
                .map(|(t, id)| WireTrajectory::new(id, t))
                .collect(),
        }
    }

    /// Back to a context for a fleet of `ids` (scenario order), or why it does not fit.
    pub fn to_context(&self, ids: &[&str]) -> Result<Context, BadContext> {
        if self.trajectories.len() != ids.len() {
            return Err(BadContext::Count {
                trajectories: self.trajectories.len(),
                fleet: ids.len(),
            });
        }
        let mut trajectories = Vec::with_capacity(ids.len());
        for (t, id) in self.trajectories.iter().zip(ids) {
            if t.vehicle != *id {
                return Err(BadContext::Vehicle {
                    named: t.vehicle.clone(),
                    expected: (*id).to_string(),
                });
            }
            trajectories.push(t.checked()?);
        }
        if !self.arrival_s.is_finite() {
            return Err(BadContext::Arrival(self.arrival_s));
        }
        Ok(Context {
            round: self.round,
            arrival: self.arrival_s,
            trajectories,
        })
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
        Trajectory::from_samples(&self.samples)
    }

    /// Back to a trajectory, or why it is unusable (empty, not finite, not timed in order).
    pub fn checked(&self) -> Result<Trajectory, BadTrajectory> {
        let ok = !self.samples.is_empty()
            && self.samples.iter().flatten().all(|v| v.is_finite())
            && self.samples.windows(2).all(|w| w[1][0] >= w[0][0]);
        if ok {
            Ok(self.to_trajectory())
        } else {
            Err(BadTrajectory(self.vehicle.clone()))
        }
    }
}
