//! `SLIPGATE_LEAFFLAGS`: Slipgate's own BSPX lump that says of each leaf what its contents
//! cannot: whether it is the inside of a `func_detail_fence`. Such a leaf is written solid, so
//! that players, monsters and traces stop at the fence as ericw-tools' qbsp makes them; light
//! must take it as open space all the same, or the floor and the lights inside a fence would
//! count as buried in a wall. The compiler writes the lump; light reads it.
//!
//! One byte per leaf, in leaf order: bit 0 set, the leaf is inside a fence. Other bits are
//! reserved and read as zero. The lump is left out when no leaf has a flag, and engines ignore
//! BSPX lumps they do not know.

use super::Bsp;
use crate::error::{FormatError, Result};

/// The lump's BSPX name.
pub const LUMP_NAME: &str = "SLIPGATE_LEAFFLAGS";
const FENCE: u8 = 1;

/// What a leaf is beyond its contents.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct LeafFlags {
    /// The leaf is inside a `func_detail_fence` brush: solid to engines, open to light.
    pub fence: bool,
}

impl LeafFlags {
    fn byte(self) -> u8 {
        u8::from(self.fence) * FENCE
    }

    fn from_byte(b: u8) -> LeafFlags {
        LeafFlags {
            fence: b & FENCE != 0,
        }
    }
}

impl Bsp {
    /// The `SLIPGATE_LEAFFLAGS` records, one per leaf, if the file has the lump.
    ///
    /// # Errors
    /// [`FormatError::BadLump`] when its length is not the leaf count.
    pub fn leaf_flags(&self) -> Result<Option<Vec<LeafFlags>>> {
        let Some(data) = self.bspx_lump(LUMP_NAME) else {
            return Ok(None);
        };
        if data.len() != self.leafs.len() {
            return Err(FormatError::BadLump {
                lump: LUMP_NAME,
                detail: format!("{} records for {} leaves", data.len(), self.leafs.len()),
            });
        }
        Ok(Some(
            data.iter().map(|&b| LeafFlags::from_byte(b)).collect(),
        ))
    }

    /// Stores `flags` (one per leaf) as the `SLIPGATE_LEAFFLAGS` lump, replacing any earlier
    /// one; with no flag set on any leaf the lump is left out.
    pub fn set_leaf_flags(&mut self, flags: &[LeafFlags]) {
        if flags.iter().all(|f| *f == LeafFlags::default()) {
            self.remove_bspx_lump(LUMP_NAME);
            return;
        }
        self.set_bspx_lump(LUMP_NAME, flags.iter().map(|f| f.byte()).collect());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsp::Leaf;

    fn bsp_with_leaves(n: usize) -> Bsp {
        Bsp {
            leafs: vec![Leaf::SHARED_SOLID; n],
            ..Bsp::default()
        }
    }

    #[test]
    fn flags_round_trip_through_the_file() {
        let mut bsp = bsp_with_leaves(3);
        assert_eq!(bsp.leaf_flags().expect("no lump"), None);
        let fence = LeafFlags { fence: true };
        let flags = [LeafFlags::default(), fence, LeafFlags::default()];
        bsp.set_leaf_flags(&flags);
        bsp.set_leaf_flags(&flags);
        assert_eq!(bsp.bspx.len(), 1, "replaced, not added");
        let read = Bsp::read(&bsp.write().expect("write")).expect("read");
        assert_eq!(read.leaf_flags().expect("lump"), Some(flags.to_vec()));
        bsp.set_leaf_flags(&[LeafFlags::default(); 3]);
        assert!(bsp.bspx.is_empty(), "no flags, no lump");
    }

    #[test]
    fn a_lump_of_another_length_is_an_error_and_reserved_bits_read_as_zero() {
        let mut bsp = bsp_with_leaves(2);
        bsp.set_bspx_lump(LUMP_NAME, vec![1, 0, 1]);
        assert!(bsp.leaf_flags().is_err(), "3 records for 2 leaves");
        bsp.set_bspx_lump(LUMP_NAME, vec![0xfe, 0xff]);
        let read = bsp.leaf_flags().expect("lump").expect("present");
        assert_eq!(read, [LeafFlags::default(), LeafFlags { fence: true }]);
    }
}
