//! Integration tests of the seed-002 Boustrophedon coverage planner through its public API:
//! row layout and U-turns on a flat map, detours and virtual boundaries around hand-built steep
//! blocks, Hybrid A* transits, a seeded synthetic seabed, and the settings' validation.
//!
//! Every plan is checked independently of the planner: exact clearance from the map, no sample
//! inside a no-go box, `|κ| ≤ 1/R_min`, samples inside the area, and a continuous path.

use std::f64::consts::PI;

use shoal_common::coverage::boustrophedon::{BoundaryReason, PlannerEvent};
use shoal_common::coverage::boxes::Rect;
use shoal_common::coverage::metrics::{coverage, exact_clearance};
use shoal_common::coverage::params::CoverageParams;
use shoal_common::coverage::path::{wrap_angle, PathSample, PieceKind};
use shoal_common::coverage::sweeps::{plan_coverage, CoveragePlan};
use shoal_common::coverage::{Terrain25Error, TerrainMap25, TerrainSpec, TraversalLimits};
use shoal_common::terrain::HeightGrid;

type TestResult = Result<(), Box<dyn std::error::Error>>;

/// A map of `size_m × size_m` from the origin on 2 m cells (nodes at cell centres, one node on
/// each edge), heights from `z(x, y)`.
fn grid_map(size_m: f64, z: impl Fn(f64, f64) -> f64) -> Result<TerrainMap25, Terrain25Error> {
    let h = 2.0;
    let n = (size_m / h).round() as usize + 1;
    let mut heights = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            heights.push(z(i as f64 * h, j as f64 * h));
        }
    }
    let grid = HeightGrid::new([0.0, 0.0], h, n, n, heights)?;
    TerrainMap25::from_grid(&grid, &TraversalLimits::default())
}

/// `height` on the closed rectangle `[x0, x1] × [y0, y1]` of nodes, 0 elsewhere: vertical walls,
/// so the cells on both sides of every wall are impassable (a 20 m rise over 4 m is 79°).
fn block(x0: f64, y0: f64, x1: f64, y1: f64, height: f64) -> impl Fn(f64, f64) -> f64 {
    move |x, y| {
        if (x0..=x1).contains(&x) && (y0..=y1).contains(&y) {
            height
        } else {
            0.0
        }
    }
}

fn count_events(plan: &CoveragePlan, pred: impl Fn(&PlannerEvent) -> bool) -> usize {
    plan.events.iter().filter(|e| pred(e)).count()
}

/// Everything a plan must satisfy whatever the terrain; returns the samples at `step`.
fn check_plan(
    plan: &CoveragePlan,
    map: &TerrainMap25,
    params: &CoverageParams,
    step: f64,
) -> Vec<PathSample> {
    const EPS: f64 = 1e-9;
    let pieces = &plan.path.pieces;
    assert!(!pieces.is_empty(), "empty plan");
    // Every piece's end is the next piece's start, in position and heading.
    for (k, w) in pieces.windows(2).enumerate() {
        let (a, b) = (w[0].1.end(), w[1].1.start());
        let gap = (a.x - b.x).hypot(a.y - b.y);
        let turn = wrap_angle(a.heading - b.heading).abs();
        assert!(
            gap <= 1e-6 && turn <= 1e-6,
            "pieces {k} ({:?}) → {} ({:?}): gap {gap} m, heading jump {turn} rad",
            w[0].0,
            k + 1,
            w[1].0
        );
    }
    let samples = plan.path.sample(step);
    assert!(samples.len() >= 2, "{} samples", samples.len());
    for w in samples.windows(2) {
        let d = (w[1].x - w[0].x).hypot(w[1].y - w[0].y);
        assert!(d <= step + EPS, "samples {d} m apart at s = {}", w[0].s);
    }
    let (a, kappa) = (plan.area, 1.0 / params.min_turn_radius_m);
    let exact_below = params.safety_clearance_m + 2.0;
    for s in &samples {
        assert!(
            s.curvature.abs() <= kappa + EPS,
            "|κ| = {} > 1/R_min at ({}, {}) [{:?}]",
            s.curvature.abs(),
            s.x,
            s.y,
            s.kind
        );
        assert!(
            s.x >= a.x0 - EPS && s.x <= a.x1 + EPS && s.y >= a.y0 - EPS && s.y <= a.y1 + EPS,
            "sample ({}, {}) [{:?}] outside the area {a:?}",
            s.x,
            s.y,
            s.kind
        );
        let c = exact_clearance(map, s.x, s.y, exact_below);
        assert!(
            c >= params.safety_clearance_m - EPS,
            "clearance {c} m < {} m at ({}, {}) [{:?}]",
            params.safety_clearance_m,
            s.x,
            s.y,
            s.kind
        );
        // The box-interior phase drives inside merged boxes, outside each obstacle's own.
        let no_go = if plan.inner_boxes.is_empty() {
            &plan.boxes
        } else {
            &plan.inner_boxes
        };
        if let Some(b) = no_go.iter().find(|b| b.contains_strictly(s.x, s.y)) {
            panic!("sample ({}, {}) [{:?}] inside box {b:?}", s.x, s.y, s.kind);
        }
    }
    samples
}

