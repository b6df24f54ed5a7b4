//! Scenario checks: every value a planner relies on, each bad one reported with the file, the
//! field and the value (see [`ScenarioError::Invalid`]).

use std::path::Path;

use super::error::{invalid_in, over, Bad, ScenarioError};
use super::inspection::InspectionSettings;
use super::model::{ObstacleKind, Scenario, VehicleKind};
use crate::geometry::Vec3;
use crate::limits;

/// The least distance between a vehicle's start and goal a path planner accepts, metres.
pub const MIN_START_GOAL_DISTANCE_M: f64 = 1.0;

impl Scenario {
    /// Checks every value a planner relies on; the first bad one is reported.
    pub fn validate(&self, file: &Path) -> Result<(), ScenarioError> {
        let bad = invalid_in(file);
        for axis in 0..3 {
            let (lo, hi) = (self.bounds.min[axis], self.bounds.max[axis]);
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(bad(
                    format!("bounds.max[{axis}]"),
                    format!("{hi}"),
                    &format!("must be finite and greater than bounds.min[{axis}] = {lo}"),
                ));
            }
        }
        self.validate_counts(&bad)?;
        self.validate_origin(&bad)?;
        let inside =
            |p: &[f64; 3]| (0..3).all(|a| p[a] >= self.bounds.min[a] && p[a] <= self.bounds.max[a]);
        for (i, o) in self.obstacles.iter().enumerate() {
            if !o.centre.iter().all(|c| c.is_finite()) {
                return Err(bad(
                    format!("obstacles[{i}].centre"),
                    format!("{:?}", o.centre),
                    "must be finite",
                ));
            }
            if !(o.radius_m.is_finite() && o.radius_m > 0.0) {
                return Err(bad(
                    format!("obstacles[{i}].radius_m"),
                    o.radius_m.to_string(),
                    "must be a positive number of metres",
                ));
            }
            if !(o.inflation_m.is_finite() && o.inflation_m >= 0.0) {
                return Err(bad(
                    format!("obstacles[{i}].inflation_m"),
                    o.inflation_m.to_string(),
                    "must be zero or a positive number of metres",
                ));
            }
        }
        self.validate_extent(&bad)?;
        if self.vehicles.is_empty() {
            return Err(bad(
                "vehicles".into(),
                "[]".into(),
                "at least one vehicle is needed",
            ));
        }
        for (i, v) in self.vehicles.iter().enumerate() {
            if crate::wire::topics::check_id("vehicle", &v.id).is_err() {
                return Err(bad(
                    format!("vehicles[{i}].id"),
                    format!("{:?}", v.id),
                    "must be 1-64 letters, digits, '-', '_' or '.' (it names the vehicle on the network)",
                ));
            }
            if let Some(j) = self.vehicles[..i].iter().position(|w| w.id == v.id) {
                return Err(bad(
                    format!("vehicles[{i}].id"),
                    format!("{:?}", v.id),
                    &format!("duplicates vehicles[{j}].id"),
                ));
            }
            for (name, p) in [("start", &v.start), ("goal", &v.goal)] {
                if !inside(p) {
                    return Err(bad(
                        format!("vehicles[{i}].{name}"),
                        format!("{p:?}"),
                        "lies outside the bounds",
                    ));
                }
                for o in self
                    .obstacles
                    .iter()
                    .filter(|o| o.kind == ObstacleKind::Hard)
                {
                    let d = (Vec3::from(*p) - o.centre()).norm();
                    if d < o.inflated_radius() {
                        return Err(bad(
                            format!("vehicles[{i}].{name}"),
                            format!("{p:?}"),
                            &format!("lies inside hard obstacle {} (radius plus inflation {:.1} m, distance {d:.1} m)", o.id, o.inflated_radius()),
                        ));
                    }
                }
            }
            // A path planner scores a path against its straight start-goal line (F(L) of seed
            // 004 eq. (9), a crawler's standardisation): with the two on top of each other
            // every score is a division by nothing. Tours and coverage have their own ends.
            let straight = (v.goal() - v.start()).norm();
            if self.inspection.is_none()
                && self.coverage.is_none()
                && straight < MIN_START_GOAL_DISTANCE_M
            {
                return Err(bad(
                    format!("vehicles[{i}].goal"),
                    format!("{:?}", v.goal),
                    &format!(
                        "lies {straight:.3} m from its start; a path needs them at least {MIN_START_GOAL_DISTANCE_M} m apart (a round trip is an [inspection] tour)"
                    ),
                ));
            }
            if !(v.speed_min_mps.is_finite() && v.speed_min_mps > 0.0) {
                return Err(bad(
                    format!("vehicles[{i}].speed_min_mps"),
                    v.speed_min_mps.to_string(),
                    "must be a positive speed in m/s",
                ));
            }
            if !(v.speed_max_mps.is_finite() && v.speed_max_mps >= v.speed_min_mps) {
                return Err(bad(
                    format!("vehicles[{i}].speed_max_mps"),
                    v.speed_max_mps.to_string(),
                    "must be at least speed_min_mps",
                ));
            }
            if !(v.max_turn_deg > 0.0 && v.max_turn_deg <= 180.0) {
                return Err(bad(
                    format!("vehicles[{i}].max_turn_deg"),
                    v.max_turn_deg.to_string(),
                    "must be in (0, 180] degrees",
                ));
            }
            if !(v.max_pitch_deg > 0.0 && v.max_pitch_deg <= 90.0) {
                return Err(bad(
                    format!("vehicles[{i}].max_pitch_deg"),
                    v.max_pitch_deg.to_string(),
                    "must be in (0, 90] degrees",
                ));
            }
            if let Some(r) = v.turn_radius_m {
                if !(r.is_finite() && r > 0.0) {
                    return Err(bad(
                        format!("vehicles[{i}].turn_radius_m"),
                        r.to_string(),
                        "must be a positive number of metres",
                    ));
                }
            }
        }
        if !(self.fleet.d_min_m.is_finite() && self.fleet.d_min_m >= 0.0) {
            return Err(bad(
                "fleet.d_min_m".into(),
                self.fleet.d_min_m.to_string(),
                "must be zero or a positive number of metres",
            ));
        }
        if !(self.fleet.mission_time_s.is_finite() && self.fleet.mission_time_s > 0.0) {
            return Err(bad(
                "fleet.mission_time_s".into(),
                self.fleet.mission_time_s.to_string(),
                "must be a positive number of seconds",
            ));
        }
        self.validate_physical(&bad)?;
        self.optimizer.validate(&bad)?;
        self.validate_work(&bad)?;
        self.validate_crawlers(&bad)?;
        self.energy.validate(self.currents.as_ref(), &bad)?;
        let algorithm = self.optimizer.algorithm;
        if let Some(inspection) = &self.inspection {
            inspection.validate(self, &bad)?;
        }
        if let Some(coverage) = &self.coverage {
            let b = &self.bounds;
            coverage.validate([b.min[0], b.min[1], b.max[0], b.max[1]], &bad)?;
        }
        if algorithm.is_tour_planner() && self.inspection.is_none() {
            return Err(bad(
                "optimizer.algorithm".into(),
                format!("{:?}", algorithm.as_str()),
                "plans inspection tours (Hu et al. 2023): add an [inspection] table",
            ));
        }
        if algorithm.is_energy_planner() {
            if self.vehicles.len() != 1 {
                return Err(bad(
                    "optimizer.algorithm".into(),
                    format!("{:?}", algorithm.as_str()),
                    &format!(
                        "plans one AUV (Zhang et al. 2022); this scenario has {} vehicles",
                        self.vehicles.len()
                    ),
                ));
            }
            if self.vehicles[0].kind != VehicleKind::Auv {
                return Err(bad(
                    "vehicles[0].kind".into(),
                    format!("{:?}", self.vehicles[0].kind),
                    &format!("{} plans AUVs, not crawlers", algorithm.as_str()),
                ));
            }
        }
        if self.inspection.is_some() && !algorithm.is_tour_planner() {
            // Every vehicle of an inspection scenario returns to its base: any other planner
            // would plan it a path of zero length and call it feasible.
            return Err(bad(
                "optimizer.algorithm".into(),
                format!("{:?}", algorithm.as_str()),
                "plans paths from a start to a goal, but this scenario has an [inspection] table: plan its tours with de-pso, ldiw-pso or lcpso",
            ));
        }
        Ok(())
    }

    /// The `[origin]`: a position a tangent plane can hang from ([`crate::geo::GeoOrigin::check`]),
    /// a box whose floor and top are altitudes on the Earth, and a box clear of the pole (where
    /// east and north turn over).
    fn validate_origin(&self, bad: Bad) -> Result<(), ScenarioError> {
        let Some(o) = &self.origin else {
            return Ok(());
        };
        if let Some((field, value, reason)) = o.first_bad() {
            return Err(bad(format!("origin.{field}"), value.to_string(), &reason));
        }
        let altitudes = crate::geo::ALT_RANGE_M;
        for (name, z) in [("min", self.bounds.min[2]), ("max", self.bounds.max[2])] {
            let alt = o.alt_m + z;
            if !altitudes.contains(&alt) {
                return Err(bad(
                    "origin.alt_m".into(),
                    o.alt_m.to_string(),
                    &format!(
                        "puts bounds.{name}[2] = {z} at {alt} m above mean sea level, outside [{}, {}] m (below the deepest sea floor or above the highest summit)",
                        altitudes.start(),
                        altitudes.end()
                    ),
                ));
            }
        }
        // The meridian distance to the nearer pole, at least (a degree of latitude is 110 574 m
        // at the equator and longer towards the poles).
        let to_pole = (90.0 - o.lat_deg.abs()) * 110_574.0;
        let b = &self.bounds;
        let reach = [b.min[0], b.max[0]]
            .iter()
            .flat_map(|x| [b.min[1], b.max[1]].map(|y| x.hypot(y)))
            .fold(0.0, f64::max);
        if reach >= to_pole {
            return Err(bad(
                "origin.lat_deg".into(),
                o.lat_deg.to_string(),
                &format!("the scenario box reaches {reach:.0} m from the origin, over the pole {to_pole:.0} m away"),
            ));
        }
        Ok(())
    }

    /// The crawler parts: hazards, crawler settings, and a seabed for every crawler.
    fn validate_crawlers(&self, bad: Bad) -> Result<(), ScenarioError> {
        for (i, h) in self.hazards.iter().enumerate() {
            if crate::wire::topics::check_id("hazard", &h.id).is_err() {
                return Err(bad(
                    format!("hazards[{i}].id"),
                    format!("{:?}", h.id),
                    "must be 1-64 letters, digits, '-', '_' or '.'",
                ));
            }
            if !h.centre.iter().all(|c| c.is_finite()) {
                return Err(bad(
                    format!("hazards[{i}].centre"),
                    format!("{:?}", h.centre),
                    "must be finite",
                ));
            }
            for (name, v) in [("radius_m", h.radius_m), ("height_m", h.height_m)] {
                if !(v.is_finite() && v > 0.0) {
                    return Err(bad(
                        format!("hazards[{i}].{name}"),
                        v.to_string(),
                        "must be a positive number of metres",
                    ));
                }
            }
        }
        self.crawler.validate(bad)?;
        for (i, v) in self.vehicles.iter().enumerate() {
            if v.kind != VehicleKind::Crawler {
                continue;
            }
            if self.seabed.is_none() && self.coverage.is_none() {
                return Err(bad(
                    format!("vehicles[{i}].kind"),
                    "\"crawler\"".into(),
                    "a crawler drives on the seabed: add a [seabed] table (relief or grid) or a [coverage] table",
                ));
            }
            for (name, p) in [("start", &v.start), ("goal", &v.goal)] {
                for h in &self.hazards {
                    let d = (p[0] - h.centre[0]).hypot(p[1] - h.centre[1]);
                    if d < h.radius_m {
                        return Err(bad(
                            format!("vehicles[{i}].{name}"),
                            format!("{p:?}"),
                            &format!(
                                "lies inside hazard {} (radius {:.1} m, distance {d:.1} m)",
                                h.id, h.radius_m
                            ),
                        ));
                    }
                }
            }
        }
        Ok(())
    }
}

