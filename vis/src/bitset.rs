//! Fixed-size bit sets over portals or leaves, stored as 64-bit words.

/// A set of indices `0..len`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BitSet {
    words: Vec<u64>,
    len: usize,
}

impl BitSet {
    pub fn new(len: usize) -> BitSet {
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

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.words.iter().all(|&w| w == 0)
    }

    #[inline]
    pub fn contains(&self, i: usize) -> bool {
        debug_assert!(i < self.len, "bit {i} outside a set of {}", self.len);
        self.words[i / 64] & (1 << (i % 64)) != 0
    }

    #[inline]
    pub fn insert(&mut self, i: usize) {
        debug_assert!(i < self.len, "bit {i} outside a set of {}", self.len);
        self.words[i / 64] |= 1 << (i % 64);
    }

    #[inline]
    pub fn remove(&mut self, i: usize) {
        debug_assert!(i < self.len, "bit {i} outside a set of {}", self.len);
        self.words[i / 64] &= !(1 << (i % 64));
    }

    pub fn count(&self) -> usize {
        self.words.iter().map(|w| w.count_ones() as usize).sum()
    }

    pub fn union_with(&mut self, other: &BitSet) {
        debug_assert_eq!(self.len, other.len);
        for (a, b) in self.words.iter_mut().zip(&other.words) {
            *a |= b;
        }
    }

    /// `self = a & b`; returns whether the result holds any index not in `known`.
    #[inline]
    pub fn assign_and(&mut self, a: &BitSet, b: &BitSet, known: &BitSet) -> bool {
        debug_assert!(self.len == a.len && a.len == b.len && b.len == known.len);
        let mut new = 0;
        for (((out, &x), &y), &k) in self
            .words
            .iter_mut()
            .zip(&a.words)
            .zip(&b.words)
            .zip(&known.words)
        {
            *out = x & y;
            new |= *out & !k;
        }
        new != 0
    }

    pub fn is_subset(&self, other: &BitSet) -> bool {
        self.words
            .iter()
            .zip(&other.words)
            .all(|(&a, &b)| a & !b == 0)
    }

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

    #[test]
    fn assign_and_reports_new_bits() {
        let mut a = BitSet::new(70);
        let mut b = BitSet::new(70);
        let mut known = BitSet::new(70);
        a.insert(65);
        b.insert(65);
        let mut out = BitSet::new(70);
        assert!(out.assign_and(&a, &b, &known));
        known.insert(65);
        assert!(!out.assign_and(&a, &b, &known));
        assert!(out.contains(65));
    }

    #[test]
    fn row_bytes_ignore_padding_bits() {
        let set = BitSet::from_row_bytes(&[0xff], 3);
        assert_eq!(set.count(), 3);
    }
}
