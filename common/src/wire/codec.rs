//! The one `encode`/`decode` pair: bincode 1.3.3, fixed-width little-endian integers, a size
//! limit, and trailing bytes rejected. No other code names the codec.
//!
//! `decode` never panics and never allocates more than the limit, whatever the bytes: a bad
//! length prefix or a truncated message is an error, as is a message from another protocol
//! version (told apart from garbage, so it can be counted separately).

use bincode::Options;
use serde::de::DeserializeOwned;
use serde::Serialize;

use super::{Envelope, PROTOCOL_VERSION};

/// Largest message either side sends or accepts, bytes. A scenario-3 context (5 trajectories of
/// 32 samples) is about 6 KB and a batch of elites a few tens of KB.
pub const MAX_MESSAGE_BYTES: u64 = 4 * 1024 * 1024;

/// Why bytes could not be read as a message.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DecodeError {
    /// Shorter than a version stamp.
    #[error("message of {0} bytes is too short to carry a protocol version")]
    TooShort(usize),
    /// A peer speaking another protocol version.
    #[error("protocol version {found}, expected {expected}")]
    Version {
        /// Version in the message.
        found: u16,
        /// This build's version.
        expected: u16,
    },
    /// Not a valid message of this version (garbage, truncated, too large, trailing bytes).
    #[error("malformed message: {0}")]
    Malformed(String),
}

/// Why a message could not be written.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("cannot encode message: {0}")]
pub struct EncodeError(String);

fn options() -> impl Options {
    bincode::DefaultOptions::new()
        .with_fixint_encoding()
        .with_little_endian()
        .with_limit(MAX_MESSAGE_BYTES)
        .reject_trailing_bytes()
}

/// Writes `message` (over [`MAX_MESSAGE_BYTES`] is an error).
pub fn encode<T: Serialize>(message: &Envelope<T>) -> Result<Vec<u8>, EncodeError> {
    options()
        .serialize(message)
        .map_err(|e| EncodeError(e.to_string()))
}

/// Reads a message of this protocol version.
pub fn decode<T: DeserializeOwned>(bytes: &[u8]) -> Result<Envelope<T>, DecodeError> {
    let Some(head) = bytes.get(..2) else {
        return Err(DecodeError::TooShort(bytes.len()));
    };
    let found = u16::from_le_bytes([head[0], head[1]]);
    if found != PROTOCOL_VERSION {
        return Err(DecodeError::Version {
            found,
            expected: PROTOCOL_VERSION,
        });
    }
    options()
        .deserialize(bytes)
        .map_err(|e| DecodeError::Malformed(e.to_string()))
}

/// Largest JSON payload of the open interface accepted, bytes.
pub const MAX_JSON_BYTES: usize = 1024 * 1024;

/// Writes a payload of the open interface ([`super::open`]) as JSON.
pub fn encode_json<T: Serialize>(payload: &T) -> Result<Vec<u8>, EncodeError> {
    serde_json::to_vec(payload).map_err(|e| EncodeError(e.to_string()))
}

/// Reads a payload of the open interface; over [`MAX_JSON_BYTES`] or not the expected JSON is
/// an error naming what is wrong.
pub fn decode_json<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, DecodeError> {
    if bytes.len() > MAX_JSON_BYTES {
        return Err(DecodeError::Malformed(format!(
            "JSON payload of {} bytes is over the {MAX_JSON_BYTES}-byte limit",
            bytes.len()
        )));
    }
    serde_json::from_slice(bytes).map_err(|e| DecodeError::Malformed(e.to_string()))
}

#[cfg(test)]
#[path = "codec_fuzz_tests.rs"]
mod fuzz_tests;

#[cfg(test)]
mod tests {
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
}
