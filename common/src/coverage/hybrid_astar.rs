//! Hybrid A* (Dolgov et al. 2008) for a forward-only tracked crawler with a minimum turning
//! radius: the search-based detour planner CPP-DSMV, §3 compares against, run under the same
//! Boustrophedon macro-routing. The caller asks for a path from a pose before a blocked stretch
//! of a row to a pose after it (or from a row end to the next row's start when the U-turn is
//! blocked); this module knows nothing about rows.
//!
//! - States are continuous poses; the closed set is a grid of `xy_resolution_m` cells ×
//!   `heading_bins` headings, one live state per cell (a cheaper arrival replaces it while open).
//! - Motion primitives are forward arcs of `steering_branches` curvatures evenly spaced in
//!   `[−1/R, 1/R]` (straight included), each `step_m` long and kept as an exact
//!   [`Piece::Arc`]/[`Piece::Line`], so the output is an exact path with `|κ| ≤ 1/R`.
//! - The heuristic is the Dubins length to the goal (≥ the Euclidean distance), admissible for a
//!   forward-only vehicle; the steering penalties only add cost, so it stays admissible. (When a
//!   search ends by the goal tolerance rather than a Dubins shot, the goal is a region and the
//!   estimate can exceed the cost to its edge by up to `goal_tolerance_m`.) It ignores
//!   obstacles: Dolgov's second, holonomic-with-obstacles heuristic is not implemented.
//! - Analytic expansion: every `analytic_expansion_every` expansions, and at every expansion
//!   within `4·R` of the goal, the Dubins path to the goal is tried and accepted if collision-free;
//!   the path then ends exactly on the goal pose.
//! - Deterministic: a binary heap ordered by `(f, h, insertion counter)` with `f64::total_cmp`,
//!   and a hash map that is only looked up, never iterated.

use super::dubins::{self, angle_diff};
use super::path::{CoveragePath, Piece, PieceKind, Pose2};
use serde::{Deserialize, Serialize};
use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashMap};
use std::f64::consts::TAU;
use std::hash::{BuildHasherDefault, Hasher};

/// Largest spacing between two collision checks along any piece, metres. The caller's map is
/// dilated by the half-width of the vehicle, so its obstacles are far wider than this.
pub const MAX_CHECK_SPACING_M: f64 = 0.5;
/// Largest grid extent per axis in cells (the cell key packs 24 bits per axis).
const MAX_AXIS_CELLS: f64 = (1u64 << 24) as f64;

mod params;
pub use params::{HybridAStarError, HybridAStarParams};

/// A found path and the effort it took.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HybridAStarResult {
    /// Exact line and arc pieces, all tagged [`PieceKind::Detour`]; consecutive primitives of the
    /// same curvature are merged into one piece (unless the merged piece's own 0.5 m samples
    /// would touch a blocked point, see `assemble`).
    pub path: CoveragePath,
    /// States expanded (popped and grown) before the path was found.
    pub expansions: usize,
}

/// The closed-set grid: which cell a pose falls in, and whether it is inside the bounds.
struct Grid {
    bounds: [f64; 4],
    res: f64,
    bins: u64,
    bin_width: f64,
}

impl Grid {
    fn new(bounds: [f64; 4], params: &HybridAStarParams) -> Result<Self, HybridAStarError> {
        let [x0, y0, x1, y1] = bounds;
        if !bounds.iter().all(|v| v.is_finite()) {
            return Err(HybridAStarError::InvalidBounds {
                bounds,
                reason: "not finite",
            });
        }
        if !(x0 < x1 && y0 < y1) {
            return Err(HybridAStarError::InvalidBounds {
                bounds,
                reason: "need xmin < xmax and ymin < ymax",
            });
        }
        let res = params.xy_resolution_m;
        if (x1 - x0) / res >= MAX_AXIS_CELLS || (y1 - y0) / res >= MAX_AXIS_CELLS {
            return Err(HybridAStarError::InvalidBounds {
                bounds,
                reason: "more than 2^24 cells of xy_resolution_m along one axis",
            });
        }
        Ok(Self {
            bounds,
            res,
            bins: params.heading_bins as u64,
            bin_width: TAU / params.heading_bins as f64,
        })
    }

