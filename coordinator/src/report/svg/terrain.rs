//! The seabed under the top view of `plan.svg` (crawler scenarios, Lu et al. 2023): a shaded map of
//! the terrain's elevation (light = low, dark = high), contour ticks on cell edges where the
//! elevation crosses a multiple of the contour interval (1 m on a gentle seabed, see
//! [`contour_step`]), and the hazard cylinders (eq. (4)) as hatched
//! discs with their ids.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use shoal_common::plan::Plan;
use shoal_common::scenario::{Scenario, VehicleKind};
use shoal_common::terrain::Terrain;

use crate::report::svg::chart::{fail, Chart};

/// Cells per axis of the shaded map.
const CELLS: usize = 60;
/// Hazard colour: blue, like the paper's Fig. 8 cylinders.
const HAZARD: RGBColor = RGBColor(40, 90, 200);

/// Shade of elevation fraction `f` in [0, 1]: sand to dark brown.
fn shade(f: f64) -> RGBColor {
    let f = f.clamp(0.0, 1.0);
    let mix = |lo: f64, hi: f64| (lo + (hi - lo) * f).round() as u8;
    RGBColor(mix(245.0, 110.0), mix(238.0, 80.0), mix(220.0, 50.0))
}

/// The lowest and highest elevation on a `CELLS × CELLS` sampling of the box.
fn elevations(t: &Terrain, (x0, x1, y0, y1): (f64, f64, f64, f64)) -> Vec<Vec<f64>> {
    (0..=CELLS)
        .map(|j| {
            let y = y0 + (y1 - y0) * j as f64 / CELLS as f64;
            (0..=CELLS)
                .map(|i| t.elevation(x0 + (x1 - x0) * i as f64 / CELLS as f64, y))
                .collect()
        })
        .collect()
}

/// Draws the seabed and hazards of `scenario` into the top view `chart` spanning the box;
/// returns the elevation range drawn, or `None` when the scenario has no seabed.
pub fn draw_seabed(
    chart: &mut Chart,
    scenario: &Scenario,
    (x0, x1, y0, y1): (f64, f64, f64, f64),
) -> anyhow::Result<Option<(f64, f64)>> {
    let Some(terrain) = scenario.terrain() else {
        return Ok(None);
    };
    let z = elevations(terrain, (x0, x1, y0, y1));
    let (lo, hi) = z
        .iter()
        .flatten()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(*v), b.max(*v))
        });
    let span = (hi - lo).max(1e-9);
    let step = contour_step(span);
    let level = |v: f64| (v / step).floor();
    let (dx, dy) = ((x1 - x0) / CELLS as f64, (y1 - y0) / CELLS as f64);
    let mut cells = Vec::with_capacity(CELLS * CELLS);
    let mut contours = Vec::new();
    for j in 0..CELLS {
        for i in 0..CELLS {
            let mean = 0.25 * (z[j][i] + z[j][i + 1] + z[j + 1][i] + z[j + 1][i + 1]);
            let (cx, cy) = (x0 + i as f64 * dx, y0 + j as f64 * dy);
            cells.push(Rectangle::new(
                [(cx, cy), (cx + dx, cy + dy)],
                shade((mean - lo) / span).filled(),
            ));
            // A contour crosses the cell's bottom or left edge where the floor of the
            // elevation changes between its ends: mark that edge.
            if level(z[j][i]) != level(z[j][i + 1]) {
                contours.push(PathElement::new(
                    vec![
                        (cx + 0.5 * dx, cy - 0.2 * dy),
                        (cx + 0.5 * dx, cy + 0.2 * dy),
                    ],
                    RGBColor(90, 60, 30).stroke_width(1),
                ));
            }
            if level(z[j][i]) != level(z[j + 1][i]) {
                contours.push(PathElement::new(
                    vec![
                        (cx - 0.2 * dx, cy + 0.5 * dy),
                        (cx + 0.2 * dx, cy + 0.5 * dy),
                    ],
                    RGBColor(90, 60, 30).stroke_width(1),
                ));
            }
        }
    }
    chart.draw_series(cells).map_err(fail("seabed"))?;
    chart.draw_series(contours).map_err(fail("contour"))?;
    let label = ("sans-serif", 14)
        .into_font()
        .color(&WHITE)
        .pos(Pos::new(HPos::Center, VPos::Center));
    for h in &scenario.hazards {
        let ring: Vec<(f64, f64)> = (0..=72)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / 72.0;
                (
                    h.centre[0] + h.radius_m * a.cos(),
                    h.centre[1] + h.radius_m * a.sin(),
                )
            })
            .collect();
        chart
            .draw_series([Polygon::new(ring.clone(), HAZARD.mix(0.55).filled())])
            .map_err(fail("hazard"))?;
        chart
            .draw_series([PathElement::new(ring, HAZARD.stroke_width(2))])
            .map_err(fail("hazard edge"))?;
        chart
            .draw_series([Text::new(
                h.id.clone(),
                (h.centre[0], h.centre[1]),
                label.clone(),
            )])
            .map_err(fail("hazard label"))?;
    }
    Ok(Some((lo, hi)))
}

