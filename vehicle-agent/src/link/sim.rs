//! The `sim` link: [`shoal_common::execution::sim::Simulator`] behind [`VehicleLink`]. The
//! simulator integrates up to the mission time each `state` asks for, so the agent's clock (real
//! time × `--time-scale`) drives it.

use std::sync::Arc;

use shoal_common::execution::sim::{SimModel, SimSettings, Simulator};
use shoal_common::execution::VehicleState;
use shoal_common::scenario::{Scenario, VehicleKind};
use shoal_common::trajectory::Trajectory;

use super::{LinkError, VehicleLink};

/// A simulated vehicle.
pub struct SimLink {
    sim: Simulator,
    kind: VehicleKind,
}

impl SimLink {
    /// Vehicle `index` of `scenario`: an AUV in the scenario's current (if any), or a crawler
    /// on its seabed (flat at the bottom of the box without one).
    pub fn new(
        scenario: &Scenario,
        index: usize,
        position_noise_m: f64,
        seed: u64,
    ) -> Result<SimLink, LinkError> {
        let vehicle = scenario
            .vehicles
            .get(index)
            .ok_or_else(|| LinkError::Io(format!("the scenario has no vehicle #{index}")))?;
        let model = match vehicle.kind {
            VehicleKind::Auv => SimModel::Auv {
                current: scenario
                    .currents
                    .as_ref()
                    .map(|c| c.field(scenario.bounds.min[2], scenario.bounds.max[2])),
                surface_z: scenario.bounds.max[2],
            },
            VehicleKind::Crawler => {
                let floor = scenario.bounds.min[2];
                let terrain = scenario.terrain().cloned();
                SimModel::Crawler {
                    seabed: Arc::new(move |x, y| {
                        terrain.as_ref().map_or(floor, |t| t.elevation(x, y))
                    }),
                    sensor_height_m: scenario.crawler.sensor_height_m,
                    slip: 0.05,
                }
            }
        };
        let defaults = SimSettings::default();
        let settings = SimSettings {
            position_noise_m,
            seed,
            turn_radius_m: scenario
                .execution_turn_radius_m(index)
                .unwrap_or(defaults.turn_radius_m),
            ..defaults
        };
        Ok(SimLink {
            sim: Simulator::new(vehicle, model, settings),
            kind: vehicle.kind,
        })
    }
}

impl VehicleLink for SimLink {
    fn name(&self) -> String {
        format!("sim ({:?})", self.kind).to_lowercase()
    }

    fn upload(&mut self, plan: &Trajectory) -> Result<(), LinkError> {
        if plan.times.is_empty() || plan.times.len() != plan.points.len() {
            return Err(LinkError::Refused(format!(
                "a trajectory of {} times and {} points",
                plan.times.len(),
                plan.points.len()
            )));
        }
        self.sim.load(plan.clone());
        Ok(())
    }

    fn state(&mut self, now: f64) -> Result<VehicleState, LinkError> {
        self.sim.advance_to(now);
        Ok(self.sim.state())
    }

    fn hold(&mut self) -> Result<(), LinkError> {
        self.sim.hold();
        Ok(())
    }

    fn stop(&mut self) -> Result<(), LinkError> {
        self.sim.stop();
        Ok(())
    }
}