    fn inside(&self, x: f64, y: f64) -> bool {
        let [x0, y0, x1, y1] = self.bounds;
        x >= x0 && x <= x1 && y >= y0 && y <= y1
    }

    /// Cell key `ix << 40 | iy << 16 | ih`, or `None` outside the bounds.
    fn key(&self, p: Pose2) -> Option<u64> {
        if !self.inside(p.x, p.y) {
            return None;
        }
        // In range by the bounds check and the 2^24 limit; `as` saturates anyway.
        let ix = ((p.x - self.bounds[0]) / self.res).floor() as u64;
        let iy = ((p.y - self.bounds[1]) / self.res).floor() as u64;
        let ih = (p.heading.rem_euclid(TAU) / self.bin_width).round() as u64 % self.bins;
        Some((ix << 40) | (iy << 16) | ih)
    }
}

/// A multiplicative hasher for the packed cell keys: deterministic and far cheaper than SipHash
/// (the map is never iterated, so the hash only affects speed).
#[derive(Default)]
struct CellHasher(u64);

impl Hasher for CellHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }
    fn write_u64(&mut self, v: u64) {
        let x = (self.0 ^ v).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        self.0 = x ^ (x >> 32);
    }
}

/// One search state.
struct Node {
    pose: Pose2,
    g: f64,
    /// Normalised steer `u = κ·R` of the primitive that reached it (0 at the start: the crawler
    /// arrives driving along its row).
    steer: f64,
    /// Parent node index and the primitive from it; `None` for the start.
    from: Option<(usize, Piece)>,
}

/// What the closed-set grid holds per cell: the live node and whether it was expanded.
#[derive(Clone, Copy)]
struct Cell {
    node: usize,
    closed: bool,
}

/// An open-list entry; the heap pops the least `f`, then the least `h`, then the oldest.
#[derive(Debug, Clone, Copy)]
struct Open {
    f: f64,
    h: f64,
    seq: u64,
    node: usize,
}

impl Ord for Open {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .f
            .total_cmp(&self.f)
            .then_with(|| other.h.total_cmp(&self.h))
            .then_with(|| other.seq.cmp(&self.seq))
    }
}