#[test]
fn flat_square_is_twenty_rows_joined_by_nineteen_u_turns() -> TestResult {
    let map = grid_map(200.0, |_, _| 0.0)?;
    let params = CoverageParams::default();
    let area = Rect::new(0.0, 0.0, 200.0, 200.0);
    let plan = plan_coverage(&map, area, &params)?;
    assert_eq!(plan.rows, 20);
    assert!(plan.boxes.is_empty(), "{:?}", plan.boxes);
    assert!(
        plan.events.is_empty(),
        "events on a flat map: {:?}",
        plan.events
    );
    assert_eq!(plan.sweeps, 1);
    let kinds = |k: PieceKind| plan.path.pieces.iter().filter(|(p, _)| *p == k).count();
    assert_eq!(kinds(PieceKind::UTurn), 19);
    assert_eq!(kinds(PieceKind::Detour), 0);
    assert_eq!(kinds(PieceKind::Transit), 0);

    // Straights: one run per row at y = 5, 15, …, 195, each spanning x ∈ [R_min, 200 − R_min]
    // (the first may start R_min + 1 m in, where the sweep enters its row).
    let r = params.min_turn_radius_m;
    let mut per_row = [0.0f64; 20];
    for (kind, piece) in &plan.path.pieces {
        if *kind != PieceKind::Straight {
            continue;
        }
        let (a, b) = (piece.start(), piece.end());
        assert!((a.y - b.y).abs() < 1e-9, "slanted straight {piece:?}");
        let k = ((a.y - 5.0) / 10.0).round();
        assert!(
            (a.y - (5.0 + 10.0 * k)).abs() < 1e-9 && (0.0..20.0).contains(&k),
            "straight off the rows at y = {}",
            a.y
        );
        for x in [a.x, b.x] {
            assert!(
                (r - 1e-9..=200.0 - r + 1e-9).contains(&x),
                "straight into U-turn space: {x}"
            );
        }
        per_row[k as usize] += piece.length();
    }
    let full = 200.0 - 2.0 * r;
    for (k, len) in per_row.iter().enumerate() {
        assert!(
            *len >= full - (r + 1.0) - 1e-6 && *len <= full + 1e-6,
            "row {k}: {len} m of straight (span {full} m)"
        );
    }
    // U-turns are semicircles of R_min in the U-turn space.
    for (kind, piece) in &plan.path.pieces {
        if *kind == PieceKind::UTurn {
            assert!((piece.length() - PI * r).abs() < 1e-9, "{piece:?}");
        }
    }

    let samples = check_plan(&plan, &map, &params, params.check_step_m);
    let c = coverage(&samples, &map, area, params.row_spacing(), 1.0);
    assert!(c.ratio >= 0.9, "coverage {}", c.ratio);
    Ok(())
}

