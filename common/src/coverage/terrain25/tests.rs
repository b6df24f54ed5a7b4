//! Tests of the 2.5D map, with hand-computed values.

use super::*;
use crate::coverage::spec::{GaussianPeak, GaussianPit, RandomGaussians, UndulationSpec};
use approx::assert_abs_diff_eq;

type TestResult = Result<(), Box<dyn std::error::Error>>;

/// `z = 0.1·x` on `nx × ny` nodes of `cell` metres.
fn plane(nx: usize, ny: usize, cell: f64) -> Result<HeightGrid, TerrainError> {
    let heights = (0..ny)
        .flat_map(|_| (0..nx).map(move |i| 0.1 * cell * i as f64))
        .collect();
    HeightGrid::new([10.0, -4.0], cell, nx, ny, heights)
}

#[test]
fn plane_slope_is_atan_of_a_tenth_everywhere() -> TestResult {
    let map = TerrainMap25::from_grid(&plane(6, 5, 2.0)?, &TraversalLimits::default())?;
    let expected = 0.1f64.atan().to_degrees(); // 5.7106°
    assert_eq!(map.slope_deg().len(), 30);
    for (k, &s) in map.slope_deg().iter().enumerate() {
        // Corners and edges use one-sided differences, the interior central ones: all 0.1.
        assert_abs_diff_eq!(s, expected, epsilon = 1e-12);
        assert!(!map.impassable()[k]);
    }
    assert_abs_diff_eq!(map.slope_at(13.3, -1.0), expected, epsilon = 1e-12);
    assert_abs_diff_eq!(map.slope_at(-1e6, 1e6), expected, epsilon = 1e-12);
    // Bilinear elevation reproduces the plane inside the grid and clamps outside.
    assert_abs_diff_eq!(map.elevation_at(15.0, 0.0), 0.5, epsilon = 1e-12);
    assert_abs_diff_eq!(map.elevation_at(100.0, 0.0), 1.0, epsilon = 1e-12);
    assert_eq!(map.impassable_fraction(), 0.0);
    assert_eq!(map.clearance_to_impassable(12.0, 0.0), f64::INFINITY);
    assert!(!map.is_no_go(12.0, 0.0));
    // A critical slope below atan(0.1) makes every cell impassable, hence no-go.
    let strict = TraversalLimits {
        critical_slope_deg: 5.0,
        ..TraversalLimits::default()
    };
    let map = TerrainMap25::from_grid(&plane(6, 5, 2.0)?, &strict)?;
    assert_eq!(
        (map.impassable_fraction(), map.no_go_fraction()),
        (1.0, 1.0)
    );
    Ok(())
}

#[test]
fn slope_field_of_a_tilted_plane_in_both_axes() {
    // z = 0.3x − 0.4y: |∇z| = 0.5 at every cell, edges included.
    let (nx, ny, h) = (4, 3, 5.0);
    let z: Vec<f64> = (0..nx * ny)
        .map(|k| 0.3 * h * (k % nx) as f64 - 0.4 * h * (k / nx) as f64)
        .collect();
    for s in slope_field_deg(&z, nx, ny, h) {
        assert_abs_diff_eq!(s, 0.5f64.atan().to_degrees(), epsilon = 1e-12);
    }
}

/// An `n × n` map of `cell`-metre cells whose only impassable cell is `(c, c)`.
fn lone_obstacle(n: usize, c: usize, cell: f64, width: f64) -> TerrainMap25 {
    let mut impassable = vec![false; n * n];
    impassable[c * n + c] = true;
    let limits = TraversalLimits {
        critical_slope_deg: 15.0,
        vehicle_width_m: width,
    };
    TerrainMap25::from_obstacles(
        [0.0, 0.0],
        cell,
        n,
        n,
        vec![0.0; n * n],
        vec![0.0; n * n],
        impassable,
        limits,
        Undulation::Unknown,
    )
}

