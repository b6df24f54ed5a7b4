//! What the hub's thread and the clients' threads share: the hub, and each client's bounded
//! queue, to which every change is handed without waiting (a client whose queue is full is cut
//! off: its thread sees the queue closed and drops the connection).

use std::sync::mpsc::{SyncSender, TrySendError};
use std::sync::{Arc, Mutex};

use super::hub::{Data, Hub, Update};
use super::protocol;
use crate::execute::live::LiveMessage;

/// What the hub queues for a client.
pub enum ToClient {
    /// An `advertise` message.
    Advertise(Arc<str>),
    /// An `unadvertise` message, and its channels (the client ends its subscriptions to them).
    Unadvertise(Vec<u32>, Arc<str>),
    /// A message on a channel (sent if the client subscribed to it).
    Data(Arc<Data>),
}

/// What the hub's thread and the clients' threads share.
#[derive(Default)]
pub struct Shared {
    /// The mission as served.
    pub hub: Hub,
    /// Each connected client's queue.
    pub clients: Vec<SyncSender<ToClient>>,
}

/// Applies one feed message to the hub and queues what changed for every client.
pub fn dispatch(shared: &Mutex<Shared>, m: &LiveMessage) {
    let Ok(mut s) = shared.lock() else {
        return;
    };
    for u in s.hub.apply(m) {
        let out = || match &u {
            Update::Advertise(channels) => {
                ToClient::Advertise(protocol::advertise(channels).into())
            }
            Update::Unadvertise(ids) => {
                ToClient::Unadvertise(ids.clone(), protocol::unadvertise(ids).into())
            }
            Update::Data(d) => ToClient::Data(Arc::clone(d)),
        };
        s.clients.retain(|c| match c.try_send(out()) {
            Ok(()) => true,
            // Too slow (its thread sees its queue closed and drops it), or gone.
            Err(TrySendError::Full(_) | TrySendError::Disconnected(_)) => false,
        });
    }
}