#[test]
fn a_steep_plateau_is_bypassed_with_the_clearance() -> TestResult {
    // 20 m plateau on x, y ∈ [140, 160] in a 300 × 300 m flat square.
    let map = grid_map(300.0, block(140.0, 140.0, 160.0, 160.0, 20.0))?;
    assert!(
        map.impassable().iter().any(|&b| b),
        "the plateau's rim is not impassable"
    );
    let params = CoverageParams::default();
    let area = Rect::new(0.0, 0.0, 300.0, 300.0);
    let plan = plan_coverage(&map, area, &params)?;
    assert_eq!(plan.boxes.len(), 1, "{:?}", plan.boxes);
    let b = plan.boxes[0];
    // Impassable centres at 138…162 (both sides of the walls), grown by 8 m.
    for (got, want) in [(b.x0, 130.0), (b.y0, 130.0), (b.x1, 170.0), (b.y1, 170.0)] {
        assert!((got - want).abs() < 1e-9, "box {b:?}");
    }
    let detours = count_events(&plan, |e| matches!(e, PlannerEvent::Detour { .. }));
    assert!(detours >= 1, "no detour: {:?}", plan.events);
    let stranded = count_events(&plan, |e| matches!(e, PlannerEvent::Stranded { .. }));
    assert_eq!(stranded, 0, "{:?}", plan.events);
    assert!(plan.path.length_by_kind()[1] > 0.0, "no detour pieces");
    let samples = check_plan(&plan, &map, &params, 0.5);
    for s in &samples {
        let c = exact_clearance(&map, s.x, s.y, 30.0);
        assert!(c >= 8.0 - 1e-9, "clearance {c} at ({}, {})", s.x, s.y);
    }
    let c = coverage(&samples, &map, area, params.row_spacing(), 1.0);
    assert!(c.ratio > 0.8, "coverage {}", c.ratio);
    Ok(())
}

#[test]
fn a_full_height_wall_near_the_east_edge_raises_virtual_boundaries() -> TestResult {
    // A 20 m wall on x ∈ [270, 274] across the whole map: its box spans [260, 284] × [−8, 308],
    // no detour stays in the area and the 11 m east of it hold no row worth driving.
    let map = grid_map(300.0, block(270.0, 0.0, 274.0, 300.0, 20.0))?;
    let params = CoverageParams::default();
    let area = Rect::new(0.0, 0.0, 300.0, 300.0);
    let plan = plan_coverage(&map, area, &params)?;
    let vb = count_events(&plan, |e| matches!(e, PlannerEvent::VirtualBoundary { .. }));
    // Every eastbound row (every other row of 30) ends at a virtual boundary.
    assert!(vb >= 14, "{vb} virtual boundaries: {:?}", plan.events);
    for e in &plan.events {
        match e {
            PlannerEvent::VirtualBoundary { at, reason, .. } => {
                assert!(
                    at[0] <= 255.0 + 1e-6,
                    "boundary at {at:?} past the wall's box"
                );
                assert!(
                    matches!(
                        reason,
                        BoundaryReason::DetourLeavesArea | BoundaryReason::DetourBlocked
                    ),
                    "{reason:?}"
                );
            }
            PlannerEvent::Detour { .. } | PlannerEvent::Stranded { .. } => {
                panic!("unexpected {e:?}")
            }
            _ => {}
        }
    }
    let samples = check_plan(&plan, &map, &params, 0.5);
    assert!(
        samples.iter().all(|s| s.x <= 260.0 + 1e-9),
        "a sample east of the wall's box"
    );
    Ok(())
}

/// A 20 m block from the area's south edge: x ∈ [140, 160], y ∈ [0, 80]; box
/// [130, 170] × [−8, 88]. Southern rows cannot detour south (out of the area) nor north (more than
/// 60 m), so they end at virtual boundaries, and their east halves need a transit.
fn south_block_map() -> Result<TerrainMap25, Terrain25Error> {
    grid_map(300.0, block(140.0, 0.0, 160.0, 80.0, 20.0))
}

