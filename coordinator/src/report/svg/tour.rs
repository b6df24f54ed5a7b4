//! Inspection points in `plan.svg` (Hu et al. 2023 tours): a cross in the vehicle's colour on a white
//! cross at every point a vehicle's tour visits, so which AUV inspects which side of which cage
//! can be read off the views.

use plotters::prelude::*;
use shoal_common::plan::Plan;

use crate::report::svg::chart::{fail, Chart};

/// Draws every tour's inspection points in view axes `(a, b)`; `colour` gives vehicle `i`'s
/// colour.
pub fn draw_inspection_points(
    chart: &mut Chart,
    plan: &Plan,
    (a, b): (usize, usize),
    colour: &dyn Fn(usize) -> RGBColor,
) -> anyhow::Result<()> {
    for (i, v) in plan.vehicles.iter().enumerate() {
        let Some(t) = &v.tour else {
            continue;
        };
        let c = colour(i);
        let marks = t.points.iter().flat_map(|p| {
            let at = (p[a], p[b]);
            [
                Cross::new(at, 7, WHITE.stroke_width(5)),
                Cross::new(at, 6, c.stroke_width(2)),
            ]
        });
        chart.draw_series(marks).map_err(fail("inspection point"))?;
    }
    Ok(())
}
