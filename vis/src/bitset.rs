//! Fixed-size bit sets over portals or leaves, stored as 64-bit words.

/// A set of indices `0..len`.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct BitSet {
    words: Vec<u64>,
    len: usize,
}

impl BitSet {
    pub(crate) fn new(len: usize) -> BitSet {
        BitSet {
            words: vec![0; len.div_ceil(64)],
            len,
        }
    }

    /// Indices `0..len`, all set.
    pub fn full(len: usize) -> BitSet {
        let mut set = BitSet::new(len);
        for i in 0..len {
            set.insert(i);
        }
        set
    }

    pub(crate) fn len(&self) -> usize {
        self.len
    }

    #[inline]
    pub(crate) fn contains(&self, i: usize) -> bool {
        debug_assert!(i < self.len, "bit {i} outside a set of {}", self.len);
        self.words[i / 64] & (1 << (i % 64)) != 0
    }

    #[inline]
    pub(crate) fn insert(&mut self, i: usize) {
        debug_assert!(i < self.len, "bit {i} outside a set of {}", self.len);
        self.words[i / 64] |= 1 << (i % 64);
    }

    #[inline]
    pub(crate) fn remove(&mut self, i: usize) {
        debug_assert!(i < self.len, "bit {i} outside a set of {}", self.len);
        self.words[i / 64] &= !(1 << (i % 64));
    }

    /// How many indices the set holds.
    pub fn count(&self) -> usize {
        self.words.iter().map(|w| w.count_ones() as usize).sum()
    }

    pub(crate) fn union_with(&mut self, other: &BitSet) {
        debug_assert_eq!(self.len, other.len);
        for (a, b) in self.words.iter_mut().zip(&other.words) {
            *a |= b;
        }
    }

    pub(crate) fn is_subset(&self, other: &BitSet) -> bool {
        self.words
            .iter()
            .zip(&other.words)
            .all(|(&a, &b)| a & !b == 0)
    }

    /// The indices the set holds, ascending.
    pub fn iter(&self) -> impl Iterator<Item = usize> + '_ {
        self.words.iter().enumerate().flat_map(|(wi, &w)| {
            let mut bits = w;
            std::iter::from_fn(move || {
                if bits == 0 {
                    return None;
                }
                let b = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                Some(wi * 64 + b)
            })
        })
    }

    /// The set as a Quake PVS row: bit `i` is bit `i % 8` of byte `i / 8`.
    pub fn to_row_bytes(&self) -> Vec<u8> {
        let mut bytes: Vec<u8> = self.words.iter().flat_map(|w| w.to_le_bytes()).collect();
        bytes.truncate(self.len.div_ceil(8));
        bytes
    }

    /// Read a Quake PVS row; bits at or past `len` are ignored.
    pub fn from_row_bytes(bytes: &[u8], len: usize) -> BitSet {
        let mut set = BitSet::new(len);
        for (i, &b) in bytes.iter().enumerate().take(len.div_ceil(8)) {
            set.words[i / 8] |= (b as u64) << (8 * (i % 8));
        }
        if let Some(last) = set.words.last_mut()
            && !len.is_multiple_of(64)
        {
            *last &= (1u64 << (len % 64)) - 1;
        }
        set
    }
}

/// A set of indices `0..len` whose members all lie in a window of words, kept as narrow as
/// the members allow: operations touch only the window. A portal flow's "might see" sets
/// shrink to a few nearby portals after the first steps (portals are numbered in tree order,
/// so nearby ones have nearby numbers), which makes this much cheaper than a whole set.
#[derive(Debug, Clone, Default)]
pub struct WindowBits {
    /// Only `words[lo..hi]` are meaningful; the others are stale.
    words: Vec<u64>,
    lo: usize,
    hi: usize,
}

impl WindowBits {
    /// Copy `set`, removing the members for which `drop` holds.
    pub fn assign_filtered(&mut self, set: &BitSet, mut drop: impl FnMut(usize) -> bool) {
        self.words.clone_from(&set.words);
        self.lo = 0;
        self.hi = self.words.len();
        for (wi, w) in self.words.iter_mut().enumerate() {
            let mut bits = *w;
            while bits != 0 {
                let b = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                if drop(wi * 64 + b) {
                    *w &= !(1 << b);
                }
            }
        }
        self.trim();
    }

    #[inline]
    pub(crate) fn contains(&self, i: usize) -> bool {
        let w = i / 64;
        (self.lo..self.hi).contains(&w) && self.words[w] & (1 << (i % 64)) != 0
    }

    fn window(&self) -> &[u64] {
        &self.words[self.lo..self.hi]
    }

    /// Narrow the window to the words holding members.
    fn trim(&mut self) {
        while self.lo < self.hi && self.words[self.lo] == 0 {
            self.lo += 1;
        }
        while self.hi > self.lo && self.words[self.hi - 1] == 0 {
            self.hi -= 1;
        }
    }

