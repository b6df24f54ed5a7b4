//! The truth model of the crawler on the 2.5D seabed (CPP-DSMV, §2.2 "Kinematic model of the
//! mining vehicle", rebuilt) and the terrain–traction law shared with the EKF and the MPC.

use super::params::TrackingParams;
use super::types::{checked_gradient, gaussian, wrap_angle, Pose2, TerrainSlope, TrackingError};
use rand::Rng;

/// Vehicle attitude imposed by the terrain under it, radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Attitude {
    /// Pitch θ, positive nose-up (climbing).
    pub pitch: f64,
    /// Roll φ, positive when the ground rises to the vehicle's left.
    pub roll: f64,
}

/// CPP-DSMV, §2.2: the body sits on the local tangent plane of `z(x, y)`, so with `g = ∇z`
///   θ = atan(g · (cosψ, sinψ)),   φ = atan(g · (−sinψ, cosψ)).
pub fn attitude(g: [f64; 2], heading: f64) -> Attitude {
    let (s, c) = heading.sin_cos();
    Attitude {
        pitch: (g[0] * c + g[1] * s).atan(),
        roll: (-g[0] * s + g[1] * c).atan(),
    }
}

/// CPP-DSMV, §2.2 (longitudinal slip): `s = clamp(s0 + k_s·max(θ, 0) + δ, 0, s_max)`, where δ is a
/// random (plant) or estimated (EKF) residual. Returns the slip and `∂s/∂θ`, `∂s/∂δ`.
pub fn slip_ratio(pitch: f64, residual: f64, p: &TrackingParams) -> (f64, f64, f64) {
    let raw = p.base_slip + p.slip_pitch_gain * pitch.max(0.0) + residual;
    if raw <= 0.0 {
        (0.0, 0.0, 0.0)
    } else if raw >= p.max_slip {
        (p.max_slip, 0.0, 0.0)
    } else {
        let ds_dtheta = if pitch > 0.0 { p.slip_pitch_gain } else { 0.0 };
        (raw, ds_dtheta, 1.0)
    }
}

/// Body-frame velocity of the crawler, m/s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyVelocity {
    /// Forward (surge) speed over ground, projected on the horizontal plane.
    pub forward: f64,
    /// Leftward (sway) speed from gravity-induced sideslip, without random terms.
    pub lateral: f64,
    /// Traction efficiency η = v_x / u = cosθ·(1 − s).
    pub efficiency: f64,
}

/// CPP-DSMV, §2.2, effective speeds of a tracked vehicle of track speed `u` on the slope:
///   v_x = u·cosθ·(1 − s)          (pitch attenuation: planar projection and slip),
///   v_y = −k_d·v_x·sinφ           (gravity-induced sideslip, down-slope, i.e. sideslip angle
///                                   β = atan(v_y/v_x) = −atan(k_d·sinφ)).
pub fn body_velocity(
    track_speed: f64,
    att: Attitude,
    slip_residual: f64,
    p: &TrackingParams,
) -> BodyVelocity {
    let (s, _, _) = slip_ratio(att.pitch, slip_residual, p);
    let efficiency = att.pitch.cos() * (1.0 - s);
    let forward = track_speed * efficiency;
    BodyVelocity {
        forward,
        lateral: -p.drift_gain * forward * att.roll.sin(),
        efficiency,
    }
}

/// First-order lag with a rate limit, advanced over `dt`:
///   x ← x + clamp((1 − e^(−dt/τ))·(x_cmd − x), −r·dt, r·dt).
pub fn lag_step(state: f64, command: f64, lag_s: f64, rate_limit: f64, dt: f64) -> f64 {
    let alpha = if lag_s > 0.0 {
        1.0 - (-dt / lag_s).exp()
    } else {
        1.0
    };
    let step = (alpha * (command - state)).clamp(-rate_limit * dt, rate_limit * dt);
    state + step
}

/// What the plant's sensors read over one sub-step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlantReadings {
    /// Track speed u (odometry, before slip), m/s.
    pub track_speed: f64,
    /// True yaw rate over the sub-step (what an ideal gyro reads), rad/s.
    pub yaw_rate: f64,
    /// Attitude at the start of the sub-step.
    pub attitude: Attitude,
    /// Forward speed over ground, m/s.
    pub forward: f64,
    /// Lateral speed over ground (with noise), m/s.
    pub lateral: f64,
}

/// The simulated crawler (truth).
#[derive(Debug, Clone, PartialEq)]
pub struct Plant {
    /// True pose; heading wrapped to (−π, π].
    pub pose: Pose2,
    /// Actuated track speed u, m/s.
    pub track_speed: f64,
    /// Actuated yaw rate (before turn slip), rad/s.
    pub yaw_rate: f64,
    /// Gauss–Markov noises: slip ratio (-), lateral speed (m/s), yaw rate (rad/s).
    noise: [f64; 3],
}

