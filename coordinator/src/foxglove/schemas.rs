//! The message types of Foxglove's well-known schemas that Shoal serves, as serde types: the
//! fields Foxglove's `foxglove.PoseInFrame`, `foxglove.LocationFix` and `foxglove.SceneUpdate`
//! define (names and meaning as Foxglove documents them), so its 3D and Map panels draw them
//! with no converter. Each channel's JSON Schema is derived from these types with `schemars`, so
//! the schema a client validates against cannot drift from the messages sent.

use serde::Serialize;

/// A time: seconds and nanoseconds since the Unix epoch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, schemars::JsonSchema)]
pub struct Time {
    /// Whole seconds.
    pub sec: u32,
    /// Nanoseconds in the second, below 10⁹.
    pub nsec: u32,
}

impl Time {
    /// The time `ns` nanoseconds after the Unix epoch (saturating at `u32::MAX` seconds).
    pub fn from_ns(ns: u64) -> Time {
        Time {
            sec: u32::try_from(ns / 1_000_000_000).unwrap_or(u32::MAX),
            // Below 10⁹, so it fits.
            nsec: (ns % 1_000_000_000) as u32,
        }
    }
}

/// A length of time (an entity's lifetime; zero: until replaced).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, schemars::JsonSchema)]
pub struct Duration {
    /// Whole seconds.
    pub sec: i32,
    /// Nanoseconds in the second.
    pub nsec: u32,
}

/// A point or a size, metres.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, schemars::JsonSchema)]
pub struct Vector3 {
    /// East (scenario x).
    pub x: f64,
    /// North (scenario y).
    pub y: f64,
    /// Up (scenario z).
    pub z: f64,
}

impl From<[f64; 3]> for Vector3 {
    fn from(p: [f64; 3]) -> Vector3 {
        Vector3 {
            x: p[0],
            y: p[1],
            z: p[2],
        }
    }
}

/// An orientation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, schemars::JsonSchema)]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w.
    pub w: f64,
}

impl Quaternion {
    /// No rotation.
    pub const IDENTITY: Quaternion = Quaternion {
        x: 0.0,
        y: 0.0,
        z: 0.0,
        w: 1.0,
    };

    /// A turn of `yaw_rad` about the up axis (counter-clockwise seen from above).
    pub fn yaw(yaw_rad: f64) -> Quaternion {
        let half = yaw_rad / 2.0;
        Quaternion {
            x: 0.0,
            y: 0.0,
            z: half.sin(),
            w: half.cos(),
        }
    }
}

/// A position and an orientation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, schemars::JsonSchema)]
pub struct Pose {
    /// Position, metres.
    pub position: Vector3,
    /// Orientation.
    pub orientation: Quaternion,
}

/// `foxglove.PoseInFrame`: a vehicle's pose in the scenario frame.
#[derive(Debug, Clone, PartialEq, Serialize, schemars::JsonSchema)]
pub struct PoseInFrame {
    /// When the fix was taken.
    pub timestamp: Time,
    /// The frame: the scenario's.
    pub frame_id: String,
    /// The pose.
    pub pose: Pose,
}

/// `foxglove.LocationFix`: a vehicle's position on WGS-84.
#[derive(Debug, Clone, PartialEq, Serialize, schemars::JsonSchema)]
pub struct LocationFix {
    /// When the fix was taken.
    pub timestamp: Time,
    /// The vehicle.
    pub frame_id: String,
    /// Latitude, degrees.
    pub latitude: f64,
    /// Longitude, degrees.
    pub longitude: f64,
    /// Altitude above mean sea level, metres.
    pub altitude: f64,
    /// Position covariance (m², east-north-up, row-major); zeros with type 0: unknown.
    pub position_covariance: [f64; 9],
    /// 0: unknown covariance.
    pub position_covariance_type: u8,
}

/// An RGBA colour, each component in [0, 1].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, schemars::JsonSchema)]
pub struct Color {
    /// Red.
    pub r: f64,
    /// Green.
    pub g: f64,
    /// Blue.
    pub b: f64,
    /// Opacity.
    pub a: f64,
}

/// A sphere (an ellipsoid whose `size` is its diameters).
#[derive(Debug, Clone, PartialEq, Serialize, schemars::JsonSchema)]
pub struct SpherePrimitive {
    /// Centre and orientation.
    pub pose: Pose,
    /// Diameter along each axis, metres.
    pub size: Vector3,
    /// Colour.
    pub color: Color,
}

