//! The scenario frame on the Earth: a scenario's local metres (x east, y north, z up) tied to
//! WGS-84 latitude and longitude by the local east-north-up (ENU) tangent plane at a geodetic
//! origin, the scenario point (0, 0, 0), and z tied to altitude: `alt = origin alt + z`.
//!
//! The conversion is exact on the WGS-84 ellipsoid (NIMA TR8350.2: a = 6 378 137 m,
//! 1/f = 298.257223563): geodetic → Earth-centred Earth-fixed (ECEF) → rotated into the
//! origin's east, north and up axes, and back; what GeographicLib calls `LocalCartesian`. The
//! `map_3d` crate (a port of pymap3d) does both steps; its ECEF → geodetic step is You's closed
//! form with one correction (J. Surveying Eng. 126(1), 2000), sub-millimetre at any depth or
//! height a vehicle reaches (the tests check it against PROJ). A sphere of the mean radius, the
//! flat-earth shortcut autopilots use for their local frames, is off by metres at 2 km: the
//! Earth's radii of curvature run from 6 335 to 6 400 km.
//!
//! **Altitude.** MAVLink's global frames carry altitude above mean sea level (AMSL, the geoid);
//! WGS-84 heights are above the ellipsoid, which lies N below the geoid (the geoid separation,
//! −106 m to +85 m in EGM2008). The origin's `alt_m` (AMSL) is used as the ellipsoidal height of
//! the tangent plane, i.e. N is taken as 0 there. Every height out of [`GeoOrigin::to_geodetic`]
//! is then AMSL again (N varies by centimetres over a scenario), and the horizontal positions
//! move by the relative scale N/R ≤ 106 m / 6 371 km ≈ 1.7·10⁻⁵: 3 cm at 2 km from the origin.
//! RFC 7946 (GeoJSON) asks for ellipsoidal heights: a reader that needs them adds N from a geoid
//! model at the origin.
//!
//! **Curvature.** The tangent plane is flat and the sea is not: a point of the plane d metres
//! from the origin is d²/2R higher than the origin (0.3 m at 2 km, 7.8 m at 10 km). A scenario's
//! z is a depth or a height (its `bounds.max[2]` is the sea surface, which follows the Earth),
//! so z is not taken along the plane's "up" but as altitude: `(x, y)` is a point of the tangent
//! plane at the origin's height, placed on the Earth by the latitude and longitude of that
//! point (its vertical), and `z` is `alt − origin alt` there — the local-level frame of
//! autopilots, on the ellipsoid. Had z been the plane's up, an AUV at z = −10 m 10 km out
//! would be sent 2.2 m *above* the sea.

use std::fmt;
use std::ops::RangeInclusive;
use std::str::FromStr;

use map_3d::Ellipsoid;
use serde::{Deserialize, Serialize};

/// Largest |latitude| of an origin, degrees. ENU is exact everywhere but at a pole, where east
/// and north are undefined; within a degree of it (111 km) they turn by a degree every 2 km of
/// easting and the scenario box may reach over the pole. 89° is also what the MAVLink link has
/// always accepted.
pub const MAX_ABS_LAT_DEG: f64 = 89.0;

/// Altitudes of an origin (AMSL of the scenario's z = 0), metres: from below the deepest sea
/// floor (Challenger Deep, 10 935 m) to above the highest summit (8 849 m). Anything outside is
/// a sign slip or a depth given where an altitude was meant.
pub const ALT_RANGE_M: RangeInclusive<f64> = -12_000.0..=9_000.0;

/// Geodetic position of the scenario point (0, 0, 0): what ties a scenario (and its plans) to the
/// Earth. Scenario files give it as an `[origin]` table, the agent and `export` as
/// `LAT,LON,ALT`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GeoOrigin {
    /// Latitude, degrees north (WGS-84).
    pub lat_deg: f64,
    /// Longitude, degrees east (WGS-84).
    pub lon_deg: f64,
    /// Altitude of the scenario's z = 0 above mean sea level, metres (negative below it), used
    /// as the tangent plane's ellipsoidal height (see the module documentation).
    pub alt_m: f64,
}

impl GeoOrigin {
    /// The origin at `lat_deg`, `lon_deg` (degrees), `alt_m` (metres above mean sea level).
    pub const fn new(lat_deg: f64, lon_deg: f64, alt_m: f64) -> GeoOrigin {
        GeoOrigin {
            lat_deg,
            lon_deg,
            alt_m,
        }
    }

    /// Whether the origin can anchor a tangent plane: latitude within [`MAX_ABS_LAT_DEG`],
    /// longitude in [−180, 180], altitude in [`ALT_RANGE_M`]; the error names the value.
    pub fn check(&self) -> Result<(), BadOrigin> {
        match self.first_bad() {
            None => Ok(()),
            Some((field, value, reason)) => Err(BadOrigin {
                field,
                value,
                reason,
            }),
        }
    }

