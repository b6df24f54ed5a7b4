//! Unit tests of `current_grid`.

use super::*;
use approx::assert_abs_diff_eq;
use proptest::prelude::*;

type TestResult = Result<(), Box<dyn std::error::Error>>;

/// x ∈ {0, 10, 20}, y ∈ {0, 20}, z ∈ {−10, 0}, with node indices (i, j, k):
/// u = i + 2j + 4k, v = i·j·k, w = −0.1·i. Trilinear interpolation reproduces these exactly
/// with i = x/10, j = y/20, k = (z + 10)/10, since each is linear in every index separately.
/// The lines are written z-major, backwards, to show the order does not matter.
fn sample_csv() -> String {
    let mut text = String::from("# sample\nX, Y, Z, U, V, W\n\n");
    for i in (0..3).rev() {
        for j in (0..2).rev() {
            for k in (0..2).rev() {
                let (x, y, z) = (10 * i, 20 * j, 10 * k - 10);
                let (u, v, w) = (i + 2 * j + 4 * k, i * j * k, -0.1 * i as f64);
                text += &format!("{x},{y},{z},{u},{v},{w} # node\n");
            }
        }
    }
    text
}

fn sample() -> Result<GridCurrent, CurrentGridError> {
    GridCurrent::from_csv(&sample_csv(), Path::new("c.csv"))
}

#[test]
fn trilinear_at_a_node_a_cell_centre_and_an_edge() -> TestResult {
    let g = sample()?;
    assert_eq!(
        g.axes()[0],
        Axis {
            first: 0.0,
            step: 10.0,
            count: 3
        }
    );
    assert_eq!(g.extent(), ([0.0, 0.0, -10.0], [20.0, 20.0, 0.0]));
    // Node (i, j, k) = (1, 1, 1): u = 1 + 2 + 4, v = 1, w = −0.1.
    let n = g.velocity(&Vec3::new(10.0, 20.0, 0.0));
    assert_abs_diff_eq!(n, Vec3::new(7.0, 1.0, -0.1), epsilon = 1e-12);
    assert_eq!(g.node(1, 1, 1), Some(n));
    // Centre of the second cell along x, (i, j, k) = (1.5, 0.5, 0.5): u = 1.5 + 1 + 2,
    // v = 1.5·0.5·0.5 (the mean of the corners 0, 0, 0, 0, 0, 1, 0, 2 over 8 = 3/8 too),
    // w = −0.15.
    let c = g.velocity(&Vec3::new(15.0, 10.0, -5.0));
    assert_abs_diff_eq!(c, Vec3::new(4.5, 0.375, -0.15), epsilon = 1e-12);
    // On the edge from node (2, 0, 1) to node (2, 1, 1), a quarter of the way: u = 2 + 0.5
    // + 4, v = 2·0.25·1, w = −0.2.
    let e = g.velocity(&Vec3::new(20.0, 5.0, 0.0));
    assert_abs_diff_eq!(e, Vec3::new(6.5, 0.5, -0.2), epsilon = 1e-12);
    // On the edge along x from node (0, 1, 0) to (1, 1, 0): u = 0.3 + 2, v = 0.
    let e = g.velocity(&Vec3::new(3.0, 20.0, -10.0));
    assert_abs_diff_eq!(e, Vec3::new(2.3, 0.0, -0.03), epsilon = 1e-12);
    Ok(())
}

#[test]
fn outside_the_lattice_the_nearest_face_is_used() -> TestResult {
    let g = sample()?;
    // West of the box: the value on the x = 0 face at (y, z) = (10, −5).
    let west = g.velocity(&Vec3::new(-100.0, 10.0, -5.0));
    assert_abs_diff_eq!(west, g.velocity(&Vec3::new(0.0, 10.0, -5.0)));
    assert_abs_diff_eq!(west, Vec3::new(3.0, 0.0, 0.0), epsilon = 1e-12);
    // Beyond the top north-east corner: node (2, 1, 1).
    let corner = g.velocity(&Vec3::new(1e9, 1e9, f64::INFINITY));
    assert_abs_diff_eq!(corner, Vec3::new(8.0, 2.0, -0.2), epsilon = 1e-12);
    // Below the bottom only z is clamped: (i, j, k) = (0.5, 0.5, 0).
    let below = g.velocity(&Vec3::new(5.0, 10.0, -1e6));
    assert_abs_diff_eq!(below, Vec3::new(1.5, 0.0, -0.05), epsilon = 1e-12);
    assert!(g.velocity(&Vec3::new(f64::NAN, 0.0, 0.0)).x.is_nan());
    Ok(())
}

