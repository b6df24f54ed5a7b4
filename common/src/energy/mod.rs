//! Zhang et al.'s cost of an AUV path in a current (eq. (4)–(13), (18)): length, energy, turning
//! radius and pitch, with the self-adjusting weights of eq. (8), (12) and (13).
//!
//! A path here is the dense polyline the AUV flies (Zhang et al. 2022, Table 2: n_p = 500 points), the
//! sampled B-spline of the particle's control points (see [`problem`]). Units: metres, seconds,
//! degrees; the resistance of eq. (4) is read in newtons, so energies are joules.
//!
//! Readings of the paper, each chosen because the literal text is ambiguous or inconsistent:
//! - **Eq. (10)–(11) are powers** (force × speed). Summed per path point they would make a path's
//!   energy depend on how finely it is sampled, so each segment's power is multiplied by the time
//!   spent on it, `Δt_j = p_j / |V_h|`: q_e is the work in joules.
//! - **θ in eq. (4) is in degrees** (in radians X_R would hardly depend on pitch, which
//!   contradicts the paper's point that steep paths cost energy), positive nose up.
//! - **θ_uc of eq. (11)** is the angle between the water velocity `V_AUV` and the current; the
//!   vehicle works against the current when `cos θ_uc < 0` (the `π/2 < θ_uc < 3π/2` branch), and
//!   `u_c` is read as the current's speed `|V_c|` (the paper's current has equal u and v).
//! - **The weights of eq. (8), (12), (13) are per segment**: `p_j` and `p_{j+1}` are consecutive
//!   segments of one path (eq. (7) sums `p_j` over the path's segments). This keeps the fitness a
//!   function of the path alone, so a particle's memory compares like with like. μ = 0.5 (the
//!   paper gives no value) is the one that makes the weight grow when the next segment's cost
//!   grows, as §3.1.1 says it should: `cos(μπ·1) = 0` at equal costs, negative above.
//! - **q_r and q_a are the unweighted sums of eq. (13)** in m² and deg²; the weights apply inside
//!   the fitness only.

pub mod problem;
pub mod reference;

use std::f64::consts::PI;
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::current::{water_velocity, CurrentField};
use crate::geometry::Vec3;
use crate::terrain::Terrain;

/// Zhang et al. 2022, eq. (4): longitudinal resistance `X_R = 0.0783 θ² − 0.0753 θ + 5.3` at pitch θ
/// (degrees), newtons. Thrust equals resistance (§2.2: constant ground speed).
pub fn resistance(pitch_deg: f64) -> f64 {
    0.0783 * pitch_deg * pitch_deg - 0.0753 * pitch_deg + 5.3
}

/// Radius of the circle through three consecutive path points (the discrete radius of curvature
/// `R_path` of eq. (5)), metres; infinite when they are collinear or two coincide.
pub fn turn_radius(a: &Vec3, b: &Vec3, c: &Vec3) -> f64 {
    let (ab, bc, ca) = ((b - a).norm(), (c - b).norm(), (a - c).norm());
    let twice_area = (b - a).cross(&(c - a)).norm();
    if twice_area <= 1e-12 * (ab * bc * ca).max(1e-300) || ab == 0.0 || bc == 0.0 {
        f64::INFINITY
    } else {
        ab * bc * ca / (2.0 * twice_area)
    }
}

/// The factor of eq. (11): `e^{|cos θ_uc|}` against the current (`cos θ_uc < 0`), else
/// `e^{−|cos θ_uc|}`.
pub fn heading_factor(cos_uc: f64) -> f64 {
    if cos_uc < 0.0 {
        cos_uc.abs().exp()
    } else {
        (-cos_uc.abs()).exp()
    }
}

/// One self-adjusting weight, eq. (8) / (12) / (13): `K = K_init − K_ur cos(μ π s)` where `s` is
/// the ratio `c_{j+1} / mean(c_j, c_{j+1})` (eq. (8), (12)) or the difference `c_{j+1} − c_j`
/// (eq. (13)).
pub fn adjusted_weight(init: f64, range: f64, mu: f64, s: f64) -> f64 {
    init - (mu * PI * s).cos() * range
}

/// The ratio of eq. (8) / (12): `next / ((this + next) / 2)`, 1 when both are zero.
fn ratio(this: f64, next: f64) -> f64 {
    let mean = 0.5 * (this + next);
    if mean > 0.0 {
        next / mean
    } else {
        1.0
    }
}

/// The constants of the weights: initial values and update ranges in the order
/// (path, energy, radius, angle), Table 2, and the vibration coefficient μ.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Weights {
    /// `K_pinit, K_einit, K_rinit, K_ainit` (Table 2: 0.25 each).
    pub init: [f64; 4],
    /// `K_urp, K_ure, K_urr, K_ura` (Table 2: 0.01 each).
    pub range: [f64; 4],
    /// μ (not in the paper; 0.5, see the module doc).
    pub mu: f64,
}

impl Default for Weights {
    fn default() -> Self {
        Weights {
            init: [0.25; 4],
            range: [0.01; 4],
            mu: 0.5,
        }
    }
}

