//! The tangent-plane conversion against published inputs and an independent implementation.
//! Latitude and longitude are those of the tangent plane's point (x, y, 0) — PROJ's inverse of
//! it — and altitude is `origin alt + z` (the module documentation says why).
//!
//! Reference values: PROJ 9.5.1 through pyproj 3.7.2, the pipeline
//! `+proj=unitconvert +xy_in=deg +xy_out=rad +step +proj=cart +ellps=WGS84 +step
//! +proj=topocentric +ellps=WGS84 +lat_0=… +lon_0=… +h_0=…` (forward, or `direction="INVERSE"`),
//! printed with `repr`. pymap3d 3.2.0 (`geodetic2enu`, `enu2geodetic`) agrees with every one to
//! 10⁻⁹ m and 10⁻¹⁴°.

use super::*;

/// Paris, GeographicLib's `example-LocalCartesian.cpp` origin: 48°50′N 2°20′E, h = 0.
const PARIS: GeoOrigin = GeoOrigin::new(48.0 + 50.0 / 60.0, 2.0 + 20.0 / 60.0, 0.0);

/// Metres per degree of latitude, roughly (for turning angle errors into distances).
const M_PER_DEG: f64 = 111_320.0;

/// Horizontal and vertical distance between two [lat, lon, alt], metres (local flat scale).
fn apart(a: [f64; 3], b: [f64; 3]) -> (f64, f64) {
    let north = (a[0] - b[0]) * M_PER_DEG;
    let east = (a[1] - b[1]) * M_PER_DEG * a[0].to_radians().cos();
    (north.hypot(east), (a[2] - b[2]).abs())
}

fn close3(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
    (0..3).all(|i| (a[i] - b[i]).abs() <= tol)
}

#[test]
fn calais_from_paris_is_the_plane_point_on_its_vertical() {
    // Calais, 50.9°N 1.8°E, h = 0 (GeographicLib's forward example, whose ground point PROJ
    // puts at -37518.64 229949.65 -4260.43: 4.3 km below the plane). The plane's point on
    // Calais's vertical, PROJ (its inverse iterated to up = 0, at h = 4263.28 m):
    // -37543.66666933034 229949.65 → 230103.4848372033.
    let p = PARIS.to_local(50.9, 1.8, 0.0);
    let reference = [-37543.66666933034, 230103.4848372033, 0.0];
    assert!(close3(p, reference, 1e-3), "{p:?}");
    let p = PARIS.to_local(50.9, 1.8, -25.0);
    assert!((p[2] + 25.0).abs() < 1e-12, "z is the altitude: {p:?}");
}

#[test]
fn geographiclibs_reverse_example_lands_within_a_millimetre() {
    // (-38 km, 230 km) from Paris (GeographicLib's reverse example, at z = 0). PROJ:
    // 50.89904122745323°N 1.7935282818281935°E; the altitude is the origin's plus z.
    let g = PARIS.to_geodetic([-38e3, 230e3, -4e3]);
    let reference = [50.89904122745323, 1.7935282818281935, -4e3];
    let (horizontal, vertical) = apart(g, reference);
    assert!(
        horizontal < 1e-3 && vertical < 1e-9,
        "{g:?}: {horizontal} m, {vertical} m"
    );
}

#[test]
fn round_trips_hold_to_a_millimetre_at_the_equator_at_60_north_and_over_the_date_line() {
    let origins = [
        GeoOrigin::new(0.0, 0.0, 0.0),
        GeoOrigin::new(60.0, 10.0, 5.0),
        GeoOrigin::new(-45.0, 179.99, 0.0),
        GeoOrigin::new(31.5, -22.0, -2000.0),
    ];
    let points = [
        [0.0; 3],
        [2500.0, -1800.0, -75.0],
        [-4000.0, 3000.0, 12.5],
        [20_000.0, 15_000.0, -5000.0],
    ];
    for o in origins {
        for p in points {
            let [lat, lon, alt] = o.to_geodetic(p);
            assert!(
                (-180.0..=180.0).contains(&lon),
                "{o:?} {p:?}: longitude {lon}"
            );
            let q = o.to_local(lat, lon, alt);
            assert!(close3(p, q, 1e-3), "{o:?}: {p:?} -> {q:?}");
        }
    }
}

