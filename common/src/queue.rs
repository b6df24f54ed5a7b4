//! The open list of the grid searches (Dijkstra, A*): `BinaryHeap` is a max-heap, so entries
//! order in reverse, least cost first, then least index, so every pop order is total and
//! repeatable.

use std::cmp::Ordering;

/// A heap entry: cost (or estimate) and node index; the heap pops the cheapest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cheapest(pub f64, pub usize);

impl Eq for Cheapest {}

impl Ord for Cheapest {
    fn cmp(&self, other: &Self) -> Ordering {
        other.0.total_cmp(&self.0).then(other.1.cmp(&self.1))
    }
}

impl PartialOrd for Cheapest {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BinaryHeap;

    #[test]
    fn the_heap_pops_the_cheapest_then_the_lowest_index() {
        let mut h: BinaryHeap<Cheapest> = [
            Cheapest(2.0, 0),
            Cheapest(1.0, 7),
            Cheapest(1.0, 3),
            Cheapest(0.5, 9),
        ]
        .into_iter()
        .collect();
        let order: Vec<usize> = std::iter::from_fn(|| h.pop().map(|c| c.1)).collect();
        assert_eq!(order, vec![9, 3, 7, 0]);
    }
}
