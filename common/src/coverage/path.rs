//! The geometry a coverage path is made of (CPP-DSMV, §2.2): straight lines and circular arcs,
//! each tagged with the planner state that produced it, and the dense samples (position,
//! heading, curvature, arc length) that the clearance checks, the coverage count and the tracking
//! layer read.
//!
//! Arcs are exact: a row, a U-turn semicircle and a tangent-arc detour are represented
//! analytically and only sampled at the end, so the curvature of every sample is exactly
//! `0` or `±1/R` — never a finite-difference estimate.

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// `a` wrapped into `(−π, π]`.
pub fn wrap_angle(a: f64) -> f64 {
    let w = a.rem_euclid(2.0 * PI);
    if w > PI {
        w - 2.0 * PI
    } else {
        w
    }
}

/// A planar pose: position (m) and heading ψ (rad, counter-clockwise from +x).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pose2 {
    /// East, metres.
    pub x: f64,
    /// North, metres.
    pub y: f64,
    /// Heading ψ, radians, counter-clockwise from east.
    pub heading: f64,
}

impl Pose2 {
    /// A pose from its parts.
    pub fn new(x: f64, y: f64, heading: f64) -> Self {
        Self { x, y, heading }
    }

    /// The position as an array.
    pub fn xy(&self) -> [f64; 2] {
        [self.x, self.y]
    }
}

/// Which state of the planner's machine produced a piece of path (CPP-DSMV, §2.2.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PieceKind {
    /// A scanning pass along a row: the only kind that counts as mining swath in the paper's
    /// reading, though every kind sweeps the seabed it crosses.
    Straight,
    /// A local deviation around a merged obstacle box.
    Detour,
    /// A turn from one row into another.
    UTurn,
    /// A transit between sweeps, to a stretch of row the sweep could not reach.
    Transit,
}

/// One exact piece of path. Externally tagged (`{"line": {…}}`) so the wire codec carries it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Piece {
    /// A straight segment from `from` to `to`.
    Line {
        /// Start point, metres.
        from: [f64; 2],
        /// End point, metres.
        to: [f64; 2],
    },
    /// A circular arc: centre, radius, start angle of the radius vector, signed sweep
    /// (positive = counter-clockwise = left turn).
    Arc {
        /// Centre, metres.
        centre: [f64; 2],
        /// Radius, metres (> 0).
        radius: f64,
        /// Angle of the vector centre → start point, radians.
        start_angle: f64,
        /// Signed swept angle, radians.
        sweep: f64,
    },
}

impl Piece {
    /// Arc length, metres.
    pub fn length(&self) -> f64 {
        match *self {
            Piece::Line { from, to } => (to[0] - from[0]).hypot(to[1] - from[1]),
            Piece::Arc { radius, sweep, .. } => radius * sweep.abs(),
        }
    }

    /// Signed curvature, 1/m (left turns positive).
    pub fn curvature(&self) -> f64 {
        match *self {
            Piece::Line { .. } => 0.0,
            Piece::Arc { radius, sweep, .. } => sweep.signum() / radius,
        }
    }

    /// The pose at arc length `s` along the piece (`s` clamped to `[0, length]`).
    pub fn pose_at(&self, s: f64) -> Pose2 {
        let s = s.clamp(0.0, self.length());
        match *self {
            Piece::Line { from, to } => {
                let len = self.length();
                let heading = (to[1] - from[1]).atan2(to[0] - from[0]);
                let f = if len > 0.0 { s / len } else { 0.0 };
                Pose2::new(
                    from[0] + f * (to[0] - from[0]),
                    from[1] + f * (to[1] - from[1]),
                    heading,
                )
            }
            Piece::Arc {
                centre,
                radius,
                start_angle,
                sweep,
            } => {
                let dir = sweep.signum();
                let a = start_angle + dir * s / radius;
                Pose2::new(
                    centre[0] + radius * a.cos(),
                    centre[1] + radius * a.sin(),
                    wrap_angle(a + dir * PI / 2.0),
                )
            }
        }
    }

    /// Start pose.
    pub fn start(&self) -> Pose2 {
        self.pose_at(0.0)
    }

    /// End pose.
    pub fn end(&self) -> Pose2 {
        self.pose_at(self.length())
    }

    /// The arc that leaves `pose` turning left (`left = true`) or right with radius `radius`
    /// through the signed-magnitude angle `angle ≥ 0`.
    pub fn turn(pose: Pose2, radius: f64, angle: f64, left: bool) -> Piece {
        let side = if left { 1.0 } else { -1.0 };
        let normal = pose.heading + side * PI / 2.0;
        let centre = [
            pose.x + radius * normal.cos(),
            pose.y + radius * normal.sin(),
        ];
        Piece::Arc {
            centre,
            radius,
            start_angle: normal + PI,
            sweep: side * angle,
        }
    }
}

/// One sample of a path: what the checks, the coverage count and the tracker read.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PathSample {
    /// Arc length from the path's start, metres.
    pub s: f64,
    /// East, metres.
    pub x: f64,
    /// North, metres.
    pub y: f64,
    /// Heading ψ, radians.
    pub heading: f64,
    /// Signed curvature κ, 1/m.
    pub curvature: f64,
    /// The planner state that produced the piece.
    pub kind: PieceKind,
}

/// A coverage path: its exact pieces in driving order.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct CoveragePath {
    /// Pieces with the state that produced each.
    pub pieces: Vec<(PieceKind, Piece)>,
}