/// What the seabed adds to a view's title: the top view's shading, the side view's dots.
pub fn caption(scenario: &Scenario, top: bool) -> Option<&'static str> {
    if top {
        scenario.terrain().map(|_| " on the seabed (dark = high)")
    } else {
        has_swimmer_over_seabed(scenario).then_some(", dots: seabed")
    }
}

/// Whether `scenario` has a seabed and an AUV over it (whose side view gets the seabed under
/// its path).
pub fn has_swimmer_over_seabed(scenario: &Scenario) -> bool {
    scenario.swimmer_seabed().is_some()
        && scenario
            .vehicles
            .iter()
            .any(|v| v.kind != VehicleKind::Crawler)
}

/// Side view: under each AUV's path, the seabed elevation at every metre of it, plotted against
/// the path's horizontal axis `a`, dotted in the vehicle's colour; how high the AUV keeps above
/// the seabed is the gap between its line and its dots. (A crawler's path is the seabed.)
pub fn draw_seabed_under_paths(
    chart: &mut Chart,
    scenario: &Scenario,
    plan: &Plan,
    a: usize,
    colour: &dyn Fn(usize) -> RGBColor,
) -> anyhow::Result<()> {
    let Some((terrain, _)) = scenario.swimmer_seabed() else {
        return Ok(());
    };
    for (i, v) in plan.vehicles.iter().enumerate() {
        // The plan gives exactly the AUVs over the seabed a height above it.
        if v.min_seabed_clearance_m.is_none() {
            continue;
        }
        let mut dots = Vec::new();
        for w in v.trajectory.windows(2) {
            let (p, q) = ([w[0][1], w[0][2]], [w[1][1], w[1][2]]);
            let n = ((q[0] - p[0]).hypot(q[1] - p[1]).ceil() as usize).max(1);
            for k in 0..n {
                let u = k as f64 / n as f64;
                let (x, y) = (p[0] + u * (q[0] - p[0]), p[1] + u * (q[1] - p[1]));
                dots.push(([x, y][a.min(1)], terrain.elevation(x, y)));
            }
        }
        let c = colour(i);
        chart
            .draw_series(
                dots.into_iter()
                    .map(|p| Circle::new(p, 1, c.mix(0.7).filled())),
            )
            .map_err(fail("seabed under a path"))?;
    }
    Ok(())
}

/// Contour interval for an elevation span: 1 m, or the smallest 1-2-5 step that keeps about a
/// dozen contours (a 55 m hill at 1 m would hatch the whole map).
pub fn contour_step(span: f64) -> f64 {
    let target = span / 12.0;
    let mut step = 1.0;
    for k in 0..12 {
        for m in [1.0, 2.0, 5.0] {
            step = m * 10f64.powi(k);
            if step >= target {
                return step;
            }
        }
    }
    step
}

#[cfg(test)]
mod tests;
