//! A fast hasher for maps keyed by small integers (grid cells, vertex numbers, a point's
//! bits). std's SipHash resists collisions an attacker picks, which a map file cannot do to
//! these keys, at several times the cost; the compiler's welding looks up a grid cell for every
//! vertex and edge. It is deterministic, as SipHash's random keys are not, but nothing may
//! depend on a map's iteration order anyway.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// Multiply-rotate mixing of 64-bit words (the hash rustc's own maps use).
#[derive(Debug, Default, Clone, Copy)]
pub struct IntHasher(u64);

const SEED: u64 = 0x51_7c_c1_b7_27_22_0a_95;

impl IntHasher {
    #[inline]
    fn add(&mut self, word: u64) {
        self.0 = (self.0.rotate_left(5) ^ word).wrapping_mul(SEED);
    }
}

impl Hasher for IntHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        let mut chunks = bytes.chunks_exact(8);
        for chunk in &mut chunks {
            let mut word = [0; 8];
            word.copy_from_slice(chunk);
            self.add(u64::from_le_bytes(word));
        }
        let rest = chunks.remainder();
        if !rest.is_empty() {
            let mut word = [0; 8];
            word[..rest.len()].copy_from_slice(rest);
            self.add(u64::from_le_bytes(word));
        }
    }

    #[inline]
    fn write_u32(&mut self, n: u32) {
        self.add(u64::from(n));
    }

    #[inline]
    fn write_u64(&mut self, n: u64) {
        self.add(n);
    }

    #[inline]
    fn write_usize(&mut self, n: usize) {
        self.add(n as u64);
    }

    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
}

/// A `HashMap` hashed by [`IntHasher`].
pub type IntMap<K, V> = HashMap<K, V, BuildHasherDefault<IntHasher>>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_cells_find_what_was_put_in() {
        let mut map: IntMap<[i64; 3], u32> = IntMap::default();
        for (i, x) in (-50i64..50).enumerate() {
            map.insert([x, -x, x * 7], i as u32);
        }
        for (i, x) in (-50i64..50).enumerate() {
            assert_eq!(map.get(&[x, -x, x * 7]), Some(&(i as u32)));
        }
        assert_eq!(map.get(&[1, 1, 1]), None);
    }
}
