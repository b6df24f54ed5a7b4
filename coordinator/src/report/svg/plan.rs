//! SVG picture of a plan: a title line and legend, a top view (x–y), a side view (x–z) and the
//! optimizer's convergence curve.
//!
//! Both views draw every obstacle twice: filled at its physical radius and with a dashed ring,
//! lightly shaded, at radius plus inflation. The planner keeps out of the inflated sphere, not the
//! physical one, so a path that hugs the dashed ring is as close as it is allowed to get, and one
//! that cuts inside it breaks a hard constraint even when it misses the filled disc. The side view
//! is the x–z section of each sphere through its centre. Circles are polygons in data coordinates
//! so they scale with the axes; the top view keeps equal aspect, the side view may stretch z (its
//! caption then says by how much). Text uses only the SVG backend's `<text>` elements, so no font
//! feature of `plotters` is needed.

use plotters::backend::SVGBackend;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use shoal_common::plan::Plan;
use shoal_common::scenario::{ObstacleKind, Scenario};

use super::chart::{fail, Chart};

/// Picture size, pixels.
const SIZE: (u32, u32) = (1200, 900);
/// Width of the top view's column, pixels; the side view and convergence share the rest.
const LEFT_COLUMN: u32 = 660;
/// Vertices of an obstacle's circle.
const CIRCLE_POINTS: usize = 72;
/// Most the side view may stretch z relative to x.
const MAX_SIDE_EXAGGERATION: f64 = 8.0;
/// Vehicle colours, cycled; no reds or oranges, which mark obstacles.
const PALETTE: [u32; 8] = [
    0x1f77b4, 0x2ca02c, 0x9467bd, 0x17becf, 0xe377c2, 0x8c564b, 0xbcbd22, 0x5a5a5a,
];
const HARD: RGBColor = RGBColor(150, 30, 30);
const SOFT: RGBColor = RGBColor(235, 165, 20);
const SOFT_RING: RGBColor = RGBColor(190, 120, 0);
const GREY: RGBColor = RGBColor(90, 90, 90);
const FONT: &str = "sans-serif";

type Fmt<'a> = &'a dyn Fn(&f64) -> String;
type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// Renders `plan` over `scenario` as an SVG document.
pub fn render_plan(scenario: &Scenario, plan: &Plan) -> anyhow::Result<String> {
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(fail("background"))?;
        let header = draw_header(&root, scenario, plan)?;
        let (_, body) = root.split_vertically(header);
        let (left, right) = body.split_horizontally(LEFT_COLUMN);
        let (side, convergence) = right.split_vertically(right.dim_in_pixel().1 / 2);
        draw_view(&left, scenario, plan, (0, 1))?;
        draw_view(&side, scenario, plan, (0, 2))?;
        draw_convergence(&convergence, &plan.convergence)?;
        root.present().map_err(fail("document"))?;
    }
    Ok(buf)
}

/// Title line and legend; returns the height they take, pixels.
fn draw_header(root: &Area, scenario: &Scenario, plan: &Plan) -> anyhow::Result<u32> {
    let separation = plan
        .fleet
        .min_separation_m
        .map_or("n/a".into(), |d| format!("{d:.1} m"));
    let feasible = if plan.feasible { "yes" } else { "no" };
    let title = format!(
        "{} — {} — feasible: {feasible} — fitness {} — min separation {separation}",
        scenario.name,
        plan.algorithm,
        num(plan.fitness),
    );
    let style = (FONT, 24).into_font().style(FontStyle::Bold).color(&BLACK);
    root.draw(&Text::new(title, (12, 10), style))
        .map_err(fail("title"))?;

    // Legend entries flow left to right and wrap. The SVG backend cannot measure text, so widths
    // are estimated generously.
    let text = (FONT, 17)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Left, VPos::Center));
    let mut cursor = (12, 44);
    let mut place = |label: &str| {
        let w = 50 + (label.chars().count() as f64 * 7.5) as i32;
        if cursor.0 + w > SIZE.0 as i32 - 12 && cursor.0 > 12 {
            cursor = (12, cursor.1 + 24);
        }
        let at = cursor;
        cursor.0 += w;
        let label = Text::new(label.to_string(), (at.0 + 30, at.1), text.clone());
        root.draw(&label).map(|()| at).map_err(fail("legend"))
    };
    for (i, v) in plan.vehicles.iter().enumerate() {
        let (x, y) = place(&v.id)?;
        let line = PathElement::new([(x, y), (x + 24, y)], colour(i).stroke_width(3));
        root.draw(&line).map_err(fail("legend"))?;
    }
    let (x, y) = place("start")?;
    root.draw(&Circle::new((x + 12, y), 6, GREY.filled()))
        .map_err(fail("legend"))?;
    let (x, y) = place("goal")?;
    root.draw(&TriangleMarker::new((x + 12, y), 8, GREY.filled()))
        .map_err(fail("legend"))?;
    for (label, c) in [
        ("hard obstacle", HARD.mix(0.75)),
        ("soft obstacle", SOFT.mix(0.55)),
    ] {
        let (x, y) = place(label)?;
        let swatch = Rectangle::new([(x + 2, y - 8), (x + 22, y + 8)], c.filled());
        root.draw(&swatch).map_err(fail("legend"))?;
    }
    let (x, y) = place("radius + inflation (kept out of)")?;
    let ring = circle((f64::from(x) + 12.0, f64::from(y)), 9.0);
    let ring = ring.into_iter().map(|(px, py)| (px as i32, py as i32));
    root.draw(&DashedPathElement::new(ring, 4, 3, HARD.stroke_width(2)))
        .map_err(fail("legend"))?;
    Ok((cursor.1 + 18) as u32)
}

