//! `shoal-coordinator replay LOG`: reads a mission log back, recomputes the execution's figures
//! from its records alone (the same fleet picture the live run used, see [`execute::replayed`]), lists the decisions, and
//! draws the planned and executed tracks (`<LOG>.svg`: top view, over the seabed and its hazards
//! when the scenario has them). Its verdict and exit status are `run`'s. With `--foxglove` it then
//! plays the log to Foxglove at its recorded pace (`--speed` times it).

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use anyhow::Context as _;
use plotters::backend::SVGBackend;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use shoal_common::scenario::{Obstacle, ObstacleKind, Scenario};
use shoal_common::trajectory::Trajectory;
use shoal_common::wire::flags::ZenohSecurityArgs;
use shoal_common::wire::open::MissionEvent;

use crate::execute;
use crate::execute::fleet::ExecutionFigures;
use crate::execute::log;
use crate::execute::verdict;
use crate::foxglove::{self, FoxgloveArgs};
use crate::report::svg::chart::fail;

/// `shoal-coordinator replay`.
#[derive(Debug, Clone, clap::Args)]
pub struct ReplayArgs {
    /// The mission log: `mission.ndjson` or `mission.mcap` of `run` (told apart by their
    /// content, not their name).
    pub log: PathBuf,
    /// Where to draw the tracks (default: the log's path with `.svg`).
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// Then serve the log in the web view here (e.g. 127.0.0.1:8080), to play it back with a
    /// time slider, until Ctrl-C.
    #[arg(long, env = "SHOAL_VIEW", value_name = "ADDR")]
    pub view: Option<std::net::SocketAddr>,
    /// Then play the log to Foxglove, as `run --foxglove` showed it live.
    #[command(flatten)]
    pub foxglove: FoxgloveArgs,
    /// With --foxglove: how many times faster than it was recorded the log plays.
    #[arg(long, default_value_t = 1.0)]
    pub speed: f64,
    /// With --view or --foxglove beyond loopback: the coordinator's TLS identity (mutual TLS,
    /// the coordinator and operators only), or --insecure (plain, anyone who reaches the port).
    #[command(flatten)]
    pub zenoh: ZenohSecurityArgs,
}

/// What a log holds, replayed.
pub struct Replayed {
    /// The scenario, with the obstacles published during the execution.
    pub scenario: Scenario,
    /// The figures recomputed from the records.
    pub figures: ExecutionFigures,
    /// The figures the run wrote at its end, if it got there.
    pub logged: Option<ExecutionFigures>,
    /// Every event, in order.
    pub events: Vec<MissionEvent>,
    /// The first plan.
    pub planned: Vec<Trajectory>,
    /// The executed tracks.
    pub tracks: Vec<Trajectory>,
    /// A last record cut short and left out (see [`log::Log::cut_short`]).
    pub cut_short: Option<log::CutShort>,
}

/// Replays the log at `path`.
pub fn replay(path: &Path) -> anyhow::Result<Replayed> {
    let log::Log { records, cut_short } = log::read(path)?;
    let mut r = execute::replayed::Replayed::new(&records, path)?;
    for record in &records {
        r.apply(record);
    }
    let figures = r.fleet.figures_for(
        &r.scenario,
        r.start.common_arrival_s,
        r.start.arrival_window_s,
    );
    let tracks = r.fleet.vehicles.iter().map(|v| v.track.clone()).collect();
    Ok(Replayed {
        scenario: r.scenario,
        figures,
        logged: r.logged,
        events: r.events,
        planned: r.planned,
        tracks,
        cut_short,
    })
}

