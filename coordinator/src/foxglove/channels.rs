//! The channels Shoal serves to Foxglove: what each carries, its topic, its schema's name and its
//! JSON Schema. Every message is JSON (`json` encoding) and every schema a JSON Schema
//! (`jsonschema`), derived from the serde type the message is made from: Foxglove's well-known
//! types (see the sibling `schemas` module) for what its panels draw, Shoal's own open types for
//! the status and the events (the events' schema is the MCAP log's, from
//! [`crate::execute::log::channels`]).

use shoal_common::wire::open::FleetStatus;

use super::schemas::{LocationFix, PoseInFrame, SceneUpdate};
use crate::execute::log::channels::{Kind, MESSAGE_ENCODING, SCHEMA_ENCODING};

/// The fleet status, once a second.
pub const TOPIC_STATUS: &str = "/shoal/status";
/// The coordinator's decisions and observations.
pub const TOPIC_EVENTS: &str = "/shoal/events";
/// Obstacles, the bounds box and the planned paths.
pub const TOPIC_SCENE: &str = "/shoal/scene";
/// The scenario frame's name in every pose and scene entity (x east, y north, z up, metres).
pub const FRAME: &str = "shoal";

/// What a channel carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Content {
    /// [`FleetStatus`].
    Status,
    /// Mission events (`shoal.event`, the MCAP log's).
    Events,
    /// `foxglove.SceneUpdate`.
    Scene,
    /// One vehicle's `foxglove.PoseInFrame`.
    Pose,
    /// One vehicle's `foxglove.LocationFix` (scenarios with a geodetic origin).
    Location,
}

impl Content {
    /// The schema's name: Foxglove picks its panels' message types by it.
    pub fn schema_name(self) -> String {
        match self {
            Content::Status => "shoal.status".into(),
            Content::Events => Kind::Event.schema_name(),
            Content::Scene => "foxglove.SceneUpdate".into(),
            Content::Pose => "foxglove.PoseInFrame".into(),
            Content::Location => "foxglove.LocationFix".into(),
        }
    }

    /// The JSON Schema of the messages.
    pub fn schema(self) -> schemars::Schema {
        match self {
            Content::Status => schemars::schema_for!(FleetStatus),
            Content::Events => Kind::Event.schema(),
            Content::Scene => schemars::schema_for!(SceneUpdate),
            Content::Pose => schemars::schema_for!(PoseInFrame),
            Content::Location => schemars::schema_for!(LocationFix),
        }
    }
}

/// One advertised channel.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Channel {
    /// Its id in this server's session (never reused: a client may still name an old one).
    pub id: u32,
    /// Its topic.
    pub topic: String,
    /// What it carries.
    pub content: Content,
    /// The vehicle of a pose or location channel.
    pub vehicle: Option<String>,
}

impl Channel {
    /// A channel of the whole fleet.
    pub fn fleet(id: u32, content: Content) -> Channel {
        let topic = match content {
            Content::Status => TOPIC_STATUS,
            Content::Events => TOPIC_EVENTS,
            _ => TOPIC_SCENE,
        };
        Channel {
            id,
            topic: topic.into(),
            content,
            vehicle: None,
        }
    }

    /// `vehicle`'s pose (`/shoal/pose/<vehicle>`) or location (`/shoal/location/<vehicle>`).
    pub fn vehicle(id: u32, content: Content, vehicle: &str) -> Channel {
        let kind = if content == Content::Location {
            "location"
        } else {
            "pose"
        };
        Channel {
            id,
            topic: format!("/shoal/{kind}/{vehicle}"),
            content,
            vehicle: Some(vehicle.into()),
        }
    }

    /// The channel as the protocol's `advertise` lists it (the schema as a JSON string).
    pub fn advertisement(&self) -> serde_json::Value {
        let schema = serde_json::to_string(&self.content.schema()).unwrap_or_default();
        serde_json::json!({
            "id": self.id,
            "topic": self.topic,
            "encoding": MESSAGE_ENCODING,
            "schemaName": self.content.schema_name(),
            "schema": schema,
            "schemaEncoding": SCHEMA_ENCODING,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_advertisement_carries_its_schema_as_json_text() -> serde_json::Result<()> {
        let a = Channel::vehicle(7, Content::Pose, "auv1").advertisement();
        assert_eq!(a["topic"], "/shoal/pose/auv1");
        assert_eq!(a["schemaName"], "foxglove.PoseInFrame");
        assert_eq!(a["encoding"], "json");
        assert_eq!(a["schemaEncoding"], "jsonschema");
        let schema: serde_json::Value = serde_json::from_str(a["schema"].as_str().unwrap_or(""))?;
        assert_eq!(schema["title"], "PoseInFrame");
        let status = Channel::fleet(1, Content::Status).advertisement();
        let schema: serde_json::Value =
            serde_json::from_str(status["schema"].as_str().unwrap_or(""))?;
        assert!(schema["properties"]["vehicles"].is_object(), "{schema}");
        Ok(())
    }
}
