//! The access-control rules a secured coordinator's router enforces (Zenoh's `access_control`
//! section: rules, subjects matched by certificate common name, policies), written by
//! `shoal-coordinator keys`. Everything is denied unless a rule allows it:
//!
//! | member | may send (ingress) | may receive (egress) |
//! |---|---|---|
//! | `coordinator` | everything | everything |
//! | vehicle `v` | its telemetry `shoal/*/telemetry/v`, its replies `shoal/*/vehicle/v/out`, its token `shoal-alive/v`; subscribe to its orders and the fleet key | its orders `shoal/*/vehicle/v/in`, `shoal/*/fleet`, coordinators' tokens |
//! | operator | obstacles `shoal/*/obstacles`, submissions and status queries; subscribe to `shoal/**` | every open key, query replies |
//!
//! So a vehicle cannot publish another vehicle's telemetry, cannot send orders (only the
//! coordinator's router originates `…/in`), cannot publish obstacles or submit missions; an
//! operator cannot send orders or pose as a vehicle. Declarations (who subscribes to what) are
//! passed to every member: Zenoh clients use them to know where to send, and they reveal key
//! names only. The router's own sessions (the coordinator's planning and execution) are local and
//! not subject to these rules; a router linked to this one (`serve`'s mission routers, a second
//! coordinator) authenticates as `coordinator`.

use serde_json::{json, Value};

/// The coordinator's identity: the common name of its certificate.
pub const COORDINATOR: &str = "coordinator";

/// The organizational unit `keys` writes into every operator's certificate: what the web view
/// and the Foxglove server recognise an operator by beyond loopback (the access-control rules
/// match common names, which only list the operators known when the keys were made).
pub const OPERATOR_UNIT: &str = "shoal-operators";

/// The fleet's members other than the coordinator.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Members {
    /// Vehicle ids.
    pub vehicles: Vec<String>,
    /// Operator client names.
    pub operators: Vec<String>,
}

/// The `access_control` section of the coordinator's Zenoh configuration.
pub fn rules(members: &Members) -> Value {
    let mut rules = vec![
        rule(
            "coordinator-all",
            &ALL_MESSAGES,
            &["ingress", "egress"],
            &["**".into()],
        ),
        rule(
            "declarations-out",
            &[
                "declare_subscriber",
                "declare_queryable",
                "declare_liveliness_subscriber",
            ],
            &["egress"],
            &[
                "shoal/**".into(),
                "shoal-alive/**".into(),
                "shoal-coordinator/**".into(),
            ],
        ),
    ];
    let mut subjects = vec![json!({"id": COORDINATOR, "cert_common_names": [COORDINATOR]})];
    let mut policies = vec![json!({"rules": ["coordinator-all"], "subjects": [COORDINATOR]})];
    for v in &members.vehicles {
        let ids = vehicle_rules(v, &mut rules);
        subjects.push(json!({"id": subject(v), "cert_common_names": [v]}));
        policies.push(json!({"rules": ids, "subjects": [subject(v)]}));
    }
    if !members.operators.is_empty() {
        let ids = operator_rules(&mut rules);
        for o in &members.operators {
            subjects.push(json!({"id": subject(o), "cert_common_names": [o]}));
        }
        let names: Vec<String> = members.operators.iter().map(|o| subject(o)).collect();
        policies.push(json!({"rules": ids, "subjects": names}));
    }
    json!({
        "enabled": true,
        "default_permission": "deny",
        "rules": rules,
        "subjects": subjects,
        "policies": policies,
    })
}

const ALL_MESSAGES: [&str; 9] = [
    "put",
    "delete",
    "declare_subscriber",
    "query",
    "declare_queryable",
    "reply",
    "liveliness_token",
    "declare_liveliness_subscriber",
    "liveliness_query",
];

fn subject(member: &str) -> String {
    format!("member-{member}")
}

fn rule(id: &str, messages: &[&str], flows: &[&str], keys: &[String]) -> Value {
    json!({
        "id": id,
        "permission": "allow",
        "messages": messages,
        "flows": flows,
        "key_exprs": keys,
    })
}

/// Rules of vehicle `v`; their ids (every policy also gets the shared declarations rule).
fn vehicle_rules(v: &str, rules: &mut Vec<Value>) -> Vec<String> {
    let id = |what: &str| format!("{v}-{what}");
    rules.push(rule(
        &id("reports"),
        &["put"],
        &["ingress"],
        &[
            format!("shoal/*/telemetry/{v}"),
            format!("shoal/*/vehicle/{v}/out"),
        ],
    ));
    rules.push(rule(
        &id("token"),
        &["liveliness_token"],
        &["ingress"],
        &[format!("shoal-alive/{v}")],
    ));
    rules.push(rule(
        &id("listen"),
        &["declare_subscriber"],
        &["ingress"],
        &[format!("shoal/*/vehicle/{v}/in"), "shoal/*/fleet".into()],
    ));
    rules.push(rule(
        &id("orders"),
        &["put"],
        &["egress"],
        &[format!("shoal/*/vehicle/{v}/in"), "shoal/*/fleet".into()],
    ));
    rules.push(rule(
        &id("coordinators"),
        &["declare_liveliness_subscriber", "liveliness_query"],
        &["ingress"],
        &["shoal-coordinator/**".into()],
    ));
    rules.push(rule(
        &id("coordinator-tokens"),
        &["liveliness_token"],
        &["egress"],
        &["shoal-coordinator/**".into()],
    ));
    [
        "reports",
        "token",
        "listen",
        "orders",
        "coordinators",
        "coordinator-tokens",
    ]
    .iter()
    .map(|w| id(w))
    .chain(["declarations-out".to_string()])
    .collect()
}

