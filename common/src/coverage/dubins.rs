//! Dubins paths: the shortest forward-only path between two poses for a vehicle whose turning
//! radius is at least `R` (Dubins 1957), as exact [`Piece::Arc`]/[`Piece::Line`] pieces.
//!
//! The Hybrid A* detour planner (the CPP-DSMV, §3 baseline) uses this twice: the Dubins length to
//! the goal is its admissible obstacle-free heuristic (every forward path with `|κ| ≤ 1/R` is at
//! least that long), and the Dubins path itself is its analytic expansion, the exact last leg that
//! lands on the goal pose.
//!
//! The six candidate words (LSL, RSR, LSR, RSL, RLR, LRL) are solved in closed form in the frame
//! where the start→goal chord is the x axis and lengths are in units of `R` (Shkel & Lumelsky
//! 2001, as in Walker's `dubins.c`); the shortest valid one is the Dubins path.

use super::path::{Piece, Pose2};
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};

/// Angles this close below `2π` are taken as `0`: a rounding residue, not a full loop.
const LOOP_EPS: f64 = 1e-10;
/// Segments shorter than this (metres) are dropped from [`DubinsPath::pieces`]: a zero-length
/// line has no heading of its own, and a zero arc carries no geometry.
const SEGMENT_EPS: f64 = 1e-12;

/// One of the six Dubins words: L = left arc, R = right arc, S = straight, in driving order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DubinsWord {
    /// Left arc, straight, left arc.
    Lsl,
    /// Right arc, straight, right arc.
    Rsr,
    /// Left arc, straight, right arc.
    Lsr,
    /// Right arc, straight, left arc.
    Rsl,
    /// Right arc, left arc, right arc.
    Rlr,
    /// Left arc, right arc, left arc.
    Lrl,
}

/// One segment of a word.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Seg {
    Left,
    Straight,
    Right,
}

impl DubinsWord {
    /// All six words, in the order ties are broken (first wins).
    pub const ALL: [DubinsWord; 6] = [
        DubinsWord::Lsl,
        DubinsWord::Rsr,
        DubinsWord::Lsr,
        DubinsWord::Rsl,
        DubinsWord::Rlr,
        DubinsWord::Lrl,
    ];

    fn segments(self) -> [Seg; 3] {
        use Seg::{Left as L, Right as R, Straight as S};
        match self {
            DubinsWord::Lsl => [L, S, L],
            DubinsWord::Rsr => [R, S, R],
            DubinsWord::Lsr => [L, S, R],
            DubinsWord::Rsl => [R, S, L],
            DubinsWord::Rlr => [R, L, R],
            DubinsWord::Lrl => [L, R, L],
        }
    }
}

/// A Dubins path: a start pose, a radius, a word and the length of each of its three segments.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DubinsPath {
    /// Where the path starts.
    pub start: Pose2,
    /// Turning radius of every arc, metres.
    pub radius: f64,
    /// Which of the six words.
    pub word: DubinsWord,
    /// Arc length of each segment, metres (≥ 0; a zero segment is dropped by `pieces`).
    pub lengths: [f64; 3],
}

impl DubinsPath {
    /// Total length, metres.
    pub fn length(&self) -> f64 {
        self.lengths.iter().sum()
    }

    /// The exact pieces in driving order; zero-length segments are left out, so a straight shot
    /// is one [`Piece::Line`] and the start-equals-goal path is empty.
    pub fn pieces(&self) -> Vec<Piece> {
        let mut out = Vec::with_capacity(3);
        let mut pose = self.start;
        for (seg, len) in self.word.segments().into_iter().zip(self.lengths) {
            if len <= SEGMENT_EPS {
                continue;
            }
            let piece = match seg {
                Seg::Straight => {
                    let from = [pose.x, pose.y];
                    let to = [
                        pose.x + len * pose.heading.cos(),
                        pose.y + len * pose.heading.sin(),
                    ];
                    // The heading is carried over, not re-derived from the chord.
                    pose = Pose2::new(to[0], to[1], pose.heading);
                    Piece::Line { from, to }
                }
                Seg::Left | Seg::Right => {
                    let arc = Piece::turn(pose, self.radius, len / self.radius, seg == Seg::Left);
                    pose = arc.end();
                    arc
                }
            };
            out.push(piece);
        }
        out
    }
}

/// `x` wrapped into `[0, 2π)`, with values a rounding step below `2π` taken as `0`. The
/// arguments here are sums of a few angles, so a couple of subtractions replace the (slow)
/// `fmod`; far-out values still go through `rem_euclid`.
fn mod2pi(x: f64) -> f64 {
    let mut m = x;
    if m.abs() > 8.0 * TAU {
        m = m.rem_euclid(TAU);
    }
    while m >= TAU {
        m -= TAU;
    }
    while m < 0.0 {
        m += TAU;
    }
    if TAU - m < LOOP_EPS {
        0.0
    } else {
        m
    }
}

/// The normalised problem: chord length `d` (units of R), start and goal headings `a`, `b`
/// relative to the chord, and their sines and cosines (computed once for all six words).
#[derive(Debug, Clone, Copy)]
struct Normalised {
    d: f64,
    a: f64,
    b: f64,
    sa: f64,
    ca: f64,
    sb: f64,
    cb: f64,
    c_ab: f64,
}