    /// `self = a & b`; returns whether the result holds any index not in `known`.
    #[inline]
    pub fn assign_and(&mut self, a: &WindowBits, b: &BitSet, known: &BitSet) -> bool {
        debug_assert!(a.words.len() == b.words.len() && b.words.len() == known.words.len());
        self.words.resize(a.words.len(), 0);
        let (lo, hi) = (a.lo, a.hi);
        let mut new = 0;
        for (((out, &x), &y), &k) in self.words[lo..hi]
            .iter_mut()
            .zip(&a.words[lo..hi])
            .zip(&b.words[lo..hi])
            .zip(&known.words[lo..hi])
        {
            *out = x & y;
            new |= *out & !k;
        }
        self.lo = lo;
        self.hi = hi;
        self.trim();
        new != 0
    }

    /// Remove each member not in `known` for which `drop` holds; returns whether any member
    /// outside `known` is left.
    #[inline]
    pub fn prune_unknown(&mut self, known: &BitSet, mut drop: impl FnMut(usize) -> bool) -> bool {
        let mut left = false;
        for wi in self.lo..self.hi {
            let w = &mut self.words[wi];
            let mut bits = *w & !known.words[wi];
            while bits != 0 {
                let b = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                if drop(wi * 64 + b) {
                    *w &= !(1 << b);
                } else {
                    left = true;
                }
            }
        }
        self.trim();
        left
    }

    /// Whether every member is a member of `other`.
    pub(crate) fn is_subset(&self, other: WindowView) -> bool {
        let other_hi = other.lo + other.words.len();
        (self.lo..self.hi).all(|wi| {
            let theirs = if (other.lo..other_hi).contains(&wi) {
                other.words[wi - other.lo]
            } else {
                0
            };
            self.words[wi] & !theirs == 0
        })
    }
}

/// The window of a [`WindowBits`] alone, kept elsewhere: what is kept of many of them takes
/// the window's words, not the whole set's.
#[derive(Debug, Clone, Copy)]
pub struct WindowView<'a> {
    /// The index of the first word.
    pub lo: usize,
    /// The window's words.
    pub words: &'a [u64],
}

impl WindowBits {
    /// The window as a view.
    pub(crate) fn view(&self) -> WindowView<'_> {
        WindowView {
            lo: self.lo,
            words: self.window(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn row_bytes_round_trip(len in 1usize..300, bits in proptest::collection::vec(any::<usize>(), 0..40)) {
            let mut set = BitSet::new(len);
            for b in bits {
                set.insert(b % len);
            }
            let bytes = set.to_row_bytes();
            prop_assert_eq!(bytes.len(), len.div_ceil(8));
            prop_assert_eq!(BitSet::from_row_bytes(&bytes, len), set.clone());
            let listed: Vec<usize> = set.iter().collect();
            prop_assert_eq!(listed.len(), set.count());
            prop_assert!(listed.iter().all(|&i| set.contains(i)));
        }
    }

    fn set_of(len: usize, members: &[usize]) -> BitSet {
        let mut set = BitSet::new(len);
        for &i in members {
            set.insert(i);
        }
        set
    }

    /// The members of a window set over `0..300`, ascending.
    fn members(bits: &WindowBits) -> Vec<usize> {
        (0..300).filter(|&i| bits.contains(i)).collect()
    }

    proptest! {
        #[test]
        fn window_bits_agree_with_whole_sets(
            a in proptest::collection::vec(0usize..300, 0..30),
            b in proptest::collection::vec(0usize..300, 0..60),
            known in proptest::collection::vec(0usize..300, 0..60),
            dropped in proptest::collection::vec(0usize..300, 0..60),
        ) {
            let (a, b, known) = (set_of(300, &a), set_of(300, &b), set_of(300, &known));
            let mut wa = WindowBits::default();
            wa.assign_filtered(&a, |i| dropped.contains(&i));
            let expected: Vec<usize> = a.iter().filter(|i| !dropped.contains(i)).collect();
            prop_assert_eq!(members(&wa), expected.clone());
            let mut and = WindowBits::default();
            let new = and.assign_and(&wa, &b, &known);
            let both: Vec<usize> = expected.iter().copied().filter(|&i| b.contains(i)).collect();
            prop_assert_eq!(members(&and), both.clone());
            prop_assert_eq!(new, both.iter().any(|&i| !known.contains(i)));
            prop_assert!(and.is_subset(wa.view()));
            prop_assert_eq!(wa.is_subset(and.view()), both.len() == expected.len());
            for i in 0..300 {
                prop_assert_eq!(and.contains(i), both.contains(&i));
            }
            let mut copy = and.clone();
            let left = copy.prune_unknown(&known, |i| i % 2 == 0);
            let kept: Vec<usize> = both.iter().copied().filter(|&i| known.contains(i) || i % 2 == 1).collect();
            prop_assert_eq!(members(&copy), kept);
            prop_assert_eq!(left, both.iter().any(|&i| !known.contains(i) && i % 2 == 1));
        }
    }

    #[test]
    fn row_bytes_ignore_padding_bits() {
        let set = BitSet::from_row_bytes(&[0xff], 3);
        assert_eq!(set.count(), 3);
    }
}
