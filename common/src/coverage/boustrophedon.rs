//! The online Boustrophedon coverage planner with virtual boundaries (CPP-DSMV, §2.2).
//!
//! Rows run east–west, `2·R_min` apart, from the south edge of the area north; the vehicle
//! alternates direction and turns between rows on semicircles of radius `R_min`, which stay inside
//! the area because rows end `R_min` short of its east and west edges (the U-turn space). The
//! planner is a deterministic finite-state machine (§2.2.1–2.2.2):
//!
//! - **Straight** (highest priority): drive along the row. The perception corridor is the next
//!   `perception_range_m` of the row's centre line; only a no-go box crossing it is a threat.
//! - **Detour**: the threat's box is bypassed on its nearer side by an analytic tangent-arc detour
//!   ([`super::arcs`]) — or, for the baseline, by Hybrid A* ([`super::hybrid_detour`]).
//! - **U-turn**: at the row's end, or earlier at a **virtual boundary**: the detour judgment is
//!   revoked and a virtual wall is raised ahead of the threat when the detour would leave the area,
//!   enter the U-turn space, hit another obstacle or need more than `max_detour_offset_m`; and the
//!   wall is pulled back (rollback, `rollback_step_m` at a time) while the U-turn into the next row
//!   would hit an obstacle. If no turn into the next row fits, turns skipping up to
//!   `max_row_skip` rows (radius `j·R_min`) are tried; if none fits, the vehicle is stranded and
//!   the plan says so.
//!
//! Every generated piece is checked at `check_step_m` before it is accepted: inside the area,
//! outside every no-go box, and — for the arc method — at least `safety_clearance_m` from every
//! impassable cell. So the returned path keeps the clearance by construction, and the metrics
//! recompute it independently.

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

use super::arcs::{lane_change, lane_change_run, u_turn};
use super::boxes::{BoxIndex, Rect};
use super::params::CoverageParams;
use super::path::{CoveragePath, Piece, PieceKind, Pose2};
use super::rows::RowBook;
use super::TerrainMap25;

/// Why the planner raised a virtual boundary (CPP-DSMV, §2.2.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BoundaryReason {
    /// No room before the box for the detour's lane change.
    NoRunUp,
    /// The detour would cross the area's boundary.
    DetourLeavesArea,
    /// The detour would end in the U-turn space at the row's end.
    DetourIntoUTurnSpace,
    /// The detour would hit another obstacle or exceed the largest offset.
    DetourBlocked,
    /// The U-turn at the row's end would hit an obstacle in the next row.
    UTurnBlocked,
}

/// One decision of the state machine, for the plan's log. Externally tagged
/// (`{"detour": {…}}`) so the wire codec, which cannot read internally tagged enums, carries it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PlannerEvent {
    /// A detour around a box.
    Detour {
        /// Row index.
        row: usize,
        /// Where the lane change starts.
        at: [f64; 2],
        /// Lateral offset, metres (positive north).
        offset_m: f64,
    },
    /// A virtual boundary: the row ends early at `at`.
    VirtualBoundary {
        /// Row index.
        row: usize,
        /// Where the U-turn starts.
        at: [f64; 2],
        /// Why.
        reason: BoundaryReason,
    },
    /// A turn that skips rows because no turn into the next one fits.
    RowSkip {
        /// From this row.
        from_row: usize,
        /// To this row.
        to_row: usize,
    },
    /// A transit to the first stretch no sweep has covered.
    Transit {
        /// Row of the stretch.
        to_row: usize,
        /// Where the transit ends.
        to: [f64; 2],
        /// Its length, metres.
        length_m: f64,
    },
    /// A stretch no transit could reach; it is left uncovered.
    Unreached {
        /// Row of the stretch.
        row: usize,
        /// The stretch `[x_a, x_b]`.
        stretch: [f64; 2],
    },
    /// No turn fits: this sweep ends here.
    Stranded {
        /// Row index.
        row: usize,
        /// Where.
        at: [f64; 2],
    },
}

/// What a detour method answers for a threat on the row.
pub enum DetourOutcome {
    /// The pieces of the bypass; the last ends back on the row, heading along it.
    Bypass(Vec<Piece>),
    /// No bypass: raise a virtual boundary no later than `wall_x` (the U-turn search starts
    /// there and rolls back toward the vehicle).
    Wall {
        /// Where the search for a U-turn starts, metres along x.
        wall_x: f64,
        /// Why.
        reason: BoundaryReason,
    },
}