/// Everything the cost needs to know about the water and the vehicle.
#[derive(Debug, Clone)]
pub struct EnergyModel {
    /// Seabed (Zhang et al. 2022, eq. (1) hills, or any Shoal terrain); `None`: open water.
    pub terrain: Option<Terrain>,
    /// Height the path keeps above the seabed, metres.
    pub terrain_clearance_m: f64,
    /// The current field (eq. (2), or a forecast).
    pub current: Arc<dyn CurrentField>,
    /// `|V_h|`, the constant speed over ground (§2.2), m/s.
    pub ground_speed_mps: f64,
    /// `R_AUV`, the smallest turning radius, metres (Table 2: 8 m).
    pub min_turn_radius_m: f64,
    /// `θ_min`, `θ_max`, degrees (Table 2: −20°, 20°).
    pub pitch_range_deg: (f64, f64),
    /// Weight constants.
    pub weights: Weights,
}

/// The Zhang et al. 2022 figures of one path.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct EnergyTerms {
    /// q_path, eq. (7): length, metres.
    pub q_path: f64,
    /// q_et, eq. (10): propulsion work, joules.
    pub q_et: f64,
    /// q_ea, eq. (11): the heading-to-current work, joules.
    pub q_ea: f64,
    /// q_e = q_et + q_ea, eq. (9), joules.
    pub q_e: f64,
    /// q_r, eq. (13) without its weight: Σ (r_mj − R_AUV)² over points turning tighter than
    /// R_AUV, m².
    pub q_r: f64,
    /// q_a, eq. (13) without its weight: Σ (θ − θ_max)² + (θ − θ_min)² over segments outside
    /// the pitch range, deg².
    pub q_a: f64,
    /// f_f, eq. (18): `(q_path + q_e + q_r + q_a) / 4` in the units above, as the paper mixes them.
    pub f_f: f64,
    /// Tightest turning radius on the path, metres (infinite for a straight line).
    pub min_turn_radius_m: f64,
    /// Steepest climb, degrees.
    pub max_pitch_deg: f64,
    /// Steepest dive (most negative pitch), degrees.
    pub min_pitch_deg: f64,
    /// Smallest height above the seabed minus the required clearance, metres (negative: the
    /// path is too close to or under the seabed); infinite without a seabed.
    pub terrain_margin_m: f64,
    /// Points closer to the seabed than the clearance.
    pub terrain_violations: usize,
    /// Time over ground at the constant ground speed, seconds.
    pub duration_s: f64,
    /// Largest through-water speed needed on any segment, m/s.
    pub max_water_speed_mps: f64,
    /// Mean of each self-adjusting weight over the path (path, energy, radius, angle).
    pub mean_weights: [f64; 4],
}

/// Per-segment and per-point pieces the weighted fitness is built from.
#[derive(Debug, Clone, Default)]
pub struct Pieces {
    /// Segment lengths p_j.
    pub lengths: Vec<f64>,
    /// Segment energies q_et,j + q_ea,j.
    pub energies: Vec<f64>,
    /// Per segment j: the squared radius shortfall at the point ending it (0 at the goal).
    pub radius: Vec<f64>,
    /// Per segment j: the squared pitch excess.
    pub angle: Vec<f64>,
}

/// The work of one straight segment flown at the model's ground speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentWork {
    /// Eq. (10) times the time on the segment, joules.
    pub thrust_j: f64,
    /// Eq. (11) times the time on the segment, joules.
    pub current_j: f64,
    /// Speed through the water, m/s.
    pub water_speed_mps: f64,
}

impl EnergyModel {
    /// The work of flying from `a` to `b` in the current at the segment's midpoint (zero for a
    /// segment of no length).
    pub fn segment_work(&self, a: &Vec3, b: &Vec3) -> SegmentWork {
        let d = b - a;
        let p = d.norm();
        let mut w = SegmentWork {
            thrust_j: 0.0,
            current_j: 0.0,
            water_speed_mps: 0.0,
        };
        if p <= 0.0 {
            return w;
        }
        let v = self.ground_speed_mps.max(1e-9);
        let pitch = d.z.atan2(d.x.hypot(d.y)).to_degrees();
        let dt = p / v;
        let ground = d * (v / p);
        let c = self.current.velocity(&(0.5 * (a + b)));
        let water = water_velocity(&ground, &c);
        let x = resistance(pitch);
        // Zhang et al. 2022, eq. (10), times Δt.
        w.thrust_j = (x * water.norm()).abs() * dt;
        // Zhang et al. 2022, eq. (11), times Δt.
        let (cw, cc) = (water.norm(), c.norm());
        if cw > 0.0 && cc > 0.0 {
            let cos = water.dot(&c) / (cw * cc);
            w.current_j = heading_factor(cos) * (x * cos * cc).abs() * dt;
        }
        w.water_speed_mps = cw;
        w
    }

