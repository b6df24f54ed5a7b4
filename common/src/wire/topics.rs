//! Every Zenoh key expression Shoal uses, and nothing else builds one.
//!
//! ```text
//! shoal/<mission>/fleet                  coordinator → all agents of a mission (context, stop)
//! shoal/<mission>/vehicle/<id>/in        coordinator → one agent (assign, migrants)
//! shoal/<mission>/vehicle/<id>/out       one agent → coordinator (elites, done)
//! shoal/*/vehicle/<id>/in                what an agent listens on: its vehicle, any mission
//! shoal/*/fleet                          what an agent listens on for contexts
//! shoal/<mission>/vehicle/*/out          what the coordinator listens on for a mission
//! shoal-alive/<id>                       an agent's liveliness token (agents outlive missions)
//! shoal-coordinator/<mission>            the coordinator's liveliness token for a mission
//! shoal/<mission>/telemetry/<id>         JSON: one vehicle's telemetry (open interface)
//! shoal/<mission>/status                 JSON: the live fleet picture (put, and a queryable)
//! shoal/<mission>/plan                   JSON: the current plan, on every (re)plan
//! shoal/<mission>/events                 JSON: the coordinator's decisions
//! shoal/<mission>/obstacles              JSON in: a new obstacle for a running mission
//! shoal/submit                           JSON query: submit a mission (`serve`)
//! ```
//!
//! Mission and vehicle ids become key chunks, so they are restricted to letters, digits, `-`, `_`
//! and `.`: no `/`, no wildcards, nothing empty. They also name directories (`<out>/<mission>/`),
//! so they are single path components: no leading `.` (`.`, `..`, hidden names) and no `\`.

/// Why an id cannot be used in a key expression.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{kind} id {id:?} is not usable on the network: use 1-64 letters, digits, '-', '_' or '.', not starting with '.'")]
pub struct IdError {
    /// "mission" or "vehicle".
    pub kind: &'static str,
    /// The id.
    pub id: String,
}

/// Checks that `id` can be one chunk of a key expression.
pub fn check_id(kind: &'static str, id: &str) -> Result<(), IdError> {
    let ok = (1..=64).contains(&id.len())
        && !id.starts_with('.')
        && id
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || matches!(b, b'-' | b'_' | b'.'));
    if ok {
        Ok(())
    } else {
        Err(IdError {
            kind,
            id: id.to_string(),
        })
    }
}

/// Coordinator → every agent of `mission`.
pub fn fleet(mission: &str) -> Result<String, IdError> {
    check_id("mission", mission)?;
    Ok(format!("shoal/{mission}/fleet"))
}

/// Coordinator → the agent of `vehicle` in `mission`.
pub fn to_agent(mission: &str, vehicle: &str) -> Result<String, IdError> {
    check_id("mission", mission)?;
    check_id("vehicle", vehicle)?;
    Ok(format!("shoal/{mission}/vehicle/{vehicle}/in"))
}

/// The agent of `vehicle` → the coordinator of `mission`.
pub fn to_coordinator(mission: &str, vehicle: &str) -> Result<String, IdError> {
    check_id("mission", mission)?;
    check_id("vehicle", vehicle)?;
    Ok(format!("shoal/{mission}/vehicle/{vehicle}/out"))
}

/// What an agent subscribes to: messages for its vehicle in any mission.
pub fn agent_inbox(vehicle: &str) -> Result<String, IdError> {
    check_id("vehicle", vehicle)?;
    Ok(format!("shoal/*/vehicle/{vehicle}/in"))
}

/// What the coordinator subscribes to: every agent's messages in `mission`.
pub fn coordinator_inbox(mission: &str) -> Result<String, IdError> {
    check_id("mission", mission)?;
    Ok(format!("shoal/{mission}/vehicle/*/out"))
}

/// The liveliness token of `vehicle`'s agent.
pub fn liveliness(vehicle: &str) -> Result<String, IdError> {
    check_id("vehicle", vehicle)?;
    Ok(format!("shoal-alive/{vehicle}"))
}

