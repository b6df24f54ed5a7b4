//! A kinematic simulator of one vehicle following its timed trajectory: the `sim` vehicle link
//! of the agent drives one, so the fleet can execute a plan without hardware. It must behave
//! like a vehicle, not teleport along the plan: speed limits, a turning radius, a pitch limit,
//! drift in the current (AUV) and track slip (crawler) make it lag and wander, which is what the
//! coordinator's live picture has to cope with.
//!
//! Guidance: trajectory tracking with velocity feed-forward plus proportional position feedback,
//! `v_d = v_ff(t) + k (r(t) − p)`, the standard kinematic tracking law for a timed reference
//! (Fossen, *Handbook of Marine Craft Hydrodynamics and Motion Control*, 2011, ch. 10,
//! trajectory tracking; Siciliano et al., *Robotics*, 2009, §11.6), then saturated by the
//! vehicle's limits: speed, yaw rate `|w| / R_turn` and pitch.

use std::f64::consts::{PI, TAU};
use std::sync::Arc;

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use super::{VehicleState, VehicleStatus};
use crate::current::CurrentField;
use crate::geometry::Vec3;
use crate::scenario::{Vehicle, VehicleKind};
use crate::trajectory::Trajectory;

/// Feedback gain `k` of the tracking law, 1/s: a 5 s time constant. A 1 m error asks for
/// 0.2 m/s extra, small against cruise speeds (≈ 1.5 m/s), so ordinary errors are corrected
/// without saturating the speed; and the heading change it asks for on a 1 m cross-track error
/// (atan(0.2 / 1.5) ≈ 8°) takes a 20 m turning radius under 2 s, so the yaw-rate limit does not
/// make the loop oscillate.
pub const TRACKING_GAIN_PER_S: f64 = 0.2;

/// Distance to the plan's last point within which, once the plan's arrival time has passed, the
/// vehicle counts as arrived, metres (a couple of acoustic position-fix errors).
pub const ARRIVAL_RADIUS_M: f64 = 2.0;

/// Distance to the plan's last point within which a vehicle that, once the plan's arrival time
/// has passed, goes by it (past its closest approach: moving away from it) counts as arrived,
/// metres: a quarter of the default 20 m turning radius, the few metres of an AUV's waypoint
/// capture radius. An AUV must keep v_min to steer, and near v_min it turns too slowly to take
/// out a miss of a few metres: held to [`ARRIVAL_RADIUS_M`] alone, a vehicle that cut a late
/// bend and passed its end 2–3 m to the side flew 64 s loops round it, arriving minutes late
/// or never.
pub const CAPTURE_RADIUS_M: f64 = 5.0;

/// Horizontal speeds below this are "still": the heading is then the hull's, m/s.
const STILL_MPS: f64 = 1e-6;

/// Tunable parts of the simulation.
#[derive(Debug, Clone, PartialEq)]
pub struct SimSettings {
    /// Standard deviation of the Gaussian noise added to each reported position, metres (per axis).
    pub position_noise_m: f64,
    /// Seed of the noise RNG (StdRng::seed_from_u64; never thread_rng).
    pub seed: u64,
    /// Integration step, seconds of mission time (default 0.2).
    pub step_s: f64,
    /// Turning radius, metres. Default 20 m: a mid-size survey AUV at 1.5 m/s, yaw rate ≈ 4°/s;
    /// 2.5 × the 8 m of Zhang et al. 2022, Table 2, so the simulator is conservative (a plan it can
    /// follow, a nimbler vehicle can too), while 35° turns at waypoints tens of metres apart
    /// cost only a few metres of corner cutting.
    pub turn_radius_m: f64,
    /// Battery drain, fraction of a full charge per hour underway (default 0.1: ten hours of
    /// endurance, typical of a battery AUV at cruise speed).
    pub battery_per_hour: f64,
}

impl Default for SimSettings {
    fn default() -> Self {
        SimSettings {
            position_noise_m: 0.0,
            seed: 0,
            step_s: 0.2,
            turn_radius_m: 20.0,
            battery_per_hour: 0.1,
        }
    }
}

/// The seabed height `z(x, y)` a crawler drives on, metres.
pub type Seabed = Arc<dyn Fn(f64, f64) -> f64 + Send + Sync>;

