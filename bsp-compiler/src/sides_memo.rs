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
const TABLE_SIZES: [usize; 2] = [256, 4096];
/// How far from its home slot an answer may be kept.
const PROBES: usize = 8;

type Table = OnceLock<Box<[AtomicU32]>>;

/// Answers by plane: no table until a brush's corners are first asked.
#[derive(Default)]
pub struct SidesMemo(OnceLock<Box<[Table; TABLE_SIZES.len()]>>);

/// Which sides of a plane something reaches: (in front, behind).
pub type Sides = (bool, bool);

impl SidesMemo {
    /// The answer for plane `id`, remembered or worked out by `corners` (and then remembered).
    pub fn get_or_insert(&self, id: PlaneId, corners: impl FnOnce() -> Sides) -> Sides {
        // A slot holds the id plus one above the two answer bits; 0 is empty.
        let Some(key) = id.checked_add(1).filter(|k| k >> 30 == 0) else {
            return corners();
        };
        // Sizes are powers of two.
        let probes = |size: usize| {
            let home = (key.wrapping_mul(0x9E37_79B9) >> 16) as usize;
            (0..PROBES).map(move |i| (home + i) & (size - 1))
        };
        let tables = self.0.get_or_init(Default::default);
        // Slots are never emptied: an empty one on the way means the answer is not in that
        // table (it would have taken that slot, or one before it).
        for table in tables.iter().rev().filter_map(OnceLock::get) {
            for i in probes(table.len()) {
                let slot = table[i].load(Ordering::Relaxed);
                if slot >> 2 == key {
                    return (slot & 2 != 0, slot & 1 != 0);
                }
                if slot == 0 {
                    break;
                }
            }
        }
        let sides = corners();
        let value = key << 2 | u32::from(sides.0) << 1 | u32::from(sides.1);
        for (table, &size) in tables.iter().zip(&TABLE_SIZES) {
            let table = table.get_or_init(|| (0..size).map(|_| AtomicU32::new(0)).collect());
            for i in probes(size) {
                match table[i].compare_exchange(0, value, Ordering::Relaxed, Ordering::Relaxed) {
                    Ok(_) => return sides,
                    // Another thread answered the same question first, with the same answer.
                    Err(held) if held >> 2 == key => return sides,
                    Err(_) => {}
                }
            }
        }
        sides
    }

    /// How many answers are kept.
    pub fn len(&self) -> usize {
        let tables = self.0.get().into_iter().flat_map(|t| t.iter());
        tables
            .filter_map(OnceLock::get)
            .flat_map(|table| table.iter())
            .filter(|s| s.load(Ordering::Relaxed) != 0)
            .count()
    }
}

/// A copy answers as the original does (the same corners).
impl Clone for SidesMemo {
    fn clone(&self) -> SidesMemo {
        let copy = SidesMemo::default();
        if let Some(tables) = self.0.get() {
            let copied = tables.each_ref().map(|table| {
                let copied = Table::new();
                if let Some(slots) = table.get() {
                    let slots = slots
                        .iter()
                        .map(|s| AtomicU32::new(s.load(Ordering::Relaxed)));
                    let _ = copied.set(slots.collect());
                }
                copied
            });
            let _ = copy.0.set(Box::new(copied));
        }
        copy
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
        assert!(memo.len() <= TABLE_SIZES.iter().sum());
    }
}