#[test]
fn points_match_proj_at_60_north_and_east_of_the_date_line() {
    // 1 km east of 60°N 10°E, h = 5 m. PROJ: 59.99999878434594°N 10.017921131850398°E (at
    // 5.078 m: the plane rises d²/2R above the ellipsoid; the altitude is the origin's).
    let g = GeoOrigin::new(60.0, 10.0, 5.0).to_geodetic([1000.0, 0.0, 0.0]);
    let (h, v) = apart(g, [59.99999878434594, 10.017921131850398, 5.0]);
    assert!(h < 1e-3 && v < 1e-3, "{g:?}");
    // (2.5 km, -1.8 km, -75 m) from 45°S 179.99°E: past the date line. PROJ for (2.5 km,
    // -1.8 km, 0): -45.0161925600543°, -179.9782840244189°.
    let g = GeoOrigin::new(-45.0, 179.99, 0.0).to_geodetic([2500.0, -1800.0, -75.0]);
    let reference = [-45.0161925600543, -179.9782840244189, -75.0];
    let (h, v) = apart(g, reference);
    assert!(h < 1e-3 && v < 1e-3, "{g:?}");
}

/// The equirectangular approximation on a sphere of 6 371 km that the MAVLink link used.
fn sphere_to_geodetic(o: &GeoOrigin, p: [f64; 3]) -> [f64; 3] {
    const R: f64 = 6_371_000.0;
    let east = R * o.lat_deg.to_radians().cos();
    [
        o.lat_deg + (p[1] / R).to_degrees(),
        o.lon_deg + (p[0] / east).to_degrees(),
        o.alt_m + p[2],
    ]
}

#[test]
fn two_km_east_of_paris_the_sphere_is_metres_off_and_the_ellipsoid_is_within_a_centimetre() {
    // PROJ: 48.83333011473296°N 2.3605754880251957°E (h = 0.313 m on the plane; the sea
    // surface stays at the origin's altitude).
    let reference = [48.83333011473296, 2.3605754880251957, 0.0];
    let p = [2000.0, 0.0, 0.0];
    let (sphere, _) = apart(sphere_to_geodetic(&PARIS, p), reference);
    let (ellipsoid, vertical) = apart(PARIS.to_geodetic(p), reference);
    assert!(sphere > 3.0, "the sphere is only {sphere} m off");
    assert!(
        ellipsoid < 0.01 && vertical < 0.01,
        "{ellipsoid} m, {vertical} m"
    );
}

#[test]
fn origins_are_checked_and_read_from_lat_lon_alt() {
    let ok: Result<GeoOrigin, _> = " 31.5, -22.0 ,-2000".parse();
    assert_eq!(ok, Ok(GeoOrigin::new(31.5, -22.0, -2000.0)));
    let o = GeoOrigin::new(-45.25, 179.5, 12.0);
    assert_eq!(o.to_string().parse::<GeoOrigin>(), Ok(o));
    for bad in [
        "",
        "1,2",
        "1,2,3,4",
        "x,2,3",
        "89.5,0,0",
        "0,180.1,0",
        "0,0,-13000",
        "0,0,NaN",
    ] {
        let Err(e) = bad.parse::<GeoOrigin>() else {
            panic!("{bad:?} was accepted");
        };
        assert!(
            e.to_string()
                .starts_with(&format!("{bad:?} is not LAT,LON,ALT (")),
            "{e}"
        );
    }
    assert!(GeoOrigin::new(-89.0, -180.0, 9000.0).check().is_ok());
    let e = GeoOrigin::new(90.0, 0.0, 0.0)
        .check()
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        e.starts_with("lat_deg = 90: must be a latitude in [-89, 89]"),
        "{e}"
    );
    let e = GeoOrigin::new(0.0, f64::NAN, 0.0)
        .check()
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(e.starts_with("lon_deg = NaN"), "{e}");
    let e = GeoOrigin::new(0.0, 0.0, f64::INFINITY)
        .check()
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(e.starts_with("alt_m = inf"), "{e}");
}

#[test]
fn an_origin_table_is_three_named_numbers_and_nothing_else() {
    let o: GeoOrigin = match toml::from_str("lat_deg = 31.5\nlon_deg = -22.0\nalt_m = -2000.0") {
        Ok(o) => o,
        Err(e) => panic!("{e}"),
    };
    assert_eq!(o, GeoOrigin::new(31.5, -22.0, -2000.0));
    assert!(
        toml::from_str::<GeoOrigin>("lat_deg = 1.0\nlon_deg = 2.0\nalt_m = 0.0\nh = 1").is_err()
    );
    assert!(toml::from_str::<GeoOrigin>("lat_deg = 1.0\nlon_deg = 2.0").is_err());
}