/// The vehicle's kinematics. The model, not `Vehicle::kind`, decides how the vehicle moves.
#[derive(Clone)]
pub enum SimModel {
    /// Free-swimming AUV: water-relative speed in [v_min, v_max] while underway, yaw rate <= v / R_turn, |pitch| <= max_pitch; optional current field adds drift (ground velocity = water velocity + current).
    Auv {
        /// The water's current, if the scenario has one.
        current: Option<Arc<dyn CurrentField>>,
        /// The sea surface's z: the vehicle does not rise above it.
        surface_z: f64,
    },
    /// Tracked crawler on the seabed: z = seabed(x, y) + sensor height; speed reduced by slip (ground speed = (1 - slip) * commanded), slip in [0, 1).
    Crawler {
        /// The seabed it drives on.
        seabed: Seabed,
        /// Height of the sensor above the seabed, metres.
        sensor_height_m: f64,
        /// Fraction of the commanded speed lost to the ground, in [0, 1).
        slip: f64,
    },
}

impl SimModel {
    /// Puts `p` back in its medium: a crawler's z on the seabed plus its sensor height, an AUV
    /// under the surface (a hard ceiling: it cannot climb out of the water).
    fn constrain(&self, mut p: Vec3) -> Vec3 {
        match self {
            SimModel::Auv { surface_z, .. } => p.z = p.z.min(*surface_z),
            SimModel::Crawler {
                seabed,
                sensor_height_m: h,
                ..
            } => p.z = seabed(p.x, p.y) + h,
        }
        p
    }
}

/// One simulated vehicle: true state, plan and noise source.
pub struct Simulator {
    model: SimModel,
    settings: SimSettings,
    v_min: f64,
    v_max: f64,
    max_pitch: f64,
    t: f64,
    p: Vec3,
    /// Hull heading, radians counter-clockwise from east.
    heading: f64,
    /// True ground velocity over the last step, m/s.
    velocity: Vec3,
    battery: f64,
    status: VehicleStatus,
    plan: Option<Trajectory>,
    /// Where it station-keeps while Holding or Arrived.
    hold_at: Vec3,
    rng: StdRng,
    /// When it reached the end of its current trajectory.
    arrived_at: Option<f64>,
}

impl Simulator {
    /// At the vehicle's start, status Idle, time 0, heading toward the goal. A crawler is put on
    /// the seabed (`z = seabed(start) + sensor height`) whatever the start's z says.
    pub fn new(vehicle: &Vehicle, model: SimModel, settings: SimSettings) -> Simulator {
        let is_crawler = matches!(model, SimModel::Crawler { .. });
        if is_crawler != (vehicle.kind == VehicleKind::Crawler) {
            tracing::warn!(id = %vehicle.id, "sim model does not match the vehicle kind");
        }
        let p = model.constrain(vehicle.start());
        Simulator {
            heading: heading_of(&(vehicle.goal() - p), 0.0),
            v_min: vehicle.speed_min_mps.max(0.0),
            v_max: vehicle.speed_max_mps.max(0.0),
            max_pitch: vehicle.max_pitch_deg.abs().to_radians(),
            rng: StdRng::seed_from_u64(settings.seed),
            model,
            settings,
            t: 0.0,
            p,
            velocity: Vec3::zeros(),
            battery: 1.0,
            status: VehicleStatus::Idle,
            plan: None,
            hold_at: p,
            arrived_at: None,
        }
    }

    /// Follow `plan` (mission-time stamped) from now on; status Underway. Replaces any previous plan (a replan mid-mission).
    /// An empty (or malformed) plan is no plan: the vehicle holds instead.
    pub fn load(&mut self, plan: Trajectory) {
        if plan.points.is_empty() || plan.points.len() != plan.times.len() {
            return self.hold();
        }
        if self.status == VehicleStatus::Idle {
            // A vehicle is launched pointing along its first leg, not wherever it was built.
            if let Some(w) = plan
                .points
                .windows(2)
                .find(|w| (w[1] - w[0]).xy().norm() > 1e-6)
            {
                self.heading = heading_of(&(w[1] - w[0]), self.heading);
            }
        }
        self.plan = Some(plan);
        self.status = VehicleStatus::Underway;
        self.arrived_at = None;
    }

    /// Hold where it is (status Holding): speed 0 (an AUV station-keeps, i.e. also cancels the current's drift).
    pub fn hold(&mut self) {
        self.hold_at = self.p;
        self.velocity = Vec3::zeros();
        self.status = VehicleStatus::Holding;
    }

