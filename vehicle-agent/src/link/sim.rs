//! The `sim` link: [`shoal_common::execution::sim::Simulator`] behind [`VehicleLink`]. The
//! simulator integrates up to the mission time each `state` asks for, so the agent's clock (real
//! time × `--time-scale`) drives it.

use std::path::Path;
use std::sync::Arc;

use shoal_common::coverage::fleet::FleetCoverage;
use shoal_common::execution::sim::{SimModel, SimSettings, Simulator};
use shoal_common::execution::{VehicleCommand, VehicleState};
use shoal_common::scenario::{Scenario, VehicleKind};
use shoal_common::trajectory::Trajectory;

use super::types::{CommandSerial, LinkError, LinkOutcome, VehicleLink};

/// A simulated vehicle.
pub struct SimLink {
    sim: Simulator,
    kind: VehicleKind,
    /// Commands done and not yet collected: a simulator confirms each at once.
    outcomes: Vec<LinkOutcome>,
    /// Commands given so far: the last one's serial.
    given: CommandSerial,
}

impl SimLink {
    /// Vehicle `index` of `scenario`: an AUV in the scenario's current (if any), or a crawler
    /// on its seabed (a coverage mission's map; flat at the bottom of the box without one).
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
            // A CPP-DSMV coverage crawler drives on the mission's 2.5-D seabed map, the one its
            // path was planned on (a heightmap file is looked up from the working directory,
            // as the agent's planning does).
            VehicleKind::Crawler if scenario.coverage.is_some() => {
                let map = FleetCoverage::new(scenario)
                    .map_err(|e| LinkError::Io(e.to_string()))?
                    .map(Path::new("."))
                    .map_err(|e| LinkError::Io(format!("the [coverage] seabed map: {e}")))?;
                SimModel::Crawler {
                    seabed: Arc::new(move |x, y| map.elevation_at(x, y)),
                    sensor_height_m: scenario.crawler.sensor_height_m,
                    slip: 0.05,
                }
            }
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
            battery_per_hour: battery_per_hour(vehicle.kind),
            ..defaults
        };
        Ok(SimLink {
            sim: Simulator::new(vehicle, model, settings),
            kind: vehicle.kind,
            outcomes: Vec::new(),
            given: 0,
        })
    }
}

impl SimLink {
    /// A command just done: its outcome, confirmed, kept for collection; its serial.
    fn done(&mut self, command: VehicleCommand, detail: &str) -> CommandSerial {
        self.given += 1;
        let serial = self.given;
        self.outcomes
            .push(LinkOutcome::confirmed(serial, command, detail));
        serial
    }
}

/// Battery drain of a simulated vehicle, fraction of a charge per hour underway: an AUV's own
/// battery ([`SimSettings`]'s default, ten hours), none for a crawler. A deep-sea collector is
/// powered from its support vessel through the umbilical of its riser (Lu et al.'s P1–P3 are
/// tens of kW for hours on end), so a coverage mission of a day or more does not end flat; a
/// battery limit made every crawler of `cpp-fleet` fault ten hours into its 22–26 h strip.
fn battery_per_hour(kind: VehicleKind) -> f64 {
    match kind {
        VehicleKind::Auv => SimSettings::default().battery_per_hour,
        VehicleKind::Crawler => 0.0,
    }
}

impl VehicleLink for SimLink {
    fn name(&self) -> String {
        format!("sim ({:?})", self.kind).to_lowercase()
    }

    fn upload(&mut self, plan: &Trajectory) -> Result<CommandSerial, LinkError> {
        if plan.times.is_empty() || plan.times.len() != plan.points.len() {
            return Err(LinkError::Refused(format!(
                "a trajectory of {} times and {} points",
                plan.times.len(),
                plan.points.len()
            )));
        }
        self.sim.load(plan.clone());
        Ok(self.done(VehicleCommand::Upload, "simulated: loaded"))
    }

    fn state(&mut self, now: f64) -> Result<VehicleState, LinkError> {
        self.sim.advance_to(now);
        Ok(self.sim.state())
    }

