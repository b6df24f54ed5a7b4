//! The whole coverage plan: sweeps of the Boustrophedon machine, chained by transits.
//!
//! A single Boustrophedon sweep (CPP-DSMV, §2.2) covers the rows it can reach by turning from one
//! into the next; stretches cut off by a large box (beyond its virtual boundary) or above a dead
//! end are left behind. The paper stops there. Shoal goes on: it sends the vehicle to the first
//! stretch no sweep has covered (south to north, west to east) along a transit planned by Hybrid A*
//! on the same safety predicate (area, boxes, clearance) and runs another sweep from there; a
//! stretch no transit reaches within the search budget is reported as unreached. Transits are
//! their own piece kind, so the figures can be read with or without them.
//!
//! Merged boxes (the paper's fusion of nearby obstacles) also hide passable ground between the
//! obstacles they merge, and one box around an L- or ring-shaped obstacle hides the ground in its
//! corners. A second phase ("box interiors") runs the same sweeps and transits with tighter
//! no-go boxes — each obstacle's boxes band by band, one row spacing high
//! ([`super::boxes::band_boxes`]) — on the rows cut by those boxes and by everything the first
//! phase drove; the safety clearance is checked exactly as before.

use serde::{Deserialize, Serialize};

use super::boustrophedon::{ArcDetour, DetourPlanner, Field, Machine, PlannerEvent, RowState};
use super::boxes::{band_boxes, no_go_boxes, Rect};
use super::hybrid_astar::HybridAStarParams;
use super::hybrid_detour::HybridDetour;
use super::params::{CoverageParams, DetourMethod};
use super::path::{CoveragePath, PieceKind, Pose2};
use super::reach::ReachGrid;
use super::rows::RowBook;
use super::{Terrain25Error, TerrainMap25};

/// A coverage plan for one area.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CoveragePlan {
    /// The path.
    pub path: CoveragePath,
    /// The merged, inflated no-go boxes used (the red rectangles of Figure 6).
    pub boxes: Vec<Rect>,
    /// The band boxes of the box-interior phase (empty when that phase did not run). Every
    /// path point lies outside these.
    pub inner_boxes: Vec<Rect>,
    /// The area planned.
    pub area: Rect,
    /// Rows the area holds.
    pub rows: usize,
    /// Sweeps run (1 + successful transits).
    pub sweeps: usize,
    /// Every decision.
    pub events: Vec<PlannerEvent>,
}

impl CoveragePlan {
    /// `(detours, virtual boundaries, row skips, transits, unreached, stranded)` counts.
    pub fn event_counts(&self) -> [usize; 6] {
        let mut c = [0; 6];
        for e in &self.events {
            c[match e {
                PlannerEvent::Detour { .. } => 0,
                PlannerEvent::VirtualBoundary { .. } => 1,
                PlannerEvent::RowSkip { .. } => 2,
                PlannerEvent::Transit { .. } => 3,
                PlannerEvent::Unreached { .. } => 4,
                PlannerEvent::Stranded { .. } => 5,
            }] += 1;
        }
        c
    }
}

/// Plans the coverage of `area` with the method `params.detour` names.
///
/// The arc method keeps `safety_clearance_m` and treats the merged boxes as no-go. The Hybrid A*
/// baseline works as the paper's search-based baselines do: on the dilated map alone (clearance
/// `W/2` from impassable cells, boxes unmerged and used only to spot threats on a row).
pub fn plan_coverage(
    map: &TerrainMap25,
    area: Rect,
    params: &CoverageParams,
) -> Result<CoveragePlan, Terrain25Error> {
    match params.detour {
        DetourMethod::Arcs => plan_coverage_with(map, area, params, &ArcDetour, true),
        DetourMethod::HybridAStar => {
            let baseline = CoverageParams {
                safety_clearance_m: map.limits().dilation_radius_m(),
                merge_gap_m: Some(0.0),
                ..params.clone()
            };
            plan_coverage_with(map, area, &baseline, &HybridDetour, false)
        }
    }
}