/// Draws `title` over `area`; returns the part below it.
fn captioned<'a>(area: &Area<'a>, title: &str) -> anyhow::Result<Area<'a>> {
    let (head, body) = area.split_vertically(34);
    let style = (FONT, 20).into_font().color(&BLACK);
    head.draw(&Text::new(title, (12, 8), style))
        .map_err(fail("caption"))?;
    Ok(body)
}

/// Grid, tick labels and axis names.
fn mesh(chart: &mut Chart, names: [&str; 2], x: Fmt, y: Fmt) -> anyhow::Result<()> {
    chart
        .configure_mesh()
        .x_desc(names[0])
        .y_desc(names[1])
        .x_labels(7)
        .y_labels(6)
        .x_label_formatter(x)
        .y_label_formatter(y)
        .label_style((FONT, 15))
        .axis_desc_style((FONT, 16))
        .light_line_style(RGBColor(235, 235, 235))
        .bold_line_style(RGBColor(215, 215, 215))
        .draw()
        .map_err(fail("axes"))
}

/// A top (axes 0, 1) or side (axes 0, 2) view of obstacles and paths.
fn draw_view(
    area: &Area,
    scenario: &Scenario,
    plan: &Plan,
    (a, b): (usize, usize),
) -> anyhow::Result<()> {
    // Axes span the bounds, widened to any trajectory sample outside them (an infeasible plan
    // must still be drawn whole).
    let extent = |axis: usize| {
        let samples = plan
            .vehicles
            .iter()
            .flat_map(|v| v.trajectory.iter().map(move |s| s[1 + axis]));
        let bounds = (scenario.bounds.min[axis], scenario.bounds.max[axis]);
        let (lo, hi) = samples
            .filter(|v| v.is_finite())
            .fold(bounds, |(lo, hi), v| (lo.min(v), hi.max(v)));
        pad(lo, hi)
    };
    let ((x0, x1), (y0, y1)) = (extent(a), extent(b));

    // Fit the plotting area to the data's aspect, centred in the panel: 34 px caption, 45 px of
    // x labels, 70 px of y labels, 25 px right margin for the last tick label.
    let (w, h) = area.dim_in_pixel();
    let (pw, ph) = (
        (f64::from(w) - 105.0).max(10.0),
        (f64::from(h) - 90.0).max(10.0),
    );
    let max_exag = if b == 2 { MAX_SIDE_EXAGGERATION } else { 1.0 };
    let (uw, uh, exag) = fit(pw, ph, x1 - x0, y1 - y0, max_exag);
    let (mx, my) = (((pw - uw) / 2.0) as u32, ((ph - uh) / 2.0) as u32);
    let mut title = ["Top view (x–y)", "Side view (x–z)"][usize::from(b == 2)].to_string();
    if exag > 1.05 {
        title.push_str(&format!(", z stretched ×{exag:.1}"));
    }
    if let Some(c) = crate::report::svg::terrain::caption(scenario, b == 1) {
        title.push_str(c);
    }
    if let Some(c) = crate::report::svg::current::caption(scenario, b == 1) {
        title.push_str(&c);
    }
    let body = captioned(area, &title)?;
    let mut chart = ChartBuilder::on(&body)
        .margin_left(mx)
        .margin_right(25 + mx)
        .margin_top(my)
        .margin_bottom(10 + my)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(fail("view axes"))?;
    let metres = |v: &f64| format!("{v:.0}");
    let names = ["x (m)", "y (m)", "z (m)"];
    mesh(&mut chart, [names[a], names[b]], &metres, &metres)?;
    if b == 1 {
        crate::report::svg::terrain::draw_seabed(&mut chart, scenario, (x0, x1, y0, y1))?;
    }
    crate::report::svg::current::draw_current(&mut chart, scenario, (a, b), (x0, x1, y0, y1))?;

    let inside = |(x, y): (f64, f64)| x >= x0 && x <= x1 && y >= y0 && y <= y1;
    let clamp = |(x, y): (f64, f64)| (x.clamp(x0, x1), y.clamp(y0, y1));
    for o in &scenario.obstacles {
        let centre = (o.centre[a], o.centre[b]);
        let (fill, ring) = match o.kind {
            ObstacleKind::Hard => (HARD.mix(0.75), HARD),
            ObstacleKind::Soft => (SOFT.mix(0.55), SOFT_RING),
        };
        // Clamping a convex polygon's vertices to the box gives its part inside the box.
        let disc = |r| circle(centre, r).into_iter().map(clamp).collect::<Vec<_>>();
        let discs = [
            Polygon::new(disc(o.inflated_radius()), ring.mix(0.10).filled()),
            Polygon::new(disc(o.radius_m), fill.filled()),
        ];
        chart.draw_series(discs).map_err(fail("obstacle"))?;
        // The ring is drawn only where it lies inside the axes, one dashed run at a time.
        let mut runs: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
        for p in circle(centre, o.inflated_radius()) {
            match (inside(p), runs.last_mut()) {
                (true, Some(run)) => run.push(p),
                (false, Some(run)) if !run.is_empty() => runs.push(Vec::new()),
                _ => {}
            }
        }
        let dashes = runs.into_iter().filter(|r| r.len() > 1);
        let dashes = dashes.map(|r| DashedPathElement::new(r, 7, 5, ring.stroke_width(2)));
        chart.draw_series(dashes).map_err(fail("obstacle margin"))?;
    }

    for (i, v) in plan.vehicles.iter().enumerate() {
        let c = colour(i);
        let path: Vec<(f64, f64)> = v.trajectory.iter().map(|s| (s[1 + a], s[1 + b])).collect();
        // Markers at the scenario's start and goal; at the path's ends for an unknown vehicle.
        // A crawler's path starts on the seabed below its start: mark the path's ends.
        let known = scenario
            .vehicles
            .iter()
            .find(|s| s.id == v.id && s.kind != shoal_common::scenario::VehicleKind::Crawler);
        let start = known
            .map(|s| (s.start[a], s.start[b]))
            .or(path.first().copied());
        let goal = known
            .map(|s| (s.goal[a], s.goal[b]))
            .or(path.last().copied());
        let line = PathElement::new(path, c.stroke_width(2));
        chart.draw_series([line]).map_err(fail("vehicle path"))?;
        let outline = WHITE.stroke_width(1);
        let starts = start
            .into_iter()
            .flat_map(|p| [Circle::new(p, 7, c.filled()), Circle::new(p, 7, outline)]);
        chart.draw_series(starts).map_err(fail("start marker"))?;
        // A white triangle behind the coloured one outlines it (triangle markers are always filled).
        let goals = goal.into_iter().flat_map(|p| {
            [
                TriangleMarker::new(p, 11, WHITE.filled()),
                TriangleMarker::new(p, 9, c.filled()),
            ]
        });
        chart.draw_series(goals).map_err(fail("goal marker"))?;
    }

    if b == 2 {
        crate::report::svg::terrain::draw_seabed_under_paths(
            &mut chart, scenario, plan, a, &colour,
        )?;
    }
    crate::report::svg::tour::draw_inspection_points(&mut chart, plan, (a, b), &colour)?;

    // Obstacle ids last, so no fill or path hides them; ids of spheres whose centres coincide in
    // this view are stacked instead of printed over each other.
    let label = (FONT, 14)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Center, VPos::Center));
    let ids: Vec<_> = scenario
        .obstacles
        .iter()
        .map(|o| (o.id.clone(), (o.centre[a], o.centre[b])))
        .collect();
    let ids: Vec<_> = ids.into_iter().filter(|(_, c)| inside(*c)).collect();
    let at = stack_labels(&ids, (uw / (x1 - x0), uh / (y1 - y0)));
    let texts = ids
        .into_iter()
        .zip(at)
        .map(|((id, _), p)| Text::new(id, p, label.clone()));
    chart.draw_series(texts).map_err(fail("obstacle label"))?;
    Ok(())
}

