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
mod tests;