    /// The first out-of-range value: its field name (as in a scenario's `[origin]` table), the
    /// value and why it is refused.
    pub(crate) fn first_bad(&self) -> Option<(&'static str, f64, String)> {
        // Written as ranges so that NaN is refused too.
        if !(-MAX_ABS_LAT_DEG..=MAX_ABS_LAT_DEG).contains(&self.lat_deg) {
            return Some((
                "lat_deg",
                self.lat_deg,
                format!(
                    "must be a latitude in [-{MAX_ABS_LAT_DEG}, {MAX_ABS_LAT_DEG}] degrees (east and north are undefined at a pole)"
                ),
            ));
        }
        if !(-180.0..=180.0).contains(&self.lon_deg) {
            return Some((
                "lon_deg",
                self.lon_deg,
                "must be a longitude in [-180, 180] degrees".into(),
            ));
        }
        if !ALT_RANGE_M.contains(&self.alt_m) {
            return Some((
                "alt_m",
                self.alt_m,
                format!(
                    "must be an altitude above mean sea level in [{}, {}] metres (negative below the sea surface)",
                    ALT_RANGE_M.start(),
                    ALT_RANGE_M.end()
                ),
            ));
        }
        None
    }

    /// Whether `other` is this origin to within `deg` degrees of latitude and longitude and
    /// `alt_m` metres of altitude (two copies of one origin read from different places).
    pub fn agrees_with(&self, other: &GeoOrigin, deg: f64, alt_m: f64) -> bool {
        (self.lat_deg - other.lat_deg).abs() <= deg
            && (self.lon_deg - other.lon_deg).abs() <= deg
            && (self.alt_m - other.alt_m).abs() <= alt_m
    }

    /// Scenario point `p` (x east, y north, z up, metres) as [latitude °, longitude ° in
    /// [−180, 180], altitude m AMSL] (see the module documentation for z).
    pub fn to_geodetic(&self, p: [f64; 3]) -> [f64; 3] {
        let (lat, lon, _) = map_3d::enu2geodetic(
            p[0],
            p[1],
            0.0,
            self.lat_deg.to_radians(),
            self.lon_deg.to_radians(),
            self.alt_m,
            Ellipsoid::WGS84,
        );
        [lat.to_degrees(), lon.to_degrees(), self.alt_m + p[2]]
    }

    /// WGS-84 latitude °, longitude °, altitude m (AMSL) as a scenario point (x east, y north,
    /// z up, metres). Any longitude works: ±180° is the same meridian.
    pub fn to_local(&self, lat_deg: f64, lon_deg: f64, alt_m: f64) -> [f64; 3] {
        // The point of the tangent plane on this vertical: found by moving along it until the
        // plane's up is 0 (the vertical leans d/R from the plane's up, so each step gains a
        // factor of (d/R)² — three steps are exact to nanometres within 100 km).
        let enu = |h: f64| {
            map_3d::geodetic2enu(
                lat_deg.to_radians(),
                lon_deg.to_radians(),
                h,
                self.lat_deg.to_radians(),
                self.lon_deg.to_radians(),
                self.alt_m,
                Ellipsoid::WGS84,
            )
        };
        let mut h = self.alt_m;
        for _ in 0..3 {
            h -= enu(h).2;
        }
        let (e, n, _) = enu(h);
        [e, n, alt_m - self.alt_m]
    }
}

/// `LAT,LON,ALT`, which [`FromStr`] reads back.
impl fmt::Display for GeoOrigin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{},{},{}", self.lat_deg, self.lon_deg, self.alt_m)
    }
}

/// An origin no tangent plane can hang from: the field (as in a scenario's `[origin]` table),
/// its value and why it is refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field} = {value}: {reason}")]
pub struct BadOrigin {
    /// `lat_deg`, `lon_deg` or `alt_m`.
    pub field: &'static str,
    /// The value refused.
    pub value: f64,
    /// Why.
    pub reason: String,
}

/// Text that is not `LAT,LON,ALT` within range; the message shows the text and the ranges.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct BadOriginText(String);

impl FromStr for GeoOrigin {
    type Err = BadOriginText;
    /// `LAT,LON,ALT`: a latitude within [`MAX_ABS_LAT_DEG`] of the equator, a longitude in
    /// [−180, 180], an altitude (AMSL) in [`ALT_RANGE_M`].
    fn from_str(s: &str) -> Result<GeoOrigin, BadOriginText> {
        let v: Vec<f64> = s.split(',').filter_map(|p| p.trim().parse().ok()).collect();
        match v[..] {
            [lat, lon, alt] if GeoOrigin::new(lat, lon, alt).check().is_ok() => {
                Ok(GeoOrigin::new(lat, lon, alt))
            }
            _ => Err(BadOriginText(format!(
                "{s:?} is not LAT,LON,ALT (latitude in [-{MAX_ABS_LAT_DEG}, {MAX_ABS_LAT_DEG}] and longitude in \
                 [-180, 180] degrees, altitude above mean sea level in [{}, {}] metres)",
                ALT_RANGE_M.start(),
                ALT_RANGE_M.end()
            ))),
        }
    }
}

#[cfg(test)]
mod tests;