/// Best fitness per iteration; a log axis when positive values span more than a factor of 100.
fn draw_convergence(area: &Area, values: &[f64]) -> anyhow::Result<()> {
    let finite: Vec<(f64, f64)> = values
        .iter()
        .enumerate()
        .filter(|(_, v)| v.is_finite())
        .map(|(i, v)| ((i + 1) as f64, *v))
        .collect();
    let start = (f64::INFINITY, f64::NEG_INFINITY);
    let (lo, hi) = finite
        .iter()
        .fold(start, |(lo, hi), (_, v)| (lo.min(*v), hi.max(*v)));
    let log = !finite.is_empty() && lo > 0.0 && hi / lo > 100.0;
    let title = if log {
        "Convergence: best fitness (log scale)"
    } else {
        "Convergence: best fitness"
    };
    let body = captioned(area, title)?;
    if finite.is_empty() {
        let (w, h) = body.dim_in_pixel();
        let (w, h) = (w as i32, h as i32);
        let frame = Rectangle::new([(70, 0), (w - 10, h - 45)], RGBColor(200, 200, 200));
        body.draw(&frame).map_err(fail("convergence frame"))?;
        let style = (FONT, 18)
            .into_font()
            .color(&GREY)
            .pos(Pos::new(HPos::Center, VPos::Center));
        let note = Text::new("no convergence data", ((w + 60) / 2, (h - 45) / 2), style);
        return body.draw(&note).map_err(fail("convergence note"));
    }
    let ys = |v: f64| if log { v.log10() } else { v };
    let points: Vec<(f64, f64)> = finite.iter().map(|&(i, v)| (i, ys(v))).collect();
    let (y0, y1) = pad(ys(lo), ys(hi));
    let (x0, x1) = pad(1.0, values.len() as f64);
    let margin = (y1 - y0) * 0.05;
    let mut chart = ChartBuilder::on(&body)
        .margin_right(30)
        .margin_bottom(10)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, (y0 - margin)..(y1 + margin))
        .map_err(fail("convergence axes"))?;
    // Only whole iterations are labelled (a one-value curve has fractional ticks).
    let whole = |v: &f64| {
        if v.fract() == 0.0 {
            format!("{v:.0}")
        } else {
            String::new()
        }
    };
    // Log ticks fall on (or near) powers of ten: 1e6, 1e5, ...
    let fitness = |v: &f64| {
        if log {
            format!("{:.0e}", 10f64.powf(*v))
        } else {
            num(*v)
        }
    };
    mesh(&mut chart, ["iteration", "best fitness"], &whole, &fitness)?;
    let line = RGBColor(31, 119, 180);
    let curve = PathElement::new(points.clone(), line.stroke_width(2));
    chart
        .draw_series([curve])
        .map_err(fail("convergence curve"))?;
    if points.len() <= 40 {
        let dots = points.into_iter().map(|p| Circle::new(p, 3, line.filled()));
        chart
            .draw_series(dots)
            .map_err(fail("convergence points"))?;
    }
    Ok(())
}