/// The row the vehicle drives and where it is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RowState {
    /// Row index.
    pub row: usize,
    /// Row centre line, metres.
    pub y: f64,
    /// `+1` east, `−1` west.
    pub dir: f64,
    /// Current x, metres.
    pub x: f64,
    /// Where the row ends in this direction (the U-turn space begins), metres.
    pub x_end: f64,
}

impl RowState {
    /// The vehicle's pose.
    pub fn pose(&self) -> Pose2 {
        Pose2::new(self.x, self.y, if self.dir > 0.0 { 0.0 } else { PI })
    }
}

/// The geometry every method shares: area, boxes, map and the piece checks.
pub struct Field<'a> {
    /// The 2.5D map.
    pub map: &'a TerrainMap25,
    /// The area planned.
    pub area: Rect,
    /// The no-go boxes.
    pub boxes: Vec<Rect>,
    /// The settings.
    pub params: &'a CoverageParams,
    /// Whether the boxes are no-go for the path (CPP-DSMV's method) or only mark threats on
    /// the rows (the Hybrid A* baseline, which only honours the dilated map).
    pub boxes_are_no_go: bool,
    /// `boxes` bucketed by band, for [`Field::point_ok`].
    pub index: BoxIndex,
}

impl<'a> Field<'a> {
    /// The field of `boxes` over `area` (indexes the boxes).
    pub fn new(
        map: &'a TerrainMap25,
        area: Rect,
        boxes: Vec<Rect>,
        params: &'a CoverageParams,
        boxes_are_no_go: bool,
    ) -> Field<'a> {
        let index = BoxIndex::new(&boxes, params.row_spacing());
        Field {
            map,
            area,
            boxes,
            params,
            boxes_are_no_go,
            index,
        }
    }
}

impl Field<'_> {
    /// Whether `(x, y)` may carry the vehicle's centre: in the area, outside every box, and at
    /// least the safety clearance from every impassable cell.
    pub fn point_ok(&self, x: f64, y: f64) -> bool {
        self.area.holds(x, y)
            && !(self.boxes_are_no_go && self.index.any_contains_strictly(&self.boxes, x, y))
            && self.map.clearance_to_impassable(x, y) >= self.params.safety_clearance_m
    }

    /// Whether every sample of `pieces` (at most `check_step_m` apart, ends included) is ok.
    pub fn pieces_ok(&self, pieces: &[Piece]) -> bool {
        let step = self.params.check_step_m;
        pieces.iter().all(|p| {
            let n = (p.length() / step).ceil().max(1.0) as usize;
            (0..=n).all(|k| {
                let pose = p.pose_at(p.length() * k as f64 / n as f64);
                self.point_ok(pose.x, pose.y)
            })
        })
    }

    /// The first box crossing the row's centre line strictly ahead of the vehicle, with its near
    /// and far x in the driving direction.
    pub fn threat(&self, st: &RowState) -> Option<(Rect, f64, f64)> {
        self.boxes
            .iter()
            .filter(|b| b.y0 < st.y && st.y < b.y1)
            .map(|b| {
                let (near, far) = if st.dir > 0.0 {
                    (b.x0, b.x1)
                } else {
                    (b.x1, b.x0)
                };
                (*b, near, far)
            })
            .filter(|&(_, _, far)| st.dir * (far - st.x) > 0.0)
            .min_by(|a, b| (st.dir * a.1).total_cmp(&(st.dir * b.1)))
    }
}

