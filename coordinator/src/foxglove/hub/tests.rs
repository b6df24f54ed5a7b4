use super::*;
use shoal_common::scenario::ObstacleKind;
use shoal_common::wire::open::{MissionEvent, OPEN_VERSION};

/// Five AUVs, twelve obstacles and a geodetic origin.
const WITH_ORIGIN: &str = include_str!("../../../../scenarios/amp-pso-3.toml");
/// Two AUVs nowhere on the Earth.
const WITHOUT_ORIGIN: &str = include_str!("../../../../scenarios/amp-pso-1.toml");
const EPOCH_MS: u64 = 1_700_000_000_000;

fn start(toml: &str) -> LiveMessage {
    LiveMessage::Record(Record::Start(Start {
        mission: "m".into(),
        scenario_toml: toml.into(),
        common_arrival_s: 2700.0,
        arrival_window_s: 30.0,
        horizon_s: 60.0,
        time_scale: 200.0,
        epoch_unix_ms: EPOCH_MS,
    }))
}

fn report(vehicle: &str, t_s: f64, position: [f64; 3]) -> LiveMessage {
    crate::execute::live::test_report(vehicle, 0, t_s, position)
}

fn data(updates: &[Update]) -> Vec<&Data> {
    updates
        .iter()
        .filter_map(|u| match u {
            Update::Data(d) => Some(d.as_ref()),
            _ => None,
        })
        .collect()
}

fn json(d: &Data) -> serde_json::Value {
    serde_json::from_slice(&d.payload).unwrap_or_default()
}

#[test]
fn a_start_advertises_a_pose_and_a_location_per_vehicle_and_draws_the_scene() {
    let mut hub = Hub::new();
    assert_eq!(hub.channels().len(), 3);
    let updates = hub.apply(&start(WITH_ORIGIN));
    let Some(Update::Advertise(added)) = updates.first() else {
        panic!("{updates:?}");
    };
    let topics: Vec<&str> = added.iter().map(|c| c.topic.as_str()).collect();
    assert_eq!(topics.len(), 10, "five AUVs: {topics:?}");
    assert_eq!(
        topics[..4],
        [
            "/shoal/pose/auv1",
            "/shoal/location/auv1",
            "/shoal/pose/auv2",
            "/shoal/location/auv2"
        ]
    );
    let scene = data(&updates);
    assert_eq!(scene.len(), 1);
    assert_eq!(scene[0].channel, Hub::SCENE);
    let entities = json(scene[0])["entities"].clone();
    let ids: Vec<&str> = entities
        .as_array()
        .map(|a| a.iter().filter_map(|e| e["id"].as_str()).collect())
        .unwrap_or_default();
    assert_eq!(ids[0], "bounds");
    assert_eq!(
        ids.iter().filter(|i| i.starts_with("obstacle/")).count(),
        12
    );
    assert_eq!(hub.latched(Hub::SCENE).len(), 1);
}

#[test]
fn without_an_origin_there_is_no_location_channel() {
    let mut hub = Hub::new();
    hub.apply(&start(WITHOUT_ORIGIN));
    assert!(hub
        .channels()
        .iter()
        .all(|c| c.content != Content::Location));
    assert_eq!(
        hub.channels()
            .iter()
            .filter(|c| c.content == Content::Pose)
            .count(),
        2
    );
}

#[test]
fn a_report_becomes_a_latched_pose_stamped_on_the_mission_clock() {
    let mut hub = Hub::new();
    hub.apply(&start(WITH_ORIGIN));
    let updates = hub.apply(&report("auv2", 12.25, [1.0, 2.0, 3.0]));
    let out = data(&updates);
    assert_eq!(out.len(), 2, "a pose and a location fix");
    let pose_channel = hub
        .channels()
        .iter()
        .find(|c| c.topic == "/shoal/pose/auv2")
        .map(|c| c.id);
    assert_eq!(Some(out[0].channel), pose_channel);
    assert_eq!(out[0].stamp_ns, EPOCH_MS * 1_000_000 + 12_250_000_000);
    let pose = json(out[0]);
    assert_eq!(pose["pose"]["position"]["y"], 2.0);
    assert_eq!(pose["timestamp"]["sec"], 1_700_000_012);
    assert_eq!(pose["timestamp"]["nsec"], 250_000_000);
    assert_eq!(hub.latched(out[0].channel).len(), 1);
    // A vehicle not of the fleet has no channel.
    assert!(hub.apply(&report("intruder", 13.0, [0.0; 3])).is_empty());
}

#[test]
fn published_obstacles_and_plans_redraw_the_scene_and_events_keep_the_latest() {
    let mut hub = Hub::new();
    hub.apply(&start(WITH_ORIGIN));
    let o = Obstacle {
        id: "pub-1".into(),
        kind: ObstacleKind::Hard,
        centre: [1.0, 2.0, 3.0],
        radius_m: 10.0,
        inflation_m: 5.0,
    };
    let updates = hub.apply(&LiveMessage::Record(Record::Obstacle(o)));
    let scene = json(data(&updates)[0]);
    let last = scene["entities"].as_array().and_then(|a| a.last()).cloned();
    assert_eq!(last.map(|e| e["id"].clone()), Some("obstacle/pub-1".into()));
    for n in 0..LATCHED_EVENTS + 5 {
        hub.apply(&LiveMessage::Record(Record::Event(MissionEvent {
            version: OPEN_VERSION,
            mission: "m".into(),
            t_s: n as f64,
            kind: "hold".into(),
            vehicles: vec![],
            detail: n.to_string(),
        })));
    }
    let events = hub.latched(Hub::EVENTS);
    assert_eq!(events.len(), LATCHED_EVENTS);
    assert_eq!(
        events.last().map(|d| json(d)["detail"].clone()),
        Some((LATCHED_EVENTS + 4).to_string().into())
    );
}

#[test]
fn a_new_mission_takes_the_old_fleets_channels_away_with_fresh_ids() {
    let mut hub = Hub::new();
    hub.apply(&start(WITH_ORIGIN));
    let old: Vec<u32> = hub.channels().iter().skip(3).map(|c| c.id).collect();
    let updates = hub.apply(&start(WITHOUT_ORIGIN));
    assert_eq!(updates.first(), Some(&Update::Unadvertise(old.clone())));
    assert!(hub.channels().iter().all(|c| !old.contains(&c.id)));
    assert!(hub.latched(old[0]).is_empty());
}