/// The liveliness token of the coordinator of `mission` (outside `shoal-alive/`, so it is never
/// mistaken for an agent's).
pub fn coordinator_liveliness(mission: &str) -> Result<String, IdError> {
    check_id("mission", mission)?;
    Ok(format!("shoal-coordinator/{mission}"))
}

/// Every coordinator's liveliness token (agents watch them to abandon a mission whose
/// coordinator is gone).
pub const ALL_COORDINATORS: &str = "shoal-coordinator/*";

/// The mission of a coordinator's liveliness token `key`, if it is one.
pub fn mission_of_coordinator(key: &str) -> Option<&str> {
    let id = key.strip_prefix("shoal-coordinator/")?;
    check_id("mission", id).ok().map(|()| id)
}

/// One vehicle's telemetry in `mission` (JSON, [`super::open::Telemetry`]).
pub fn telemetry(mission: &str, vehicle: &str) -> Result<String, IdError> {
    check_id("mission", mission)?;
    check_id("vehicle", vehicle)?;
    Ok(format!("shoal/{mission}/telemetry/{vehicle}"))
}

/// Every vehicle's telemetry in `mission`.
pub fn all_telemetry(mission: &str) -> Result<String, IdError> {
    check_id("mission", mission)?;
    Ok(format!("shoal/{mission}/telemetry/*"))
}

/// The vehicle of a key built by [`telemetry`].
pub fn vehicle_of_telemetry(key: &str) -> Option<&str> {
    let rest = key.strip_prefix("shoal/")?;
    let mut parts = rest.split('/');
    let (mission, kw, vehicle) = (parts.next()?, parts.next()?, parts.next()?);
    if parts.next().is_some() || kw != "telemetry" {
        return None;
    }
    check_id("mission", mission).ok()?;
    check_id("vehicle", vehicle).ok().map(|()| vehicle)
}

/// One of a mission's open JSON keys: `status`, `plan`, `events` or `obstacles`.
pub fn open_key(mission: &str, what: OpenKey) -> Result<String, IdError> {
    check_id("mission", mission)?;
    Ok(format!("shoal/{mission}/{}", what.chunk()))
}

/// The mission-wide JSON keys of the open interface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OpenKey {
    /// The live fleet picture.
    Status,
    /// The current plan.
    Plan,
    /// The coordinator's decisions.
    Events,
    /// New obstacles (input).
    Obstacles,
}

impl OpenKey {
    fn chunk(self) -> &'static str {
        match self {
            OpenKey::Status => "status",
            OpenKey::Plan => "plan",
            OpenKey::Events => "events",
            OpenKey::Obstacles => "obstacles",
        }
    }
}

/// Where missions are submitted (a query with a JSON submission; `shoal-coordinator serve`).
pub const SUBMIT: &str = "shoal/submit";

/// Every running mission's fleet picture (what `shoal-coordinator status` queries).
pub const ALL_STATUS: &str = "shoal/*/status";

/// Every agent's liveliness token.
pub const ALL_LIVELINESS: &str = "shoal-alive/*";

/// What an agent subscribes to for contexts: every mission's fleet key.
pub const ALL_FLEETS: &str = "shoal/*/fleet";

/// The mission of a key built by [`fleet`].
pub fn mission_of_fleet(key: &str) -> Option<&str> {
    let mission = key.strip_prefix("shoal/")?.strip_suffix("/fleet")?;
    check_id("mission", mission).ok().map(|()| mission)
}

/// The vehicle whose liveliness token `key` is, if it is one.
pub fn vehicle_of_liveliness(key: &str) -> Option<&str> {
    let id = key.strip_prefix("shoal-alive/")?;
    check_id("vehicle", id).ok().map(|()| id)
}