#[test]
fn lone_steep_cell_dilates_to_exactly_the_disc() {
    // Half-width 2 cells (width 4 cells of 1.5 m): the cells with di² + dj² ≤ 4, i.e. the centre,
    // its 8 neighbours and the 4 cells two steps away along the axes — 13 cells. (±2, ±1) has
    // di² + dj² = 5 and stays free.
    let map = lone_obstacle(11, 5, 1.5, 6.0);
    let mut count = 0;
    for j in 0..11 {
        for i in 0..11 {
            let (di, dj) = (i as i64 - 5, j as i64 - 5);
            let expected = di * di + dj * dj <= 4;
            let [x, y] = map.cell_centre(i, j);
            assert_eq!(map.is_no_go(x, y), expected, "cell ({i}, {j})");
            count += usize::from(expected);
        }
    }
    assert_eq!(count, 13);
    assert_abs_diff_eq!(map.no_go_fraction(), 13.0 / 121.0);
    assert_abs_diff_eq!(map.impassable_fraction(), 1.0 / 121.0);
    assert!(map.is_impassable(7.5, 7.5) && !map.is_impassable(9.0, 7.5));
    // Off the map is no-go.
    assert!(map.is_no_go(-1.0, 3.0) && map.is_no_go(3.0, 16.0));
    // Width 0: only the cell itself.
    assert_abs_diff_eq!(lone_obstacle(11, 5, 1.5, 0.0).no_go_fraction(), 1.0 / 121.0);
}

#[test]
fn clearance_three_cells_from_a_lone_cell_is_three_cells() {
    let h = 2.5;
    let map = lone_obstacle(12, 4, h, 8.0);
    let [ox, oy] = map.cell_centre(4, 4);
    // Three cells east, and three cells north, of the obstacle centre.
    assert_eq!(map.cell_clearance(7, 4), 3.0 * h);
    assert_abs_diff_eq!(map.clearance_to_impassable(ox + 3.0 * h, oy), 3.0 * h);
    assert_abs_diff_eq!(map.clearance_to_impassable(ox, oy + 3.0 * h), 3.0 * h);
    // Off-centre, 3 cells away along a 3-4-5 direction: still exact.
    let d = map.clearance_to_impassable(ox + 1.8 * h, oy + 2.4 * h);
    assert_abs_diff_eq!(d, 3.0 * h, epsilon = 1e-12);
    assert_eq!(map.cell_clearance(4, 4), 0.0);
    assert_eq!(map.cell_clearance(99, 4), f64::INFINITY);
}

/// 400 m × 400 m with 4 m cells: small enough for quick tests.
fn small_spec() -> TerrainSpec {
    TerrainSpec {
        size_m: [400.0, 400.0],
        cell_m: 4.0,
        random_peaks: RandomGaussians {
            count: 3,
            ..RandomGaussians::default()
        },
        random_pits: RandomGaussians {
            count: 2,
            ..RandomGaussians::default()
        },
        ..TerrainSpec::default()
    }
}

#[test]
fn same_seed_same_map_other_seed_differs() -> TestResult {
    let limits = TraversalLimits::default();
    let a = TerrainMap25::generate(&small_spec(), &limits, 2024)?;
    let b = TerrainMap25::generate(&small_spec(), &limits, 2024)?;
    let c = TerrainMap25::generate(&small_spec(), &limits, 2025)?;
    assert_eq!(a, b);
    assert_ne!(a.elevation(), c.elevation());
    assert_ne!(a.seabed().map(|s| &s.peaks), c.seabed().map(|s| &s.peaks));
    assert_eq!(
        (a.nx(), a.ny(), a.cell_m(), a.origin()),
        (100, 100, 4.0, [2.0, 2.0])
    );
    let seabed = a.seabed().ok_or("generated map has a seabed")?;
    assert_eq!((seabed.peaks.len(), seabed.pits.len()), (3, 2));
    for p in &seabed.peaks {
        assert!((0.0..=400.0).contains(&p.centre[0]) && (10.0..=60.0).contains(&p.height_m));
        assert!((20.0..=60.0).contains(&p.sigma_m));
    }
    Ok(())
}