#[test]
fn a_box_on_the_south_edge_raises_a_virtual_boundary() -> TestResult {
    let map = south_block_map()?;
    let params = CoverageParams::default();
    let area = Rect::new(0.0, 0.0, 300.0, 300.0);
    let plan = plan_coverage(&map, area, &params)?;
    let leaves = count_events(&plan, |e| {
        matches!(
            e,
            PlannerEvent::VirtualBoundary {
                reason: BoundaryReason::DetourLeavesArea,
                ..
            }
        )
    });
    assert!(
        leaves >= 1,
        "no DetourLeavesArea boundary: {:?}",
        plan.events
    );
    // Row 0 (y = 5) meets the box eastbound: its boundary stands R_min before the box.
    let row0 = plan.events.iter().find_map(|e| match e {
        PlannerEvent::VirtualBoundary { row: 0, at, .. } => Some(*at),
        _ => None,
    });
    match row0 {
        Some(at) => assert!(
            (at[0] - 125.0).abs() < 1e-3 && (at[1] - 5.0).abs() < 1e-9,
            "{at:?}"
        ),
        None => panic!("no virtual boundary on row 0: {:?}", plan.events),
    }
    check_plan(&plan, &map, &params, 0.5);
    Ok(())
}

#[test]
fn transits_keep_the_clearance_and_the_curvature_bound() -> TestResult {
    let map = south_block_map()?;
    let params = CoverageParams::default();
    let area = Rect::new(0.0, 0.0, 300.0, 300.0);
    let plan = plan_coverage(&map, area, &params)?;
    let transits: Vec<([f64; 2], f64)> = plan
        .events
        .iter()
        .filter_map(|e| match e {
            PlannerEvent::Transit { to, length_m, .. } => Some((*to, *length_m)),
            _ => None,
        })
        .collect();
    assert!(!transits.is_empty(), "no transit: {:?}", plan.events);
    assert_eq!(plan.sweeps, transits.len() + 1);
    let pieces: Vec<_> = plan
        .path
        .pieces
        .iter()
        .filter(|(k, _)| *k == PieceKind::Transit)
        .map(|(_, p)| *p)
        .collect();
    let total: f64 = transits.iter().map(|t| t.1).sum();
    let driven = plan.path.length_by_kind()[3];
    assert!(
        (total - driven).abs() < 1e-6,
        "events say {total} m, pieces {driven} m"
    );
    for (to, _) in &transits {
        let ends = pieces.iter().any(|p| {
            let e = p.end();
            (e.x - to[0]).hypot(e.y - to[1]) < 1e-6
        });
        assert!(ends, "no transit piece ends at {to:?}");
    }
    let samples = check_plan(&plan, &map, &params, 0.5);
    let kappa = 1.0 / params.min_turn_radius_m;
    let mut seen = 0;
    for s in samples.iter().filter(|s| s.kind == PieceKind::Transit) {
        seen += 1;
        let c = exact_clearance(&map, s.x, s.y, 30.0);
        assert!(
            c >= 8.0 - 1e-9,
            "transit clearance {c} at ({}, {})",
            s.x,
            s.y
        );
        assert!(
            s.curvature.abs() <= kappa + 1e-9,
            "transit κ {}",
            s.curvature
        );
    }
    assert!(seen > 0, "no transit samples");
    // The transits let the planner reach the east halves of the southern rows.
    let east_south = samples
        .iter()
        .filter(|s| s.kind == PieceKind::Straight && s.x > 180.0 && s.y < 80.0)
        .count();
    assert!(
        east_south > 0,
        "the east of the southern rows was never driven"
    );
    Ok(())
}

fn seeded_map(seed: u64) -> Result<TerrainMap25, Terrain25Error> {
    let mut spec = TerrainSpec::default();
    spec.random_peaks.count = 8;
    spec.random_pits.count = 4;
    TerrainMap25::generate(&spec, &TraversalLimits::default(), seed)
}

