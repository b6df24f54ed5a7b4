//! `plan.svg` of a coverage mission (CPP-DSMV, Figures 5–7): the shaded 2.5D map with its
//! impassable cells, the merged no-go boxes (red), the planned path (blue) and the tracked path
//! (orange) on the left; the three distributions of Figure 7 — clearance to impassable terrain,
//! slope under the path, |cross-track error| — on the right.

use plotters::prelude::*;
use shoal_common::coverage::boxes::Rect;
use shoal_common::coverage::fleet::FleetCoverageReport;
use shoal_common::coverage::metrics::Distribution;
use shoal_common::coverage::mission::CoverageReport;
use shoal_common::coverage::TerrainMap25;

use crate::report::svg::chart::fail;

/// Canvas size.
const SIZE: (u32, u32) = (1500, 960);
/// Map raster drawn per axis.
const CELLS: usize = 120;
const NO_GO: RGBColor = RGBColor(210, 30, 30);
const PLANNED: RGBColor = RGBColor(30, 70, 200);
const TRACKED: RGBColor = RGBColor(240, 140, 0);

/// Colours of the crawlers of a fleet (planned paths; tracked paths are drawn lighter).
const FLEET: [RGBColor; 6] = [
    RGBColor(30, 70, 200),
    RGBColor(0, 140, 70),
    RGBColor(150, 40, 170),
    RGBColor(0, 150, 170),
    RGBColor(120, 80, 20),
    RGBColor(200, 30, 120),
];

/// One crawler's paths on the map.
struct Track<'a> {
    label: String,
    planned: &'a [[f64; 2]],
    tracked: &'a [[f64; 2]],
    planned_colour: RGBColor,
    tracked_colour: RGBColor,
}

/// What the map panel shows.
struct MapView<'a> {
    area: Rect,
    title: String,
    boxes: &'a [Rect],
    tracks: Vec<Track<'a>>,
    /// Strip edges of a fleet (drawn as lines across the area).
    strip_edges: Vec<f64>,
}

/// Renders the report over its map.
pub fn render_coverage(report: &CoverageReport, map: &TerrainMap25) -> anyhow::Result<String> {
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
    let view = MapView {
        area: report.area,
        title,
        boxes: &report.boxes,
        tracks: vec![Track {
            label: "planned".into(),
            planned: &report.planned_path,
            tracked: &report.tracked_path,
            planned_colour: PLANNED,
            tracked_colour: TRACKED,
        }],
        strip_edges: Vec::new(),
    };
    let clearance_title = format!(
        "(a) clearance to impassable cells, m — {} samples < {} m",
        report.samples_below_clearance, report.safety_clearance_m
    );
    let cte = report.tracking.as_ref().map(|t| &t.cross_track);
    render(
        map,
        &view,
        [
            (&clearance_title, Some(&report.clearance)),
            ("(b) slope under the path, degrees", Some(&report.slope)),
            ("(c) |cross-track error| of the tracked path, m", cte),
        ],
    )
}

/// Renders a fleet's strips, paths and fleet-wide distributions over the map.
pub fn render_fleet_coverage(
    report: &FleetCoverageReport,
    map: &TerrainMap25,
) -> anyhow::Result<String> {
    let sep = &report.separation;
    let title = format!(
        "{} crawlers — coverage {:.2} %, min separation {:.1} m (d_min {} m)",
        report.vehicles.len(),
        100.0 * report.coverage.ratio,
        sep.min_distance_m,
        sep.d_min_m
    );
    let tracks = report
        .vehicles
        .iter()
        .enumerate()
        .map(|(k, v)| {
            let colour = FLEET[k % FLEET.len()];
            Track {
                label: v.vehicle.clone(),
                planned: &v.report.planned_path,
                tracked: &v.report.tracked_path,
                planned_colour: colour,
                tracked_colour: TRACKED,
            }
        })
        .collect();
    let view = MapView {
        area: report.area,
        title,
        boxes: report.vehicles.first().map_or(&[], |v| &v.report.boxes),
        tracks,
        strip_edges: report.vehicles.iter().skip(1).map(|v| v.strip.y0).collect(),
    };
    let clearance_title = format!(
        "(a) clearance to impassable cells, m — {} samples < {} m",
        report.samples_below_clearance, report.safety_clearance_m
    );
    render(
        map,
        &view,
        [
            (&clearance_title, Some(&report.clearance)),
            ("(b) slope under the paths, degrees", Some(&report.slope)),
            (
                "(c) |cross-track error| of the tracked paths, m",
                report.cross_track.as_ref(),
            ),
        ],
    )
}

/// The map on the left, three histograms on the right.
fn render(
    map: &TerrainMap25,
    view: &MapView,
    hists: [(&str, Option<&Distribution>); 3],
) -> anyhow::Result<String> {
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(fail("background"))?;
        let (left, right) = root.split_horizontally(960);
        draw_map(&left, view, map)?;
        let panels = right.split_evenly((3, 1));
        for (area, (title, dist)) in panels.iter().zip(hists) {
            draw_histogram(area, title, dist)?;
        }
        root.present().map_err(fail("document"))?;
    }
    Ok(buf)
}

fn draw_map<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    view: &MapView,
    map: &TerrainMap25,
) -> anyhow::Result<()> {
    let a = view.area;
    let mut chart = ChartBuilder::on(area)
        .caption(&view.title, ("sans-serif", 18))
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
            view.boxes
                .iter()
                .map(|b| Rectangle::new([(b.x0, b.y0), (b.x1, b.y1)], NO_GO.mix(0.25).filled())),
        )
        .map_err(fail("no-go boxes"))?
        .label("no-go boxes")
        .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], NO_GO.mix(0.4).filled()));
    chart
        .draw_series(
            view.boxes
                .iter()
                .map(|b| Rectangle::new([(b.x0, b.y0), (b.x1, b.y1)], NO_GO.stroke_width(2))),
        )
        .map_err(fail("no-go box edges"))?;
    for t in &view.tracks {
        let planned: Vec<(f64, f64)> = t.planned.iter().map(|p| (p[0], p[1])).collect();
        let colour = t.planned_colour;
        chart
            .draw_series(LineSeries::new(planned, colour.stroke_width(1)))
            .map_err(fail("planned path"))?
            .label(t.label.clone())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 14, y)], colour.stroke_width(2))
            });
    }
    for (k, t) in view.tracks.iter().enumerate() {
        if t.tracked.is_empty() {
            continue;
        }
        let tracked: Vec<(f64, f64)> = t.tracked.iter().map(|p| (p[0], p[1])).collect();
        let colour = t.tracked_colour;
        let series = chart
            .draw_series(LineSeries::new(tracked, colour.mix(0.8).stroke_width(1)))
            .map_err(fail("tracked path"))?;
        if k == 0 {
            series.label("tracked").legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 14, y)], colour.stroke_width(2))
            });
        }
    }
    for &y in &view.strip_edges {
        chart
            .draw_series(LineSeries::new(
                [(a.x0, y), (a.x1, y)],
                BLACK.stroke_width(2),
            ))
            .map_err(fail("strip edge"))?;
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