#[test]
fn gaussian_peak_and_pit_reach_their_height_at_the_centre() -> TestResult {
    // Cell centres on even metres (origin −1 m, 2 m cells), λ = 100 m, A = 1.5 m.
    let spec = TerrainSpec {
        origin_m: [-1.0, -1.0],
        size_m: [1000.0, 1000.0],
        peaks: vec![GaussianPeak {
            centre: [200.0, 300.0],
            height_m: 40.0,
            sigma_m: 30.0,
        }],
        pits: vec![GaussianPit {
            centre: [600.0, 650.0],
            depth_m: 25.0,
            sigma_m: 20.0,
        }],
        ..TerrainSpec::default()
    };
    let map = TerrainMap25::generate(&spec, &TraversalLimits::default(), 7)?;
    // (200, 300) is a lattice point of every octave, where the Perlin part is exactly 0.
    assert_eq!(map.undulation_at(200.0, 300.0), 0.0);
    assert_abs_diff_eq!(map.elevation_at(200.0, 300.0), 40.0, epsilon = 1e-9);
    // (600, 650) is not: the pit's floor is −25 m within the noise bound A.
    let floor = map.elevation_at(600.0, 650.0);
    assert!((floor + 25.0).abs() <= 1.5, "{floor}");
    assert_abs_diff_eq!(
        floor,
        -25.0 + map.undulation_at(600.0, 650.0),
        epsilon = 1e-9
    );
    // One σ from the peak: 40·e^{−1/2} (+ the undulation there).
    let one_sigma = map.elevation_at(230.0, 300.0) - map.undulation_at(230.0, 300.0);
    assert_abs_diff_eq!(one_sigma, 40.0 * (-0.5f64).exp(), epsilon = 1e-9);
    // Flanks: steepest slope atan(40/30·e^{−1/2}) ≈ 39° at r = σ; impassable there, summit not.
    assert!(map.is_impassable(230.0, 300.0) && map.is_no_go(230.0, 300.0));
    assert!(!map.is_impassable(200.0, 300.0));
    assert!(map.slope_at(230.0, 300.0) > 35.0);
    // The summit is enclosed by the impassable ring (r ≈ 10–60 m for a 15° limit).
    let summit_clearance = map.clearance_to_impassable(200.0, 300.0);
    assert!(
        (4.0..20.0).contains(&summit_clearance),
        "{summit_clearance}"
    );
    let fraction = map.impassable_fraction();
    assert!(fraction > 0.0 && fraction < 0.05, "{fraction}");
    Ok(())
}

#[test]
fn default_undulation_is_minor_and_queryable() -> TestResult {
    let map = TerrainMap25::generate(&TerrainSpec::default(), &TraversalLimits::default(), 1)?;
    assert_eq!((map.nx(), map.ny()), (500, 500));
    let steepest = map.slope_deg().iter().fold(0.0f64, |a, &b| a.max(b));
    // About 3° over seeds 0–4; the 15° critical slope is far away.
    assert!(steepest < 6.0, "steepest default undulation {steepest}°");
    assert_eq!(map.impassable_fraction(), 0.0);
    assert_eq!(map.no_go_fraction(), 0.0);
    // Without peaks and pits, the elevation at a cell centre *is* the undulation there.
    for (i, j) in [(0, 0), (137, 411), (499, 250)] {
        let [x, y] = map.cell_centre(i, j);
        let k = map.index(i, j).ok_or("cell exists")?;
        assert_eq!(map.elevation()[k], map.undulation_at(x, y));
        assert!(map.undulation_at(x, y).abs() <= 1.5);
    }
    // The gradient is the tracking layer's disturbance; it matches differences.
    let (u, [gx, gy]) = map.undulation_gradient_at(321.7, 54.2);
    let d = 1e-4;
    let dx = (map.undulation_at(321.7 + d, 54.2) - map.undulation_at(321.7 - d, 54.2)) / (2.0 * d);
    let dy = (map.undulation_at(321.7, 54.2 + d) - map.undulation_at(321.7, 54.2 - d)) / (2.0 * d);
    assert_eq!(u, map.undulation_at(321.7, 54.2));
    assert_abs_diff_eq!(gx, dx, epsilon = 1e-8);
    assert_abs_diff_eq!(gy, dy, epsilon = 1e-8);
    Ok(())
}