/// How a line's points join.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LineType {
    /// Each point to the next.
    Strip = 0,
    /// Pairs of points, each pair one segment.
    List = 2,
}

impl Serialize for LineType {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_u8(*self as u8)
    }
}

impl schemars::JsonSchema for LineType {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "LineType".into()
    }

    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        schemars::json_schema!({
            "description": "0: line strip, 1: line loop, 2: line list",
            "type": "integer",
            "enum": [0, 1, 2]
        })
    }
}

/// A line through points.
#[derive(Debug, Clone, PartialEq, Serialize, schemars::JsonSchema)]
pub struct LinePrimitive {
    /// Strip or list.
    #[serde(rename = "type")]
    pub line_type: LineType,
    /// Origin of the points.
    pub pose: Pose,
    /// Width, pixels when `scale_invariant`, metres otherwise.
    pub thickness: f64,
    /// Whether `thickness` is in pixels.
    pub scale_invariant: bool,
    /// The points, metres.
    pub points: Vec<Vector3>,
    /// Colour of the whole line.
    pub color: Color,
    /// Per-point colours (empty: `color`).
    pub colors: Vec<Color>,
    /// Which points to draw, in order (empty: all).
    pub indices: Vec<u32>,
}

/// One thing drawn in the 3D scene; it replaces the earlier one with its `id`.
#[derive(Debug, Clone, PartialEq, Serialize, schemars::JsonSchema)]
pub struct SceneEntity {
    /// When it was made.
    pub timestamp: Time,
    /// Its frame: the scenario's.
    pub frame_id: String,
    /// What it is (`obstacle/HObs#1`, `path/auv1`, `bounds`).
    pub id: String,
    /// Zero: shown until replaced.
    pub lifetime: Duration,
    /// Whether it follows its frame (the scenario frame does not move).
    pub frame_locked: bool,
    /// Key-value notes (an obstacle's kind and radius).
    pub metadata: Vec<KeyValuePair>,
    /// Unused by Shoal (always empty).
    pub arrows: Vec<serde_json::Value>,
    /// Unused by Shoal (always empty).
    pub cubes: Vec<serde_json::Value>,
    /// Obstacles.
    pub spheres: Vec<SpherePrimitive>,
    /// Unused by Shoal (always empty).
    pub cylinders: Vec<serde_json::Value>,
    /// Paths and the bounds box.
    pub lines: Vec<LinePrimitive>,
    /// Unused by Shoal (always empty).
    pub triangles: Vec<serde_json::Value>,
    /// Unused by Shoal (always empty).
    pub texts: Vec<serde_json::Value>,
    /// Unused by Shoal (always empty).
    pub models: Vec<serde_json::Value>,
}

/// A key and its value.
#[derive(Debug, Clone, PartialEq, Serialize, schemars::JsonSchema)]
pub struct KeyValuePair {
    /// The key.
    pub key: String,
    /// The value.
    pub value: String,
}

/// `foxglove.SceneUpdate`: entities to add or replace (Shoal sends the whole scene each time).
#[derive(Debug, Clone, PartialEq, Serialize, schemars::JsonSchema)]
pub struct SceneUpdate {
    /// Entities to remove first (unused: every update replaces the entities by id).
    pub deletions: Vec<serde_json::Value>,
    /// The entities.
    pub entities: Vec<SceneEntity>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_split_into_seconds_and_nanoseconds() {
        assert_eq!(
            Time::from_ns(1_700_000_000_123_456_789),
            Time {
                sec: 1_700_000_000,
                nsec: 123_456_789
            }
        );
        assert_eq!(Time::from_ns(u64::MAX).sec, u32::MAX);
    }

    #[test]
    fn a_quarter_turn_of_yaw_is_the_textbook_quaternion() {
        let q = Quaternion::yaw(std::f64::consts::FRAC_PI_2);
        let h = std::f64::consts::FRAC_1_SQRT_2;
        assert!((q.z - h).abs() < 1e-12 && (q.w - h).abs() < 1e-12, "{q:?}");
        assert_eq!(Quaternion::yaw(0.0), Quaternion::IDENTITY);
    }

    #[test]
    fn line_types_are_numbers_in_the_json_and_the_schema() -> serde_json::Result<()> {
        assert_eq!(serde_json::to_string(&LineType::List)?, "2");
        let schema = serde_json::to_value(schemars::schema_for!(LinePrimitive))?;
        assert_eq!(schema["properties"]["type"]["$ref"], "#/$defs/LineType");
        assert_eq!(schema["$defs"]["LineType"]["type"], "integer");
        Ok(())
    }
}