/// Positions for centred labels at `anchors` (data coordinates, `scale` pixels per unit): each
/// moves down a line at a time until it clears the labels placed before it.
fn stack_labels(anchors: &[(String, (f64, f64))], (sx, sy): (f64, f64)) -> Vec<(f64, f64)> {
    const CHAR_PX: f64 = 7.0;
    const LINE_PX: f64 = 15.0;
    let mut placed: Vec<(f64, f64, f64)> = Vec::new(); // pixel x, pixel y (down), half width
    let clash = |placed: &[(f64, f64, f64)], (px, py, half): (f64, f64, f64)| {
        placed
            .iter()
            .any(|&(qx, qy, qh)| (px - qx).abs() < half + qh && (py - qy).abs() < LINE_PX)
    };
    anchors
        .iter()
        .map(|(id, (x, y))| {
            let mut at = (x * sx, -y * sy, id.chars().count() as f64 * CHAR_PX / 2.0);
            while clash(&placed, at) {
                at.1 += LINE_PX;
            }
            placed.push(at);
            (*x, -at.1 / sy)
        })
        .collect()
}

/// The colour of the `i`-th vehicle.
fn colour(i: usize) -> RGBColor {
    let [_, r, g, b] = PALETTE[i % PALETTE.len()].to_be_bytes();
    RGBColor(r, g, b)
}