#[test]
fn spec_reads_toml_with_defaults_and_rejects_unknown_or_bad_fields() -> TestResult {
    let spec: TerrainSpec = toml::from_str(
        "cell_m = 5.0\n[undulation]\namplitude_m = 0.5\n\
         [random_peaks]\ncount = 4\n[[pits]]\ncentre = [10.0, 20.0]\ndepth_m = 3.0\nsigma_m = 8.0\n",
    )?;
    assert_eq!(spec.size_m, [1000.0, 1000.0]);
    assert_eq!(
        spec.undulation,
        UndulationSpec {
            amplitude_m: 0.5,
            ..UndulationSpec::default()
        }
    );
    assert_eq!(
        (spec.random_peaks.count, spec.random_peaks.sigma_m),
        (4, [20.0, 60.0])
    );
    assert_eq!(spec.pits.len(), 1);
    assert!(toml::from_str::<TerrainSpec>("cell = 5.0").is_err());
    assert!(toml::from_str::<TerrainSpec>("[undulation]\noctave = 2").is_err());
    let limits: TraversalLimits = toml::from_str("vehicle_width_m = 6.0")?;
    assert_eq!(
        (limits.critical_slope_deg, limits.dilation_radius_m()),
        (15.0, 3.0)
    );
    assert!(toml::from_str::<TraversalLimits>("width = 6.0").is_err());

    let ok = TraversalLimits::default();
    let bad = |edit: fn(&mut TerrainSpec)| {
        let mut s = small_spec();
        edit(&mut s);
        TerrainMap25::generate(&s, &ok, 0)
            .map(|_| ())
            .map_err(|e| e.to_string())
    };
    assert!(bad(|_| ()).is_ok());
    let msg = bad(|s| s.cell_m = 0.0).err().unwrap_or_default();
    assert!(msg.contains("`cell_m`"), "{msg}");
    let msg = bad(|s| s.random_pits.sigma_m = [5.0, 1.0])
        .err()
        .unwrap_or_default();
    assert!(
        msg.contains("random_pits.sigma_m") && msg.contains("min 5 > max 1"),
        "{msg}"
    );
    assert!(bad(|s| s.size_m[1] = f64::NAN).is_err());
    assert!(bad(|s| s.size_m[0] = 6.0).is_err()); // fewer than two 4 m cells
    assert!(bad(|s| s.undulation.wavelength_m = 0.0).is_err());
    assert!(bad(|s| s.random_peaks.count = 1_000_000).is_err());
    assert!(bad(|s| s.peaks.push(GaussianPeak {
        centre: [1.0, 1.0],
        height_m: 5.0,
        sigma_m: 0.0
    }))
    .is_err());
    let too_fine = bad(|s| s.cell_m = 0.01).err().unwrap_or_default();
    assert!(too_fine.contains("cell limit"), "{too_fine}");
    for limits in [
        TraversalLimits {
            critical_slope_deg: 90.0,
            ..ok
        },
        TraversalLimits {
            vehicle_width_m: -1.0,
            ..ok
        },
    ] {
        assert!(TerrainMap25::generate(&small_spec(), &limits, 0).is_err());
    }
    Ok(())
}

#[test]
fn from_file_grid_and_back() -> TestResult {
    let dir = tempfile::tempdir()?;
    // A 4 × 3 ESRI grid, 10 m cells, rising 1 m per cell eastward (slope atan 0.1).
    let path = dir.path().join("ridge.asc");
    std::fs::write(
        &path,
        "ncols 4\nnrows 3\nxllcenter 0\nyllcenter 0\ncellsize 10\n\
         0 1 2 3\n0 1 2 3\n0 1 2 3\n",
    )?;
    let map = TerrainMap25::load(&path, &TraversalLimits::default())?;
    assert_eq!((map.nx(), map.ny(), map.cell_m()), (4, 3, 10.0));
    assert_abs_diff_eq!(
        map.slope_at(15.0, 5.0),
        0.1f64.atan().to_degrees(),
        epsilon = 1e-12
    );
    assert_eq!(map.undulation_at(15.0, 5.0), 0.0);
    assert!(map.seabed().is_none());
    let grid = map.to_height_grid()?;
    assert_abs_diff_eq!(grid.elevation(25.0, 10.0), map.elevation_at(25.0, 10.0));
    // A missing file is an error, not a panic.
    let missing = TerrainMap25::load(&dir.path().join("none.asc"), &TraversalLimits::default());
    assert!(matches!(
        missing,
        Err(Terrain25Error::Grid(TerrainError::Io { .. }))
    ));
    Ok(())
}
