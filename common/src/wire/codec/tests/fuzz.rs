//! Fuzzing the decoders (property tests): every message survives a round trip, and arbitrary
//! bytes — random, or a valid encoding mutated — are an error or a message, never a panic.
//! Cases are kept at about 2,000 per decoder so the suite stays fast; the million-input run is
//! `cargo run --release -p shoal-coordinator --example fuzz_decoders`.

use proptest::prelude::*;

use super::super::*;
use crate::execution::{VehicleState, VehicleStatus};
use crate::scenario::{Obstacle, ObstacleKind};
use crate::wire::agent_to_coordinator::AgentToCoordinator;
use crate::wire::coordinator_to_agent::CoordinatorToAgent;
use crate::wire::open::{FleetStatus, Telemetry, VehicleStatusRow, OPEN_VERSION};
use crate::wire::WireTrajectory;

fn cases(n: u32) -> ProptestConfig {
    ProptestConfig::with_cases(n)
}

fn samples() -> impl Strategy<Value = Vec<[f64; 4]>> {
    proptest::collection::vec(proptest::array::uniform4(-1e6f64..1e6), 0..20)
}

/// Orders of every kind the coordinator sends to one vehicle.
fn order() -> impl Strategy<Value = CoordinatorToAgent> {
    let id = "[a-z0-9-]{1,12}";
    prop_oneof![
        (id, id, ".{0,40}").prop_map(|(mission, vehicle, reason)| CoordinatorToAgent::Hold {
            mission,
            vehicle,
            reason
        }),
        (id, ".{0,40}").prop_map(|(mission, reason)| CoordinatorToAgent::Stop { mission, reason }),
        (id, id, any::<u32>(), samples()).prop_map(|(mission, vehicle, revision, samples)| {
            CoordinatorToAgent::Update {
                trajectory: WireTrajectory {
                    vehicle: vehicle.clone(),
                    samples,
                },
                mission,
                vehicle,
                revision,
            }
        }),
        (id, id, samples(), any::<u64>(), 0.1f64..1e4, any::<u64>()).prop_map(
            |(mission, vehicle, samples, epoch_unix_ms, time_scale, seed)| {
                CoordinatorToAgent::Execute {
                    scenario_toml: "name = \"x\"".into(),
                    trajectory: WireTrajectory {
                        vehicle: vehicle.clone(),
                        samples,
                    },
                    mission,
                    vehicle,
                    epoch_unix_ms,
                    time_scale,
                    telemetry_hz: 2.0,
                    seed,
                }
            }
        ),
    ]
}

/// Messages of every small kind an agent sends.
fn up() -> impl Strategy<Value = AgentToCoordinator> {
    let id = "[a-z0-9-]{1,12}";
    prop_oneof![
        (id, id).prop_map(|(mission, vehicle)| AgentToCoordinator::Joined { mission, vehicle }),
        (id, id, any::<u32>(), any::<u64>()).prop_map(|(mission, vehicle, n, evaluations)| {
            AgentToCoordinator::Done {
                mission,
                vehicle,
                iterations: n,
                elites_sent: n / 2,
                evaluations,
                dropped: n % 7,
            }
        }),
    ]
}

fn state() -> impl Strategy<Value = VehicleState> {
    (
        -1e5f64..1e5,
        proptest::array::uniform3(-1e5f64..1e5),
        0.0f64..1.0,
        prop_oneof![
            Just(VehicleStatus::Underway),
            Just(VehicleStatus::Holding),
            Just(VehicleStatus::Arrived),
            Just(VehicleStatus::Fault),
        ],
    )
        .prop_map(|(t_s, position, battery, status)| VehicleState {
            t_s,
            position,
            velocity: [0.5, -0.25, 0.0],
            heading_deg: 12.5,
            depth_m: Some(100.0),
            altitude_m: None,
            battery,
            status,
            arrived_s: None,
        })
}

fn telemetry() -> impl Strategy<Value = Telemetry> {
    ("[a-z0-9-]{1,12}", "[a-z0-9]{1,8}", any::<u64>(), state()).prop_map(
        |(mission, vehicle, seq, state)| Telemetry {
            version: OPEN_VERSION,
            mission,
            vehicle,
            seq,
            revision: 3,
            sent_unix_us: 1_700_000_000_000_000,
            state,
            command: None,
        },
    )
}