impl Plant {
    /// A plant at `pose` already moving with track speed `u` and yaw rate `w`; noises start at 0.
    pub fn new(pose: Pose2, u: f64, w: f64) -> Self {
        Self {
            pose,
            track_speed: u,
            yaw_rate: w,
            noise: [0.0; 3],
        }
    }

    /// Advances by one sub-step `dt` under the command `(v_cmd, ω_cmd)`:
    ///   u̇ and ω̇_a: first-order lags with rate limits (see [`lag_step`]);
    ///   n ← a·n + √(1−a²)·σ·w, a = e^(−dt/τ_n)   (Gauss–Markov slip noises);
    ///   ψ̇ = (1 − s_ω)·ω_a + n_ω;  ẋ = v_x cosψ_m − v_y sinψ_m;  ẏ = v_x sinψ_m + v_y cosψ_m,
    /// with ψ_m = ψ + ψ̇·dt/2 (midpoint rule) and the attitude taken at the sub-step start.
    pub fn step<R: Rng>(
        &mut self,
        cmd_speed: f64,
        cmd_yaw_rate: f64,
        dt: f64,
        terrain: &dyn TerrainSlope,
        p: &TrackingParams,
        rng: &mut R,
    ) -> Result<PlantReadings, TrackingError> {
        self.track_speed = lag_step(
            self.track_speed,
            cmd_speed,
            p.speed_lag_s,
            p.max_accel_mps2,
            dt,
        );
        self.yaw_rate = lag_step(
            self.yaw_rate,
            cmd_yaw_rate,
            p.yaw_lag_s,
            p.max_yaw_accel_radps2,
            dt,
        );
        let a = (-dt / p.noise_corr_time_s).exp();
        let b = (1.0 - a * a).sqrt();
        let sig = [
            p.slip_noise_std,
            p.lateral_noise_std_mps,
            p.yaw_noise_std_radps,
        ];
        for (n, s) in self.noise.iter_mut().zip(sig) {
            let w = if s > 0.0 { gaussian(rng) } else { 0.0 };
            *n = a * *n + b * s * w;
        }
        let g = checked_gradient(terrain, self.pose.x, self.pose.y)?;
        let att = attitude(g, self.pose.heading);
        let body = body_velocity(self.track_speed, att, self.noise[0], p);
        let lateral = body.lateral + self.noise[1];
        let yaw_rate = (1.0 - p.turn_slip) * self.yaw_rate + self.noise[2];
        let psi_m = self.pose.heading + 0.5 * yaw_rate * dt;
        let (s, c) = psi_m.sin_cos();
        self.pose.x += dt * (body.forward * c - lateral * s);
        self.pose.y += dt * (body.forward * s + lateral * c);
        self.pose.heading = wrap_angle(self.pose.heading + yaw_rate * dt);
        Ok(PlantReadings {
            track_speed: self.track_speed,
            yaw_rate,
            attitude: att,
            forward: body.forward,
            lateral,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::types::FlatTerrain;
    use super::*;
    use approx::assert_abs_diff_eq;
    use rand::rngs::StdRng;
    use rand::SeedableRng;

    fn quiet() -> TrackingParams {
        TrackingParams {
            slip_noise_std: 0.0,
            lateral_noise_std_mps: 0.0,
            yaw_noise_std_radps: 0.0,
            ..TrackingParams::default()
        }
    }

    #[test]
    fn flat_terrain_gives_exact_straight_motion() {
        let p = TrackingParams {
            base_slip: 0.0,
            ..quiet()
        };
        let mut rng = StdRng::seed_from_u64(1);
        let heading = 0.3;
        let mut plant = Plant::new(Pose2::new(10.0, -5.0, heading), 0.8, 0.0);
        for _ in 0..100 {
            plant
                .step(0.8, 0.0, 0.1, &FlatTerrain, &p, &mut rng)
                .unwrap_or_else(|e| panic!("{e}"));
        }
        // 10 s at 0.8 m/s along heading 0.3.
        assert_abs_diff_eq!(plant.pose.x, 10.0 + 8.0 * heading.cos(), epsilon = 1e-9);
        assert_abs_diff_eq!(plant.pose.y, -5.0 + 8.0 * heading.sin(), epsilon = 1e-9);
        assert_abs_diff_eq!(plant.pose.heading, heading, epsilon = 1e-12);
    }

    #[test]
    fn base_slip_shortens_the_straight_run() {
        let p = quiet(); // base slip 0.05
        let mut rng = StdRng::seed_from_u64(1);
        let mut plant = Plant::new(Pose2::new(0.0, 0.0, 0.0), 1.0, 0.0);
        for _ in 0..50 {
            plant
                .step(1.0, 0.0, 0.1, &FlatTerrain, &p, &mut rng)
                .unwrap_or_else(|e| panic!("{e}"));
        }
        assert_abs_diff_eq!(plant.pose.x, 5.0 * 0.95, epsilon = 1e-9);
        assert_abs_diff_eq!(plant.pose.y, 0.0, epsilon = 1e-12);
    }

    #[test]
    fn known_gradient_gives_expected_pitch_roll_attenuation_and_drift() {
        // Plane z = 0.1·x + 0.05·y; vehicle heading east (ψ = 0).
        let g = [0.1, 0.05];
        let att = attitude(g, 0.0);
        assert_abs_diff_eq!(att.pitch, 0.1f64.atan(), epsilon = 1e-12);
        assert_abs_diff_eq!(att.roll, 0.05f64.atan(), epsilon = 1e-12);
        // Heading north: the x-slope is now on the right (ground falls to the left ⇒ negative roll).
        let att_n = attitude(g, std::f64::consts::FRAC_PI_2);
        assert_abs_diff_eq!(att_n.pitch, 0.05f64.atan(), epsilon = 1e-12);
        assert_abs_diff_eq!(att_n.roll, -(0.1f64.atan()), epsilon = 1e-12);

        let p = quiet(); // s0 = 0.05, k_s = 1.5, k_d = 0.5
        let theta = 0.1f64.atan(); // 0.099669 rad
        let phi = 0.05f64.atan(); // 0.049958 rad
        let s = 0.05 + 1.5 * theta; // 0.199503
        let vx = 1.0 * theta.cos() * (1.0 - s); // 0.796524
        let vy = -0.5 * vx * phi.sin(); // −0.019888
        let body = body_velocity(1.0, att, 0.0, &p);
        assert_abs_diff_eq!(body.forward, vx, epsilon = 1e-12);
        assert_abs_diff_eq!(body.forward, 0.796_524, epsilon = 1e-6);
        assert_abs_diff_eq!(body.lateral, vy, epsilon = 1e-12);
        assert_abs_diff_eq!(body.lateral, -0.019_888, epsilon = 1e-6);

        // The plant moves by the same amounts over one sub-step.
        let terrain = |_x: f64, _y: f64| g;
        let mut plant = Plant::new(Pose2::new(0.0, 0.0, 0.0), 1.0, 0.0);
        let mut rng = StdRng::seed_from_u64(3);
        let r = plant
            .step(1.0, 0.0, 0.1, &terrain, &p, &mut rng)
            .unwrap_or_else(|e| panic!("{e}"));
        assert_abs_diff_eq!(plant.pose.x, 0.1 * vx, epsilon = 1e-12);
        assert_abs_diff_eq!(plant.pose.y, 0.1 * vy, epsilon = 1e-12);
        assert_abs_diff_eq!(r.attitude.pitch, theta, epsilon = 1e-12);

        // Downhill: no extra slip, only the cosine.
        let down = body_velocity(1.0, attitude(g, std::f64::consts::PI), 0.0, &p);
        assert_abs_diff_eq!(down.forward, theta.cos() * 0.95, epsilon = 1e-12);
        // Steep climb saturates at s_max.
        let steep = body_velocity(1.0, attitude([1.0, 0.0], 0.0), 0.0, &p);
        assert_abs_diff_eq!(steep.forward, (1.0f64).atan().cos() * 0.5, epsilon = 1e-12);
    }

    #[test]
    fn actuator_lag_and_rate_limit() {
        // τ = 1 s, 0.1 s step: 1 − e^(−0.1) = 0.09516 of the gap, but at most 0.05·0.1 = 0.005.
        let v = lag_step(0.5, 1.0, 1.0, 0.05, 0.1);
        assert_abs_diff_eq!(v, 0.505, epsilon = 1e-12);
        let v = lag_step(0.5, 0.52, 1.0, 0.05, 0.1);
        assert_abs_diff_eq!(v, 0.5 + 0.02 * (1.0 - (-0.1f64).exp()), epsilon = 1e-12);
        assert_abs_diff_eq!(lag_step(0.5, 0.52, 0.0, 1.0, 0.1), 0.52, epsilon = 1e-12);
    }

    #[test]
    fn constant_yaw_rate_on_flat_ground_draws_a_circle() {
        let p = TrackingParams {
            base_slip: 0.0,
            turn_slip: 0.0,
            ..quiet()
        };
        let mut rng = StdRng::seed_from_u64(1);
        let r = 5.0;
        let v = 0.5;
        let mut plant = Plant::new(Pose2::new(0.0, 0.0, 0.0), v, v / r);
        let steps = (std::f64::consts::PI * r / v / 0.1).round() as usize;
        for _ in 0..steps {
            plant
                .step(v, v / r, 0.1, &FlatTerrain, &p, &mut rng)
                .unwrap_or_else(|e| panic!("{e}"));
        }
        // Half a circle of radius ≈ 5 m (midpoint rule on chords: within a few mm).
        assert_abs_diff_eq!(plant.pose.x, 0.0, epsilon = 0.02);
        assert_abs_diff_eq!(plant.pose.y, 2.0 * r, epsilon = 0.02);
    }
}
