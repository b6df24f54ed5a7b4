//! Seabed tables read from whole scenarios: grids, hazards, crawler settings.

use super::super::error::ScenarioError;
use super::super::model::Scenario;
use std::path::Path;

const CRAWLER: &str = r#"
name = "c"
[bounds]
min = [0.0, 0.0, 0.0]
max = [100.0, 100.0, 10.0]
[[vehicles]]
id = "dsmv"
kind = "crawler"
start = [1.0, 1.0, 0.5]
goal = [99.0, 99.0, 0.5]
speed_min_mps = 0.5
speed_max_mps = 1.0
max_turn_deg = 35.0
max_pitch_deg = 15.0
[fleet]
d_min_m = 5.0
mission_time_s = 200.0
"#;

const RELIEF: &str = "[seabed.relief]\na = 0.0\nb = 0.5\nc = 0.0\nd = 0.0\ne = 0.0\nf = 0.0\ng = 0.0\nlength_scale_m = 20.0\nheight_scale_m = 0.5\n";

fn message(r: Result<Scenario, ScenarioError>) -> String {
    r.err().map(|e| e.to_string()).unwrap_or_default()
}

#[test]
fn a_crawler_needs_a_seabed_and_gets_one() -> Result<(), ScenarioError> {
    let msg = message(Scenario::parse(CRAWLER, Path::new("s/c.toml")));
    assert!(
        msg.contains("s/c.toml") && msg.contains("vehicles[0].kind") && msg.contains("[seabed]"),
        "{msg}"
    );
    let s = Scenario::parse(&format!("{CRAWLER}{RELIEF}"), Path::new("s/c.toml"))?;
    let t = s.terrain().ok_or(ScenarioError::Parse {
        file: "t".into(),
        message: "no terrain".into(),
    })?;
    // sin(y/20 + 0)·0.5 + 0.5·sin(x/20)·0.5 ranges over ±0.75 m: the lowest point in the
    // box is lifted to 0 (§2.1), so every elevation is in [0, 1.5].
    let mut low = f64::INFINITY;
    for i in 0..=100 {
        for j in 0..=100 {
            low = low.min(t.elevation(i as f64, j as f64));
        }
    }
    assert!(low.abs() < 0.01, "{low}");
    assert!(s.crawler_model(0).is_some());
    Ok(())
}

#[test]
fn bad_seabed_values_name_the_field() {
    let cases = [
            (
                RELIEF.replace("length_scale_m = 20.0", "length_scale_m = 0.0"),
                "seabed.relief.length_scale_m",
            ),
            (
                format!("{RELIEF}[[seabed.mountains]]\ncentre = [5.0, 5.0]\nheight_m = 2.0\nspread_m = [0.0, 3.0]\n"),
                "seabed.mountains[0].spread_m",
            ),
            (
                format!("{RELIEF}[[hazards]]\nid = \"h\"\ncentre = [50.0, 50.0]\nradius_m = -1.0\nheight_m = 2.0\n"),
                "hazards[0].radius_m",
            ),
            (
                format!("{RELIEF}[[hazards]]\nid = \"h\"\ncentre = [2.0, 2.0]\nradius_m = 5.0\nheight_m = 2.0\n"),
                "vehicles[0].start",
            ),
            (
                format!("{RELIEF}[crawler]\nsafe_distance_m = [5.0, 1.0]\n"),
                "crawler.safe_distance_m",
            ),
            (
                "[seabed]\n".to_string(),
                "`seabed`",
            ),
            (
                RELIEF.replace("[seabed.relief]", "[seabed]\nauv_clearance_m = -1.0\n[seabed.relief]"),
                "`seabed.auv_clearance_m` = -1",
            ),
        ];
    for (extra, field) in cases {
        let msg = message(Scenario::parse(
            &format!("{CRAWLER}{extra}"),
            Path::new("s/c.toml"),
        ));
        assert!(
            msg.contains("s/c.toml") && msg.contains(field),
            "{field}: {msg}"
        );
    }
}

#[test]
fn a_malformed_grid_file_is_named_with_its_line() -> Result<(), Box<dyn std::error::Error>> {
    let dir = tempfile::tempdir()?;
    std::fs::write(dir.path().join("bad.csv"), "0,1,2\n0,x,2\n0,1,2\n")?;
    let text = format!("{CRAWLER}[seabed.grid]\nfile = \"bad.csv\"\ncell_m = 50.0\n");
    let msg = message(Scenario::parse(&text, &dir.path().join("c.toml")));
    assert!(
        msg.contains("c.toml") && msg.contains("bad.csv:2") && msg.contains("`x`"),
        "{msg}"
    );
    std::fs::write(dir.path().join("good.csv"), "0,1,2\n0,1,2\n0,1,2\n")?;
    let text = format!("{CRAWLER}[seabed.grid]\nfile = \"good.csv\"\ncell_m = 50.0\n");
    let s = Scenario::parse(&text, &dir.path().join("c.toml"))?;
    // Heights 0, 1, 2 along x at 50 m spacing: 0.02 m per metre.
    let z = s.terrain().map(|t| t.elevation(25.0, 10.0));
    assert!(z.is_some_and(|z| (z - 0.5).abs() < 1e-12), "{z:?}");
    // The file path is stored absolute, so an agent elsewhere finds it too.
    let g = s.seabed.as_ref().and_then(|b| b.grid.as_ref());
    assert!(g.is_some_and(|g| g.file.is_absolute()));
    Ok(())
}

#[test]
fn a_grid_smaller_than_the_area_is_refused() -> Result<(), Box<dyn std::error::Error>> {
    let dir = tempfile::tempdir()?;
    // 2 × 2 nodes 50 m apart: x and y 0..50 m of the 100 × 100 m box.
    std::fs::write(dir.path().join("small.csv"), "0,1\n0,1\n")?;
    let text = format!("{CRAWLER}[seabed.grid]\nfile = \"small.csv\"\ncell_m = 50.0\n");
    let msg = message(Scenario::parse(&text, &dir.path().join("c.toml")));
    assert!(
        msg.contains("c.toml")
            && msg.contains("seabed.grid.file")
            && msg.contains("small.csv")
            && msg.contains("covers x 0.0..50.0 m, y 0.0..50.0 m")
            && msg.contains("x 0.0..100.0 m, y 0.0..100.0 m"),
        "{msg}"
    );
    // 3 × 3 nodes 40 m apart reach 80 m: with the half cell of a centre-registered grid
    // they cover the 100 m box.
    std::fs::write(dir.path().join("centres.csv"), "0,1,2\n0,1,2\n0,1,2\n")?;
    let text = format!("{CRAWLER}[seabed.grid]\nfile = \"centres.csv\"\ncell_m = 40.0\n");
    assert!(Scenario::parse(&text, &dir.path().join("c.toml")).is_ok());
    Ok(())
}