/// A way to bypass a threat (the arc method or the Hybrid A* baseline).
pub trait DetourPlanner {
    /// Plans the bypass of `threat` (box, near x, far x) from the vehicle's row state.
    fn detour(&self, field: &Field<'_>, st: &RowState, threat: (Rect, f64, f64)) -> DetourOutcome;
}

/// CPP-DSMV's detour: coarse polygon around the box on its nearer side, smoothed by tangent arcs.
pub struct ArcDetour;

impl DetourPlanner for ArcDetour {
    fn detour(&self, field: &Field<'_>, st: &RowState, threat: (Rect, f64, f64)) -> DetourOutcome {
        const EPS: f64 = 1e-6;
        let (b, near, far) = threat;
        let r = field.params.min_turn_radius_m;
        let wall_x = near - st.dir * (r + EPS);
        let mut sides = [b.y1 + EPS, b.y0 - EPS];
        sides.sort_by(|p, q| (p - st.y).abs().total_cmp(&(q - st.y).abs()));
        let mut reason = BoundaryReason::DetourBlocked;
        let mut worst = 0;
        let mut note = |why: BoundaryReason, rank: usize| {
            if rank > worst {
                worst = rank;
                reason = why;
            }
        };
        for y_dev in sides {
            let offset = y_dev - st.y;
            if offset.abs() > field.params.max_detour_offset_m {
                note(BoundaryReason::DetourBlocked, 1);
                continue;
            }
            if y_dev < field.area.y0 || y_dev > field.area.y1 {
                note(BoundaryReason::DetourLeavesArea, 2);
                continue;
            }
            let run = lane_change_run(offset, r);
            let x_s = near - st.dir * run;
            if st.dir * (x_s - st.x) < 0.0 {
                note(BoundaryReason::NoRunUp, 3);
                continue;
            }
            if st.dir * (st.x_end - (far + st.dir * run)) < 0.0 {
                note(BoundaryReason::DetourIntoUTurnSpace, 4);
                continue;
            }
            let heading = st.pose().heading;
            // Left of the heading is north when driving east, south when driving west.
            let left = offset * st.dir;
            let mut pieces = Vec::new();
            if (x_s - st.x).abs() > EPS {
                pieces.push(Piece::Line {
                    from: [st.x, st.y],
                    to: [x_s, st.y],
                });
            }
            pieces.extend(lane_change(Pose2::new(x_s, st.y, heading), left, r));
            pieces.push(Piece::Line {
                from: [near, y_dev],
                to: [far, y_dev],
            });
            pieces.extend(lane_change(Pose2::new(far, y_dev, heading), -left, r));
            if field.pieces_ok(&pieces) {
                return DetourOutcome::Bypass(pieces);
            }
            note(BoundaryReason::DetourBlocked, 1);
        }
        DetourOutcome::Wall { wall_x, reason }
    }
}

/// How one sweep ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SweepEnd {
    /// The last row is done.
    LastRow,
    /// The next row's stretch is already covered.
    Covered,
    /// No turn fits.
    Stranded,
}

/// The state machine of one sweep: drives rows from an entry state until the last row, a row
/// already covered, or a dead end; appends to `path` and `events`, books rows in `book`.
pub struct Machine<'f, 'a> {
    /// The shared geometry.
    pub field: &'f Field<'a>,
    /// The path so far.
    pub path: CoveragePath,
    /// Every decision so far.
    pub events: Vec<PlannerEvent>,
    /// Which stretches of which rows are driven.
    pub book: RowBook,
}

impl Machine<'_, '_> {
    /// Runs the Straight / Detour / U-turn machine from `st` (CPP-DSMV, §2.2.1–2.2.2).
    pub fn sweep(&mut self, mut st: RowState, method: &dyn DetourPlanner) -> SweepEnd {
        let params = self.field.params;
        loop {
            // Straight: the first box crossing the row before its end.
            let threat = self
                .field
                .threat(&st)
                .filter(|t| st.dir * (t.1 - st.x) <= st.dir * (st.x_end - st.x));
            let Some(threat) = threat else {
                let end = st.x_end;
                match self.turn(&mut st, end) {
                    Ok(()) => continue,
                    Err(why) => return why,
                }
            };
            if st.dir * (threat.1 - st.x) > params.perception_range_m {
                // Not yet in the perception corridor: drive until it is.
                let seen_at = threat.1 - st.dir * params.perception_range_m;
                self.straight(&mut st, seen_at);
                continue;
            }
            match method.detour(self.field, &st, threat) {
                DetourOutcome::Bypass(pieces) => self.bypass(&mut st, pieces),
                DetourOutcome::Wall { wall_x, reason } => {
                    let from = if st.dir * (wall_x - st.x) < 0.0 {
                        st.x
                    } else {
                        wall_x
                    };
                    self.events.push(PlannerEvent::VirtualBoundary {
                        row: st.row,
                        at: [from, st.y],
                        reason,
                    });
                    if let Err(why) = self.turn(&mut st, from) {
                        return why;
                    }
                }
            }
        }
    }

