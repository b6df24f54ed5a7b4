//! What coverage crawlers (CPP-DSMV under `run`) did on their seabed map: how close each
//! executed track came to impassable ground (cells steeper than the critical slope, dilated by
//! half the vehicle width: the planner kept `safety_clearance_m` from them), how many metres of
//! it lay on such ground, and how much of the area the executed swaths covered. The plan's
//! figures say what the paths would do; these say what the driven tracks did.

use std::path::Path;

use shoal_common::coverage::fleet::FleetCoverage;
use shoal_common::coverage::metrics::{coverage, CoverageCount};
use shoal_common::coverage::path::{PathSample, PieceKind};
use shoal_common::coverage::TerrainMap25;
use shoal_common::scenario::Scenario;
use shoal_common::trajectory::Trajectory;

/// Spacing of the samples taken along an executed track, metres (the map's cells are 2 m in the
/// shipped scenarios).
pub const GROUND_STEP_M: f64 = 1.0;

/// One crawler's track on the map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackOnGround {
    /// Smallest distance from a sample to an impassable cell centre, metres (0 on one).
    pub min_clearance_m: f64,
    /// Length of track whose samples lie on impassable cells, metres.
    pub impassable_m: f64,
}

/// The fleet's tracks on the map.
#[derive(Debug, Clone, PartialEq)]
pub struct Ground {
    /// Per track, scenario order; `None` for a track without fixes.
    pub tracks: Vec<Option<TrackOnGround>>,
    /// The area the executed swaths covered.
    pub coverage: CoverageCount,
}

/// The figures of `tracks` on `scenario`'s coverage map; `None` for a scenario without a
/// `[coverage]` table, or whose map cannot be built here (a heightmap file that is gone: the
/// figures are then left out, not guessed).
pub fn ground(scenario: &Scenario, tracks: &[Trajectory]) -> Option<Ground> {
    let job = FleetCoverage::new(scenario).ok()?;
    let map = match job.map(Path::new(".")) {
        Ok(m) => m,
        Err(e) => {
            tracing::warn!("no ground figures: the [coverage] map: {e}");
            return None;
        }
    };
    Some(on_map(
        &map,
        tracks,
        job.area,
        job.settings.planner.row_spacing(),
    ))
}

/// [`ground`] on a given map, area and swath width.
fn on_map(
    map: &TerrainMap25,
    tracks: &[Trajectory],
    area: shoal_common::coverage::boxes::Rect,
    swath_m: f64,
) -> Ground {
    let mut all = Vec::new();
    let figures = tracks
        .iter()
        .map(|t| {
            let samples = sample(t, GROUND_STEP_M);
            let mut min_clearance_m = f64::INFINITY;
            let mut impassable_m = 0.0;
            for (k, s) in samples.iter().enumerate() {
                min_clearance_m = min_clearance_m.min(map.clearance_to_impassable(s.x, s.y));
                if k > 0 && map.is_impassable(s.x, s.y) {
                    impassable_m += s.s - samples[k - 1].s;
                }
            }
            let out = (!samples.is_empty()).then_some(TrackOnGround {
                min_clearance_m,
                impassable_m,
            });
            all.extend(samples);
            out
        })
        .collect();
    Ground {
        tracks: figures,
        coverage: coverage(&all, map, area, swath_m, 1.0),
    }
}