/// The replay command: prints the events and the figures and writes the SVG.
pub fn command(args: &ReplayArgs, shutdown: &AtomicBool) -> anyhow::Result<i32> {
    let security = args.zenoh.security()?;
    let foxglove = args.foxglove.settings(&security)?;
    let speed = foxglove::pace::check_speed(args.speed)?;
    let r = replay(&args.log)?;
    let mut out = String::new();
    for e in &r.events {
        out.push_str(&format!(
            "t {:>7.1} s  {:<18} {}\n",
            e.t_s, e.kind, e.detail
        ));
    }
    let f = &r.figures;
    out.push_str(&format!(
        "min separation {} (d_min {:.0} m); every vehicle in the arrival window: {}; {} reports; latency median {} ms, p99 {} ms\n",
        f.min_separation_m.map_or("–".into(), |d| format!("{d:.1} m")),
        f.d_min_m,
        if f.all_arrived_in_window { "yes" } else { "no" },
        f.reports,
        crate::report::summary::opt(f.latency_median_ms, 2),
        crate::report::summary::opt(f.latency_p99_ms, 2)
    ));
    for v in &f.vehicles {
        out.push_str(&verdict::vehicle_line(v));
    }
    out.push_str(&verdict::coverage_line(f));
    out.push_str(&verdict::verdict_line(f));
    match &r.logged {
        Some(l) if same_figures(l, f) => out.push_str("the figures match the log's end record\n"),
        Some(_) => {
            out.push_str("the figures differ from the log's end record (see execution.json)\n")
        }
        None => out.push_str("the log has no end record: the run did not finish\n"),
    }
    if let Some(cut) = r.cut_short {
        out.push_str(&format!(
            "{cut}, the last, is cut short (the run stopped while writing it): left out\n"
        ));
    }
    let svg_path = args
        .svg
        .clone()
        .unwrap_or_else(|| args.log.with_extension("svg"));
    let svg = render(&r)?;
    std::fs::write(&svg_path, svg)
        .with_context(|| format!("cannot write {}", svg_path.display()))?;
    out.push_str(&format!("Wrote {}\n", svg_path.display()));
    crate::report::out::say(&out);
    if args.view.is_some() && foxglove.is_some() {
        anyhow::bail!("--view and --foxglove: a log is played to one of them at a time");
    }
    if let Some(addr) = args.view {
        crate::view::serve_log(addr, &security, &args.log, shutdown)?;
    }
    if let Some(served) = foxglove {
        foxglove::stream_log(served, &args.log, speed, shutdown)?;
    }
    // As `run`: 0 when the execution met its figures, 3 when it did not.
    Ok(if verdict::failures(f).is_empty() {
        crate::commands::exit::EXIT_FEASIBLE
    } else {
        crate::commands::exit::EXIT_VIOLATIONS
    })
}

/// Top view: obstacles (filled: radius; ring: inflated), planned paths dashed, executed tracks
/// solid.
pub fn render(r: &Replayed) -> anyhow::Result<String> {
    const PALETTE: [RGBColor; 6] = [
        RGBColor(31, 119, 180),
        RGBColor(44, 160, 44),
        RGBColor(148, 103, 189),
        RGBColor(23, 190, 207),
        RGBColor(227, 119, 194),
        RGBColor(140, 86, 75),
    ];
    let b = &r.scenario.bounds;
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, (900, 900)).into_drawing_area();
        root.fill(&WHITE).map_err(fail("background"))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!(
                    "{}: executed (solid) vs planned (dashed); min separation {}",
                    r.scenario.name,
                    r.figures
                        .min_separation_m
                        .map_or("–".into(), |d| format!("{d:.1} m"))
                ),
                ("sans-serif", 18),
            )
            .margin(20)
            .x_label_area_size(30)
            .y_label_area_size(50)
            .build_cartesian_2d(b.min[0]..b.max[0], b.min[1]..b.max[1])
            .map_err(fail("axes"))?;
        chart.configure_mesh().draw().map_err(fail("mesh"))?;
        // Crawler and seabed scenarios: the shaded seabed and its hazards under the tracks.
        crate::report::svg::terrain::draw_seabed(
            &mut chart,
            &r.scenario,
            (b.min[0], b.max[0], b.min[1], b.max[1]),
        )?;
        let circle = |o: &Obstacle, r: f64| -> Vec<(f64, f64)> {
            (0..=72)
                .map(|k| {
                    let a = k as f64 / 72.0 * std::f64::consts::TAU;
                    (o.centre[0] + r * a.cos(), o.centre[1] + r * a.sin())
                })
                .collect()
        };
        for o in &r.scenario.obstacles {
            let c = if o.kind == ObstacleKind::Hard {
                RGBColor(150, 30, 30)
            } else {
                RGBColor(235, 165, 20)
            };
            chart
                .draw_series([Polygon::new(circle(o, o.radius_m), c.mix(0.4).filled())])
                .map_err(fail("obstacle"))?;
            chart
                .draw_series([PathElement::new(circle(o, o.inflated_radius()), c.mix(0.6))])
                .map_err(fail("obstacle margin"))?;
        }
        for (k, (plan, track)) in r.planned.iter().zip(&r.tracks).enumerate() {
            let c = PALETTE[k % PALETTE.len()];
            let planned: Vec<(f64, f64)> = plan.points.iter().map(|p| (p.x, p.y)).collect();
            chart
                .draw_series([DashedPathElement::new(planned, 6, 4, c.mix(0.5))])
                .map_err(fail("planned path"))?;
            let executed: Vec<(f64, f64)> = track.points.iter().map(|p| (p.x, p.y)).collect();
            chart
                .draw_series([PathElement::new(executed, c.stroke_width(2))])
                .map_err(fail("executed track"))?
                .label(r.scenario.vehicles.get(k).map_or("", |v| v.id.as_str()))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                });
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(fail("legend"))?;
        root.present().map_err(fail("document"))?;
    }
    Ok(buf)
}

