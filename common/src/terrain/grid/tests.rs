//! Unit tests of `terrain::grid`.

use super::super::Terrain;
use super::*;
use approx::assert_abs_diff_eq;
use proptest::prelude::*;

type TestResult = Result<(), Box<dyn std::error::Error>>;

#[test]
fn slope_of_ten_degree_plane_grid() -> TestResult {
    let rise = 10.0 * 10f64.to_radians().tan();
    let grid = HeightGrid::new([0.0, 0.0], 10.0, 2, 2, vec![0.0, rise, 0.0, rise])?;
    let t = Terrain::Grid(grid);
    assert_abs_diff_eq!(t.slope_deg(5.0, 5.0), 10.0, epsilon = 1e-9);
    assert_abs_diff_eq!(t.slope_deg(1.0, 9.0), 10.0, epsilon = 1e-9);
    assert_abs_diff_eq!(
        t.crawler_z(5.0, 5.0, 1.5),
        rise / 2.0 + 1.5,
        epsilon = 1e-12
    );
    Ok(())
}

#[test]
fn bilinear_centre_and_clamping() -> TestResult {
    // South row 1, 2; north row 3, 4.
    let g = HeightGrid::new([100.0, 200.0], 2.0, 2, 2, vec![1.0, 2.0, 3.0, 4.0])?;
    assert_abs_diff_eq!(g.elevation(101.0, 201.0), 2.5, epsilon = 1e-12);
    assert_abs_diff_eq!(g.elevation(0.0, 0.0), 1.0, epsilon = 1e-12);
    assert_abs_diff_eq!(g.elevation(1e9, 1e9), 4.0, epsilon = 1e-12);
    assert_abs_diff_eq!(g.elevation(-50.0, 201.0), 2.0, epsilon = 1e-12);
    assert_eq!(g.gradient(-50.0, 201.0).0, 0.0);
    assert_abs_diff_eq!(g.gradient(-50.0, 201.0).1, 1.0, epsilon = 1e-12);
    assert!(g.elevation(f64::NAN, 0.0).is_nan());
    assert!(HeightGrid::new([0.0, 0.0], 1.0, 2, 2, vec![1.0; 3]).is_err());
    assert!(HeightGrid::new([0.0, 0.0], 0.0, 2, 2, vec![1.0; 4]).is_err());
    Ok(())
}

#[test]
fn csv_three_by_three_first_line_is_north() -> TestResult {
    let text = "# depth survey\n1, 2, 3\n\n4,5,6 # middle\n7,8,9\n";
    let g = HeightGrid::from_csv(text, Path::new("a.csv"), 1.0, [0.0, 0.0])?;
    assert_eq!((g.cols, g.rows), (3, 3));
    assert_eq!(g.node(0, 0), Some(7.0));
    assert_eq!(g.node(2, 2), Some(3.0));
    assert_abs_diff_eq!(g.elevation(0.0, 0.0), 7.0, epsilon = 1e-12);
    assert_abs_diff_eq!(g.elevation(2.0, 2.0), 3.0, epsilon = 1e-12);
    // Cell centre between rows 0 (7 8 9) and 1 (4 5 6), cols 1–2: mean of 8, 9, 5, 6.
    assert_abs_diff_eq!(g.elevation(1.5, 0.5), 7.0, epsilon = 1e-12);
    Ok(())
}

const ESRI: &str = "NCOLS 3\nnrows 3\nxllcorner 100\nYllCorner 200\ncellsize 10\n\
                    NODATA_value -9999\n1 2 3\n4 5 6\n7 8 9\n";

#[test]
fn esri_three_by_three_corner_and_centre() -> TestResult {
    let g = HeightGrid::from_esri_ascii(ESRI, Path::new("b.asc"))?;
    assert_eq!((g.cols, g.rows, g.cell_m), (3, 3, 10.0));
    assert_eq!(g.origin, [105.0, 205.0]);
    assert_abs_diff_eq!(g.elevation(105.0, 205.0), 7.0, epsilon = 1e-12);
    assert_abs_diff_eq!(g.elevation(125.0, 225.0), 3.0, epsilon = 1e-12);
    let centre = ESRI.replace("xllcorner", "xllcenter");
    let g = HeightGrid::from_esri_ascii(&centre, Path::new("b.asc"))?;
    assert_eq!(g.origin, [100.0, 205.0]);
    Ok(())
}

/// The error message of `result`, which must name `file:line` and contain `text`.
fn check_err(result: Result<HeightGrid, TerrainError>, file: &str, line: usize, text: &str) {
    match result {
        Ok(_) => panic!("expected an error at {file}:{line} about {text}"),
        Err(e) => {
            let msg = e.to_string();
            assert!(msg.contains(&format!("{file}:{line}:")), "{msg}");
            assert!(msg.contains(text), "`{text}` missing from: {msg}");
        }
    }
}