fn normalise(start: Pose2, goal: Pose2, radius: f64) -> Option<Normalised> {
    let ok = radius.is_finite()
        && radius > 0.0
        && [
            start.x,
            start.y,
            start.heading,
            goal.x,
            goal.y,
            goal.heading,
        ]
        .iter()
        .all(|v| v.is_finite());
    if !ok {
        return None;
    }
    let dx = goal.x - start.x;
    let dy = goal.y - start.y;
    let d = dx.hypot(dy) / radius;
    // With coincident positions the chord direction is arbitrary; 0 keeps the formulas valid.
    let phi = if d > 0.0 { dy.atan2(dx) } else { 0.0 };
    let a = mod2pi(start.heading - phi);
    let b = mod2pi(goal.heading - phi);
    let (sa, ca) = a.sin_cos();
    let (sb, cb) = b.sin_cos();
    Some(Normalised {
        d,
        a,
        b,
        sa,
        ca,
        sb,
        cb,
        c_ab: (a - b).cos(),
    })
}

/// `(t, p, q)` of one word in units of R (arc angles; `p` is a distance for the straight
/// words), or `None` when the word has no solution for this geometry.
fn solve(word: DubinsWord, n: Normalised) -> Option<[f64; 3]> {
    let Normalised {
        d,
        a,
        b,
        sa,
        ca,
        sb,
        cb,
        c_ab,
    } = n;
    // A tangent length squared a rounding step below zero is a touching tangent.
    let root = |sq: f64| {
        if sq < -1e-10 {
            None
        } else {
            Some(sq.max(0.0).sqrt())
        }
    };
    match word {
        DubinsWord::Lsl => {
            let p = root(2.0 + d * d - 2.0 * c_ab + 2.0 * d * (sa - sb))?;
            let th = (cb - ca).atan2(d + sa - sb);
            Some([mod2pi(th - a), p, mod2pi(b - th)])
        }
        DubinsWord::Rsr => {
            let p = root(2.0 + d * d - 2.0 * c_ab + 2.0 * d * (sb - sa))?;
            let th = (ca - cb).atan2(d - sa + sb);
            Some([mod2pi(a - th), p, mod2pi(th - b)])
        }
        DubinsWord::Lsr => {
            let p = root(-2.0 + d * d + 2.0 * c_ab + 2.0 * d * (sa + sb))?;
            let th = (-ca - cb).atan2(d + sa + sb) - (-2.0f64).atan2(p);
            Some([mod2pi(th - a), p, mod2pi(th - b)])
        }
        DubinsWord::Rsl => {
            let p = root(-2.0 + d * d + 2.0 * c_ab - 2.0 * d * (sa + sb))?;
            let th = (ca + cb).atan2(d - sa - sb) - 2.0f64.atan2(p);
            Some([mod2pi(a - th), p, mod2pi(b - th)])
        }
        DubinsWord::Rlr => {
            let c = (6.0 - d * d + 2.0 * c_ab + 2.0 * d * (sa - sb)) / 8.0;
            if c.abs() > 1.0 {
                return None;
            }
            let phi = (ca - cb).atan2(d - sa + sb);
            let p = mod2pi(TAU - c.acos());
            let t = mod2pi(a - phi + p / 2.0);
            Some([t, p, mod2pi(a - b - t + p)])
        }
        DubinsWord::Lrl => {
            let c = (6.0 - d * d + 2.0 * c_ab + 2.0 * d * (sb - sa)) / 8.0;
            if c.abs() > 1.0 {
                return None;
            }
            let phi = (ca - cb).atan2(d + sa - sb);
            let p = mod2pi(TAU - c.acos());
            let t = mod2pi(-a - phi + p / 2.0);
            Some([t, p, mod2pi(b - a - t + p)])
        }
    }
}

/// Every valid word from `start` to `goal` with turning radius `radius`, in [`DubinsWord::ALL`]
/// order; empty for a non-finite pose or a radius that is not finite and positive.
pub fn candidates(start: Pose2, goal: Pose2, radius: f64) -> Vec<DubinsPath> {
    let Some(n) = normalise(start, goal, radius) else {
        return Vec::new();
    };
    DubinsWord::ALL
        .iter()
        .filter_map(|&word| {
            solve(word, n).map(|tpq| DubinsPath {
                start,
                radius,
                word,
                lengths: tpq.map(|v| v * radius),
            })
        })
        .collect()
}

/// The Dubins path: the shortest valid word (ties go to the earlier word in
/// [`DubinsWord::ALL`]). `None` only for invalid input; some word always exists otherwise.
pub fn shortest(start: Pose2, goal: Pose2, radius: f64) -> Option<DubinsPath> {
    let mut best: Option<DubinsPath> = None;
    for c in candidates(start, goal, radius) {
        if best.is_none_or(|b| c.length() < b.length()) {
            best = Some(c);
        }
    }
    best
}

/// The Dubins length alone, without building a path (the Hybrid A* heuristic calls this once
/// per successor); bit-identical to `shortest(..).length()`.
pub fn shortest_length(start: Pose2, goal: Pose2, radius: f64) -> Option<f64> {
    let n = normalise(start, goal, radius)?;
    DubinsWord::ALL
        .iter()
        .filter_map(|&w| solve(w, n).map(|tpq| tpq.map(|v| v * radius).iter().sum::<f64>()))
        .reduce(f64::min)
}

/// Heading difference `a − b` wrapped into `[−π, π)`.
pub fn angle_diff(a: f64, b: f64) -> f64 {
    (a - b + PI).rem_euclid(TAU) - PI
}

#[cfg(test)]
mod tests;