impl InspectionSettings {
    /// Indices (into `scenario.obstacles`) of the cages to inspect, in scenario order.
    pub fn cage_indices(&self, scenario: &Scenario) -> Vec<usize> {
        scenario
            .obstacles
            .iter()
            .enumerate()
            .filter(|(_, o)| {
                o.kind == ObstacleKind::Hard
                    && (self.cages.is_empty() || self.cages.contains(&o.id))
            })
            .map(|(i, _)| i)
            .collect()
    }

    /// Checks the table against the scenario it belongs to.
    pub fn validate(&self, scenario: &Scenario, bad: Bad) -> Result<(), ScenarioError> {
        for (i, id) in self.cages.iter().enumerate() {
            let found = scenario.obstacles.iter().find(|o| &o.id == id);
            match found {
                None => {
                    return Err(bad(
                        format!("inspection.cages[{i}]"),
                        format!("{id:?}"),
                        "names no obstacle of the scenario",
                    ))
                }
                Some(o) if o.kind != ObstacleKind::Hard => {
                    return Err(bad(
                        format!("inspection.cages[{i}]"),
                        format!("{id:?}"),
                        "is a soft obstacle; cages are hard obstacles",
                    ))
                }
                Some(_) => {}
            }
        }
        let cages = self.cage_indices(scenario);
        if cages.is_empty() {
            return Err(bad(
                "inspection.cages".into(),
                format!("{:?}", self.cages),
                "no hard obstacle to inspect: add [[obstacles]] of kind \"hard\"",
            ));
        }
        if !(self.standoff_m.is_finite() && self.standoff_m > 0.0) {
            return Err(bad(
                "inspection.standoff_m".into(),
                self.standoff_m.to_string(),
                "must be a positive number of metres",
            ));
        }
        for &c in &cages {
            let o = &scenario.obstacles[c];
            if self.standoff_m <= o.inflation_m {
                return Err(bad(
                    "inspection.standoff_m".into(),
                    self.standoff_m.to_string(),
                    &format!(
                        "must exceed the clearance (inflation_m = {}) of cage {}, or its inspection points lie inside the space the legs keep clear",
                        o.inflation_m, o.id
                    ),
                ));
            }
        }
        for (name, v) in [
            ("inspection.order_particles", self.order_particles),
            ("inspection.order_iterations", self.order_iterations),
        ] {
            if v == 0 {
                return Err(bad(name.into(), v.to_string(), "must be at least 1"));
            }
        }
        let (n, i) = (self.order_particles, self.order_iterations);
        if n > limits::MAX_PARTICLES {
            let name = "MAX_PARTICLES";
            return Err(over(
                bad,
                "inspection.order_particles",
                n,
                limits::MAX_PARTICLES,
                name,
            ));
        }
        if i > limits::MAX_ITERATIONS {
            let name = "MAX_ITERATIONS";
            return Err(over(
                bad,
                "inspection.order_iterations",
                i,
                limits::MAX_ITERATIONS,
                name,
            ));
        }
        if (n as u128) * (i as u128) > limits::MAX_EVALUATIONS {
            return Err(bad(
                "inspection.order_iterations".into(),
                i.to_string(),
                &format!(
                    "with {n} order_particles is over the limit {} evaluations (limits::MAX_EVALUATIONS)",
                    limits::MAX_EVALUATIONS
                ),
            ));
        }
        for (i, v) in scenario.vehicles.iter().enumerate() {
            if v.kind != VehicleKind::Auv {
                return Err(bad(
                    format!("vehicles[{i}].kind"),
                    format!("{:?}", v.kind),
                    "inspection tours are flown by AUVs",
                ));
            }
            if v.start != v.goal {
                return Err(bad(
                    format!("vehicles[{i}].goal"),
                    format!("{:?}", v.goal),
                    &format!(
                        "an inspection tour returns to its base: the goal must equal the start {:?}",
                        v.start
                    ),
                ));
            }
        }
        Ok(())
    }
}
