//! Size and range checks against [`crate::limits`]: how many of each thing a scenario lists, how
//! much work its optimizer settings ask for, and the physical ranges of its quantities. They run
//! first, so that no later check loops over a million vehicles and nothing is allocated for a
//! value no vehicle could have.

use super::error::{in_range, Bad, ScenarioError};
use super::model::Scenario;
use crate::limits;

impl Scenario {
    /// The counts of every list, before anything loops over them.
    pub(super) fn validate_counts(&self, bad: Bad) -> Result<(), ScenarioError> {
        let lists = [
            (
                "vehicles",
                self.vehicles.len(),
                limits::MAX_VEHICLES,
                "MAX_VEHICLES",
            ),
            (
                "obstacles",
                self.obstacles.len(),
                limits::MAX_OBSTACLES,
                "MAX_OBSTACLES",
            ),
            (
                "hazards",
                self.hazards.len(),
                limits::MAX_OBSTACLES,
                "MAX_OBSTACLES",
            ),
            (
                "seabed.mountains",
                self.seabed.as_ref().map_or(0, |s| s.mountains.len()),
                limits::MAX_OBSTACLES,
                "MAX_OBSTACLES",
            ),
            (
                "coverage.terrain.peaks",
                self.coverage.as_ref().map_or(0, |c| c.terrain.peaks.len()),
                limits::MAX_OBSTACLES,
                "MAX_OBSTACLES",
            ),
            (
                "coverage.terrain.pits",
                self.coverage.as_ref().map_or(0, |c| c.terrain.pits.len()),
                limits::MAX_OBSTACLES,
                "MAX_OBSTACLES",
            ),
        ];
        for (field, n, bound, name) in lists {
            if n > bound {
                return Err(bad(
                    field.into(),
                    format!("{n} entries"),
                    &format!("is over the limit {bound} (limits::{name})"),
                ));
            }
        }
        Ok(())
    }

    /// The diagonal of the bounds, metres (bounds already checked finite).
    fn diagonal(&self) -> f64 {
        let b = &self.bounds;
        (0..3)
            .map(|a| (b.max[a] - b.min[a]).powi(2))
            .sum::<f64>()
            .sqrt()
    }

    /// Extent of the box and obstacle sizes against it (before a start is found inside an
    /// obstacle the size of the ocean).
    pub(super) fn validate_extent(&self, bad: Bad) -> Result<(), ScenarioError> {
        for axis in 0..3 {
            let extent = self.bounds.max[axis] - self.bounds.min[axis];
            if extent > limits::MAX_EXTENT_M {
                return Err(bad(
                    format!("bounds.max[{axis}]"),
                    self.bounds.max[axis].to_string(),
                    &format!(
                        "makes the box {extent} m wide, over the limit {} m (limits::MAX_EXTENT_M)",
                        limits::MAX_EXTENT_M
                    ),
                ));
            }
        }
        let diagonal = self.diagonal();
        for (i, o) in self.obstacles.iter().enumerate() {
            // An obstacle wider than the whole box leaves nothing to plan in (a soft one is a
            // threat everywhere): a unit mistake, not a mission.
            if o.inflated_radius() > diagonal {
                return Err(bad(
                    format!("obstacles[{i}].radius_m"),
                    o.radius_m.to_string(),
                    &format!(
                        "plus inflation {} m is larger than the bounds' diagonal {diagonal:.1} m",
                        o.inflation_m
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The fleet's d_min against the box, its mission time, and the vehicles' speeds.
    pub(super) fn validate_physical(&self, bad: Bad) -> Result<(), ScenarioError> {
        let diagonal = self.diagonal();
        if self.fleet.d_min_m > diagonal {
            return Err(bad(
                "fleet.d_min_m".into(),
                self.fleet.d_min_m.to_string(),
                &format!("is larger than the bounds' diagonal {diagonal:.1} m: no two vehicles inside the box can keep it"),
            ));
        }
        let t = self.fleet.mission_time_s;
        if t > limits::MAX_MISSION_TIME_S {
            return Err(bad(
                "fleet.mission_time_s".into(),
                t.to_string(),
                &format!(
                    "is over the limit {} s (limits::MAX_MISSION_TIME_S, 30 days)",
                    limits::MAX_MISSION_TIME_S
                ),
            ));
        }
        for (i, v) in self.vehicles.iter().enumerate() {
            for (name, s) in [
                ("speed_min_mps", v.speed_min_mps),
                ("speed_max_mps", v.speed_max_mps),
            ] {
                in_range(
                    bad,
                    &format!("vehicles[{i}].{name}"),
                    s,
                    limits::SPEED_MPS,
                    "m/s (limits::SPEED_MPS)",
                )?;
            }
        }
        Ok(())
    }

    /// Evaluations the optimizer settings ask for: particles × populations × iterations ×
    /// vehicles, each within its own bound and the product within
    /// [`limits::MAX_EVALUATIONS`].
    pub(super) fn validate_work(&self, bad: Bad) -> Result<(), ScenarioError> {
        let o = &self.optimizer;
        // Single-population algorithms ignore `populations`; a multi-population one runs the
        // followers and a leader of `leader_particles` besides.
        let per_iteration = if o.algorithm.is_multi_population() {
            (o.populations as u128) * (o.particles as u128) + o.leader_particles as u128
        } else {
            o.particles as u128
        };
        let total = per_iteration * o.iterations as u128 * self.vehicles.len().max(1) as u128;
        if total > limits::MAX_EVALUATIONS {
            return Err(bad(
                "optimizer.iterations".into(),
                o.iterations.to_string(),
                &format!(
                    "with {} particles, {} populations and {} vehicles asks for {total} vehicle evaluations, over the limit {} (limits::MAX_EVALUATIONS)",
                    o.particles,
                    o.populations,
                    self.vehicles.len(),
                    limits::MAX_EVALUATIONS
                ),
            ));
        }
        Ok(())
    }
}
