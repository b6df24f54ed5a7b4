//! How the refinement searches: its budget of passes and programs, its trust region and the
//! margins it keeps inside the limits.

use std::time::Instant;

/// How the refinement searches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefineSettings {
    /// Passes over the vehicles (a pass that keeps nothing ends it).
    pub rounds: usize,
    /// Programs solved per vehicle and pass.
    pub steps: usize,
    /// First trust radius, metres per coordinate.
    pub radius_m: f64,
    /// Trust radius below which a vehicle's search ends, metres.
    pub min_radius_m: f64,
    /// Degrees kept inside the pitch and turn limits (the fitness's tests are sharp: a plan on
    /// the limit is one rounding away from a penalty).
    pub angle_margin_deg: f64,
    /// Metres kept outside every hard sphere and added to d_min.
    pub distance_margin_m: f64,
    /// Separation samples along the timed trajectories, seconds apart.
    pub sample_step_s: f64,
    /// When to stop whatever is left (a replan's budget); `None`: no limit.
    pub deadline: Option<Instant>,
}

impl Default for RefineSettings {
    /// Three passes of up to 40 programs per vehicle; a first trust radius of 20 m; margins of
    /// 0.05° and 0.5 m; separation sampled every 2 s (at 3 m/s closing speed a pair moves 6 m
    /// between samples and the closest approach between them is at most 0.1 m under the
    /// nearer sample's at d_min = 50 m).
    fn default() -> Self {
        RefineSettings {
            rounds: 3,
            steps: 40,
            radius_m: 20.0,
            min_radius_m: 0.01,
            angle_margin_deg: 0.05,
            distance_margin_m: 0.5,
            sample_step_s: 2.0,
            deadline: None,
        }
    }
}