#[test]
fn seeded_seabed_is_covered_safely_and_deterministically() -> TestResult {
    let params = CoverageParams::default();
    let area = Rect::new(0.0, 0.0, 1000.0, 1000.0);
    let (map, again) = (seeded_map(3)?, seeded_map(3)?);
    assert!(map == again, "the same seed gave two maps");
    assert!(
        map.impassable().iter().any(|&b| b),
        "seed 3 has no impassable cell"
    );
    let plan = plan_coverage(&map, area, &params)?;
    let replay = plan_coverage(&again, area, &params)?;
    assert!(
        plan == replay,
        "same seed, different plans: {} vs {} pieces, {} vs {} events",
        plan.path.pieces.len(),
        replay.path.pieces.len(),
        plan.events.len(),
        replay.events.len()
    );
    assert_eq!(plan.rows, 100);
    let samples = check_plan(&plan, &map, &params, 0.5);
    let c = coverage(&samples, &map, area, params.row_spacing(), 1.0);
    assert!(c.ratio > 0.5, "coverage {}", c.ratio);
    // Transits on this map keep the bounds too (checked with every sample above).
    let transits = count_events(&plan, |e| matches!(e, PlannerEvent::Transit { .. }));
    let transit_len = plan.path.length_by_kind()[3];
    assert_eq!(
        transits > 0,
        transit_len > 0.0,
        "{transits} transits, {transit_len} m"
    );
    Ok(())
}

/// The `InvalidParam` of `r`, or a panic naming what came instead.
fn invalid_param(r: Result<impl std::fmt::Debug, Terrain25Error>) -> (String, String) {
    match r {
        Err(Terrain25Error::InvalidParam { field, what }) => (field, what),
        other => panic!("expected an InvalidParam error, got {other:?}"),
    }
}

#[test]
fn invalid_settings_and_areas_name_the_field_and_value() -> TestResult {
    let negative = CoverageParams {
        min_turn_radius_m: -5.0,
        ..CoverageParams::default()
    };
    let (field, what) = invalid_param(negative.validate());
    assert_eq!(field, "min_turn_radius_m");
    assert!(what.contains("-5"), "{what}");

    let coarse = CoverageParams {
        check_step_m: 6.0,
        ..CoverageParams::default()
    };
    let (field, what) = invalid_param(coarse.validate());
    assert_eq!(field, "check_step_m");
    assert!(what.contains('6') && what.contains('5'), "{what}");

    let nan = CoverageParams {
        safety_clearance_m: f64::NAN,
        ..CoverageParams::default()
    };
    let (field, what) = invalid_param(nan.validate());
    assert_eq!(field, "safety_clearance_m");
    assert!(what.contains("NaN"), "{what}");
    CoverageParams::default().validate()?;

    let map = grid_map(100.0, |_, _| 0.0)?;
    // plan_coverage validates the settings before anything else.
    let (field, _) = invalid_param(plan_coverage(
        &map,
        Rect::new(0.0, 0.0, 100.0, 100.0),
        &negative,
    ));
    assert_eq!(field, "min_turn_radius_m");
    // Too narrow for a row with its U-turn space (4·R_min = 20 m), too short for one row (10 m).
    for area in [
        Rect::new(0.0, 0.0, 15.0, 100.0),
        Rect::new(0.0, 0.0, 100.0, 8.0),
    ] {
        let err = plan_coverage(&map, area, &CoverageParams::default());
        let message = match &err {
            Err(e) => e.to_string(),
            Ok(_) => String::new(),
        };
        let (field, _) = invalid_param(err);
        assert_eq!(field, "area");
        assert!(message.contains("area"), "{message}");
    }
    // The smallest area that holds one row plans it.
    let one = plan_coverage(
        &map,
        Rect::new(0.0, 0.0, 20.0, 10.0),
        &CoverageParams::default(),
    )?;
    assert_eq!(one.rows, 1);
    Ok(())
}

