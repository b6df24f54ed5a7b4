//! Closed-loop trajectory tracking under terrain disturbances (CPP-DSMV, §2.3 and §2.4): a
//! terrain-aware crawler plant, a terrain-adaptive adaptive EKF (TA-AEKF) and a variable-weight
//! MPC (V-MPC) solved as a QP with Clarabel, run together along a coverage reference.
//!
//! The seed's equations were lost in extraction; the ones used here are rebuilt from its text and
//! standard formulations and written next to the code (`// CPP-DSMV, §…`). In short:
//!
//! - **Plant** ([`plant`]): pose `(x, y, ψ)`; pitch `θ = atan(∇z·(cosψ, sinψ))`, roll
//!   `φ = atan(∇z·(−sinψ, cosψ))`; track speed `u` and yaw rate `ω` behind a first-order lag with
//!   rate limits; slip `s = clamp(s0 + k_s·max(θ,0) + n_s, 0, s_max)`; forward speed
//!   `v_x = u·cosθ·(1 − s)`; gravity-induced sideslip `v_y = −k_d·v_x·sinφ + n_y` (down-slope);
//!   yaw `ψ̇ = (1 − s_ω)·ω + n_ω`; coloured (Gauss–Markov) slip noise.
//! - **TA-AEKF** ([`ekf`]): state `[x, y, ψ, δs, d]` (slip-ratio residual and lateral drift
//!   residual), prediction through the same terrain–traction model fed by track odometry and a
//!   gyro; `Q` scaled by `1 + k_q·|∇z|`; fix noise `R` adapted by a diagonal Sage–Husa estimator
//!   with clamps and a χ² inflation gate; Joseph-form updates.
//! - **V-MPC** ([`mpc`]): Frenet error model `[e_y, e_ψ]` augmented with the actuator lag states,
//!   exact zero-order-hold discretisation, horizon `N_p` with move blocking `N_c`, weights that
//!   interpolate with the normalised reference curvature `|κ|·R_min`, hard limits on `v`,
//!   curvature `|ω| ≤ (1+m)·v/R_min` and rates; a dense condensed QP solved by Clarabel.
//! - **Reference** ([`mod@reference`]): monotone windowed projection onto the sampled polyline; the
//!   signed cross-track error (left of the path positive) is measured on the TRUE position.
//!
//! Entry points: [`track`], [`track_with_progress`], [`track_from_pose`].

mod discrete;
pub mod ekf;
pub mod mpc;
pub mod params;
pub mod plant;
pub mod reference;
mod sim;
mod types;

#[cfg(test)]
mod tests;

pub use params::TrackingParams;
pub use sim::{track, track_from_pose, track_with_progress};
pub use types::{FlatTerrain, TerrainSlope, TrackedSample, TrackingError, TrackingResult};