#[test]
fn a_single_value_makes_the_axis_constant() -> TestResult {
    let text = "x,y,z,u,v,w\n0,0,-5,1,0,0\n10,0,-5,3,0,0\n0,10,-5,1,2,0\n10,10,-5,3,2,0\n";
    let g = GridCurrent::from_csv(text, Path::new("layer.csv"))?;
    assert_eq!(
        g.axes()[2],
        Axis {
            first: -5.0,
            step: 0.0,
            count: 1
        }
    );
    for z in [-100.0, -5.0, 0.0, 7.0] {
        let v = g.velocity(&Vec3::new(5.0, 5.0, z));
        assert_abs_diff_eq!(v, Vec3::new(2.0, 1.0, 0.0), epsilon = 1e-12);
    }
    let one = GridCurrent::from_csv("x,y,z,u,v,w\n1,2,3,0.5,-0.5,0\n", Path::new("u.csv"))?;
    let v = one.velocity(&Vec3::new(-7.0, 1e3, 0.0));
    assert_abs_diff_eq!(v, Vec3::new(0.5, -0.5, 0.0));
    Ok(())
}

/// The error message of `text`, which must fail naming `c.csv:line:` and containing `what`.
fn check_err(text: &str, line: usize, what: &str) -> CurrentGridError {
    match GridCurrent::from_csv(text, Path::new("c.csv")) {
        Ok(_) => panic!("accepted, expected an error at line {line} about {what}"),
        Err(e) => {
            let msg = e.to_string();
            assert!(
                msg.contains(&format!("c.csv:{line}:")),
                "line {line}: {msg}"
            );
            assert!(msg.contains(what), "`{what}` missing from: {msg}");
            e
        }
    }
}

const SMALL: &str = "x,y,z,u,v,w\n0,0,0,1,1,0\n10,0,0,1,1,0\n0,10,0,1,1,0\n10,10,0,1,1,0\n";

#[test]
fn errors_name_the_file_the_line_and_the_value() {
    assert!(GridCurrent::from_csv(SMALL, Path::new("c.csv")).is_ok());
    let e = check_err("# forecast\nx,y,z,u,v\n", 2, "found `x,y,z,u,v`");
    assert!(matches!(e, CurrentGridError::Header { .. }));
    check_err("x;y;z;u;v;w\n0;0;0;1;1;0\n", 1, "`x;y;z;u;v;w`");
    let e = check_err("# only a comment\n\n", 2, "found nothing");
    assert!(matches!(e, CurrentGridError::Header { .. }));
    let e = check_err(&SMALL.replace("10,0,0,1,1,0", "10,0,0,1,1"), 3, "found 5");
    assert!(matches!(e, CurrentGridError::FieldCount { .. }));
    let e = check_err(
        &SMALL.replace("0,10,0,1,1,0", "0,10,0,1,x1,0"),
        4,
        "`v`: `x1`",
    );
    assert!(matches!(e, CurrentGridError::NotANumber { .. }));
    check_err(
        &SMALL.replace("0,10,0,1,1,0", "0,10,,1,1,0"),
        4,
        "`z`: nothing",
    );
    let e = check_err(
        &SMALL.replace("10,10,0,1,1,0", "10,10,0,inf,1,0"),
        5,
        "`inf`",
    );
    assert!(matches!(e, CurrentGridError::NonFinite { .. }));
    check_err(
        &SMALL.replace("0,0,0,1,1,0", "NaN,0,0,1,1,0"),
        2,
        "`x`: `NaN`",
    );
    let e = check_err("x,y,z,u,v,w\n# none\n", 2, "at least one node");
    assert!(matches!(e, CurrentGridError::NoNodes { .. }));
}