/// Whether the replayed figures are the logged ones. A log written before the planned arrival
/// and a coverage mission's ground figures were kept has none in its end record: the replay's
/// own count as matching them.
fn same_figures(logged: &ExecutionFigures, replayed: &ExecutionFigures) -> bool {
    let mut logged = logged.clone();
    for (l, r) in logged.vehicles.iter_mut().zip(&replayed.vehicles) {
        l.planned_arrival_s = l.planned_arrival_s.or(r.planned_arrival_s);
        l.min_ground_clearance_m = l.min_ground_clearance_m.or(r.min_ground_clearance_m);
        l.impassable_m = l.impassable_m.or(r.impassable_m);
    }
    if logged.coverage.is_none() {
        logged.coverage = replayed.coverage.clone();
    }
    logged == *replayed
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::execute::log::{LogWriter, Record, Start};
    use shoal_common::wire::open::PlanNotice;

    fn plan(revision: u32, changed: &[&str], tracks: &[(&str, Vec<[f64; 4]>)]) -> Record {
        Record::Plan(PlanNotice {
            version: 1,
            mission: "m".into(),
            revision,
            changed: changed.iter().map(|s| s.to_string()).collect(),
            trajectories: tracks
                .iter()
                .map(|(v, s)| (v.to_string(), s.clone()))
                .collect(),
        })
    }

    fn report(seq: u64, revision: u32, t_s: f64, position: [f64; 3]) -> Record {
        report_of("auv1", seq, revision, t_s, position)
    }

    fn report_of(vehicle: &str, seq: u64, revision: u32, t_s: f64, position: [f64; 3]) -> Record {
        let mut telemetry = crate::execute::live::test_telemetry(vehicle, seq, t_s, position);
        telemetry.version = 1;
        telemetry.revision = revision;
        telemetry.sent_unix_us = 1_000_000;
        telemetry.state.heading_deg = 90.0;
        Record::Telemetry {
            received_unix_us: 1_000_000 + seq,
            telemetry,
        }
    }

    /// A vehicle told to hold drifts 40 m off its plan before its replan arrives: as in the live
    /// run, that is not tracking error, so the replayed cross-track stays the 3 m measured on
    /// the new plan (before the fix the replay counted the 40 m and disagreed with the log).
    #[test]
    fn a_hold_is_not_tracking_error_in_the_replay() -> anyhow::Result<()> {
        let dir = std::env::temp_dir().join(format!("shoal-replay-hold-{}", std::process::id()));
        std::fs::create_dir_all(&dir)?;
        let path = dir.join("m.ndjson");
        let auv2 = vec![[0.0, 0.0, 500.0, 0.0], [1000.0, 1000.0, 500.0, 0.0]];
        let mut w = LogWriter::create(&path)?;
        for r in [
            Record::Start(Start {
                mission: "m".into(),
                scenario_toml: include_str!("../../../scenarios/amp-pso-1.toml").into(),
                common_arrival_s: 1000.0,
                arrival_window_s: 30.0,
                horizon_s: 180.0,
                time_scale: 50.0,
                epoch_unix_ms: 0,
            }),
            plan(
                0,
                &["auv1", "auv2"],
                &[
                    (
                        "auv1",
                        vec![[0.0, 0.0, 0.0, 0.0], [1000.0, 1000.0, 0.0, 0.0]],
                    ),
                    ("auv2", auv2.clone()),
                ],
            ),
            report(1, 0, 100.0, [100.0, 1.0, 0.0]),
            Record::Event(MissionEvent {
                version: 1,
                mission: "m".into(),
                t_s: 150.0,
                kind: log::EVENT_HOLD.into(),
                vehicles: vec!["auv1".into()],
                detail: "auv1 told to hold".into(),
            }),
            report(2, 0, 200.0, [150.0, 40.0, 0.0]),
            plan(
                1,
                &["auv1"],
                &[
                    (
                        "auv1",
                        vec![[200.0, 150.0, 40.0, 0.0], [1050.0, 1000.0, 40.0, 0.0]],
                    ),
                    ("auv2", auv2),
                ],
            ),
            report(3, 1, 300.0, [250.0, 43.0, 0.0]),
        ] {
            w.write(&r);
        }
        w.flush();
        let r = replay(&path)?;
        std::fs::remove_dir_all(&dir)?;
        let v = &r.figures.vehicles[0];
        assert_eq!(v.vehicle, "auv1");
        assert_eq!(v.revision, 1);
        // Reports 1 and 3 count (1 m and 3 m off); report 2, while holding, does not.
        assert!((v.max_cross_track_m - 3.0).abs() < 1e-6, "{v:?}");
        let median = v.median_cross_track_m.unwrap_or(f64::NAN);
        assert!((median - 2.0).abs() < 1e-6, "{v:?}");
        // An end record written before the planned arrivals were kept still matches; a figure
        // that differs does not.
        assert_eq!(v.planned_arrival_s, Some(1000.0));
        let mut old = r.figures.clone();
        for v in &mut old.vehicles {
            v.planned_arrival_s = None;
        }
        assert!(same_figures(&old, &r.figures));
        old.vehicles[0].max_cross_track_m += 1.0;
        assert!(!same_figures(&old, &r.figures));
        Ok(())
    }

    /// A crawler whose fixes cross the soft-substrate hazard `soft1` of `seabed-fleet` (centre
    /// (120, 140), radius 12 m; the fixes run through its centre, so 12 m inside): the replay
    /// names it, exits 3 as `run` would, and draws the hazard under the tracks.
    #[test]
    fn a_replayed_crawler_track_into_a_hazard_is_not_met() -> anyhow::Result<()> {
        let dir = std::env::temp_dir().join(format!("shoal-replay-hazard-{}", std::process::id()));
        std::fs::create_dir_all(&dir)?;
        let path = dir.join("m.ndjson");
        let line =
            |a: [f64; 2], b: [f64; 2], z: f64| vec![[0.0, a[0], a[1], z], [420.0, b[0], b[1], z]];
        let mut w = LogWriter::create(&path)?;
        for r in [
            Record::Start(Start {
                mission: "m".into(),
                scenario_toml: include_str!("../../../scenarios/seabed-fleet.toml").into(),
                common_arrival_s: 420.0,
                arrival_window_s: 30.0,
                horizon_s: 180.0,
                time_scale: 50.0,
                epoch_unix_ms: 0,
            }),
            plan(
                0,
                &["crawler1", "crawler2", "auv1"],
                &[
                    ("crawler1", line([10.0, 150.0], [290.0, 150.0], 0.0)),
                    ("crawler2", line([150.0, 10.0], [150.0, 290.0], 0.0)),
                    ("auv1", line([10.0, 10.0], [290.0, 290.0], 40.0)),
                ],
            ),
            report_of("crawler1", 1, 0, 10.0, [10.0, 150.0, 0.0]),
            report_of("crawler1", 2, 0, 120.0, [120.0, 140.0, 0.0]),
        ] {
            w.write(&r);
        }
        w.flush();
        let r = replay(&path)?;
        let c = &r.figures.vehicles[0];
        assert_eq!(c.vehicle, "crawler1");
        let clearance = c.min_hazard_clearance_m.unwrap_or(f64::NAN);
        assert!((clearance + 12.0).abs() < 1e-6, "{c:?}");
        assert!(
            verdict::failures(&r.figures)
                .iter()
                .any(|f| f == "crawler1's track entered a soft-substrate hazard (12.0 m inside it)"),
            "{:?}",
            verdict::failures(&r.figures)
        );
        // Its end record round-trips although crawler2 and auv1 never reported (no median, no
        // percentile: before, those were NaN, written as null, and the log no longer read).
        w.write(&Record::End(r.figures.clone()));
        w.flush();
        let again = replay(&path)?;
        assert_eq!(again.logged.as_ref(), Some(&r.figures));
        let svg = dir.join("m.svg");
        let code = command(
            &ReplayArgs {
                log: path,
                svg: Some(svg.clone()),
                view: None,
                foxglove: FoxgloveArgs::default(),
                speed: 1.0,
                zenoh: ZenohSecurityArgs::default(),
            },
            &AtomicBool::new(false),
        )?;
        assert_eq!(code, crate::commands::exit::EXIT_VIOLATIONS);
        let drawn = std::fs::read_to_string(&svg)?;
        std::fs::remove_dir_all(&dir)?;
        assert!(drawn.contains("soft1"), "the hazard is not drawn");
        Ok(())
    }

    #[test]
    fn replaying_dev_zero_is_refused_at_the_line_limit_naming_line_1() {
        // /dev/zero has no newline: the reader stops one byte past the limit instead of
        // filling the memory (it used to abort at 4.3 GB).
        let zero = Path::new("/dev/zero");
        if !zero.exists() {
            return;
        }
        let e = replay(zero)
            .err()
            .map(|e| format!("{e:#}"))
            .unwrap_or_default();
        assert!(
            e.contains("/dev/zero line 1")
                && e.contains(&shoal_common::limits::MAX_LOG_LINE_BYTES.to_string()),
            "{e}"
        );
    }
}