    fn hold(&mut self, now: f64) -> Result<CommandSerial, LinkError> {
        self.sim.advance_to(now);
        self.sim.hold();
        Ok(self.done(VehicleCommand::Hold, "simulated: holds"))
    }

    fn stop(&mut self) -> Result<CommandSerial, LinkError> {
        self.sim.stop();
        Ok(self.done(VehicleCommand::Stop, "simulated: stopped"))
    }

    fn outcomes(&mut self) -> Vec<LinkOutcome> {
        std::mem::take(&mut self.outcomes)
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use shoal_common::coverage::fleet::FleetCoverage;
    use shoal_common::execution::VehicleStatus;
    use shoal_common::geometry::Vec3;
    use shoal_common::scenario::Scenario;
    use shoal_common::trajectory::Trajectory;

    use super::*;

    fn scenario(name: &str) -> Result<Scenario, String> {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../scenarios")
            .join(name);
        Scenario::load(&path).map_err(|e| e.to_string())
    }

    /// A coverage crawler drives on the mission's seabed map (its z is the map's height plus
    /// the sensor height) and is still going after 12 h: no battery runs flat.
    #[test]
    fn a_coverage_crawler_drives_on_the_map_for_longer_than_a_battery_lasts() -> Result<(), String>
    {
        let s = scenario("cpp-seabed.toml")?;
        let map = FleetCoverage::new(&s)
            .map_err(|e| e.to_string())?
            .map(Path::new("."))
            .map_err(|e| e.to_string())?;
        let mut link = SimLink::new(&s, 0, 0.0, 1).map_err(|e| e.to_string())?;
        // Back and forth along y = 5 m at 0.5 m/s (4 × 900 m, 2 h) and then holding there.
        let xs = [50.0, 950.0, 50.0, 950.0, 50.0];
        let plan = Trajectory {
            times: (0..xs.len()).map(|k| 1800.0 * k as f64).collect(),
            points: xs.iter().map(|x| Vec3::new(*x, 5.0, 0.0)).collect(),
        };
        link.upload(&plan).map_err(|e| e.to_string())?;
        let mid = link.state(2700.0).map_err(|e| e.to_string())?;
        let [x, y, z] = mid.position;
        assert!((z - (map.elevation_at(x, y) + s.crawler.sensor_height_m)).abs() < 1e-9);
        assert!((x - 500.0).abs() < 20.0, "x = {x}");
        let late = link.state(12.0 * 3600.0).map_err(|e| e.to_string())?;
        assert_eq!(late.status, VehicleStatus::Arrived);
        assert!((late.battery - 1.0).abs() < 1e-12, "{}", late.battery);
        Ok(())
    }

    /// A hold between two reports takes effect where the vehicle is when it comes, not where
    /// it was at the last report: at 500× two reports at 2 Hz are 250 mission seconds apart.
    #[test]
    fn a_hold_between_reports_holds_where_the_vehicle_is_then() -> Result<(), String> {
        let s = scenario("cpp-seabed.toml")?;
        let mut link = SimLink::new(&s, 0, 0.0, 1).map_err(|e| e.to_string())?;
        // East along y = 5 m from x = 50 at 0.5 m/s.
        let plan = Trajectory {
            times: vec![0.0, 1800.0],
            points: vec![Vec3::new(50.0, 5.0, 0.0), Vec3::new(950.0, 5.0, 0.0)],
        };
        link.upload(&plan).map_err(|e| e.to_string())?;
        let report = link.state(100.0).map_err(|e| e.to_string())?;
        // Told to hold at t = 350 s, with no report since t = 100 s (x ≈ 100 m then).
        link.hold(350.0).map_err(|e| e.to_string())?;
        let held = link.state(600.0).map_err(|e| e.to_string())?;
        assert_eq!(held.status, VehicleStatus::Holding);
        assert!(
            (held.position[0] - 225.0).abs() < 10.0,
            "{:?}",
            held.position
        );
        assert!(held.position[0] - report.position[0] > 100.0);
        Ok(())
    }

    #[test]
    fn an_auv_drains_its_battery_a_crawler_does_not() {
        assert!(battery_per_hour(VehicleKind::Auv) > 0.0);
        assert_eq!(battery_per_hour(VehicleKind::Crawler), 0.0);
    }
}