/// Plans the coverage of `area` with a given detour method; `boxes_are_no_go` as in
/// [`Field::boxes_are_no_go`].
pub fn plan_coverage_with(
    map: &TerrainMap25,
    area: Rect,
    params: &CoverageParams,
    method: &dyn DetourPlanner,
    boxes_are_no_go: bool,
) -> Result<CoveragePlan, Terrain25Error> {
    params.validate()?;
    let r = params.min_turn_radius_m;
    let spacing = params.row_spacing();
    if !(area.x1 - area.x0 >= 4.0 * r && area.y1 - area.y0 >= spacing) {
        return Err(Terrain25Error::InvalidParam {
            field: "area".into(),
            what: format!(
                "{:.1} × {:.1} m cannot hold one row with its U-turn space (R_min = {r} m)",
                area.x1 - area.x0,
                area.y1 - area.y0
            ),
        });
    }
    let field = Field::new(
        map,
        area,
        no_go_boxes(map, params.safety_clearance_m, params.merge_gap()),
        params,
        boxes_are_no_go,
    );
    let rows = ((area.y1 - area.y0) / spacing + 1e-9).floor() as usize;
    let ys: Vec<f64> = (0..rows)
        .map(|k| area.y0 + spacing / 2.0 + k as f64 * spacing)
        .collect();
    let x_range = (area.x0 + r, area.x1 - r);
    let mut run = Sweeping {
        path: CoveragePath::default(),
        events: Vec::new(),
        sweeps: 0,
        budget: params.transit_budget,
    };
    let book = run.phase(
        &field,
        RowBook::new(ys.clone(), x_range, &field.boxes, r),
        method,
    )?;
    // Box interiors: merged boxes hold passable ground between the obstacles they merge. A
    // second phase sweeps what is left with each obstacle's own inflated box as no-go (every
    // point still keeps the safety clearance), starting from what the first phase drove.
    let mut inner_boxes = Vec::new();
    if boxes_are_no_go && params.merge_gap() > 0.0 {
        let inner = Field::new(
            map,
            area,
            band_boxes(map, params.safety_clearance_m, spacing),
            params,
            true,
        );
        if inner.boxes != field.boxes {
            // The second book's stretches are the rows cut by the obstacles' own boxes and by
            // what the first phase drove, so what is left inside the merged boxes is open.
            let mut cuts = inner.boxes.clone();
            cuts.extend(book.drives().iter().map(|&(k, a, b)| {
                let y = book.y(k);
                Rect::new(a, y - 0.25 * r, b, y + 0.25 * r)
            }));
            run.phase(&inner, RowBook::new(ys, x_range, &cuts, r), method)?;
            inner_boxes = inner.boxes;
        }
    }
    Ok(CoveragePlan {
        path: run.path,
        inner_boxes,
        boxes: field.boxes.clone(),
        area,
        rows,
        sweeps: run.sweeps,
        events: run.events,
    })
}

/// The plan as it grows over the phases.
struct Sweeping {
    path: CoveragePath,
    events: Vec<PlannerEvent>,
    sweeps: usize,
    /// Transit search expansions left for the whole plan.
    budget: usize,
}