    /// Stop: status Stopped, speed 0; later load() resumes.
    pub fn stop(&mut self) {
        self.velocity = Vec3::zeros();
        self.status = VehicleStatus::Stopped;
    }

    /// Integrate in steps of at most step_s up to mission time `t` (no-op if t <= now).
    pub fn advance_to(&mut self, t: f64) {
        if !t.is_finite() || t <= self.t {
            return;
        }
        let step = self.settings.step_s.max(1e-3); // a zero or negative step would never end
        let n = ((t - self.t) / step).ceil().max(1.0) as u64;
        let (t0, dt) = (self.t, (t - self.t) / n as f64);
        for i in 1..=n {
            // Times from t0 rather than summed, so the last step lands exactly on t.
            self.step(if i == n { t } else { t0 + dt * i as f64 });
        }
    }

    /// The report at the current time: position with noise, true velocity, heading, depth (AUV) or altitude (crawler), battery, status.
    pub fn state(&mut self) -> VehicleState {
        let sigma = self.settings.position_noise_m;
        let mut position = [self.p.x, self.p.y, self.p.z];
        if sigma > 0.0 {
            for c in &mut position {
                *c += sigma * gaussian(&mut self.rng);
            }
        }
        let (v, p) = (self.velocity, self.p);
        let arrived = self.status == VehicleStatus::Arrived;
        let (depth_m, altitude_m) = match &self.model {
            SimModel::Auv { surface_z, .. } => (Some(surface_z - p.z), None),
            SimModel::Crawler { seabed, .. } => (None, Some(p.z - seabed(p.x, p.y))),
        };
        VehicleState {
            t_s: self.t,
            position,
            velocity: [v.x, v.y, v.z],
            heading_deg: heading_of(&v, self.heading).to_degrees(),
            depth_m,
            altitude_m,
            battery: self.battery,
            status: self.status,
            arrived_s: self.arrived_at.filter(|_| arrived),
        }
    }

    /// True position (no noise), for tests and figures.
    pub fn position(&self) -> Vec3 {
        self.p
    }
    /// Mission time of the simulation, seconds.
    pub fn time(&self) -> f64 {
        self.t
    }
    /// What the vehicle is doing.
    pub fn status(&self) -> VehicleStatus {
        self.status
    }
    /// Hull heading, radians counter-clockwise from east, in (−π, π].
    pub fn heading(&self) -> f64 {
        self.heading
    }
    /// True ground velocity, m/s.
    pub fn velocity(&self) -> Vec3 {
        self.velocity
    }

    /// One integration step, from now to `t_next`.
    fn step(&mut self, t_next: f64) {
        let dt = t_next - self.t;
        let next = match self.status {
            VehicleStatus::Underway => self.track(dt),
            VehicleStatus::Holding | VehicleStatus::Arrived => self.station_keep(),
            VehicleStatus::Idle | VehicleStatus::Stopped | VehicleStatus::Fault => Vec3::zeros(),
        };
        let next = self.model.constrain(self.p + next * dt);
        self.velocity = (next - self.p) / dt;
        self.p = next;
        self.t = t_next;
        if self.status != VehicleStatus::Underway {
            return;
        }
        // Hotel load while holding is ignored: only propulsion underway drains the battery.
        self.battery = (self.battery - self.settings.battery_per_hour * dt / 3600.0).max(0.0);
        if self.battery <= 0.0 {
            // Flat battery: the link reports a fault and the vehicle no longer moves.
            self.status = VehicleStatus::Fault;
            self.velocity = Vec3::zeros();
        } else if let Some(plan) = &self.plan {
            let end = plan.points[plan.points.len() - 1];
            let to_end = end - self.p;
            let passing = to_end.norm() <= CAPTURE_RADIUS_M && to_end.dot(&self.velocity) <= 0.0;
            if self.t >= plan.arrival() && (to_end.norm() <= ARRIVAL_RADIUS_M || passing) {
                self.status = VehicleStatus::Arrived;
                self.hold_at = end;
                self.arrived_at.get_or_insert(self.t);
            }
        }
    }

