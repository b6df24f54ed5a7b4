//! The motion limits of a waypoint path as penalties (Zhi & Zuo 2024, §4 and Table 4: turning
//! angle within ±35°, pitch within ±20°): each violation costs `1 + excess / limit`.

use crate::geometry::{pitch, Vec3, MIN_HEADING_EXTENT};

/// Turn penalty: for every heading change (see [`crate::geometry::turns`]) that exceeds `max_turn` (radians),
/// `1 + excess / max_turn`. The cosine is compared first so only violations pay for `atan2`.
pub fn turn_penalty(points: &[Vec3], max_turn: f64) -> f64 {
    let cos_max = max_turn.cos();
    let mut p = 0.0;
    let mut prev: Option<(f64, f64, f64)> = None;
    for w in points.windows(2) {
        let (x, y) = (w[1].x - w[0].x, w[1].y - w[0].y);
        let n = (x * x + y * y).sqrt();
        if n <= MIN_HEADING_EXTENT {
            continue;
        }
        if let Some((px, py, pn)) = prev {
            p += turn_excess(px * x + py * y, px * y - py * x, cos_max * pn * n, max_turn);
        }
        prev = Some((x, y, n));
    }
    p
}

/// One heading change's share of [`turn_penalty`]: `1 + excess / max_turn` for a turn past
/// `max_turn`, else 0; from the two headings' dot and cross products and `bound`, the dot
/// product of a turn of exactly `max_turn` (so only a turn past it pays for `atan2`).
#[inline]
fn turn_excess(dot: f64, cross: f64, bound: f64, max_turn: f64) -> f64 {
    if dot < bound {
        let t = cross.atan2(dot).abs();
        if t > max_turn {
            return 1.0 + (t - max_turn) / max_turn;
        }
    }
    0.0
}

/// The turn penalty of entering `points` from a vehicle already moving along `heading` (its
/// horizontal part counts): the [`turn_penalty`] of the heading change from `heading` to the
/// path's first leg with a horizontal extent. A replan that starts under way uses it, so the
/// new path leaves the vehicle's present course within the same per-waypoint limit as every
/// other turn (Zhi & Zuo's turn constraint, applied at the start too). A heading with no
/// horizontal part, or a path without a horizontal leg, adds nothing.
pub fn entry_turn_penalty(heading: Vec3, points: &[Vec3], max_turn: f64) -> f64 {
    let Some(first) = points.first() else {
        return 0.0;
    };
    let h = Vec3::new(heading.x, heading.y, 0.0);
    if h.norm() <= MIN_HEADING_EXTENT {
        return 0.0;
    }
    let Some(k) = points
        .iter()
        .position(|p| (p.x - first.x).hypot(p.y - first.y) > MIN_HEADING_EXTENT)
    else {
        return 0.0;
    };
    let behind = first - h / h.norm();
    let mut entry = Vec::with_capacity(k + 2);
    entry.push(behind);
    entry.extend_from_slice(&points[..=k]);
    turn_penalty(&entry, max_turn)
}

/// Pitch penalty: for every leg whose |pitch| exceeds `max_pitch` (radians),
/// `1 + excess / max_pitch`. The slope is compared first so only violations pay for `atan2`.
pub fn pitch_penalty(points: &[Vec3], max_pitch: f64) -> f64 {
    let tan_max = max_pitch.tan();
    let mut p = 0.0;
    for w in points.windows(2) {
        let d = w[1] - w[0];
        let h = (d.x * d.x + d.y * d.y).sqrt();
        if d.z.abs() <= tan_max * h {
            continue;
        }
        let a = pitch(&w[0], &w[1]).abs();
        if a > max_pitch {
            p += 1.0 + (a - max_pitch) / max_pitch;
        }
    }
    p
}

/// A vehicle's turn and pitch limits (radians) with the cosine and the tangent the penalties
/// compare against first: taken once per vehicle rather than at each of the swarm's
/// evaluations, where `cos` and `tan` took about 1 % of the 32-vehicle lanes swarm's time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionLimits {
    /// Largest heading change per waypoint, radians.
    pub max_turn: f64,
    /// Its cosine.
    pub cos_max_turn: f64,
    /// Largest |pitch| of a leg, radians.
    pub max_pitch: f64,
    /// Its tangent.
    pub tan_max_pitch: f64,
}

impl MotionLimits {
    /// The limits `max_turn` and `max_pitch` (radians) with their cosine and tangent.
    pub fn new(max_turn: f64, max_pitch: f64) -> MotionLimits {
        MotionLimits {
            max_turn,
            cos_max_turn: max_turn.cos(),
            max_pitch,
            tan_max_pitch: max_pitch.tan(),
        }
    }
}

/// `turn_penalty(points, max_turn) + pitch_penalty(points, max_pitch)` to the last bit, in one
/// pass that takes each leg's horizontal extent once for both.
pub fn turn_and_pitch_penalty(points: &[Vec3], max_turn: f64, max_pitch: f64) -> f64 {
    turn_and_pitch_penalty_within(points, &MotionLimits::new(max_turn, max_pitch))
}

/// [`turn_and_pitch_penalty`] against limits whose cosine and tangent are known.
pub fn turn_and_pitch_penalty_within(points: &[Vec3], limits: &MotionLimits) -> f64 {
    let (max_turn, max_pitch) = (limits.max_turn, limits.max_pitch);
    let (cos_max, tan_max) = (limits.cos_max_turn, limits.tan_max_pitch);
    let (mut turn, mut climb) = (0.0, 0.0);
    let mut prev: Option<(f64, f64, f64)> = None;
    for w in points.windows(2) {
        let d = w[1] - w[0];
        let n = (d.x * d.x + d.y * d.y).sqrt();
        if d.z.abs() > tan_max * n {
            let a = pitch(&w[0], &w[1]).abs();
            if a > max_pitch {
                climb += 1.0 + (a - max_pitch) / max_pitch;
            }
        }
        if n <= MIN_HEADING_EXTENT {
            continue;
        }
        if let Some((px, py, pn)) = prev {
            turn += turn_excess(
                px * d.x + py * d.y,
                px * d.y - py * d.x,
                cos_max * pn * n,
                max_turn,
            );
        }
        prev = Some((d.x, d.y, n));
    }
    turn + climb
}
