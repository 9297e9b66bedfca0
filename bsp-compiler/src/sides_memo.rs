//! A brush's remembered answers to "which sides of this plane do your corners reach?".
//!
//! Choosing a node's splitter asks it of every brush in the node for every candidate plane, and
//! the node's children ask again of each brush they keep whole, for the candidates they keep: a
//! brush that survives ten levels unsplit is asked the same questions ten times. Its bounding
//! box answers most of them at once; the rest walk every corner of every side, which for grown
//! clip-hull brushes (fifty corners and more) is most of the tree's cost. Those answers are kept
//! here, per canonical plane.
//!
//! The candidates of one node are scored on several threads at once, all reading the same
//! brushes, so the memo is a small open-addressed table of atomic slots (and a larger second one
//! once the first fills): each slot is written once, by compare-and-swap, and an answer is found
//! within [`PROBES`] slots of its home in a table or not at all. A full neighbourhood in both
//! drops the answer, which costs only time: what is remembered is exactly what the corners would
//! say again, so the tree is the same whatever was kept.

use crate::planes::PlaneId;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicU32, Ordering};

/// The tables a brush may make, the second only when the first is full around an answer's home:
/// most brushes need none or the first; grown terrain brushes meet a thousand planes and more.
/// A brush with a second table is one that meets many planes, so lookups try it first: most of
/// its answers are there, and the first's full neighbourhoods would be walked for nothing.
const SMALL: usize = 256;
/// The second table's slots.
const LARGE: usize = 4096;
/// How far from its home slot an answer may be kept.
const PROBES: usize = 8;

/// Answers by plane: no table until a brush's corners are first asked. The tables have fixed
/// sizes, so finding a slot takes no bounds check.
#[derive(Default)]
pub struct SidesMemo {
    small: OnceLock<Box<[AtomicU32; SMALL]>>,
    large: OnceLock<Box<[AtomicU32; LARGE]>>,
}

/// Which sides of a plane something reaches: (in front, behind).
pub type Sides = (bool, bool);

/// A table's slots, for each the id plus one above the two answer bits; 0 is empty.
fn empty_table<const N: usize>() -> Box<[AtomicU32; N]> {
    Box::new(std::array::from_fn(|_| AtomicU32::new(0)))
}

/// The slots an answer for `key` may take in a table of `N` slots (a power of two), in order.
fn probes<const N: usize>(key: u32) -> impl Iterator<Item = usize> {
    const { assert!(N.is_power_of_two()) };
    let home = (key.wrapping_mul(0x9E37_79B9) >> 16) as usize;
    (0..PROBES).map(move |i| (home + i) & (N - 1))
}

/// The answer for `key` in `table`, if it holds one. Slots are never emptied: an empty one on
/// the way means the answer is not there (it would have taken that slot, or one before it).
fn find<const N: usize>(table: &[AtomicU32; N], key: u32) -> Option<Sides> {
    for i in probes::<N>(key) {
        let slot = table[i].load(Ordering::Relaxed);
        if slot >> 2 == key {
            return Some((slot & 2 != 0, slot & 1 != 0));
        }
        if slot == 0 {
            return None;
        }
    }
    None
}

/// Keeps `value` for `key` in `table`: whether it is held (by this call or by another thread
/// that answered the same question first, with the same answer).
fn keep<const N: usize>(table: &[AtomicU32; N], key: u32, value: u32) -> bool {
    probes::<N>(key).any(|i| {
        match table[i].compare_exchange(0, value, Ordering::Relaxed, Ordering::Relaxed) {
            Ok(_) => true,
            Err(held) => held >> 2 == key,
        }
    })
}

impl SidesMemo {
    /// The answer for plane `id`, remembered or worked out by `corners` (and then remembered).
    pub fn get_or_insert(&self, id: PlaneId, corners: impl FnOnce() -> Sides) -> Sides {
        let Some(key) = id.checked_add(1).filter(|k| k >> 30 == 0) else {
            return corners();
        };
        if let Some(sides) = self.large.get().and_then(|t| find(t, key)) {
            return sides;
        }
        if let Some(sides) = self.small.get().and_then(|t| find(t, key)) {
            return sides;
        }
        let sides = corners();
        let value = key << 2 | u32::from(sides.0) << 1 | u32::from(sides.1);
        if !keep(self.small.get_or_init(empty_table), key, value) {
            keep(self.large.get_or_init(empty_table), key, value);
        }
        sides
    }

    /// How many answers are kept.
    pub fn len(&self) -> usize {
        let small = self.small.get().map(|t| t.as_slice());
        let large = self.large.get().map(|t| t.as_slice());
        [small, large]
            .into_iter()
            .flatten()
            .flatten()
            .filter(|s| s.load(Ordering::Relaxed) != 0)
            .count()
    }
}

/// A copy answers as the original does (the same corners).
impl Clone for SidesMemo {
    fn clone(&self) -> SidesMemo {
        fn copied<const N: usize>(
            table: &OnceLock<Box<[AtomicU32; N]>>,
        ) -> OnceLock<Box<[AtomicU32; N]>> {
            let copy = OnceLock::new();
            if let Some(slots) = table.get() {
                let slots =
                    std::array::from_fn(|i| AtomicU32::new(slots[i].load(Ordering::Relaxed)));
                let _ = copy.set(Box::new(slots));
            }
            copy
        }
        SidesMemo {
            small: copied(&self.small),
            large: copied(&self.large),
        }
    }
}

/// Remembered answers are not part of a brush's value.
impl PartialEq for SidesMemo {
    fn eq(&self, _: &SidesMemo) -> bool {
        true
    }
}

impl std::fmt::Debug for SidesMemo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "SidesMemo({} answers)", self.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::Cell;

    #[test]
    fn an_answer_is_worked_out_once_and_then_remembered() {
        let memo = SidesMemo::default();
        let asked = Cell::new(0);
        let ask = |sides: Sides| {
            asked.set(asked.get() + 1);
            sides
        };
        assert_eq!(memo.get_or_insert(7, || ask((true, false))), (true, false));
        assert_eq!(memo.get_or_insert(7, || ask((false, true))), (true, false));
        assert_eq!(memo.get_or_insert(8, || ask((false, true))), (false, true));
        assert_eq!(asked.get(), 2);
        assert_eq!(
            memo.clone().get_or_insert(8, || ask((true, true))),
            (false, true)
        );
        assert_eq!(asked.get(), 2);
    }

    #[test]
    fn a_full_table_still_answers_every_question_right() {
        let memo = SidesMemo::default();
        let answer = |id: PlaneId| (id.is_multiple_of(3), id.is_multiple_of(2));
        for round in 0..2 {
            for id in 0..2 * 4096 {
                assert_eq!(
                    memo.get_or_insert(id, || answer(id)),
                    answer(id),
                    "{round} {id}"
                );
            }
        }
        assert!(memo.len() <= SMALL + LARGE);
    }
}