/// A valid encoding with a few bytes changed, cut short or grown: the inputs most likely to
/// reach deep into a decoder.
fn mutated(bytes: Vec<u8>, edits: &[(usize, u8, u8)]) -> Vec<u8> {
    let mut b = bytes;
    for &(at, value, op) in edits {
        let at = if b.is_empty() { 0 } else { at % b.len() };
        match op % 4 {
            0 if !b.is_empty() => b[at] = value,
            1 => b.insert(at, value),
            2 if !b.is_empty() => {
                b.remove(at);
            }
            _ => b.truncate(at),
        }
    }
    b
}

fn edits() -> impl Strategy<Value = Vec<(usize, u8, u8)>> {
    proptest::collection::vec((any::<usize>(), any::<u8>(), any::<u8>()), 1..6)
}

fn fleet_status(t: &Telemetry) -> FleetStatus {
    FleetStatus {
        version: OPEN_VERSION,
        mission: t.mission.clone(),
        t_s: t.state.t_s,
        d_min_m: 50.0,
        vehicles: vec![VehicleStatusRow {
            vehicle: t.vehicle.clone(),
            state: Some(t.state.clone()),
            progress: None,
            revision: t.revision,
            silent_s: 0.5,
            lost: false,
            command: None,
        }],
        current_min_separation_m: None,
        current_pair: None,
        predicted: None,
        horizon_s: 180.0,
    }
}

fn err(e: impl std::fmt::Display) -> TestCaseError {
    TestCaseError::fail(e.to_string())
}

proptest! {
    #![proptest_config(cases(500))]

    #[test]
    fn every_order_and_report_survives_the_codec_with_its_number(
        down in order(), upward in up(), seq in any::<u64>(),
    ) {
        let d = Envelope::sequenced(down, seq);
        prop_assert_eq!(decode::<CoordinatorToAgent>(&encode(&d).map_err(err)?), Ok(d));
        let u = Envelope::new(upward);
        prop_assert_eq!(decode::<AgentToCoordinator>(&encode(&u).map_err(err)?), Ok(u));
    }

    #[test]
    fn telemetry_and_status_survive_the_json_codec(t in telemetry()) {
        let back: Telemetry = decode_json(&encode_json(&t).map_err(err)?).map_err(err)?;
        prop_assert_eq!(&back, &t);
        let s = fleet_status(&t);
        let back: FleetStatus = decode_json(&encode_json(&s).map_err(err)?).map_err(err)?;
        prop_assert_eq!(back, s);
    }
}

proptest! {
    #![proptest_config(cases(2_000))]

    #[test]
    fn random_bytes_with_this_version_are_an_error_or_a_message_never_a_panic(
        tail in proptest::collection::vec(any::<u8>(), 0..300),
    ) {
        let bytes = [&PROTOCOL_VERSION.to_le_bytes()[..], &tail].concat();
        let _ = decode::<AgentToCoordinator>(&bytes);
        let _ = decode::<CoordinatorToAgent>(&bytes);
        let _ = decode_json::<Telemetry>(&tail);
        let _ = decode_json::<Obstacle>(&tail);
        let _ = decode_json::<FleetStatus>(&tail);
    }

    #[test]
    fn mutated_orders_and_reports_never_panic_the_decoder(
        down in order(), upward in up(), e in edits(),
    ) {
        let d = encode(&Envelope::sequenced(down, 7)).map_err(err)?;
        let _ = decode::<CoordinatorToAgent>(&mutated(d, &e));
        let u = encode(&Envelope::new(upward)).map_err(err)?;
        let _ = decode::<AgentToCoordinator>(&mutated(u, &e));
    }

    #[test]
    fn mutated_json_never_panics_the_decoder(t in telemetry(), e in edits(), r in -1e300f64..1e300) {
        let _ = decode_json::<Telemetry>(&mutated(encode_json(&t).map_err(err)?, &e));
        let s = fleet_status(&t);
        let _ = decode_json::<FleetStatus>(&mutated(encode_json(&s).map_err(err)?, &e));
        let o = Obstacle {
            id: t.vehicle.clone(),
            kind: ObstacleKind::Hard,
            centre: t.state.position,
            radius_m: r,
            inflation_m: 5.0,
        };
        let bytes = encode_json(&o).map_err(err)?;
        let back: Obstacle = decode_json(&bytes).map_err(err)?;
        prop_assert_eq!(&back, &o);
        let _ = decode_json::<Obstacle>(&mutated(bytes, &e));
    }
}