    /// Appends a bypass; pieces on the row's line count as Straight.
    fn bypass(&mut self, st: &mut RowState, pieces: Vec<Piece>) {
        let offset = pieces
            .iter()
            .map(|p| p.end().y - st.y)
            .fold(0.0, |a: f64, b| if b.abs() > a.abs() { b } else { a });
        self.events.push(PlannerEvent::Detour {
            row: st.row,
            at: pieces.first().map_or([st.x, st.y], |p| p.start().xy()),
            offset_m: offset,
        });
        let end = pieces.last().map_or(st.x, |p| p.end().x);
        for p in pieces {
            let kind = match p {
                Piece::Line { from, to } if from[1] == st.y && to[1] == st.y => {
                    self.book.drive(st.row, from[0], to[0]);
                    PieceKind::Straight
                }
                _ => PieceKind::Detour,
            };
            self.path.pieces.push((kind, p));
        }
        st.x = end;
    }

    /// Drives straight along the row to `x` (no-op if not ahead).
    pub fn straight(&mut self, st: &mut RowState, x: f64) {
        if st.dir * (x - st.x) > 1e-9 {
            self.path.pieces.push((
                PieceKind::Straight,
                Piece::Line {
                    from: [st.x, st.y],
                    to: [x, st.y],
                },
            ));
            self.book.drive(st.row, st.x, x);
            st.x = x;
        }
    }

    /// U-turn state: turns into the next row no later than `x_start`, rolling the virtual
    /// boundary back toward the vehicle until the turn is clear, then trying row skips.
    fn turn(&mut self, st: &mut RowState, x_start: f64) -> Result<(), SweepEnd> {
        let rows = self.book.rows();
        if st.row + 1 >= rows {
            self.straight(st, x_start);
            return Err(SweepEnd::LastRow);
        }
        let step = self.field.params.rollback_step_m;
        let span = (st.dir * (x_start - st.x)).max(0.0);
        let tries = (span / step).floor() as usize;
        for j in 1..=self.field.params.max_row_skip.max(1) {
            let next = st.row + j;
            if next >= rows {
                break;
            }
            let offset = self.book.y(next) - st.y;
            for t in 0..=tries + 1 {
                let x_v = if t > tries {
                    st.x
                } else {
                    x_start - st.dir * step * t as f64
                };
                let pose = Pose2::new(x_v, st.y, st.pose().heading);
                // North is left when driving east.
                let arc = u_turn(pose, offset * st.dir);
                if !self.field.pieces_ok(&[arc]) {
                    continue;
                }
                if self.book.is_done(next, x_v) {
                    // The sweep has reached rows already covered: finish this row and stop —
                    // unless no turn either way fits at the row's end (a row end boxed in on
                    // both sides), where a forward-only vehicle could never leave and every
                    // later transit would fail: then stop at the turn just found and give the
                    // rest of the row up.
                    let end = Pose2::new(x_start, st.y, st.pose().heading);
                    let spacing = self.field.params.row_spacing();
                    let leaves = [spacing, -spacing]
                        .iter()
                        .any(|&o| self.field.pieces_ok(&[u_turn(end, o)]));
                    if leaves || (x_v - x_start).abs() <= 1e-9 {
                        self.straight(st, x_start);
                    } else {
                        self.straight(st, x_v);
                        self.book.abandon_at(st.row, x_start);
                    }
                    return Err(SweepEnd::Covered);
                }
                if (x_v - x_start).abs() > 1e-9 {
                    self.events.push(PlannerEvent::VirtualBoundary {
                        row: st.row,
                        at: [x_v, st.y],
                        reason: BoundaryReason::UTurnBlocked,
                    });
                }
                if j > 1 {
                    self.events.push(PlannerEvent::RowSkip {
                        from_row: st.row,
                        to_row: next,
                    });
                }
                self.straight(st, x_v);
                self.path.pieces.push((PieceKind::UTurn, arc));
                let (x_lo, x_hi) = self.book.x_range();
                *st = RowState {
                    row: next,
                    y: self.book.y(next),
                    dir: -st.dir,
                    x: x_v,
                    x_end: if st.dir > 0.0 { x_lo } else { x_hi },
                };
                return Ok(());
            }
        }
        self.events.push(PlannerEvent::Stranded {
            row: st.row,
            at: [st.x, st.y],
        });
        Err(SweepEnd::Stranded)
    }
}
