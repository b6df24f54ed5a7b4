//! `[currents] model = "grid"`: a scenario reads its current field from a CSV grid next to it.

use std::path::{Path, PathBuf};

use shoal_common::geometry::Vec3;
use shoal_common::scenario::{CurrentModel, Scenario};

type TestResult = Result<(), Box<dyn std::error::Error>>;

const DEPTH_DECAY: &str =
    "model = \"depth-decay\"    # eq. (2)\nsurface_velocity_mps = [-1.0, -1.0]";

/// `scenarios/epa-pso.toml` with its `[currents]` table body replaced by `currents`.
fn epa_pso_with(currents: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/epa-pso.toml");
    let text = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(text.contains(DEPTH_DECAY), "{} changed", path.display());
    text.replacen(DEPTH_DECAY, currents, 1)
}

/// A 2 × 2 × 2 grid over the whole 100 m box: u = 0.01·x, v = −0.5 + 0.01·z, w = 0.001·x·y/100
/// at the nodes (the last is a product, only trilinear in the cell).
const GRID: &str = "\
# test current
x,y,z,u,v,w
0,0,0,0,-0.5,0
100,0,0,1,-0.5,0
0,100,0,0,-0.5,0
100,100,0,1,-0.5,0.1
0,0,100,0,0.5,0
100,0,100,1,0.5,0
0,100,100,0,0.5,0
100,100,100,1,0.5,0.1
";

/// Writes the scenario (as `s.toml`) and the grid (as `currents.csv`) into a fresh directory.
fn write(dir: &Path, scenario: &str) -> std::io::Result<PathBuf> {
    std::fs::write(dir.join("currents.csv"), GRID)?;
    let path = dir.join("s.toml");
    std::fs::write(&path, scenario)?;
    Ok(path)
}

#[test]
fn a_grid_current_is_loaded_and_interpolated() -> TestResult {
    let dir = tempfile::tempdir()?;
    let path = write(
        dir.path(),
        &epa_pso_with("model = \"grid\"\nfile = \"currents.csv\""),
    )?;
    let s = Scenario::load(&path)?;
    let c = s.currents.as_ref().ok_or("no [currents]")?;
    assert_eq!(c.model, CurrentModel::Grid);
    assert_eq!(c.surface_velocity_mps, None);
    // The file is stored absolute, so a copy of the scenario sent to an agent finds it.
    assert_eq!(
        c.file.as_deref(),
        Some(dir.path().join("currents.csv").as_path())
    );
    let field = c.field(s.bounds.min[2], s.bounds.max[2]);
    // (25, 50, 75): u = 0.25, v = −0.5 + 0.75, w = 0.1·0.25·0.5.
    let v = field.velocity(&Vec3::new(25.0, 50.0, 75.0));
    assert!((v - Vec3::new(0.25, 0.25, 0.0125)).norm() < 1e-12, "{v:?}");
    // Above the box, the top face.
    let top = field.velocity(&Vec3::new(100.0, 100.0, 500.0));
    assert!((top - Vec3::new(1.0, 0.5, 0.1)).norm() < 1e-12, "{top:?}");
    // A scenario sent over the wire as TOML and parsed again elsewhere loads the same grid.
    let again = Scenario::parse(&toml::to_string(&s)?, Path::new("/elsewhere/s.toml"))?;
    assert_eq!(again.currents, s.currents);
    Ok(())
}

#[test]
fn a_missing_or_bad_grid_file_is_an_error_naming_currents_file() -> TestResult {
    let dir = tempfile::tempdir()?;
    let path = write(
        dir.path(),
        &epa_pso_with("model = \"grid\"\nfile = \"nowhere.csv\""),
    )?;
    let msg = Scenario::load(&path).err().map(|e| e.to_string());
    let msg = msg.ok_or("a missing grid file was accepted")?;
    assert!(
        msg.contains("s.toml")
            && msg.contains("currents.file")
            && msg.contains("nowhere.csv\"")
            && msg.contains("cannot be read"),
        "{msg}"
    );
    // A bad value in the grid is named with the grid's line.
    std::fs::write(
        dir.path().join("bad.csv"),
        GRID.replace("0,0.5,0\n", "0,0.5,oops\n"),
    )?;
    let path = write(
        dir.path(),
        &epa_pso_with("model = \"grid\"\nfile = \"bad.csv\""),
    )?;
    let msg = Scenario::load(&path).err().map(|e| e.to_string());
    let msg = msg.ok_or("a bad grid file was accepted")?;
    assert!(
        msg.contains("currents.file") && msg.contains("bad.csv:7:") && msg.contains("`oops`"),
        "{msg}"
    );
    Ok(())
}

#[test]
fn keys_must_fit_the_model() -> TestResult {
    let cases = [
        ("model = \"grid\"", "currents.file", "(missing)"),
        (
            "model = \"grid\"\nfile = \"currents.csv\"\nsurface_velocity_mps = [1.0, 0.0]",
            "currents.surface_velocity_mps",
            "depth-decay",
        ),
        (
            "model = \"depth-decay\"\nsurface_velocity_mps = [1.0, 0.0]\nfile = \"currents.csv\"",
            "currents.file",
            "\"grid\"",
        ),
        (
            "model = \"depth-decay\"",
            "currents.surface_velocity_mps",
            "(missing)",
        ),
        ("model = \"grid\"\ngrid = 3", "grid", "unknown field"),
    ];
    for (currents, field, what) in cases {
        let dir = tempfile::tempdir()?;
        let path = write(dir.path(), &epa_pso_with(currents))?;
        let msg = Scenario::load(&path).err().map(|e| e.to_string());
        let msg = msg.ok_or_else(|| format!("{currents:?} was accepted"))?;
        assert!(
            msg.contains(field) && msg.contains(what),
            "{currents:?}: {msg}"
        );
    }
    // The shipped depth-decay form still loads.
    let dir = tempfile::tempdir()?;
    let path = write(dir.path(), &epa_pso_with(DEPTH_DECAY))?;
    let s = Scenario::load(&path)?;
    let c = s.currents.as_ref().ok_or("no [currents]")?;
    assert_eq!(c.surface_velocity_mps, Some([-1.0, -1.0]));
    let v = c.field(0.0, 100.0).velocity(&Vec3::new(0.0, 0.0, 100.0));
    assert!((v - Vec3::new(-1.0, -1.0, 0.0)).norm() < 1e-12, "{v:?}");
    Ok(())
}