#[test]
fn duplicate_missing_and_uneven_nodes_are_named() {
    // Line 5 repeats the node of line 3 (a typo for y = 10).
    let e = check_err(
        &SMALL.replace("10,10,0,1,1,0", "10,0,0,2,2,0"),
        5,
        "node x = 10, y = 0, z = 0 is given twice (first at line 3)",
    );
    assert!(matches!(e, CurrentGridError::Duplicate { .. }));
    // No line for (10, 10, 0): reported at the last line.
    let text = SMALL.replace("10,10,0,1,1,0\n", "# end\n");
    let e = check_err(&text, 5, "no line for node x = 10, y = 10, z = 0");
    assert!(e.to_string().contains("2 × 2 × 1 lattice"), "{e}");
    assert!(e.to_string().contains("(3 data lines for 4 nodes)"), "{e}");
    // A missing node in the middle of the storage order.
    let text = "x,y,z,u,v,w\n0,0,0,1,1,0\n10,0,0,1,1,0\n10,10,0,1,1,0\n\
                0,0,1,1,1,0\n10,0,1,1,1,0\n0,10,1,1,1,0\n10,10,1,1,1,0\n";
    check_err(text, 8, "no line for node x = 0, y = 10, z = 0");
    // x = 15 on line 6 is a typo for 20: it is on one line where the others are on two.
    let text = "x,y,z,u,v,w\n0,0,0,0,0,0\n10,0,0,0,0,0\n20,0,0,0,0,0\n\
                0,5,0,0,0,0\n15,5,0,0,0,0\n10,5,0,0,0,0\n";
    let e = check_err(text, 6, "x = 15 breaks the even spacing of the x values");
    assert!(e.to_string().contains("(0, 10, 15, 20)"), "{e}");
    assert!(e.to_string().contains("from 5 to 10"), "{e}");
    // A lattice uneven on every line: the end of the first uneven step is blamed.
    let text = "x,y,z,u,v,w\n0,0,0,0,0,0\n0,0,1,0,0,0\n0,0,3,0,0,0\n";
    let e = check_err(text, 3, "z = 1 breaks");
    assert!(matches!(e, CurrentGridError::Spacing { axis: "z", .. }));
    // Steps within 1e-6 relative pass, a 1e-5 wobble does not.
    let ok = "x,y,z,u,v,w\n0,0,0,0,0,0\n1.0000001,0,0,0,0,0\n2,0,0,0,0,0\n";
    assert!(GridCurrent::from_csv(ok, Path::new("c.csv")).is_ok());
    check_err(&ok.replace("1.0000001", "1.00001"), 3, "x = 1.00001");
    // A span too wide for f64 is refused, not interpolated into NaN.
    let wide = "x,y,z,u,v,w\n-1e308,0,0,0,0,0\n0,0,0,0,0,0\n1e308,0,0,0,0,0\n";
    check_err(wide, 4, "breaks the even spacing");
}

#[test]
fn load_reads_a_file_and_names_an_unreadable_one() -> TestResult {
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("c.csv");
    std::fs::write(&path, format!("\u{feff}{}", sample_csv()))?;
    let g = GridCurrent::load(&path)?;
    assert_eq!(g.file(), path);
    assert!(format!("{g:?}").contains("nodes: 12"));
    let missing = dir.path().join("none.csv");
    match GridCurrent::load(&missing) {
        Err(e @ CurrentGridError::Io { .. }) => {
            assert!(e.to_string().contains("none.csv: cannot read"), "{e}");
            // The OS reason once in the chained report, which is what `main` prints.
            let text = crate::fixtures::chained(&e);
            assert_eq!(text.matches("(os error").count(), 1, "{text}");
        }
        other => panic!("{other:?}"),
    }
    Ok(())
}

proptest! {
    #[test]
    fn parsing_never_panics(text in ".{0,300}") {
        let _ = GridCurrent::from_csv(&text, Path::new("p.csv"));
    }

    #[test]
    fn near_grids_never_panic(
        body in "([-0-9.e,#nai]{0,16}\n){0,12}",
        p in proptest::array::uniform3(-1e3f64..1e3),
    ) {
        let text = format!("x,y,z,u,v,w\n{body}");
        if let Ok(g) = GridCurrent::from_csv(&text, Path::new("p.csv")) {
            let v = g.velocity(&Vec3::from(p));
            prop_assert!(v.iter().all(|c| c.is_finite()));
        }
    }

    #[test]
    fn interpolation_stays_within_the_node_values(
        values in proptest::collection::vec(-2.0f64..2.0, 12),
        p in proptest::array::uniform3(-50f64..50.0),
    ) {
        let mut text = String::from("x,y,z,u,v,w\n");
        for (n, u) in values.iter().enumerate() {
            let (i, j, k) = (n % 3, (n / 3) % 2, n / 6);
            text += &format!("{},{},{},{u},0,0\n", 10 * i, 7 * j, 5 * k);
        }
        let g = GridCurrent::from_csv(&text, Path::new("p.csv"))
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        let u = g.velocity(&Vec3::from(p)).x;
        let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        prop_assert!(u >= lo - 1e-12 && u <= hi + 1e-12, "{u} not in [{lo}, {hi}]");
    }
}