    /// Underway: the ground velocity of the tracking law, saturated by the vehicle's limits
    /// (turns the hull as a side effect).
    fn track(&mut self, dt: f64) -> Vec3 {
        let Some(plan) = &self.plan else {
            return Vec3::zeros();
        };
        let (k, p) = (TRACKING_GAIN_PER_S, self.p);
        let v_d = feed_forward(plan, self.t) + (plan.position_at(self.t) - p) * k;
        let to_end = (plan.points[plan.points.len() - 1] - p).norm();
        let turn_radius = self.settings.turn_radius_m.max(1e-3);
        match &self.model {
            SimModel::Auv { current, .. } => {
                let c = current.as_ref().map_or(Vec3::zeros(), |f| f.velocity(&p));
                let w_d = v_d - c;
                // An AUV needs way on to steer, so it keeps v_min, except so close to the end
                // that the feedback itself asks for less than v_min (|k e| < v_min): there it
                // may slow down to arrive and stop rather than circle the end point.
                let near_end = to_end <= ARRIVAL_RADIUS_M.max(self.v_min / k);
                let lo = if near_end { 0.0 } else { self.v_min };
                let speed = w_d.norm().clamp(lo.min(self.v_max), self.v_max);
                let max_turn = speed / turn_radius * dt;
                self.heading = turn_toward(self.heading, heading_of(&w_d, self.heading), max_turn);
                let pitch = self.max_pitch;
                let theta = w_d.z.atan2(w_d.xy().norm()).clamp(-pitch, pitch);
                let (h, psi) = (speed * theta.cos(), self.heading);
                Vec3::new(h * psi.cos(), h * psi.sin(), speed * theta.sin()) + c
            }
            SimModel::Crawler { seabed, slip, .. } => {
                // Speeds along the seabed (the planner's draped lengths are 3-D).
                let speed = v_d.norm().min(self.v_max);
                let max_turn = speed / turn_radius * dt;
                self.heading = turn_toward(self.heading, heading_of(&v_d, self.heading), max_turn);
                let u = Vec3::new(self.heading.cos(), self.heading.sin(), 0.0);
                // Slope along the heading by a forward difference, so that the distance driven
                // along the ground, not its horizontal shadow, is the slipped speed times dt
                // (`step` then drapes the point on the seabed).
                let g = (seabed(p.x + 0.1 * u.x, p.y + 0.1 * u.y) - seabed(p.x, p.y)) / 0.1;
                u * ((1.0 - slip.clamp(0.0, 1.0)) * speed / (1.0 + g * g).sqrt())
            }
        }
    }

    /// Holding or Arrived: station-keeping on `hold_at` with the same gain, no minimum speed
    /// and no turn limit (thrusters, or tracks turning in place), the current's drift cancelled.
    fn station_keep(&self) -> Vec3 {
        let mut v = (self.hold_at - self.p) * TRACKING_GAIN_PER_S;
        if let SimModel::Crawler { .. } = self.model {
            v.z = 0.0;
        }
        if v.norm() <= STILL_MPS {
            return Vec3::zeros();
        }
        v * (self.v_max / v.norm()).min(1.0)
    }
}

/// Velocity of the plan's leg at `t`; zero before its start and after its arrival.
fn feed_forward(plan: &Trajectory, t: f64) -> Vec3 {
    let n = plan.times.len();
    if n < 2 || t < plan.times[0] || t >= plan.times[n - 1] {
        return Vec3::zeros();
    }
    let k = plan.times.partition_point(|&s| s <= t).clamp(1, n - 1);
    let dt = plan.times[k] - plan.times[k - 1];
    if dt > 0.0 {
        (plan.points[k] - plan.points[k - 1]) / dt
    } else {
        Vec3::zeros()
    }
}

/// Heading of `v`'s horizontal part in (−π, π], or `fallback` when it is (nearly) vertical.
fn heading_of(v: &Vec3, fallback: f64) -> f64 {
    wrap(if v.xy().norm() > STILL_MPS {
        v.y.atan2(v.x)
    } else {
        fallback
    })
}

/// Angle wrapped into (−π, π].
fn wrap(a: f64) -> f64 {
    PI - (PI - a).rem_euclid(TAU)
}

/// Heading `from` turned toward `to` by at most `max` radians, the short way round.
fn turn_toward(from: f64, to: f64, max: f64) -> f64 {
    wrap(from + wrap(to - from).clamp(-max, max))
}

/// One standard normal sample (Box–Muller; the crate has no `rand_distr`).
fn gaussian(rng: &mut StdRng) -> f64 {
    let u1: f64 = 1.0 - rng.random::<f64>(); // (0, 1]: the log is finite
    let u2: f64 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (TAU * u2).cos()
}

#[cfg(test)]
mod tests;