#[test]
fn csv_errors_name_file_line_and_text() {
    let csv = |text: &str| HeightGrid::from_csv(text, Path::new("s.csv"), 1.0, [0.0, 0.0]);
    check_err(
        csv("1,2,3\n4,5\n"),
        "s.csv",
        2,
        "expected 3 values, found 2",
    );
    check_err(csv("1,2\n# c\nx7,4\n"), "s.csv", 3, "`x7`");
    check_err(csv("1,2\n3,inf\n"), "s.csv", 2, "`inf`");
    check_err(csv("1,2\n3,\n"), "s.csv", 2, "(empty)");
    check_err(csv("\n1,2,3\n"), "s.csv", 2, "3 columns × 1 rows");
    check_err(csv("1\n2\n"), "s.csv", 1, "1 columns × 2 rows");
    check_err(csv("# nothing\n"), "s.csv", 1, "need at least 2×2");
    let bad_cell = HeightGrid::from_csv("1,2\n3,4\n", Path::new("s.csv"), 0.0, [0.0, 0.0]);
    assert!(matches!(bad_cell, Err(TerrainError::BadParameter { .. })));
}

#[test]
fn esri_errors_name_file_line_and_text() {
    let asc = |text: &str| HeightGrid::from_esri_ascii(text, Path::new("g.asc"));
    let no_cell = ESRI.replace("cellsize 10\n", "");
    check_err(asc(&no_cell), "g.asc", 6, "`cellsize`");
    let no_y = ESRI.replace("YllCorner 200\n", "");
    check_err(asc(&no_y), "g.asc", 6, "`yllcorner`");
    check_err(
        asc(&ESRI.replace("nrows 3", "nrows 4")),
        "g.asc",
        9,
        "nrows 4",
    );
    check_err(asc(&format!("{ESRI}1 2 3\n")), "g.asc", 10, "nrows 3");
    check_err(asc(&ESRI.replace("4 5 6", "4 5")), "g.asc", 8, "found 2");
    check_err(
        asc(&ESRI.replace("4 5 6", "4 5 6 0")),
        "g.asc",
        8,
        "found 4",
    );
    check_err(
        asc(&ESRI.replace("cellsize 10", "cellsize -1")),
        "g.asc",
        5,
        "`-1`",
    );
    check_err(
        asc(&ESRI.replace("cellsize 10", "cellsize 0")),
        "g.asc",
        5,
        "`0`",
    );
    let nodata = asc(&ESRI.replace("6\n", "-9999\n"));
    check_err(nodata, "g.asc", 8, "row 2, column 3 is NODATA (`-9999`)");
    check_err(
        asc(&ESRI.replace("NCOLS 3", "ncols three")),
        "g.asc",
        1,
        "`three`",
    );
    check_err(asc(&ESRI.replace("8 9", "NaN 9")), "g.asc", 9, "`NaN`");
    check_err(asc(&ESRI.replace("8 9", "8x 9")), "g.asc", 9, "`8x`");
    check_err(
        asc(&ESRI.replace("NCOLS 3", "ncols 1")),
        "g.asc",
        1,
        "1 columns",
    );
    check_err(
        asc(&ESRI.replace("nrows 3", "nrows 0")),
        "g.asc",
        2,
        "0 rows",
    );
    check_err(
        asc(&ESRI.replace("cellsize 10", "cellsize 10 m")),
        "g.asc",
        5,
        "10 m",
    );
    let both = ESRI.replace("cellsize", "xllcenter 3\ncellsize");
    check_err(asc(&both), "g.asc", 5, "xllcenter");
}

#[test]
fn load_chooses_parser_by_extension() -> TestResult {
    let dir = std::env::temp_dir().join(format!("shoal-terrain-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let asc = dir.join("g.ASC");
    std::fs::write(&asc, ESRI)?;
    assert_eq!(HeightGrid::load(&asc)?.origin, [105.0, 205.0]);
    let csv = dir.join("g.csv");
    std::fs::write(&csv, "1,2\n3,4\n")?;
    let g = HeightGrid::load(&csv)?;
    assert_eq!(
        (g.origin, g.cell_m, g.node(0, 0)),
        ([0.0, 0.0], 1.0, Some(3.0))
    );
    let missing = HeightGrid::load(&dir.join("none.csv"));
    match missing {
        // The OS reason once in the chained report, which is what `main` prints.
        Err(e @ TerrainError::Io { .. }) => {
            let text = crate::fixtures::chained(&e);
            assert_eq!(text.matches("(os error").count(), 1, "{text}");
            assert!(text.contains("none.csv: cannot read: "), "{text}");
        }
        other => panic!("{other:?}"),
    }
    let txt = HeightGrid::load(&dir.join("g.txt"));
    assert!(matches!(txt, Err(TerrainError::UnknownFormat { .. })));
    std::fs::remove_dir_all(&dir)?;
    Ok(())
}

proptest! {
    #[test]
    fn parsers_never_panic(text in ".{0,300}") {
        let _ = HeightGrid::from_csv(&text, Path::new("p.csv"), 1.0, [0.0, 0.0]);
        let _ = HeightGrid::from_esri_ascii(&text, Path::new("p.asc"));
    }

    #[test]
    fn parsers_never_panic_on_near_grids(
        text in "((ncols|nrows|xllcorner|yllcenter|cellsize|nodata_value) [-0-9.e]{1,4}\n){0,7}([-0-9 ,.#naif]{0,12}\n){0,5}"
    ) {
        let _ = HeightGrid::from_csv(&text, Path::new("p.csv"), 1.0, [0.0, 0.0]);
        if let Ok(g) = HeightGrid::from_esri_ascii(&text, Path::new("p.asc")) {
            let t = Terrain::Grid(g);
            let _ = (t.elevation(1.0, 2.0), t.slope_deg(-1e9, 1e9));
        }
    }
}
