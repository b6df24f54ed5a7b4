//! Counting the messages the agent drops, apart from the session loop so that the checks it
//! runs (such as [`super::order_seq`]) can count into it.

use std::collections::HashSet;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::Arc;

/// Counts dropped messages and logs the first of each kind.
#[derive(Debug, Default)]
pub struct Drops {
    /// Messages dropped so far.
    pub count: Arc<AtomicU32>,
    logged: HashSet<&'static str>,
}

impl Drops {
    /// Counts one dropped message of `kind`, logging the first of that kind.
    pub fn drop_message(&mut self, kind: &'static str, detail: &str) {
        self.count.fetch_add(1, Ordering::Relaxed);
        if self.logged.insert(kind) {
            tracing::warn!(
                "dropped a message ({kind}): {detail}; further ones of this kind are only counted"
            );
        }
    }
}
