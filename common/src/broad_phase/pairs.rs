//! The pairs the vehicle–vehicle broad phase keeps, each with the time slabs it kept them in.

/// The slabs a pair's boxes come near in: bit `k` for slab `k`.
pub type SlabMask = u32;

/// A set of vehicle pairs `(i, j)`, `i < j`, each with the slabs it was found in: one bit per
/// ordered pair, so inserting is a bit set whatever the slab that found it, and iterating goes
/// in row order `(0, 1), (0, 2), …`, the order the all-pairs loop sums in, so the fitness is the
/// same to the last bit.
#[derive(Debug, Clone, Default)]
pub struct PairSet {
    /// Vehicles.
    n: usize,
    /// Bit `i * n + j`.
    words: Vec<u64>,
    /// The pair's slabs at `i * n + j`.
    slabs: Vec<SlabMask>,
}

impl PairSet {
    /// Empty.
    pub fn new() -> PairSet {
        PairSet::default()
    }

    /// Clears the set for `n` vehicles, keeping its buffers.
    pub fn reset(&mut self, n: usize) {
        self.n = n;
        self.words.clear();
        self.words.resize((n * n).div_ceil(64), 0);
        self.slabs.clear();
        self.slabs.resize(n * n, 0);
    }

    /// The index of the pair of `a` and `b` (in either order), or `None` for `a == b` or a
    /// vehicle out of range.
    fn index(&self, a: usize, b: usize) -> Option<usize> {
        let (i, j) = (a.min(b), a.max(b));
        (i != j && j < self.n).then_some(i * self.n + j)
    }

    /// Marks the pair of `a` and `b` (in either order; `a == b` is ignored).
    pub fn insert(&mut self, a: usize, b: usize) {
        if let Some(bit) = self.index(a, b) {
            self.words[bit / 64] |= 1 << (bit % 64);
        }
    }

    /// Marks the pair of `a` and `b` as near in slab `k`.
    pub fn mark(&mut self, a: usize, b: usize, k: usize) {
        if let Some(bit) = self.index(a, b) {
            self.words[bit / 64] |= 1 << (bit % 64);
            self.slabs[bit] |= 1 << (k % SlabMask::BITS as usize);
        }
    }

    /// Whether the pair of `a` and `b` is marked.
    pub fn contains(&self, a: usize, b: usize) -> bool {
        self.index(a, b)
            .is_some_and(|bit| self.words[bit / 64] & (1 << (bit % 64)) != 0)
    }

    /// The slabs the pair of `a` and `b` was marked in (none for a pair only inserted).
    pub fn slabs(&self, a: usize, b: usize) -> SlabMask {
        self.index(a, b).map_or(0, |bit| self.slabs[bit])
    }

    /// The marked pairs in row order.
    pub fn iter(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        let n = self.n.max(1);
        self.words.iter().enumerate().flat_map(move |(w, &word)| {
            let mut rest = word;
            std::iter::from_fn(move || {
                if rest == 0 {
                    return None;
                }
                let b = rest.trailing_zeros() as usize;
                rest &= rest - 1;
                let bit = w * 64 + b;
                Some((bit / n, bit % n))
            })
        })
    }
}