/// Two steep plateaus 30 m apart (north–south) whose inflated boxes are merged into one: the
/// first phase treats the merged box as no-go, the box-interior phase then sweeps the row that
/// runs between them (y = 135 m, 15 m from either cliff), still outside the plateaus' band boxes
/// and at the safety clearance.
#[test]
fn the_gap_inside_a_merged_box_is_swept_by_the_interior_phase() -> TestResult {
    let a = block(100.0, 100.0, 200.0, 120.0, 40.0);
    let b = block(100.0, 150.0, 200.0, 170.0, 40.0);
    let map = grid_map(300.0, |x, y| a(x, y) + b(x, y))?;
    let params = CoverageParams {
        merge_gap_m: Some(20.0),
        ..CoverageParams::default()
    };
    let plan = plan_coverage(&map, Rect::new(0.0, 0.0, 300.0, 300.0), &params)?;
    // One merged box over the gap in the first phase; none in the second.
    let spans_gap = |r: &Rect| r.y0 < 130.0 && r.y1 > 140.0 && r.x0 < 150.0 && r.x1 > 150.0;
    assert!(plan.boxes.iter().any(spans_gap), "{:?}", plan.boxes);
    assert!(!plan.inner_boxes.is_empty());
    assert!(
        !plan.inner_boxes.iter().any(spans_gap),
        "{:?}",
        plan.inner_boxes
    );
    let samples = check_plan(&plan, &map, &params, 0.5);
    let in_gap = samples
        .iter()
        .filter(|s| (s.y - 135.0).abs() < 1e-6 && s.x > 110.0 && s.x < 190.0)
        .count();
    assert!(
        in_gap > 100,
        "{in_gap} samples on the gap's row between the plateaus"
    );
    Ok(())
}

/// Two plateaus on the west edge leave a corridor 30 m high between them (y 120–150 m) in which
/// no U-turn keeps the 8 m clearance. A sweep driving west along the corridor's row (y = 135 m)
/// whose next row is already covered must not end at the corridor's boxed-in west end, where a
/// forward-only crawler cannot turn and every later transit would fail: it stops where the turn
/// it found fits, east of the plateaus, and gives the rest of the row up.
#[test]
fn no_sweep_ends_in_a_boxed_in_row_end() -> TestResult {
    use shoal_common::coverage::boustrophedon::{ArcDetour, Field, Machine, RowState, SweepEnd};
    use shoal_common::coverage::boxes::no_go_boxes;
    use shoal_common::coverage::path::CoveragePath;
    use shoal_common::coverage::rows::RowBook;
    let a = block(0.0, 100.0, 60.0, 120.0, 40.0);
    let b = block(0.0, 150.0, 60.0, 170.0, 40.0);
    let map = grid_map(300.0, |x, y| a(x, y) + b(x, y))?;
    let params = CoverageParams::default();
    let field = Field::new(
        &map,
        Rect::new(0.0, 0.0, 300.0, 300.0),
        no_go_boxes(&map, params.safety_clearance_m, params.merge_gap()),
        &params,
        true,
    );
    let ys: Vec<f64> = (0..30).map(|k| 5.0 + 10.0 * k as f64).collect();
    let mut book = RowBook::new(ys, (5.0, 295.0), &field.boxes, 5.0);
    book.drive(14, 5.0, 295.0); // the row north of the corridor is covered
    let mut m = Machine {
        field: &field,
        path: CoveragePath::default(),
        events: Vec::new(),
        book,
    };
    let start = RowState {
        row: 13,
        y: 135.0,
        dir: -1.0,
        x: 250.0,
        x_end: 5.0,
    };
    assert_eq!(m.sweep(start, &ArcDetour), SweepEnd::Covered);
    let Some((_, last)) = m.path.pieces.last() else {
        panic!("no path");
    };
    let end = last.end();
    // The plateaus' cliffs end at x = 60 m; a turn needs 8 m of clearance beyond them.
    assert!(end.x > 60.0, "the sweep ended at ({}, {})", end.x, end.y);
    assert!((end.y - 135.0).abs() < 1e-9);
    assert!(m.book.is_done(13, 20.0), "the corridor's rest is given up");
    Ok(())
}