/// Points along `track`'s polyline every `step` metres (its fixes and corners included), as
/// path samples (arc length, position; heading and curvature are not used here).
fn sample(track: &Trajectory, step: f64) -> Vec<PathSample> {
    let at = |s: f64, x: f64, y: f64| PathSample {
        s,
        x,
        y,
        heading: 0.0,
        curvature: 0.0,
        kind: PieceKind::Straight,
    };
    let mut out = Vec::new();
    let mut s0 = 0.0;
    if let Some(p) = track.points.first() {
        out.push(at(0.0, p.x, p.y));
    }
    for w in track.points.windows(2) {
        let (a, b) = (w[0], w[1]);
        let len = (b.x - a.x).hypot(b.y - a.y);
        let n = (len / step).ceil().max(1.0) as usize;
        for k in 1..=n {
            let u = k as f64 / n as f64;
            out.push(at(
                s0 + u * len,
                a.x + u * (b.x - a.x),
                a.y + u * (b.y - a.y),
            ));
        }
        s0 += len;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use shoal_common::coverage::boxes::Rect;
    use shoal_common::geometry::Vec3;
    use shoal_common::terrain::HeightGrid;

    /// 100 × 100 cells of 2 m (nodes at x = 2i), flat but for a 100 m block on columns 40–44. The
    /// slope is a central difference, so the two columns at each of its edges (39–40 and 44–45,
    /// nodes at x 78–80 and 88–90 m) are steeper than any limit; its flat top is passable.
    fn cliff_map() -> TerrainMap25 {
        let n = 100;
        let z: Vec<f64> = (0..n * n)
            .map(|k| {
                if (40..45).contains(&(k % n)) {
                    100.0
                } else {
                    0.0
                }
            })
            .collect();
        let grid = match HeightGrid::new([0.0, 0.0], 2.0, n, n, z) {
            Ok(g) => g,
            Err(e) => panic!("{e}"),
        };
        match TerrainMap25::from_grid(&grid, &Default::default()) {
            Ok(m) => m,
            Err(e) => panic!("{e}"),
        }
    }

    fn line(from: [f64; 2], to: [f64; 2]) -> Trajectory {
        Trajectory {
            times: vec![0.0, 100.0],
            points: vec![
                Vec3::new(from[0], from[1], 0.0),
                Vec3::new(to[0], to[1], 0.0),
            ],
        }
    }

    #[test]
    fn a_track_clear_of_the_cliff_keeps_its_distance_and_one_across_it_is_counted() {
        let map = cliff_map();
        let area = Rect::new(0.0, 0.0, 200.0, 200.0);
        let west = line([10.0, 50.0], [10.0, 150.0]);
        let across = line([10.0, 20.0], [190.0, 20.0]);
        let g = on_map(&map, &[west, across], area, 10.0);
        let w = g.tracks[0].unwrap_or(TrackOnGround {
            min_clearance_m: f64::NAN,
            impassable_m: f64::NAN,
        });
        // The nearest impassable cell is column 39, centred on its grid node at x = 78 m.
        assert!((w.min_clearance_m - 68.0).abs() < 1e-9, "{w:?}");
        assert_eq!(w.impassable_m, 0.0);
        let a = g.tracks[1].unwrap_or(w);
        assert_eq!(a.min_clearance_m, 0.0);
        // 4 m over each edge.
        assert!((a.impassable_m - 8.0).abs() < 1e-9, "{a:?}");
        // Two swaths of 10 m: 100 m + 180 m long, one 5 m overlap at most.
        let c = &g.coverage;
        assert!(
            c.covered_m2 > 10.0 * 270.0 && c.covered_m2 < 10.0 * 290.0 + 100.0,
            "{c:?}"
        );
        assert!((c.area_m2 - 40_000.0).abs() < 1e-6);
    }

    #[test]
    fn a_track_without_fixes_has_no_figure() {
        let map = cliff_map();
        let empty = Trajectory {
            times: vec![],
            points: vec![],
        };
        let g = on_map(&map, &[empty], Rect::new(0.0, 0.0, 200.0, 200.0), 10.0);
        assert_eq!(g.tracks, vec![None]);
        assert_eq!(g.coverage.covered_m2, 0.0);
    }

    #[test]
    fn samples_are_a_step_apart_and_keep_the_corners() {
        let t = Trajectory {
            times: vec![0.0, 1.0, 2.0],
            points: vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(3.0, 0.0, 0.0),
                Vec3::new(3.0, 2.5, 0.0),
            ],
        };
        let s = sample(&t, 1.0);
        let xy: Vec<[f64; 3]> = s.iter().map(|p| [p.s, p.x, p.y]).collect();
        assert_eq!(xy.len(), 1 + 3 + 3);
        assert_eq!(xy[3], [3.0, 3.0, 0.0]);
        assert_eq!(xy[6], [5.5, 3.0, 2.5]);
    }
}