/// Vertices of a circle, closed (the first repeated last), in data coordinates.
fn circle((cx, cy): (f64, f64), r: f64) -> Vec<(f64, f64)> {
    let angle = |k: usize| std::f64::consts::TAU * k as f64 / CIRCLE_POINTS as f64;
    (0..=CIRCLE_POINTS)
        .map(|k| (cx + r * angle(k).cos(), cy + r * angle(k).sin()))
        .collect()
}

/// A non-empty range: an empty one is widened around its middle.
fn pad(lo: f64, hi: f64) -> (f64, f64) {
    if !(lo.is_finite() && hi.is_finite()) {
        (0.0, 1.0)
    } else if hi - lo > 1e-9 * lo.abs().max(hi.abs()).max(1e-9) {
        (lo, hi)
    } else {
        let (mid, half) = ((lo + hi) / 2.0, ((lo + hi).abs() * 0.025).max(0.5));
        (mid - half, mid + half)
    }
}

/// Pixel size of a plot of data extents (`dx`, `dy`) fitted into `pw` × `ph` pixels with the
/// vertical scale 1 to `max_exag` times the horizontal one, and that ratio.
fn fit(pw: f64, ph: f64, dx: f64, dy: f64, max_exag: f64) -> (f64, f64, f64) {
    let exag = ((ph / dy) / (pw / dx)).clamp(1.0, max_exag.max(1.0));
    let s = (pw / dx).min(ph / (exag * dy));
    (s * dx, s * exag * dy, exag)
}

