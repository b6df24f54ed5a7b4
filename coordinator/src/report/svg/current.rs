//! The current field in `plan.svg` (Zhang et al. 2022, eq. (2)): arrows on a grid over the top and side
//! views, pointing where the water flows and as long as it is fast. The top view samples the
//! field at the mean depth of the vehicles' starts and goals, the side view on the box's middle
//! y (the analytic model varies with depth only; a gridded field anywhere).

use plotters::prelude::*;
use shoal_common::geometry::Vec3;
use shoal_common::scenario::Scenario;

use crate::report::svg::chart::{fail, Chart};

/// Arrows per axis.
const GRID: usize = 9;
/// Arrow colour: sea blue, light enough to stay behind the paths.
const ARROW: RGBColor = RGBColor(70, 130, 180);

/// The title suffix for a view of `scenario`, or `None` without a current.
pub fn caption(scenario: &Scenario, top: bool) -> Option<String> {
    let c = scenario.currents.as_ref()?;
    let b = &scenario.bounds;
    let field = c.field(b.min[2], b.max[2]);
    let surface = field
        .velocity(&Vec3::new(b.min[0], b.min[1], b.max[2]))
        .norm();
    Some(if top {
        format!(", current at z = {:.0} m", sample_z(scenario))
    } else {
        format!(", current ({surface:.2} m/s at the surface)")
    })
}

/// Mean z of the vehicles' starts and goals: where the top view samples the field.
fn sample_z(scenario: &Scenario) -> f64 {
    let n = 2 * scenario.vehicles.len();
    if n == 0 {
        return 0.5 * (scenario.bounds.min[2] + scenario.bounds.max[2]);
    }
    scenario
        .vehicles
        .iter()
        .map(|v| v.start[2] + v.goal[2])
        .sum::<f64>()
        / n as f64
}

/// Draws the current arrows of view axes `(a, b)` (0, 1: top; 0, 2: side) over `chart`, which
/// spans `(x0, x1, y0, y1)`. Nothing without a current.
pub fn draw_current(
    chart: &mut Chart,
    scenario: &Scenario,
    (a, b): (usize, usize),
    (x0, x1, y0, y1): (f64, f64, f64, f64),
) -> anyhow::Result<()> {
    let Some(c) = &scenario.currents else {
        return Ok(());
    };
    let bounds = &scenario.bounds;
    let field = c.field(bounds.min[2], bounds.max[2]);
    let fixed = if b == 1 {
        sample_z(scenario)
    } else {
        0.5 * (bounds.min[1] + bounds.max[1])
    };
    let cell = ((x1 - x0) / GRID as f64, (y1 - y0) / GRID as f64);
    let mut samples = Vec::with_capacity(GRID * GRID);
    for i in 0..GRID {
        for j in 0..GRID {
            let (u, v) = (
                x0 + cell.0 * (i as f64 + 0.5),
                y0 + cell.1 * (j as f64 + 0.5),
            );
            let mut p = Vec3::new(u, fixed, fixed);
            p[a] = u;
            p[b] = v;
            let w = field.velocity(&p);
            samples.push(((u, v), (w[a], w[b])));
        }
    }
    let fastest = samples
        .iter()
        .map(|(_, (du, dv))| du.hypot(*dv))
        .fold(0.0, f64::max);
    if fastest <= 0.0 {
        return Ok(());
    }
    // The fastest arrow spans 80 % of a cell in each axis's own units.
    let scale = (0.8 * cell.0 / fastest, 0.8 * cell.1 / fastest);
    let mut lines = Vec::new();
    for ((u, v), (du, dv)) in samples {
        let (ex, ey) = (du * scale.0, dv * scale.1);
        if ex.abs() < 1e-3 * cell.0 && ey.abs() < 1e-3 * cell.1 {
            continue;
        }
        let (sx, sy) = (u - 0.5 * ex, v - 0.5 * ey);
        let tip = (sx + ex, sy + ey);
        lines.push(vec![(sx, sy), tip]);
        // Head: two short strokes at ±150° from the arrow, a quarter of its length.
        let ang = ey.atan2(ex);
        let len = 0.25 * ex.hypot(ey);
        for side in [-1.0, 1.0] {
            let t = ang + side * 150f64.to_radians();
            lines.push(vec![tip, (tip.0 + len * t.cos(), tip.1 + len * t.sin())]);
        }
    }
    chart
        .draw_series(
            lines
                .into_iter()
                .map(|l| PathElement::new(l, ARROW.mix(0.7).stroke_width(1))),
        )
        .map_err(fail("current arrow"))?;
    Ok(())
}