impl CoveragePath {
    /// Whether every number of every piece is finite and every arc has a positive radius (a
    /// path read from the network is checked with this before it is used).
    pub fn is_valid(&self) -> bool {
        self.pieces.iter().all(|(_, p)| match *p {
            Piece::Line { from, to } => from.iter().chain(&to).all(|v| v.is_finite()),
            Piece::Arc {
                centre,
                radius,
                start_angle,
                sweep,
            } => {
                centre.iter().all(|v| v.is_finite())
                    && radius.is_finite()
                    && radius > 0.0
                    && start_angle.is_finite()
                    && sweep.is_finite()
            }
        })
    }

    /// Total length, metres.
    pub fn length(&self) -> f64 {
        // A fold from +0.0: `sum` of no floats is −0.0, which printed as "-0 m".
        self.pieces.iter().fold(0.0, |acc, (_, p)| acc + p.length())
    }

    /// Length driven in each state: (straight, detour, U-turn, transit), metres.
    pub fn length_by_kind(&self) -> [f64; 4] {
        let mut out = [0.0; 4];
        for (kind, p) in &self.pieces {
            let k = match kind {
                PieceKind::Straight => 0,
                PieceKind::Detour => 1,
                PieceKind::UTurn => 2,
                PieceKind::Transit => 3,
            };
            out[k] += p.length();
        }
        out
    }

    /// Samples no more than `step` metres apart along every piece, each piece's ends included
    /// (a join appears once). Empty pieces are skipped.
    pub fn sample(&self, step: f64) -> Vec<PathSample> {
        let step = if step.is_finite() && step > 0.0 {
            step
        } else {
            1.0
        };
        let mut out: Vec<PathSample> = Vec::new();
        let mut s0 = 0.0;
        for (kind, piece) in &self.pieces {
            let len = piece.length();
            if len <= 0.0 {
                continue;
            }
            let n = (len / step).ceil().max(1.0) as usize;
            let first = if out.is_empty() { 0 } else { 1 };
            for k in first..=n {
                let s = len * k as f64 / n as f64;
                let pose = piece.pose_at(s);
                out.push(PathSample {
                    s: s0 + s,
                    x: pose.x,
                    y: pose.y,
                    heading: pose.heading,
                    curvature: piece.curvature(),
                    kind: *kind,
                });
            }
            s0 += len;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn an_empty_path_is_plus_zero_metres_long() {
        let empty = CoveragePath::default();
        assert_eq!(empty.length(), 0.0);
        assert!(empty.length().is_sign_positive());
        assert_eq!(format!("{:.0}", empty.length()), "0");
    }

    #[test]
    fn a_left_quarter_turn_from_the_origin_heading_east_ends_at_r_r_heading_north() {
        let arc = Piece::turn(Pose2::new(0.0, 0.0, 0.0), 5.0, PI / 2.0, true);
        let end = arc.end();
        assert_abs_diff_eq!(end.x, 5.0, epsilon = 1e-12);
        assert_abs_diff_eq!(end.y, 5.0, epsilon = 1e-12);
        assert_abs_diff_eq!(end.heading, PI / 2.0, epsilon = 1e-12);
        assert_abs_diff_eq!(arc.length(), 5.0 * PI / 2.0, epsilon = 1e-12);
        assert_abs_diff_eq!(arc.curvature(), 0.2, epsilon = 1e-12);
        let start = arc.start();
        assert_abs_diff_eq!(start.x, 0.0, epsilon = 1e-12);
        assert_abs_diff_eq!(start.heading, 0.0, epsilon = 1e-12);
    }

    #[test]
    fn a_right_semicircle_heading_west_drops_two_radii_and_heads_east() {
        let arc = Piece::turn(Pose2::new(10.0, 20.0, PI), 4.0, PI, false);
        let end = arc.end();
        assert_abs_diff_eq!(end.x, 10.0, epsilon = 1e-12);
        assert_abs_diff_eq!(end.y, 28.0, epsilon = 1e-12);
        assert_abs_diff_eq!(end.heading.cos(), 1.0, epsilon = 1e-12);
        assert_abs_diff_eq!(arc.curvature(), -0.25, epsilon = 1e-12);
    }

    #[test]
    fn sampling_keeps_the_step_and_counts_arc_length_across_pieces() {
        let line = Piece::Line {
            from: [0.0, 0.0],
            to: [10.0, 0.0],
        };
        let arc = Piece::turn(line.end(), 5.0, PI, true);
        let path = CoveragePath {
            pieces: vec![(PieceKind::Straight, line), (PieceKind::UTurn, arc)],
        };
        let samples = path.sample(1.0);
        assert_eq!(samples.len(), 11 + 16);
        for w in samples.windows(2) {
            let d = (w[1].x - w[0].x).hypot(w[1].y - w[0].y);
            assert!(d <= 1.0 + 1e-9, "gap {d}");
            assert!(w[1].s > w[0].s);
        }
        let last = samples.last().copied().unwrap_or(samples[0]);
        assert_abs_diff_eq!(last.s, 10.0 + 5.0 * PI, epsilon = 1e-9);
        assert_abs_diff_eq!(last.x, 10.0, epsilon = 1e-9);
        assert_abs_diff_eq!(last.y, 10.0, epsilon = 1e-9);
        assert_abs_diff_eq!(path.length(), 10.0 + 5.0 * PI, epsilon = 1e-12);
        assert_eq!(path.length_by_kind()[1], 0.0);
    }
}