/// A number for a label: plain when moderate, scientific when very large or small.
fn num(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        format!("{v}")
    } else if !(1e-2..1e5).contains(&v.abs()) {
        format!("{v:.2e}")
    } else {
        format!("{v:.3}")
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use shoal_common::geometry::Vec3;
    use shoal_common::plan::assess;
    use shoal_common::trajectory::Trajectory;

    use super::*;

    const VEHICLE: &str = "kind = 'auv'\nspeed_min_mps = 0.5\nspeed_max_mps = 2.0\nmax_turn_deg = 35.0\nmax_pitch_deg = 20.0";

    /// One hard and one soft obstacle (the soft one overhangs the bounds), two vehicles.
    fn scenario() -> anyhow::Result<Scenario> {
        let text = format!(
            r#"
name = "svg-test"
bounds = {{ min = [0.0, 0.0, 0.0], max = [1000.0, 800.0, 300.0] }}
fleet = {{ d_min_m = 50.0, mission_time_s = 1000.0 }}
obstacles = [
  {{ id = "HObs#1", kind = "hard", centre = [500.0, 400.0, 150.0], radius_m = 100.0, inflation_m = 50.0 }},
  {{ id = "SObs#1", kind = "soft", centre = [950.0, 100.0, 100.0], radius_m = 120.0, inflation_m = 50.0 }},
]
[[vehicles]]
id = "auv-red"
start = [0.0, 0.0, 250.0]
goal = [1000.0, 800.0, 50.0]
{VEHICLE}
[[vehicles]]
id = "auv-blue"
start = [0.0, 800.0, 250.0]
goal = [1000.0, 0.0, 50.0]
{VEHICLE}
"#
        );
        Ok(Scenario::parse(&text, Path::new("t.toml"))?)
    }

    /// A plan of `[t, x, y, z]` samples per scenario vehicle, with figures from `assess`.
    fn plan(s: &Scenario, samples: &[&[[f64; 4]]], convergence: Vec<f64>) -> Plan {
        let trajectory = |v: &[[f64; 4]]| Trajectory {
            times: v.iter().map(|p| p[0]).collect(),
            points: v.iter().map(|p| Vec3::new(p[1], p[2], p[3])).collect(),
        };
        let a = assess(
            s,
            &samples.iter().map(|v| trajectory(v)).collect::<Vec<_>>(),
        );
        Plan {
            scenario: s.name.clone(),
            algorithm: "amp-pso".into(),
            mode: "in-process".into(),
            seed: 1,
            runtime_s: 0.1,
            fitness: 12.5,
            objective: 12.5,
            penalty: 0.0,
            feasible: a.violations.is_empty(),
            violations: a.violations,
            notices: vec![],
            mission_time_s: 1000.0,
            common_arrival_s: 1000.0,
            d_min_m: 50.0,
            iterations: convergence.len(),
            evaluations: 100,
            termination: "iterations".into(),
            vehicles: a.vehicles,
            fleet: a.fleet,
            convergence,
            distributed: None,
            origin: s.origin,
        }
    }

    #[test]
    fn svg_shows_vehicles_obstacles_and_margins() -> anyhow::Result<()> {
        let s = scenario()?;
        // Red runs south-west to north-east, blue north-west to south-east; they cross.
        let red = [
            [0.0, 0.0, 0.0, 250.0],
            [500.0, 300.0, 150.0, 150.0],
            [1e3, 1e3, 800.0, 50.0],
        ];
        let blue = [
            [0.0, 0.0, 800.0, 250.0],
            [500.0, 250.0, 650.0, 150.0],
            [1e3, 1e3, 0.0, 50.0],
        ];
        let p = plan(&s, &[&red, &blue], vec![40.0, 20.0, 15.0, 12.5]);
        let svg = render_plan(&s, &p)?;
        assert!(svg.starts_with("<svg"));
        // Each id is a whole `<text>` element: legend entries and obstacle labels.
        let texts: Vec<&str> = svg
            .split("<text")
            .skip(1)
            .filter_map(|t| t.split_once(">\n")?.1.split_once("\n</text>"))
            .map(|(text, _)| text)
            .collect();
        for id in ["auv-red", "auv-blue", "HObs#1", "SObs#1"] {
            assert!(texts.contains(&id), "{id} missing from {texts:?}");
        }
        let separation = p.fleet.min_separation_m.unwrap_or(f64::NAN);
        let title = format!(
            "svg-test — amp-pso — feasible: no — fitness 12.5 — min separation {separation:.1} m"
        );
        assert!(
            texts.contains(&title.as_str()),
            "{title} missing from {texts:?}"
        );
        // Two obstacles × (margin + body) × two views; two paths × two views + convergence.
        let count = |tag: &str| svg.matches(tag).count();
        assert!(count("<polygon") >= 8, "{} polygons", count("<polygon"));
        assert!(count("<polyline") >= 5, "{} polylines", count("<polyline"));
        Ok(())
    }

    #[test]
    fn degenerate_inputs_render() -> anyhow::Result<()> {
        // One vehicle with a one-sample trajectory, no obstacles.
        let mut s = scenario()?;
        s.obstacles.clear();
        s.vehicles.truncate(1);
        let still: &[[f64; 4]] = &[[0.0, 0.0, 0.0, 250.0]];
        for convergence in [vec![], vec![7.0], vec![3.0, 3.0, 3.0], vec![1e6, 1e3, 2.0]] {
            let svg = render_plan(&s, &plan(&s, &[still], convergence))?;
            assert!(svg.contains("<svg") && svg.contains("auv-red"));
        }
        let svg = render_plan(&s, &plan(&s, &[still], vec![]))?;
        assert!(svg.contains("no convergence data") && svg.contains("min separation n/a"));
        // A vehicle without samples still gets its start and goal markers from the scenario.
        let mut p = plan(&s, &[still], vec![1.0]);
        p.vehicles[0].trajectory.clear();
        assert!(render_plan(&s, &p)?.contains("auv-red"));
        Ok(())
    }

    #[test]
    fn ranges_and_fit_never_collapse() {
        assert_eq!(pad(2.0, 5.0), (2.0, 5.0));
        for v in [3.0, 0.0, -1e6] {
            let (lo, hi) = pad(v, v);
            assert!(lo < v && hi > v, "{v}: {lo}..{hi}");
        }
        let (w, h, e) = fit(500.0, 500.0, 2000.0, 1000.0, 1.0);
        assert!((w - 500.0).abs() < 1e-9 && (h - 250.0).abs() < 1e-9 && e == 1.0);
        let (_, _, e) = fit(500.0, 400.0, 2000.0, 100.0, 8.0);
        assert!((e - 8.0).abs() < 1e-9);
    }
}
