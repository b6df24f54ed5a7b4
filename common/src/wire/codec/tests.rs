//! Unit tests of the codec: golden bytes and round trips; the decoder fuzzing is in `fuzz`.

use super::*;
use crate::wire::agent_to_coordinator::AgentToCoordinator;
use crate::wire::coordinator_to_agent::CoordinatorToAgent;
use crate::wire::{WireChromosome, WireContext, WireTrajectory};
use proptest::prelude::*;

#[test]
fn golden_bytes_of_a_stop_message() -> Result<(), Box<dyn std::error::Error>> {
    let m = Envelope::sequenced(
        CoordinatorToAgent::Stop {
            mission: "m1".into(),
            reason: "ok".into(),
        },
        0x0102,
    );
    let bytes = encode(&m)?;
    // version 6 (u16 LE) | seq 0x0102 (u64 LE) | variant 3 (u32 LE) | len 2 (u64 LE) "m1"
    // | len 2 "ok"
    let expected: Vec<u8> = [
        &[6u8, 0][..],
        &[2, 1, 0, 0, 0, 0, 0, 0],
        &[3, 0, 0, 0],
        &[2, 0, 0, 0, 0, 0, 0, 0],
        b"m1",
        &[2, 0, 0, 0, 0, 0, 0, 0],
        b"ok",
    ]
    .concat();
    assert_eq!(bytes, expected);
    assert_eq!(decode::<CoordinatorToAgent>(&bytes)?, m);
    Ok(())
}

#[test]
fn other_versions_short_trailing_and_oversized_are_errors() -> Result<(), EncodeError> {
    let m = Envelope::new(AgentToCoordinator::Done {
        mission: "m".into(),
        vehicle: "auv1".into(),
        iterations: 200,
        elites_sent: 200,
        evaluations: 100_000,
        dropped: 0,
    });
    let mut bytes = encode(&m)?;
    let mut v1 = bytes.clone();
    v1[0] = 1;
    assert_eq!(
        decode::<AgentToCoordinator>(&v1),
        Err(DecodeError::Version {
            found: 1,
            expected: PROTOCOL_VERSION
        })
    );
    assert_eq!(
        decode::<AgentToCoordinator>(&bytes[..1]),
        Err(DecodeError::TooShort(1))
    );
    assert!(matches!(
        decode::<AgentToCoordinator>(&bytes[..bytes.len() - 1]),
        Err(DecodeError::Malformed(_))
    ));
    bytes.push(0);
    assert!(matches!(
        decode::<AgentToCoordinator>(&bytes),
        Err(DecodeError::Malformed(_))
    ));
    // A length prefix claiming 2^60 bytes must not allocate: the limit stops it.
    let mut huge = PROTOCOL_VERSION.to_le_bytes().to_vec();
    huge.extend_from_slice(&[0; 8]);
    huge.extend_from_slice(&[0, 0, 0, 0]);
    huge.extend_from_slice(&(1u64 << 60).to_le_bytes());
    assert!(matches!(
        decode::<AgentToCoordinator>(&huge),
        Err(DecodeError::Malformed(_))
    ));
    // Too big to send.
    let big = Envelope::new(AgentToCoordinator::Elites {
        mission: "m".into(),
        vehicle: "auv1".into(),
        round: 0,
        iteration: 0,
        evaluations: 0,
        particles: vec![WireChromosome {
            x: vec![0.0; 600_000],
            v: vec![],
        }],
    });
    assert!(encode(&big).is_err());
    Ok(())
}

fn particle() -> impl Strategy<Value = WireChromosome> {
    proptest::collection::vec(-1e4f64..1e4, 0..40).prop_map(|x| WireChromosome {
        v: x.iter().map(|a| a * 0.5).collect(),
        x,
    })
}

proptest! {
    #[test]
    fn messages_round_trip(
        mission in "[a-z0-9-]{1,12}",
        particles in proptest::collection::vec(particle(), 0..5),
        samples in proptest::collection::vec(proptest::array::uniform4(-1e4f64..1e4), 0..40),
        it in 0u32..10_000,
    ) {
        let up = Envelope::new(AgentToCoordinator::Elites {
            mission: mission.clone(), vehicle: "auv1".into(), round: it, iteration: it, evaluations: 7, particles: particles.clone(),
        });
        prop_assert_eq!(decode::<AgentToCoordinator>(&encode(&up).map_err(|e| TestCaseError::fail(e.to_string()))?), Ok(up));
        let down = Envelope::new(CoordinatorToAgent::Context {
            mission, context: WireContext { round: it, arrival_s: 2700.0,
            trajectories: vec![WireTrajectory { vehicle: "auv2".into(), samples }] },
        });
        prop_assert_eq!(decode::<CoordinatorToAgent>(&encode(&down).map_err(|e| TestCaseError::fail(e.to_string()))?), Ok(down));
    }

    #[test]
    fn garbage_is_an_error_never_a_panic(bytes in proptest::collection::vec(any::<u8>(), 0..200)) {
        let _ = decode::<AgentToCoordinator>(&bytes);
        let _ = decode::<CoordinatorToAgent>(&bytes);
    }
}

mod fuzz;
