//! Whether an execution met its figures, in plain words: one place for the live run's summary
//! (`run`) and for `replay`, so the two say the same of the same figures.

use super::fleet::{ExecutionFigures, VehicleFigures};
use crate::report::summary::opt;

/// Why the execution falls short: d_min broken, an executed track inside a hard obstacle (its
/// physical sphere: the inflation is the planner's margin), an AUV's through the seabed, a
/// crawler's into a soft-substrate hazard or (coverage) onto impassable ground, a vehicle that
/// did not arrive in the window. Empty when it met all of them.
pub fn failures(f: &ExecutionFigures) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(d) = f.min_separation_m.filter(|d| *d < f.d_min_m) {
        out.push(format!(
            "separation fell to {d:.1} m, under d_min {:.0} m",
            f.d_min_m
        ));
    }
    for v in &f.vehicles {
        if let Some(c) = v.min_obstacle_clearance_m.filter(|c| *c <= 0.0) {
            out.push(format!(
                "{}'s track entered a hard obstacle ({:.1} m inside its surface)",
                v.vehicle,
                0.0 - c
            ));
        }
        if let Some(c) = v.min_hazard_clearance_m.filter(|c| *c < 0.0) {
            out.push(format!(
                "{}'s track entered a soft-substrate hazard ({:.1} m inside it)",
                v.vehicle, -c
            ));
        }
        if let Some(m) = v.impassable_m.filter(|m| *m > 0.0) {
            out.push(format!(
                "{}'s track crossed {m:.0} m of impassable ground",
                v.vehicle
            ));
        }
        if let Some(c) = v.min_seabed_clearance_m.filter(|c| *c < 0.0) {
            out.push(format!(
                "{}'s track went {:.1} m into the seabed",
                v.vehicle, -c
            ));
        }
        if !v.in_window {
            let planned = v
                .planned_arrival_s
                .map_or(String::new(), |p| format!(" (due at {p:.0} s)"));
            out.push(match v.arrived_s {
                Some(t) => format!(
                    "{} arrived at {t:.0} s, outside the window{planned}",
                    v.vehicle
                ),
                None => match v.fault_s {
                    Some(t) => format!(
                        "{} never arrived: its link reported a fault at {t:.0} s",
                        v.vehicle
                    ),
                    None => format!("{} never arrived", v.vehicle),
                },
            });
        }
    }
    out
}

/// The verdict line: `  MET: …` or `  NOT MET: <every failure>`.
pub fn verdict_line(f: &ExecutionFigures) -> String {
    let failures = failures(f);
    if failures.is_empty() {
        "  MET: d_min kept, no hard obstacle, seabed, hazard or impassable ground entered, every vehicle in the window\n"
            .to_string()
    } else {
        format!("  NOT MET: {}\n", failures.join("; "))
    }
}

/// A coverage mission's line: the area the executed swaths covered; empty for other missions.
pub fn coverage_line(f: &ExecutionFigures) -> String {
    f.coverage.as_ref().map_or(String::new(), |c| {
        format!(
            "  coverage: the executed tracks' swaths cover {:.2} % of the area ({:.2} % of the passable area)\n",
            100.0 * c.ratio,
            100.0 * c.ratio_of_passable
        )
    })
}

