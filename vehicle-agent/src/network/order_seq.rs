//! The agent's check of the coordinator's order numbers ([`Envelope::seq`]): on its inbox, an
//! order acts only if its number is above the last one this agent took for that mission. A
//! replayed order (the same number again) or one overtaken by a later one is dropped, counted
//! and logged once, so a recorded `Hold` or `Stop` played back later does nothing.
//!
//! The fleet key (the shared plan every agent of a mission reads) is not checked: Zenoh keeps
//! order per key, not across keys, so its numbers interleave with the inbox's in any order.
//!
//! [`Envelope::seq`]: shoal_common::wire::Envelope::seq

use std::collections::HashMap;

use super::drops::Drops;

/// Kind under which a refused order is counted (and logged once).
pub const REFUSED: &str = "replayed or out-of-order order";

/// The last order number taken, per mission.
#[derive(Debug, Default)]
pub struct OrderSeqs {
    /// Mission id → highest order number acted on.
    last: HashMap<String, u64>,
}

impl OrderSeqs {
    /// Whether order `seq` of `mission` may act; a refusal is counted in `drops`. Nothing is
    /// noted until [`OrderSeqs::take`]: an order that is refused for another reason (another
    /// vehicle's, an unknown mission's) must not raise the mark.
    pub fn admits(&self, drops: &mut Drops, mission: &str, seq: u64) -> bool {
        match self.last.get(mission) {
            Some(&last) if seq <= last => {
                drops.drop_message(
                    REFUSED,
                    &format!(
                        "mission {mission}: order number {seq} is not after {last}, the last one taken"
                    ),
                );
                false
            }
            _ => true,
        }
    }

    /// Notes that order `seq` of `mission` acted.
    pub fn take(&mut self, mission: &str, seq: u64) {
        let last = self.last.entry(mission.to_string()).or_insert(seq);
        *last = (*last).max(seq);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::Ordering;

    /// Admits and, when admitted, takes: what the inbox does with an order that acts.
    fn order(seqs: &mut OrderSeqs, drops: &mut Drops, mission: &str, seq: u64) -> bool {
        let ok = seqs.admits(drops, mission, seq);
        if ok {
            seqs.take(mission, seq);
        }
        ok
    }

    #[test]
    fn a_replayed_hold_and_an_overtaken_one_are_dropped_and_counted_and_a_fresh_one_acts() {
        let (mut seqs, mut drops) = (OrderSeqs::default(), Drops::default());
        assert!(
            order(&mut seqs, &mut drops, "m", 100),
            "the Execute starting it"
        );
        assert!(order(&mut seqs, &mut drops, "m", 104), "a Hold");
        assert!(
            !order(&mut seqs, &mut drops, "m", 104),
            "the same Hold replayed"
        );
        assert!(
            !order(&mut seqs, &mut drops, "m", 102),
            "an older one, late"
        );
        assert_eq!(drops.count.load(Ordering::Relaxed), 2);
        assert!(order(&mut seqs, &mut drops, "m", 105), "the next one acts");
        assert_eq!(drops.count.load(Ordering::Relaxed), 2);
    }

    #[test]
    fn missions_are_numbered_apart_and_a_refused_order_raises_no_mark() {
        let (mut seqs, mut drops) = (OrderSeqs::default(), Drops::default());
        assert!(order(&mut seqs, &mut drops, "a", 5_000));
        // Another coordinator's mission counts from its own start.
        assert!(order(&mut seqs, &mut drops, "b", 7));
        assert!(order(&mut seqs, &mut drops, "b", 8));
        // Only checked, not taken (say it named another vehicle): the mark stays at 5,000.
        assert!(seqs.admits(&mut drops, "a", u64::MAX));
        assert!(order(&mut seqs, &mut drops, "a", 5_001));
        assert_eq!(drops.count.load(Ordering::Relaxed), 0);
    }
}