/// Rules shared by every operator; their ids.
fn operator_rules(rules: &mut Vec<Value>) -> Vec<String> {
    rules.push(rule(
        "operator-obstacles",
        &["put"],
        &["ingress"],
        &["shoal/*/obstacles".into()],
    ));
    rules.push(rule(
        "operator-queries",
        &["query"],
        &["ingress"],
        &["shoal/submit".into(), "shoal/*/status".into()],
    ));
    rules.push(rule(
        "operator-replies",
        &["reply"],
        &["egress"],
        &["shoal/submit".into(), "shoal/*/status".into()],
    ));
    rules.push(rule(
        "operator-read",
        &[
            "declare_subscriber",
            "declare_liveliness_subscriber",
            "liveliness_query",
        ],
        &["ingress"],
        &[
            "shoal/**".into(),
            "shoal-alive/**".into(),
            "shoal-coordinator/**".into(),
        ],
    ));
    rules.push(rule(
        "operator-receive",
        &["put", "liveliness_token"],
        &["egress"],
        &[
            "shoal/**".into(),
            "shoal-alive/**".into(),
            "shoal-coordinator/**".into(),
        ],
    ));
    [
        "operator-obstacles",
        "operator-queries",
        "operator-replies",
        "operator-read",
        "operator-receive",
        "declarations-out",
    ]
    .map(String::from)
    .to_vec()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn members() -> Members {
        Members {
            vehicles: vec!["auv1".into(), "auv2".into()],
            operators: vec!["operator".into()],
        }
    }

    /// The keys a subject may use for `message` in `flow`, by walking the rules as zenoh does.
    fn allowed(acl: &Value, member: &str, message: &str, flow: &str) -> Vec<String> {
        let subject = acl["subjects"]
            .as_array()
            .into_iter()
            .flatten()
            .find(|s| s["cert_common_names"][0] == member)
            .map(|s| s["id"].clone());
        let Some(subject) = subject else {
            return Vec::new();
        };
        let rule_ids: Vec<Value> = acl["policies"]
            .as_array()
            .into_iter()
            .flatten()
            .filter(|p| {
                p["subjects"]
                    .as_array()
                    .is_some_and(|s| s.contains(&subject))
            })
            .flat_map(|p| p["rules"].as_array().cloned().unwrap_or_default())
            .collect();
        acl["rules"]
            .as_array()
            .into_iter()
            .flatten()
            .filter(|r| rule_ids.contains(&r["id"]))
            .filter(|r| {
                r["messages"]
                    .as_array()
                    .is_some_and(|m| m.contains(&json!(message)))
            })
            .filter(|r| {
                r["flows"]
                    .as_array()
                    .is_some_and(|f| f.contains(&json!(flow)))
            })
            .flat_map(|r| r["key_exprs"].as_array().cloned().unwrap_or_default())
            .filter_map(|k| k.as_str().map(String::from))
            .collect()
    }

    #[test]
    fn a_vehicle_may_publish_only_its_own_reports() {
        let acl = rules(&members());
        assert_eq!(acl["default_permission"], "deny");
        assert_eq!(
            allowed(&acl, "auv1", "put", "ingress"),
            ["shoal/*/telemetry/auv1", "shoal/*/vehicle/auv1/out"]
        );
        assert_eq!(
            allowed(&acl, "auv1", "put", "egress"),
            ["shoal/*/vehicle/auv1/in", "shoal/*/fleet"]
        );
        assert!(allowed(&acl, "auv1", "query", "ingress").is_empty());
        assert_eq!(
            allowed(&acl, "auv2", "liveliness_token", "ingress"),
            ["shoal-alive/auv2"]
        );
    }

    #[test]
    fn an_operator_may_publish_obstacles_and_query_but_never_order() {
        let acl = rules(&members());
        assert_eq!(
            allowed(&acl, "operator", "put", "ingress"),
            ["shoal/*/obstacles"]
        );
        assert_eq!(
            allowed(&acl, "operator", "query", "ingress"),
            ["shoal/submit", "shoal/*/status"]
        );
        assert!(allowed(&acl, "operator", "liveliness_token", "ingress").is_empty());
        assert!(allowed(&acl, "stranger", "put", "ingress").is_empty());
    }

    #[test]
    fn the_coordinator_may_do_everything() {
        let acl = rules(&members());
        for m in ALL_MESSAGES {
            assert_eq!(allowed(&acl, COORDINATOR, m, "ingress"), ["**"], "{m}");
        }
    }

    #[test]
    fn zenoh_accepts_the_rules() -> zenoh::Result<()> {
        let mut config = zenoh::Config::default();
        config.insert_json5("access_control", &rules(&members()).to_string())?;
        assert_eq!(config.get_json("access_control/enabled")?, "true");
        Ok(())
    }
}
