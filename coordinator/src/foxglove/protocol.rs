//! The Foxglove WebSocket protocol, version 1 (`foxglove.websocket.v1`, published at
//! github.com/foxglove/ws-protocol), as far as a server that only publishes needs it: the
//! server's JSON messages (`serverInfo`, `advertise`, `unadvertise`, `status`), its binary
//! message-data frame, and the client's `subscribe` / `unsubscribe`. Shoal advertises no
//! capability, so a client has nothing else to send; anything else is refused (and counted).

use serde::Deserialize;

use super::channels::Channel;
use super::hub::Data;

/// The WebSocket subprotocol a client must ask for.
pub const SUBPROTOCOL: &str = "foxglove.websocket.v1";
/// Opcode of a server's binary message-data frame.
const MESSAGE_DATA: u8 = 0x01;

/// `serverInfo`: the first message a client gets.
pub fn server_info(session: &str) -> String {
    serde_json::json!({
        "op": "serverInfo",
        "name": concat!("shoal-coordinator ", env!("CARGO_PKG_VERSION")),
        "capabilities": [],
        "supportedEncodings": [],
        "metadata": {},
        "sessionId": session,
    })
    .to_string()
}

/// `advertise` of `channels`.
pub fn advertise(channels: &[Channel]) -> String {
    let channels: Vec<serde_json::Value> = channels.iter().map(Channel::advertisement).collect();
    serde_json::json!({ "op": "advertise", "channels": channels }).to_string()
}

/// `unadvertise` of the channels `ids`.
pub fn unadvertise(ids: &[u32]) -> String {
    serde_json::json!({ "op": "unadvertise", "channelIds": ids }).to_string()
}

/// How grave a `status` message is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Level {
    /// 1: something the client did was refused.
    Warning = 1,
    /// 2: the connection ends.
    Error = 2,
}

/// `status`: tells the client, in words, what was refused.
pub fn status(level: Level, message: &str) -> String {
    serde_json::json!({ "op": "status", "level": level as u8, "message": message }).to_string()
}

/// A message-data frame: opcode, the subscription's id (u32, little-endian), the message's time
/// (u64 nanoseconds, little-endian), the message.
pub fn message_data(subscription: u32, d: &Data) -> Vec<u8> {
    let mut out = Vec::with_capacity(13 + d.payload.len());
    out.push(MESSAGE_DATA);
    out.extend_from_slice(&subscription.to_le_bytes());
    out.extend_from_slice(&d.stamp_ns.to_le_bytes());
    out.extend_from_slice(&d.payload);
    out
}

/// A client's subscription of one channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
pub struct Subscription {
    /// The client's id for it.
    pub id: u32,
    /// The channel.
    #[serde(rename = "channelId")]
    pub channel: u32,
}

/// What a client may ask.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(tag = "op")]
pub enum ClientMessage {
    /// Start receiving channels' messages.
    #[serde(rename = "subscribe")]
    Subscribe {
        /// One per channel.
        subscriptions: Vec<Subscription>,
    },
    /// Stop.
    #[serde(rename = "unsubscribe")]
    Unsubscribe {
        /// The client's ids of the subscriptions to end.
        #[serde(rename = "subscriptionIds")]
        ids: Vec<u32>,
    },
}

impl ClientMessage {
    /// Reads a client's text message (its size is bounded by the WebSocket layer).
    pub fn parse(text: &str) -> serde_json::Result<ClientMessage> {
        serde_json::from_str(text)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_message_data_frame_is_opcode_subscription_time_payload() {
        let d = Data {
            channel: 9,
            stamp_ns: 0x0102_0304_0506_0708,
            payload: b"{}".to_vec(),
        };
        assert_eq!(
            message_data(0xA1B2_C3D4, &d),
            [
                0x01, 0xD4, 0xC3, 0xB2, 0xA1, 0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01, b'{',
                b'}'
            ]
        );
    }

    #[test]
    fn subscribe_and_unsubscribe_are_read_and_anything_else_refused() {
        assert_eq!(
            ClientMessage::parse(r#"{"op":"subscribe","subscriptions":[{"id":4,"channelId":2}]}"#)
                .ok(),
            Some(ClientMessage::Subscribe {
                subscriptions: vec![Subscription { id: 4, channel: 2 }]
            })
        );
        assert_eq!(
            ClientMessage::parse(r#"{"op":"unsubscribe","subscriptionIds":[4]}"#).ok(),
            Some(ClientMessage::Unsubscribe { ids: vec![4] })
        );
        for bad in [
            r#"{"op":"advertise","channels":[]}"#,
            r#"{"op":"subscribe","subscriptions":[{"id":-1,"channelId":2}]}"#,
            r#"{"op":"subscribe"}"#,
            "not json",
        ] {
            assert!(ClientMessage::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn server_messages_name_their_op() -> serde_json::Result<()> {
        let info: serde_json::Value = serde_json::from_str(&server_info("s1"))?;
        assert_eq!(info["op"], "serverInfo");
        assert_eq!(info["capabilities"], serde_json::json!([]));
        let gone: serde_json::Value = serde_json::from_str(&unadvertise(&[4, 5]))?;
        assert_eq!(gone["channelIds"], serde_json::json!([4, 5]));
        let s: serde_json::Value = serde_json::from_str(&status(Level::Warning, "no"))?;
        assert_eq!(
            (s["op"].as_str(), s["level"].as_u64()),
            (Some("status"), Some(1))
        );
        Ok(())
    }
}