impl PartialOrd for Open {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl PartialEq for Open {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Open {}

/// The forward primitive of normalised steer `u` from `pose` and its end pose (heading wrapped
/// into `[−π, π)`).
fn primitive(pose: Pose2, u: f64, radius: f64, step: f64) -> (Piece, Pose2) {
    if u == 0.0 {
        let (s, c) = pose.heading.sin_cos();
        let to = [pose.x + step * c, pose.y + step * s];
        let piece = Piece::Line {
            from: [pose.x, pose.y],
            to,
        };
        (piece, Pose2::new(to[0], to[1], pose.heading))
    } else {
        let r = radius / u.abs();
        let piece = Piece::turn(pose, r, step / r, u > 0.0);
        let end = piece.end();
        (
            piece,
            Pose2::new(end.x, end.y, angle_diff(end.heading, 0.0)),
        )
    }
}

/// Whether every point of `piece` after its start, sampled at most [`MAX_CHECK_SPACING_M`]
/// apart, is inside the bounds and free. (The start is the previous piece's checked end.)
fn piece_free(piece: &Piece, grid: &Grid, free: &dyn Fn(f64, f64) -> bool) -> bool {
    let len = piece.length();
    let n = (len / MAX_CHECK_SPACING_M).ceil().max(1.0) as usize;
    (1..=n).all(|k| {
        let p = piece.pose_at(len * k as f64 / n as f64);
        grid.inside(p.x, p.y) && free(p.x, p.y)
    })
}

/// Appends `p`, merging it into the last piece when it continues the same line or circle.
fn push_merged(out: &mut Vec<Piece>, p: Piece) {
    const TOL: f64 = 1e-9;
    if let Some(last) = out.last_mut() {
        match (last, p) {
            (Piece::Line { from, to }, Piece::Line { from: f2, to: t2 }) => {
                let (a, b) = (
                    [to[0] - from[0], to[1] - from[1]],
                    [t2[0] - f2[0], t2[1] - f2[1]],
                );
                let norm = a[0].hypot(a[1]) * b[0].hypot(b[1]);
                let cross = (a[0] * b[1] - a[1] * b[0]).abs();
                let joined = (to[0] - f2[0]).hypot(to[1] - f2[1]) < TOL;
                if joined && norm > 0.0 && cross <= 1e-12 * norm && a[0] * b[0] + a[1] * b[1] > 0.0
                {
                    *to = t2;
                    return;
                }
            }
            (
                Piece::Arc {
                    centre,
                    radius,
                    sweep,
                    ..
                },
                Piece::Arc {
                    centre: c2,
                    radius: r2,
                    sweep: s2,
                    ..
                },
            ) => {
                let same_circle = (*radius - r2).abs() < TOL
                    && (centre[0] - c2[0]).hypot(centre[1] - c2[1]) < TOL;
                if same_circle && sweep.signum() == s2.signum() {
                    *sweep += s2;
                    return;
                }
            }
            _ => {}
        }
    }
    out.push(p);
}

/// Plans a forward-only path from `start` to `goal` whose centre stays where `free` says and
/// inside `bounds = [xmin, ymin, xmax, ymax]`.
///
/// `Ok(None)` when no path was found within `max_expansions` (or the open list ran dry, or the
/// start or goal is itself blocked or out of bounds); `Err` only for invalid parameters, bounds
/// or non-finite poses.
pub fn plan(
    start: Pose2,
    goal: Pose2,
    free: &dyn Fn(f64, f64) -> bool,
    bounds: [f64; 4],
    params: &HybridAStarParams,
) -> Result<Option<HybridAStarResult>, HybridAStarError> {
    plan_guided(start, goal, free, bounds, params, &|_, _| 0.0)
}

/// [`plan`] with an extra heuristic term: the search ranks a pose by
/// `max(Dubins length, guide(x, y))`. A guide that knows the obstacles (Dolgov's
/// holonomic-with-obstacles distance, e.g. a grid Dijkstra from the goal) steers the search
/// around dead ends; a grid distance can overestimate by a few percent, so a guided path is no
/// longer guaranteed shortest — fine for transits, which need to be found fast.
pub fn plan_guided(
    start: Pose2,
    goal: Pose2,
    free: &dyn Fn(f64, f64) -> bool,
    bounds: [f64; 4],
    params: &HybridAStarParams,
    guide: &dyn Fn(f64, f64) -> f64,
) -> Result<Option<HybridAStarResult>, HybridAStarError> {
    params.validate()?;
    for (which, pose) in [("start", start), ("goal", goal)] {
        if ![pose.x, pose.y, pose.heading].iter().all(|v| v.is_finite()) {
            return Err(HybridAStarError::NonFinitePose { which, pose });
        }
    }
    let grid = Grid::new(bounds, params)?;
    let start = Pose2::new(start.x, start.y, angle_diff(start.heading, 0.0));
    let (Some(start_key), Some(_)) = (grid.key(start), grid.key(goal)) else {
        return Ok(None);
    };
    if !free(start.x, start.y) || !free(goal.x, goal.y) {
        return Ok(None);
    }

    let radius = params.min_turn_radius_m;
    let step = params.step_m;
    let half = (params.steering_branches / 2) as f64;
    // u from −1 (full right) to +1 (full left), exactly 0 in the middle.
    let steers: Vec<f64> = (0..params.steering_branches)
        .map(|b| (b as f64 - half) / half)
        .collect();
    let near_goal = 4.0 * radius;
    let heuristic = |p: Pose2| {
        let chord = (goal.x - p.x).hypot(goal.y - p.y);
        let base = dubins::shortest_length(p, goal, radius).map_or(chord, |d| d.max(chord));
        base.max(guide(p.x, p.y))
    };

    let mut nodes = vec![Node {
        pose: start,
        g: 0.0,
        steer: 0.0,
        from: None,
    }];
    let mut cells: HashMap<u64, Cell, BuildHasherDefault<CellHasher>> = HashMap::default();
    cells.insert(
        start_key,
        Cell {
            node: 0,
            closed: false,
        },
    );
    let mut open = BinaryHeap::new();
    let h0 = heuristic(start);
    open.push(Open {
        f: h0,
        h: h0,
        seq: 0,
        node: 0,
    });
    let mut seq = 1u64;
    let mut expansions = 0usize;

    while let Some(top) = open.pop() {
        let pose = nodes[top.node].pose;
        let Some(key) = grid.key(pose) else { continue };
        match cells.get_mut(&key) {
            Some(cell) if cell.node == top.node && !cell.closed => cell.closed = true,
            _ => continue, // superseded by a cheaper state in the same cell, or already expanded
        }
        if expansions >= params.max_expansions {
            return Ok(None);
        }
        expansions += 1;

        let every = params.analytic_expansion_every;
        let chord = (goal.x - pose.x).hypot(goal.y - pose.y);
        if every > 0 && ((expansions - 1).is_multiple_of(every) || chord <= near_goal) {
            if let Some(shot) = dubins::shortest(pose, goal, radius) {
                let tail = shot.pieces();
                if tail.iter().all(|p| piece_free(p, &grid, free)) {
                    let pieces = assemble(&nodes, top.node, tail, &grid, free);
                    return Ok(Some(result(pieces, expansions)));
                }
            }
        }
        if chord <= params.goal_tolerance_m
            && angle_diff(pose.heading, goal.heading).abs() <= params.goal_heading_tolerance_rad
        {
            let pieces = assemble(&nodes, top.node, Vec::new(), &grid, free);
            return Ok(Some(result(pieces, expansions)));
        }

        let (g, steer) = (nodes[top.node].g, nodes[top.node].steer);
        for &u in &steers {
            let (piece, end) = primitive(pose, u, radius, step);
            let Some(end_key) = grid.key(end) else {
                continue;
            };
            if end_key == key {
                continue;
            }
            let g2 = g + step
                * (1.0
                    + params.steer_penalty * u.abs()
                    + params.steer_change_penalty * (u - steer).abs());
            if let Some(cell) = cells.get(&end_key) {
                if cell.closed || nodes[cell.node].g <= g2 {
                    continue;
                }
            }
            if !piece_free(&piece, &grid, free) {
                continue;
            }
            let h = heuristic(end);
            let idx = nodes.len();
            nodes.push(Node {
                pose: end,
                g: g2,
                steer: u,
                from: Some((top.node, piece)),
            });
            cells.insert(
                end_key,
                Cell {
                    node: idx,
                    closed: false,
                },
            );
            open.push(Open {
                f: g2 + h,
                h,
                seq,
                node: idx,
            });
            seq += 1;
        }
    }
    Ok(None)
}

/// The pieces from the start to `last` along the search tree, then `tail`, with runs of the
/// same line or circle merged. The merged pieces are re-checked at the same spacing (their
/// samples differ from the primitives'); if one fails, the unmerged pieces are returned, so the
/// points `CoveragePath::sample(MAX_CHECK_SPACING_M)` yields are always ones that were checked.
fn assemble(
    nodes: &[Node],
    last: usize,
    tail: Vec<Piece>,
    grid: &Grid,
    free: &dyn Fn(f64, f64) -> bool,
) -> Vec<Piece> {
    let mut pieces = Vec::new();
    let mut at = last;
    while let Some((parent, piece)) = nodes.get(at).and_then(|n| n.from) {
        pieces.push(piece);
        at = parent;
    }
    pieces.reverse();
    pieces.extend(tail);
    let mut merged = Vec::with_capacity(pieces.len());
    for &p in &pieces {
        push_merged(&mut merged, p);
    }
    if merged.iter().all(|p| piece_free(p, grid, free)) {
        merged
    } else {
        pieces
    }
}

fn result(pieces: Vec<Piece>, expansions: usize) -> HybridAStarResult {
    HybridAStarResult {
        path: CoveragePath {
            pieces: pieces.into_iter().map(|p| (PieceKind::Detour, p)).collect(),
        },
        expansions,
    }
}

#[cfg(test)]
mod tests;