    /// The figures and the per-segment pieces of a path.
    pub fn terms(&self, points: &[Vec3]) -> (EnergyTerms, Pieces) {
        let n = points.len();
        let segments = n.saturating_sub(1);
        let mut t = EnergyTerms {
            min_turn_radius_m: f64::INFINITY,
            terrain_margin_m: f64::INFINITY,
            max_pitch_deg: f64::NEG_INFINITY,
            min_pitch_deg: f64::INFINITY,
            ..EnergyTerms::default()
        };
        let mut pieces = Pieces {
            lengths: Vec::with_capacity(segments),
            energies: Vec::with_capacity(segments),
            radius: vec![0.0; segments],
            angle: Vec::with_capacity(segments),
        };
        let v = self.ground_speed_mps.max(1e-9);
        let (lo, hi) = self.pitch_range_deg;
        for w in points.windows(2) {
            let d = w[1] - w[0];
            let p = d.norm();
            let horizontal = d.x.hypot(d.y);
            let pitch = d.z.atan2(horizontal).to_degrees();
            let (mut e_t, mut e_a) = (0.0, 0.0);
            if p > 0.0 {
                t.max_pitch_deg = t.max_pitch_deg.max(pitch);
                t.min_pitch_deg = t.min_pitch_deg.min(pitch);
                let work = self.segment_work(&w[0], &w[1]);
                (e_t, e_a) = (work.thrust_j, work.current_j);
                t.duration_s += p / v;
                t.max_water_speed_mps = t.max_water_speed_mps.max(work.water_speed_mps);
            }
            let excess = if pitch > hi {
                (pitch - hi).powi(2)
            } else if pitch < lo {
                (pitch - lo).powi(2)
            } else {
                0.0
            };
            t.q_path += p;
            t.q_et += e_t;
            t.q_ea += e_a;
            t.q_a += excess;
            pieces.lengths.push(p);
            pieces.energies.push(e_t + e_a);
            pieces.angle.push(excess);
        }
        for i in 1..n.saturating_sub(1) {
            let r = turn_radius(&points[i - 1], &points[i], &points[i + 1]);
            t.min_turn_radius_m = t.min_turn_radius_m.min(r);
            if r < self.min_turn_radius_m {
                let s = (r - self.min_turn_radius_m).powi(2);
                t.q_r += s;
                pieces.radius[i - 1] = s;
            }
        }
        if let Some(terrain) = &self.terrain {
            for p in points {
                let margin = p.z - terrain.elevation(p.x, p.y) - self.terrain_clearance_m;
                t.terrain_margin_m = t.terrain_margin_m.min(margin);
                if margin < 0.0 {
                    t.terrain_violations += 1;
                }
            }
        }
        if segments == 0 {
            t.max_pitch_deg = 0.0;
            t.min_pitch_deg = 0.0;
        }
        t.q_e = t.q_et + t.q_ea;
        t.f_f = 0.25 * (t.q_path + t.q_e + t.q_r + t.q_a);
        t.mean_weights = self.mean_weights(&pieces);
        (t, pieces)
    }

    /// The weights of segment `j`, eq. (8), (12), (13), in the order (path, energy, radius,
    /// angle). The last segment has no successor and keeps the weight of equal costs.
    pub fn segment_weights(&self, pieces: &Pieces, j: usize) -> [f64; 4] {
        let w = &self.weights;
        let next = |v: &[f64]| v.get(j + 1).copied().unwrap_or(v[j]);
        [
            adjusted_weight(
                w.init[0],
                w.range[0],
                w.mu,
                ratio(pieces.lengths[j], next(&pieces.lengths)),
            ),
            adjusted_weight(
                w.init[1],
                w.range[1],
                w.mu,
                ratio(pieces.energies[j], next(&pieces.energies)),
            ),
            adjusted_weight(
                w.init[2],
                w.range[2],
                w.mu,
                next(&pieces.radius) - pieces.radius[j],
            ),
            adjusted_weight(
                w.init[3],
                w.range[3],
                w.mu,
                next(&pieces.angle) - pieces.angle[j],
            ),
        ]
    }

    fn mean_weights(&self, pieces: &Pieces) -> [f64; 4] {
        let n = pieces.lengths.len();
        if n == 0 {
            return self.weights.init;
        }
        let mut sum = [0.0; 4];
        for j in 0..n {
            for (s, k) in sum.iter_mut().zip(self.segment_weights(pieces, j)) {
                *s += k;
            }
        }
        sum.map(|s| s / n as f64)
    }

    /// Eq. (6) with the self-adjusting weights: `Σ_j K_path,j p_j + K_e,j q_e,j + K_r,j q_r,j +
    /// K_a,j q_a,j`, each term divided by its scale in `scales` (path, energy, radius, angle) so
    /// that metres, joules, m² and deg² can be added (§4: "normalization is carried out").
    pub fn weighted(&self, pieces: &Pieces, scales: [f64; 4]) -> f64 {
        let s = scales.map(|s| if s > 0.0 { 1.0 / s } else { 1.0 });
        (0..pieces.lengths.len())
            .map(|j| {
                let k = self.segment_weights(pieces, j);
                k[0] * pieces.lengths[j] * s[0]
                    + k[1] * pieces.energies[j] * s[1]
                    + k[2] * pieces.radius[j] * s[2]
                    + k[3] * pieces.angle[j] * s[3]
            })
            .sum()
    }
}

#[cfg(test)]
mod tests;
