//! `plan.svg` of a coverage mission (seed 002 Figures 5–7): the shaded 2.5D map with its
//! impassable cells, the merged no-go boxes (red), the planned path (blue) and the tracked path
//! (orange) on the left; the three distributions of Figure 7 — clearance to impassable terrain,
//! slope under the path, |cross-track error| — on the right.

use plotters::prelude::*;
use shoal_common::coverage::metrics::Distribution;
use shoal_common::coverage::mission::CoverageReport;
use shoal_common::coverage::TerrainMap25;

use crate::svg::fail;

/// Canvas size.
const SIZE: (u32, u32) = (1500, 960);
/// Map raster drawn per axis.
const CELLS: usize = 120;
const NO_GO: RGBColor = RGBColor(210, 30, 30);
const PLANNED: RGBColor = RGBColor(30, 70, 200);
const TRACKED: RGBColor = RGBColor(240, 140, 0);

/// Renders the report over its map.
pub fn render_coverage(report: &CoverageReport, map: &TerrainMap25) -> anyhow::Result<String> {
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(fail("background"))?;
        let (left, right) = root.split_horizontally(960);
        draw_map(&left, report, map)?;
        let panels = right.split_evenly((3, 1));
        let cte = report.tracking.as_ref().map(|t| &t.cross_track);
        let clearance_title = format!(
            "(a) clearance to impassable cells, m — {} samples < {} m",
            report.samples_below_clearance, report.safety_clearance_m
        );
        let hists: [(&str, Option<&Distribution>); 3] = [
            (&clearance_title, Some(&report.clearance)),
            ("(b) slope under the path, degrees", Some(&report.slope)),
            ("(c) |cross-track error| of the tracked path, m", cte),
        ];
        for (area, (title, dist)) in panels.iter().zip(hists) {
            draw_histogram(area, title, dist)?;
        }
        root.present().map_err(fail("document"))?;
    }
    Ok(buf)
}

fn draw_map<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    report: &CoverageReport,
    map: &TerrainMap25,
) -> anyhow::Result<()> {
    let a = report.area;
    let title = format!(
        "{} — coverage {:.2} %, planning {:.3} s, {} detours, {} virtual boundaries",
        match report.method {
            shoal_common::coverage::params::DetourMethod::Arcs => "Boustrophedon + arcs",
            shoal_common::coverage::params::DetourMethod::HybridAStar => "Hybrid A* baseline",
        },
        100.0 * report.coverage.ratio,
        report.planning_time_s,
        report.event_counts[0],
        report.event_counts[1]
    );
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(45)
        .build_cartesian_2d(a.x0..a.x1, a.y0..a.y1)
        .map_err(fail("map axes"))?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("east, m")
        .y_desc("north, m")
        .draw()
        .map_err(fail("map mesh"))?;
    let (dx, dy) = ((a.x1 - a.x0) / CELLS as f64, (a.y1 - a.y0) / CELLS as f64);
    let mut zs = Vec::with_capacity(CELLS * CELLS);
    for j in 0..CELLS {
        for i in 0..CELLS {
            let (x, y) = (a.x0 + (i as f64 + 0.5) * dx, a.y0 + (j as f64 + 0.5) * dy);
            zs.push((x, y, map.elevation_at(x, y), map.is_impassable(x, y)));
        }
    }
    let lo = zs.iter().map(|z| z.2).fold(f64::INFINITY, f64::min);
    let hi = zs.iter().map(|z| z.2).fold(f64::NEG_INFINITY, f64::max);
    let span = (hi - lo).max(1e-9);
    chart
        .draw_series(zs.iter().map(|&(x, y, z, blocked)| {
            let f = (z - lo) / span;
            let mix = |p: f64, q: f64| (p + (q - p) * f).round() as u8;
            let colour = if blocked {
                RGBColor(90, 40, 40)
            } else {
                RGBColor(mix(245.0, 120.0), mix(238.0, 95.0), mix(220.0, 60.0))
            };
            Rectangle::new(
                [(x - dx / 2.0, y - dy / 2.0), (x + dx / 2.0, y + dy / 2.0)],
                colour.filled(),
            )
        }))
        .map_err(fail("terrain"))?;
    chart
        .draw_series(
            report
                .boxes
                .iter()
                .map(|b| Rectangle::new([(b.x0, b.y0), (b.x1, b.y1)], NO_GO.mix(0.25).filled())),
        )
        .map_err(fail("no-go boxes"))?
        .label("no-go boxes")
        .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], NO_GO.mix(0.4).filled()));
    chart
        .draw_series(
            report
                .boxes
                .iter()
                .map(|b| Rectangle::new([(b.x0, b.y0), (b.x1, b.y1)], NO_GO.stroke_width(2))),
        )
        .map_err(fail("no-go box edges"))?;
    let planned: Vec<(f64, f64)> = report.planned_path.iter().map(|p| (p[0], p[1])).collect();
    chart
        .draw_series(LineSeries::new(planned, PLANNED.stroke_width(1)))
        .map_err(fail("planned path"))?
        .label("planned")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], PLANNED.stroke_width(2)));
    if !report.tracked_path.is_empty() {
        let tracked: Vec<(f64, f64)> = report.tracked_path.iter().map(|p| (p[0], p[1])).collect();
        chart
            .draw_series(LineSeries::new(tracked, TRACKED.mix(0.8).stroke_width(1)))
            .map_err(fail("tracked path"))?
            .label("tracked")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], TRACKED.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(fail("legend"))?;
    Ok(())
}

fn draw_histogram<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    dist: Option<&Distribution>,
) -> anyhow::Result<()> {
    let Some(d) = dist else {
        area.titled(&format!("{title}: not simulated"), ("sans-serif", 15))
            .map_err(fail("histogram title"))?;
        return Ok(());
    };
    let h = &d.histogram;
    let total = d.count.max(1) as f64;
    let (lo, hi) = (
        h.edges.first().copied().unwrap_or(0.0),
        h.edges.last().copied().unwrap_or(1.0),
    );
    let top = h
        .counts
        .iter()
        .map(|&c| c as f64 / total)
        .fold(0.0, f64::max)
        .max(1e-3)
        * 1.1;
    let caption = format!(
        "{title} — median {:.2}, p95 {:.2}, max {:.2}; {} above range",
        d.median, d.p95, d.max, h.above
    );
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 14))
        .margin(12)
        .x_label_area_size(25)
        .y_label_area_size(45)
        .build_cartesian_2d(lo..hi, 0.0..top)
        .map_err(fail("histogram axes"))?;
    chart
        .configure_mesh()
        .y_desc("share of samples")
        .draw()
        .map_err(fail("histogram mesh"))?;
    chart
        .draw_series(h.counts.iter().enumerate().filter_map(|(k, &c)| {
            let (a, b) = (h.edges.get(k)?, h.edges.get(k + 1)?);
            Some(Rectangle::new(
                [(*a, 0.0), (*b, c as f64 / total)],
                PLANNED.mix(0.6).filled(),
            ))
        }))
        .map_err(fail("histogram bars"))?;
    Ok(())
}