/// `(mission, vehicle)` of a key built by [`to_agent`] or [`to_coordinator`].
pub fn mission_and_vehicle(key: &str) -> Option<(&str, &str)> {
    let rest = key.strip_prefix("shoal/")?;
    let mut parts = rest.split('/');
    let (mission, kw, vehicle, dir) = (parts.next()?, parts.next()?, parts.next()?, parts.next()?);
    if parts.next().is_some() || kw != "vehicle" || !matches!(dir, "in" | "out") {
        return None;
    }
    check_id("mission", mission).ok()?;
    check_id("vehicle", vehicle).ok()?;
    Some((mission, vehicle))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_built_and_read_back() -> Result<(), IdError> {
        assert_eq!(fleet("m-1")?, "shoal/m-1/fleet");
        assert_eq!(to_agent("m-1", "auv3")?, "shoal/m-1/vehicle/auv3/in");
        assert_eq!(to_coordinator("m-1", "auv3")?, "shoal/m-1/vehicle/auv3/out");
        assert_eq!(agent_inbox("auv3")?, "shoal/*/vehicle/auv3/in");
        assert_eq!(coordinator_inbox("m-1")?, "shoal/m-1/vehicle/*/out");
        assert_eq!(liveliness("auv3")?, "shoal-alive/auv3");
        assert_eq!(vehicle_of_liveliness("shoal-alive/auv3"), Some("auv3"));
        assert_eq!(mission_of_fleet(&fleet("m-1")?), Some("m-1"));
        assert_eq!(coordinator_liveliness("m-1")?, "shoal-coordinator/m-1");
        assert_eq!(
            mission_of_coordinator(&coordinator_liveliness("m-1")?),
            Some("m-1")
        );
        assert_eq!(mission_of_coordinator("shoal-coordinator/a/b"), None);
        assert_eq!(mission_of_fleet("shoal/a/b/fleet"), None);
        assert_eq!(vehicle_of_liveliness("shoal-alive/a/b"), None);
        assert_eq!(
            mission_and_vehicle(&to_coordinator("m-1", "auv3")?),
            Some(("m-1", "auv3"))
        );
        assert_eq!(mission_and_vehicle("shoal/m-1/vehicle/auv3/sideways"), None);
        assert_eq!(telemetry("m-1", "auv3")?, "shoal/m-1/telemetry/auv3");
        assert_eq!(all_telemetry("m-1")?, "shoal/m-1/telemetry/*");
        assert_eq!(
            vehicle_of_telemetry(&telemetry("m-1", "auv3")?),
            Some("auv3")
        );
        assert_eq!(vehicle_of_telemetry("shoal/m-1/telemetry/a/b"), None);
        assert_eq!(vehicle_of_telemetry("shoal/m-1/vehicle/auv3"), None);
        assert_eq!(open_key("m-1", OpenKey::Status)?, "shoal/m-1/status");
        assert_eq!(open_key("m-1", OpenKey::Plan)?, "shoal/m-1/plan");
        assert_eq!(open_key("m-1", OpenKey::Events)?, "shoal/m-1/events");
        assert_eq!(open_key("m-1", OpenKey::Obstacles)?, "shoal/m-1/obstacles");
        assert_eq!(
            mission_and_vehicle("shoal/m-1/vehicle/auv3/out/extra"),
            None
        );
        Ok(())
    }

    #[test]
    fn ids_that_would_change_a_key_are_refused() {
        for bad in [
            "",
            "a/b",
            "*",
            "**",
            "a b",
            "$x",
            "auv?",
            &"x".repeat(65),
            ".",
            "..",
            ".hidden",
            "a\\b",
            "../x",
        ] {
            assert!(check_id("vehicle", bad).is_err(), "{bad:?}");
            assert!(to_agent("m", bad).is_err());
        }
        let e = fleet("two missions")
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("mission id \"two missions\""), "{e}");
        for good in ["a..b", "m.1", "x".repeat(64).as_str()] {
            assert!(check_id("mission", good).is_ok(), "{good:?}");
        }
    }
}