impl Sweeping {
    /// Sweeps every open stretch of `book` on `field`, joined by transits, from where the path
    /// ends; returns the book.
    fn phase(
        &mut self,
        field: &Field<'_>,
        book: RowBook,
        method: &dyn DetourPlanner,
    ) -> Result<RowBook, Terrain25Error> {
        let (params, area) = (field.params, field.area);
        let r = params.min_turn_radius_m;
        let mut m = Machine {
            field,
            path: std::mem::take(&mut self.path),
            events: std::mem::take(&mut self.events),
            book,
        };
        let transit_params = HybridAStarParams {
            min_turn_radius_m: r,
            max_expansions: params.transit_expansions.max(1),
            ..HybridAStarParams::default()
        };
        let free = |x: f64, y: f64| field.point_ok(x, y);
        // The search's own bounds sit 1 m outside the area so a pose on the area's edge (where
        // every row's U-turn reaches) is inside its grid; `free` keeps the path in the area.
        let bounds = [area.x0 - 1.0, area.y0 - 1.0, area.x1 + 1.0, area.y1 + 1.0];
        let reach = ReachGrid::new(area, field.map.cell_m(), &free);
        while let Some((k, i)) = next_stretch(&m) {
            let here = m.path.pieces.last().map(|(_, p)| p.end());
            let Some(entry) = entry_state(field, &m.book, k, i, here) else {
                m.book.abandon(k, i);
                continue;
            };
            if let Some(from) = here {
                let goal = entry.pose();
                let affordable = params.transit_expansions > 0 && self.budget > 0;
                let transit = if affordable {
                    reach.guided_search(from, goal, &free, bounds, &transit_params)
                } else {
                    Ok(None)
                };
                let transit = transit.map_err(|e| Terrain25Error::InvalidParam {
                    field: "transit".into(),
                    what: e.to_string(),
                })?;
                self.budget = self.budget.saturating_sub(
                    transit
                        .as_ref()
                        .map_or(params.transit_expansions, |f| f.expansions),
                );
                let Some(found) = transit else {
                    let s = m.book.stretches(k).get(i).copied().unwrap_or((0.0, 0.0));
                    m.events.push(PlannerEvent::Unreached {
                        row: k,
                        stretch: [s.0, s.1],
                    });
                    m.book.abandon(k, i);
                    continue;
                };
                m.events.push(PlannerEvent::Transit {
                    to_row: k,
                    to: goal.xy(),
                    length_m: found.path.length(),
                });
                m.path.pieces.extend(
                    found
                        .path
                        .pieces
                        .into_iter()
                        .map(|(_, p)| (PieceKind::Transit, p)),
                );
            }
            self.sweeps += 1;
            m.sweep(entry, method);
            if !m.book.stretch_done(k, i) {
                // The sweep could not drive its own entry stretch: do not come back to it.
                m.book.abandon(k, i);
            }
        }
        self.path = m.path;
        self.events = m.events;
        Ok(m.book)
    }
}

/// The open stretch whose nearer end is closest to the vehicle (the first one before it
/// starts).
fn next_stretch(m: &Machine<'_, '_>) -> Option<(usize, usize)> {
    let open = m.book.open_stretches();
    let Some((_, here)) = m.path.pieces.last() else {
        return open.first().map(|&(k, i, _)| (k, i));
    };
    let p = here.end();
    open.into_iter()
        .map(|(k, i, [a, b])| {
            let y = m.book.y(k);
            let d = (a - p.x).hypot(y - p.y).min((b - p.x).hypot(y - p.y));
            (d, k, i)
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, k, i)| (k, i))
}

/// Where a sweep of stretch `i` of row `k` starts: its first admissible point from the end nearer
/// to the vehicle (the west end when it has not started yet), heading into the stretch.
fn entry_state(
    field: &Field<'_>,
    book: &RowBook,
    k: usize,
    i: usize,
    here: Option<Pose2>,
) -> Option<RowState> {
    let &(a, b) = book.stretches(k).get(i)?;
    let y = book.y(k);
    let east = here.is_none_or(|p| (p.x - a).abs() <= (p.x - b).abs());
    // Enter R_min + 1 m inside: the turn into the row must stay clear of whatever ends it.
    let inset = field.params.min_turn_radius_m + 1.0;
    let (dir, from, to) = if east {
        (1.0, a + inset, b)
    } else {
        (-1.0, b - inset, a)
    };
    if dir * (to - from) <= 0.0 {
        return None;
    }
    let step = field.params.rollback_step_m;
    let n = ((to - from).abs() / step).floor() as usize;
    let (x_lo, x_hi) = book.x_range();
    (0..=n)
        .map(|t| from + dir * step * t as f64)
        .find(|&x| field.point_ok(x, y))
        .filter(|&x| dir * (to - x) > 0.0)
        .map(|x| RowState {
            row: k,
            y,
            dir,
            x,
            x_end: if dir > 0.0 { x_hi } else { x_lo },
        })
}