/// One vehicle's line of a summary: arrival, tracking error, clearances, reports.
pub fn vehicle_line(v: &VehicleFigures) -> String {
    format!(
        "  {:<8} arrived {:>8} {} | cross-track median {} m, p95 {} m, max {:.2} m | obstacle clearance {}{}{}{} | {} reports, revision {}{}{}\n",
        v.vehicle,
        v.arrived_s.map_or("never".to_string(), |t| format!("{t:.0} s")),
        if v.in_window { "(in window)" } else { "(OUT of window)" },
        opt(v.median_cross_track_m, 2),
        opt(v.p95_cross_track_m, 2),
        v.max_cross_track_m,
        v.min_obstacle_clearance_m
            .map_or("–".to_string(), |c| format!("{c:.1} m")),
        v.min_seabed_clearance_m
            .map_or(String::new(), |c| format!(", above the seabed {c:.1} m")),
        v.min_hazard_clearance_m
            .map_or(String::new(), |c| format!(", hazard clearance {c:.1} m")),
        v.min_ground_clearance_m.map_or(String::new(), |c| format!(
            ", from impassable ground {c:.1} m{}",
            v.impassable_m
                .filter(|m| *m > 0.0)
                .map_or(String::new(), |m| format!(" ({m:.0} m on it)"))
        )),
        v.reports,
        v.revision,
        if v.lost { ", LOST" } else { "" },
        v.fault_s
            .map_or(String::new(), |t| format!(", FAULT since {t:.0} s"))
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vehicle(id: &str) -> VehicleFigures {
        VehicleFigures {
            vehicle: id.to_string(),
            reports: 10,
            arrived_s: Some(420.0),
            planned_arrival_s: Some(420.0),
            in_window: true,
            max_cross_track_m: 2.0,
            p95_cross_track_m: Some(1.5),
            min_obstacle_clearance_m: None,
            min_seabed_clearance_m: None,
            min_hazard_clearance_m: None,
            min_ground_clearance_m: None,
            impassable_m: None,
            median_cross_track_m: Some(1.0),
            revision: 0,
            lost: false,
            fault_s: None,
        }
    }

    fn figures(vehicles: Vec<VehicleFigures>) -> ExecutionFigures {
        ExecutionFigures {
            d_min_m: 10.0,
            min_separation_m: Some(15.0),
            min_separation_at_s: Some(200.0),
            min_separation_pair: None,
            common_arrival_s: 420.0,
            arrival_window_s: 30.0,
            all_arrived_in_window: true,
            vehicles,
            reports: 20,
            latency_median_ms: Some(0.2),
            latency_p99_ms: Some(0.4),
            coverage: None,
        }
    }

    #[test]
    fn the_coverage_line_is_there_only_for_a_coverage_mission() {
        let mut f = figures(vec![vehicle("crawler1")]);
        assert_eq!(coverage_line(&f), "");
        f.coverage = Some(shoal_common::coverage::metrics::CoverageCount {
            ratio: 0.8614,
            ratio_of_passable: 0.95312,
            covered_m2: 861_400.0,
            area_m2: 1_000_000.0,
        });
        assert_eq!(
            coverage_line(&f),
            "  coverage: the executed tracks' swaths cover 86.14 % of the area (95.31 % of the passable area)\n"
        );
    }

    #[test]
    fn a_clean_execution_is_met() {
        let f = figures(vec![vehicle("auv1"), vehicle("crawler1")]);
        assert!(failures(&f).is_empty());
        assert!(verdict_line(&f).starts_with("  MET: "));
    }

    #[test]
    fn every_shortfall_is_named() {
        let mut a = vehicle("auv1");
        a.min_seabed_clearance_m = Some(-2.0);
        a.min_obstacle_clearance_m = Some(0.0);
        let mut c = vehicle("crawler1");
        c.min_hazard_clearance_m = Some(-6.0);
        c.impassable_m = Some(12.4);
        c.in_window = false;
        c.arrived_s = None;
        let mut broken = vehicle("auv2");
        broken.in_window = false;
        broken.arrived_s = None;
        broken.fault_s = Some(36_012.4);
        let mut late = vehicle("crawler2");
        late.in_window = false;
        late.arrived_s = Some(1312.4);
        late.planned_arrival_s = Some(1250.0);
        let mut f = figures(vec![a, c, late, broken]);
        f.min_separation_m = Some(8.25);
        let got = failures(&f);
        assert_eq!(
            got,
            vec![
                "separation fell to 8.2 m, under d_min 10 m",
                "auv1's track entered a hard obstacle (0.0 m inside its surface)",
                "auv1's track went 2.0 m into the seabed",
                "crawler1's track entered a soft-substrate hazard (6.0 m inside it)",
                "crawler1's track crossed 12 m of impassable ground",
                "crawler1 never arrived",
                "crawler2 arrived at 1312 s, outside the window (due at 1250 s)",
                "auv2 never arrived: its link reported a fault at 36012 s",
            ]
        );
        assert!(verdict_line(&f).starts_with("  NOT MET: separation fell"));
    }

    #[test]
    fn a_vehicle_line_shows_only_the_clearances_it_has() {
        let mut c = vehicle("crawler1");
        c.min_hazard_clearance_m = Some(10.14);
        let line = vehicle_line(&c);
        assert!(line.contains("hazard clearance 10.1 m"), "{line}");
        assert!(line.contains("obstacle clearance –"), "{line}");
        assert!(!line.contains("seabed"), "{line}");
        assert!(!line.contains("impassable"), "{line}");
        let mut g = vehicle("crawler2");
        g.min_ground_clearance_m = Some(7.96);
        g.impassable_m = Some(0.0);
        let line = vehicle_line(&g);
        assert!(line.contains("from impassable ground 8.0 m |"), "{line}");
        g.min_ground_clearance_m = Some(0.0);
        g.impassable_m = Some(3.2);
        let line = vehicle_line(&g);
        assert!(
            line.contains("from impassable ground 0.0 m (3 m on it)"),
            "{line}"
        );
        let mut a = vehicle("auv1");
        a.min_seabed_clearance_m = Some(37.46);
        a.lost = true;
        let line = vehicle_line(&a);
        assert!(line.contains("above the seabed 37.5 m"), "{line}");
        assert!(line.ends_with(", LOST\n"), "{line}");
        a.fault_s = Some(600.2);
        assert!(vehicle_line(&a).ends_with(", LOST, FAULT since 600 s\n"));
        a.fault_s = None;
        // No report: no median, no percentile.
        a.median_cross_track_m = None;
        a.p95_cross_track_m = None;
        let line = vehicle_line(&a);
        assert!(line.contains("cross-track median – m, p95 – m"), "{line}");
    }
}
